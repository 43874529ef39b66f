// No data lost: `parallax reconstruct` killed with SIGKILL in the middle of a stage leaves no
// truncated file under a final name, and a re-run completes, redoing only what was cut short;
// while it runs, no other process writes the workspace.
#include <csignal>
#include <chrono>
#include <fstream>
#include <map>
#include <thread>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>
#include <spawn.h>
#include <sys/wait.h>
#include <unistd.h>

#include "core/atomic_file.h"
#include "core/depth_map.h"
#include "core/image.h"
#include "core/sparse_model.h"
#include "core/workspace.h"
#include "tests/cli_runner.h"
#include "tests/temp_dir.h"
#include "tests/test_paths.h"

extern char** environ;

namespace parallax {
namespace {

namespace fs = std::filesystem;

const fs::path kSmallImages = SourceDir() / "example_images" / "small" / "images";

size_t CountFiles(const fs::path& dir, const std::string& extension) {
  if (!fs::is_directory(dir)) return 0;
  size_t count = 0;
  for (const auto& entry : fs::directory_iterator(dir)) {
    count += entry.path().extension() == extension && entry.path().string().find(".tmp") == std::string::npos;
  }
  return count;
}

// Every file under a final name reads back whole in its format.
void ExpectEveryFileComplete(const fs::path& workspace) {
  for (const auto& entry : fs::recursive_directory_iterator(workspace)) {
    if (!entry.is_regular_file()) continue;
    const fs::path& path = entry.path();
    if (path.string().find(".tmp") != std::string::npos) continue;  // Not a final name.
    const std::string extension = path.extension().string();
    SCOPED_TRACE(path.string());
    if (extension == ".exr" || extension == ".png") {
      EXPECT_NO_THROW(ReadImage(path));
    } else if (extension == ".json") {
      EXPECT_TRUE(nlohmann::json::accept(ReadFileBytes(path)));
    } else if (extension == ".bin" && path.parent_path().parent_path().filename() == "stereo") {
      EXPECT_NO_THROW(ReadColmapArray(path));
    }
  }
  if (fs::exists(workspace / "sparse" / "images.bin")) {
    EXPECT_NO_THROW(ReadSparseModel(workspace / "sparse"));
  }
}

TEST(KillResume, SigkillDuringDepthLosesNothingAndTheRerunCompletes) {
  const TempDir dir;
  const fs::path workspace = dir.Path() / "ws";
  const std::string executable = ParallaxExecutable();
  const std::string photos = kSmallImages.string(), ws = workspace.string();
  const char* argv[] = {executable.c_str(), "reconstruct", photos.c_str(), ws.c_str(),
                        "--no-mesh", nullptr};
  posix_spawnattr_t attributes;
  posix_spawnattr_init(&attributes);
  // Its own process group, so the kill also reaches a running colmap.
  posix_spawnattr_setflags(&attributes, POSIX_SPAWN_SETPGROUP);
  posix_spawnattr_setpgroup(&attributes, 0);
  pid_t pid = 0;
  ASSERT_EQ(posix_spawn(&pid, executable.c_str(), nullptr, &attributes,
                        const_cast<char* const*>(argv), environ), 0);
  posix_spawnattr_destroy(&attributes);

  // One writer: once the run holds the workspace, a second reconstruct is turned away, naming
  // the run (and a render, below, once the workspace has cameras to render from).
  const std::string holder = "reconstruct " + std::to_string(pid);
  const fs::path lock_file = workspace / ".lock";
  const auto lock_deadline = std::chrono::steady_clock::now() + std::chrono::minutes(5);
  while (std::chrono::steady_clock::now() < lock_deadline &&
         !(fs::exists(lock_file) && ReadFileBytes(lock_file).starts_with(holder))) {
    std::this_thread::sleep_for(std::chrono::milliseconds(10));
  }
  const std::string refusal = "is being written by reconstruct (pid " + std::to_string(pid) + ")";
  const CliResult second = RunParallax("reconstruct " + Quote(photos) + " " + Quote(ws) + " --no-mesh");
  EXPECT_EQ(second.exit_code, 2) << second.output;
  EXPECT_NE(second.output.find(refusal), std::string::npos) << second.output;

  // Kill once the depth stage has written some of its 12 maps, not all. The deadline only
  // bounds a failing run: about 10 s reach that point, the sanitized build on a busy machine
  // took more than 3 minutes.
  const auto deadline = std::chrono::steady_clock::now() + std::chrono::minutes(20);
  bool mid_depth = false;
  while (std::chrono::steady_clock::now() < deadline) {
    const size_t maps = CountFiles(Workspace(workspace).DepthDir(), ".exr");
    if (maps >= 2 && CountFiles(Workspace(workspace).DepthDir(), ".json") == 0) {
      mid_depth = true;
      break;
    }
    int status = 0;
    if (waitpid(pid, &status, WNOHANG) == pid) break;  // Finished early: nothing to kill.
    std::this_thread::sleep_for(std::chrono::milliseconds(20));
  }
  if (mid_depth) {
    const CliResult render =
        RunParallax("render " + Quote(ws) + " --path orbit:2 --out " + Quote((dir.Path() / "render").string()));
    EXPECT_EQ(render.exit_code, 2) << render.output;
    EXPECT_NE(render.output.find(refusal), std::string::npos) << render.output;
  }
  ::kill(-pid, SIGKILL);
  waitpid(pid, nullptr, 0);
  ASSERT_TRUE(mid_depth) << "the depth stage was never caught half-done";
  const std::string stages = ReadFileBytes(workspace / "stages.json");
  EXPECT_EQ(stages.find("\"depth\""), std::string::npos) << "an interrupted stage is not done";
  ExpectEveryFileComplete(workspace);
  // What the killed run finished: every view's PatchMatch estimate (the maps are written by the
  // filter, after the last estimate) and some views' filtered maps (a report each, written
  // after the maps).
  const fs::path estimates = Workspace(workspace).StereoEstimates();
  const size_t estimated = CountFiles(estimates, ".bin"), filtered = CountFiles(estimates, ".json");
  EXPECT_EQ(estimated, 12u);
  EXPECT_GE(filtered, 1u);

  // The killed run's lock went with it.
  const CliResult rerun = RunParallax("reconstruct " + Quote(photos) + " " + Quote(ws) + " --no-mesh");
  ASSERT_EQ(rerun.exit_code, 0) << rerun.output;
  // SfM stages were complete and are skipped; the depth stage runs again.
  const nlohmann::json report = nlohmann::json::parse(ReadFileBytes(workspace / "report.json"));
  std::map<std::string, bool> skipped;
  for (const nlohmann::json& stage : report.at("reconstruct").at("stages")) {
    skipped[stage.at("name").get<std::string>()] = stage.at("skipped").get<bool>();
  }
  EXPECT_TRUE(skipped.at("mapper"));
  EXPECT_TRUE(skipped.at("undistort"));
  EXPECT_FALSE(skipped.at("depth"));
  // The depth stage resumes: what was written whole is kept, so at most the view in flight
  // when the kill came is computed twice.
  const nlohmann::json& depth = report.at("reconstruct").at("depth");
  EXPECT_EQ(depth.at("resumed_estimates").get<size_t>(), estimated);
  EXPECT_EQ(depth.at("resumed_filtered").get<size_t>(), filtered);
  EXPECT_NE(rerun.output.find("depth: resumed a run cut short: kept " + std::to_string(estimated)),
            std::string::npos)
      << rerun.output;
  EXPECT_EQ(CountFiles(Workspace(workspace).DepthDir(), ".exr"), 24u);  // Depth + confidence per view.
  ExpectEveryFileComplete(workspace);
}

// Processes whose command line names `path`.
size_t ProcessesNaming(const std::string& path) {
  size_t count = 0;
  for (const auto& entry : fs::directory_iterator("/proc")) {
    const std::string name = entry.path().filename().string();
    if (name.find_first_not_of("0123456789") != std::string::npos) continue;
    std::ifstream file(entry.path() / "cmdline", std::ios::binary);
    const std::string command_line((std::istreambuf_iterator<char>(file)), {});
    count += command_line.find(path) != std::string::npos;
  }
  return count;
}

// SIGTERM while colmap extracts features: the run stops at once with 128 + 15, colmap with
// it, no temporary file is left, and the next run resumes.
TEST(KillResume, SigtermStopsColmapRemovesTemporariesAndTheRerunResumes) {
  const TempDir dir;
  const fs::path workspace = dir.Path() / "ws";
  const std::string executable = ParallaxExecutable();
  const std::string photos = kSmallImages.string(), ws = workspace.string();
  const char* argv[] = {executable.c_str(), "reconstruct", photos.c_str(), ws.c_str(), "--no-depth", nullptr};
  pid_t pid = 0;
  ASSERT_EQ(posix_spawn(&pid, executable.c_str(), nullptr, nullptr, const_cast<char* const*>(argv), environ), 0);
  const fs::path database = Workspace(workspace).Database().string() + ".tmp";
  const auto deadline = std::chrono::steady_clock::now() + std::chrono::minutes(5);
  while (!fs::exists(database) && std::chrono::steady_clock::now() < deadline) {
    std::this_thread::sleep_for(std::chrono::milliseconds(2));
  }
  ASSERT_TRUE(fs::exists(database)) << "colmap never started";
  ::kill(pid, SIGTERM);  // parallax alone, not its process group: it must stop colmap itself.
  int status = 0;
  waitpid(pid, &status, 0);
  // At once: colmap was stopped mid-extraction, not waited for (it would have renamed its
  // database into place).
  EXPECT_FALSE(fs::exists(Workspace(workspace).Database())) << "the run waited for colmap to finish";
  ASSERT_TRUE(WIFEXITED(status));
  EXPECT_EQ(WEXITSTATUS(status), 128 + SIGTERM);
  std::this_thread::sleep_for(std::chrono::milliseconds(100));
  EXPECT_EQ(ProcessesNaming(ws), 0u) << "colmap outlived the run";
  for (const auto& entry : fs::recursive_directory_iterator(workspace)) {
    EXPECT_EQ(entry.path().string().find(".tmp"), std::string::npos) << entry.path();
  }
  ExpectEveryFileComplete(workspace);
  const CliResult rerun = RunParallax("reconstruct " + Quote(photos) + " " + Quote(ws) + " --no-depth");
  EXPECT_EQ(rerun.exit_code, 0) << rerun.output;
}

// A small file system of its own for the workspace (tmpfs, so root only), unmounted at the end.
class SmallDisk {
 public:
  explicit SmallDisk(const fs::path& where) : where_(where) {
    fs::create_directories(where);
    mounted_ = ::geteuid() == 0 &&
               std::system(("mount -t tmpfs -o size=64m tmpfs '" + where.string() + "' 2>/dev/null").c_str()) == 0;
  }
  ~SmallDisk() {
    if (mounted_) (void)std::system(("umount '" + where_.string() + "'").c_str());
  }
  bool Mounted() const { return mounted_; }
  // Takes all but `leave_kib` of the free space.
  void Fill(int64_t leave_kib) {
    const auto free_kib = static_cast<int64_t>(fs::space(where_).available / 1024);
    std::ofstream filler(where_ / "filler", std::ios::binary);
    const std::string block(1024, '\0');
    for (int64_t i = 0; i < free_kib - leave_kib; ++i) filler.write(block.data(), 1024);
  }
  void Empty() { fs::remove(where_ / "filler"); }

 private:
  fs::path where_;
  bool mounted_ = false;
};

// A full disk in colmap's stage and in parallax's own: exit 2 naming the file and the cause,
// nothing earlier lost, and once there is room the run resumes where it stopped.
TEST(KillResume, AFullDiskExitsTwoNamingThePathAndTheRerunResumes) {
  const TempDir dir;
  SmallDisk room(dir.Path() / "disk");
  if (!room.Mounted()) GTEST_SKIP() << "needs root to mount a small tmpfs";
  const fs::path workspace = dir.Path() / "disk" / "ws";
  const std::string reconstruct = "reconstruct " + Quote(kSmallImages.string()) + " " + Quote(workspace.string());

  room.Fill(100);
  const CliResult features = RunParallax(reconstruct + " --no-depth");
  EXPECT_EQ(features.exit_code, 2) << features.output;
  EXPECT_NE(features.output.find("colmap feature_extractor could not write its output: No space left on device"),
            std::string::npos)
      << features.output;
  room.Empty();
  ASSERT_EQ(RunParallax(reconstruct + " --no-depth").exit_code, 0);

  room.Fill(300);
  const CliResult depth = RunParallax(reconstruct);
  EXPECT_EQ(depth.exit_code, 2) << depth.output;
  EXPECT_NE(depth.output.find("cannot write " + (workspace / "stereo").string()), std::string::npos) << depth.output;
  EXPECT_NE(depth.output.find("No space left on device"), std::string::npos) << depth.output;
  ExpectEveryFileComplete(workspace);
  room.Empty();
  const CliResult resumed = RunParallax(reconstruct);
  ASSERT_EQ(resumed.exit_code, 0) << resumed.output;
  EXPECT_NE(resumed.output.find("mapper       skipped: inputs and options unchanged"), std::string::npos)
      << resumed.output;
  ExpectEveryFileComplete(workspace);
  EXPECT_EQ(CountFiles(workspace / "depth", ".exr"), 24u);
}

}  // namespace
}  // namespace parallax
