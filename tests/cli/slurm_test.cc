// `reconstruct --executor slurm` and `render --executor slurm` on a real one-node Slurm
// cluster (scripts/slurm-cluster: munged, slurmctld and slurmd on localhost), against local
// runs of the same workspace.
#include <filesystem>
#include <fstream>
#include <map>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>
#include <unistd.h>

#include "tests/cli_runner.h"
#include "tests/temp_dir.h"
#include "tests/test_paths.h"

namespace parallax {
namespace {

namespace fs = std::filesystem;

const fs::path kSmallImages = SourceDir() / "example_images" / "small" / "images";
const fs::path kClusterScript = SourceDir() / "scripts" / "slurm-cluster";

// The cluster for as long as it lives: stopped whatever happens to the test.
class SlurmCluster {
 public:
  explicit SlurmCluster(const fs::path& dir) : dir_(dir) {
    const CliResult started = RunCommand(Quote(kClusterScript.string()) + " start " + Quote(dir.string()));
    up_ = started.exit_code == 0;
    message_ = started.output;
  }
  ~SlurmCluster() { RunCommand(Quote(kClusterScript.string()) + " stop " + Quote(dir_.string())); }
  SlurmCluster(const SlurmCluster&) = delete;
  SlurmCluster& operator=(const SlurmCluster&) = delete;

  bool Up() const { return up_; }
  const std::string& Message() const { return message_; }
  std::string Environment() const { return "SLURM_CONF=" + Quote((dir_ / "slurm.conf").string()); }

 private:
  fs::path dir_;
  bool up_ = false;
  std::string message_;
};

std::string ReadBytes(const fs::path& path) {
  std::ifstream file(path, std::ios::binary);
  return {std::istreambuf_iterator<char>(file), std::istreambuf_iterator<char>()};
}

// Every file of the outputs that a local run writes the same every time, by relative path:
// the depth maps, the fused cloud and the gains. Not the mesh: colmap's poisson_mesher is
// multi-threaded, and two local runs differ in their bytes too (same triangle count).
std::map<std::string, std::string> Outputs(const fs::path& workspace) {
  std::map<std::string, std::string> files;
  for (const char* folder : {"depth", "stereo"}) {
    for (const auto& entry : fs::recursive_directory_iterator(workspace / folder)) {
      if (entry.is_regular_file()) files[fs::relative(entry.path(), workspace).string()] = ReadBytes(entry.path());
    }
  }
  for (const char* file : {"fused.ply", "color_gains.json"}) files[file] = ReadBytes(workspace / file);
  // The depth stage's summary, less its timings.
  nlohmann::json views = nlohmann::json::parse(files.at("depth/views.json"));
  views.erase("photometric_seconds");
  views.erase("geometric_seconds");
  files["depth/views.json"] = views.dump();
  return files;
}

// The files a render writes, by name: every image, and render.csv less its timings (the
// last column).
std::map<std::string, std::string> RenderedFrames(const fs::path& out) {
  std::map<std::string, std::string> files;
  for (const auto& entry : fs::directory_iterator(out)) {
    const std::string name = entry.path().filename().string();
    if (name.ends_with(".png") || name.ends_with(".exr")) files[name] = ReadBytes(entry.path());
  }
  std::ifstream csv(out / "render.csv");
  for (std::string line; std::getline(csv, line);) files["render.csv"] += line.substr(0, line.rfind(',')) + "\n";
  return files;
}

nlohmann::json ReadJson(const fs::path& path) {
  std::ifstream file(path);
  return nlohmann::json::parse(file);
}

TEST(Slurm, JobArraysOnARealClusterWriteWhatALocalRunWrites) {
  if (::geteuid() != 0) GTEST_SKIP() << "slurmd runs jobs as their user and needs root here";
  const TempDir dir;
  const SlurmCluster cluster(dir.Path() / "cluster");
  if (!cluster.Up()) GTEST_SKIP() << "no one-node Slurm cluster: " << cluster.Message();

  // One SfM for both: colmap's threads need not give the same model twice.
  const fs::path local = dir.Path() / "local";
  const std::string photos = Quote(kSmallImages.string());
  const CliResult sfm = RunParallax("reconstruct " + photos + " " + Quote(local.string()) + " --quality fast --no-depth");
  ASSERT_EQ(sfm.exit_code, 0) << sfm.output;
  const fs::path on_cluster = dir.Path() / "on cluster";
  fs::copy(local, on_cluster, fs::copy_options::recursive);

  const CliResult local_run = RunParallax("reconstruct " + photos + " " + Quote(local.string()) + " --quality fast");
  ASSERT_EQ(local_run.exit_code, 0) << local_run.output;
  const CliResult cluster_run =
      RunParallax("reconstruct " + photos + " " + Quote(on_cluster.string()) +
                      " --quality fast --executor slurm --slurm-block-size 2 --slurm-wait --sbatch '--time=10'",
                  cluster.Environment());
  ASSERT_EQ(cluster_run.exit_code, 0) << cluster_run.output;
  EXPECT_NE(cluster_run.output.find("slurm: submitted jobs"), std::string::npos) << cluster_run.output;

  // 12 views in blocks of 2: six photometric and six geometric tasks, each with its log.
  int task_logs = 0;
  for (const auto& entry : fs::directory_iterator(on_cluster / "slurm" / "logs")) {
    const std::string name = entry.path().filename().string();
    task_logs += name.starts_with("photometric-") || name.starts_with("geometric-");
    if (name.starts_with("photometric-")) {
      EXPECT_NE(ReadBytes(entry.path()).find("2 view(s) in block"), std::string::npos) << name;
    }
  }
  EXPECT_EQ(task_logs, 12);
  EXPECT_EQ(ReadJson(on_cluster / "stages.json"), ReadJson(local / "stages.json"));
  const auto expected = Outputs(local);
  const auto actual = Outputs(on_cluster);
  EXPECT_GT(expected.size(), 60u);
  const double triangles = ReadJson(local / "mesh" / "summary.json")["triangles"];
  EXPECT_NEAR(ReadJson(on_cluster / "mesh" / "summary.json")["triangles"].get<double>(), triangles, 0.01 * triangles);
  ASSERT_EQ(actual.size(), expected.size());
  for (const auto& [name, bytes] : expected) {
    ASSERT_TRUE(actual.contains(name)) << name;
    EXPECT_TRUE(actual.at(name) == bytes) << name << " differs from the local run's";
  }

  // Submitted again, every job finds its work done.
  const CliResult again =
      RunParallax("reconstruct " + photos + " " + Quote(on_cluster.string()) +
                      " --quality fast --executor slurm --slurm-block-size 2 --slurm-wait",
                  cluster.Environment());
  ASSERT_EQ(again.exit_code, 0) << again.output;
  EXPECT_TRUE(Outputs(on_cluster) == expected);

  // A camera path rendered as a job array, 2 frames a task (the last one frame), writes the
  // local render's images and rows.
  const fs::path frames_local = dir.Path() / "frames local";
  const fs::path frames_cluster = dir.Path() / "frames on cluster";
  const std::string render = "render " + Quote(local.string()) + " --path orbit:5 --out ";
  const CliResult local_render = RunParallax(render + Quote(frames_local.string()));
  ASSERT_EQ(local_render.exit_code, 0) << local_render.output;
  const CliResult cluster_render =
      RunParallax(render + Quote(frames_cluster.string()) + " --executor slurm --slurm-block-size 2 --slurm-wait",
                  cluster.Environment());
  ASSERT_EQ(cluster_render.exit_code, 0) << cluster_render.output;
  int frame_logs = 0;
  for (const auto& entry : fs::directory_iterator(frames_cluster / "slurm" / "logs")) {
    frame_logs += entry.path().filename().string().starts_with("frames-");
  }
  EXPECT_EQ(frame_logs, 3);
  const auto frames = RenderedFrames(frames_local);
  EXPECT_EQ(frames.size(), 5u * 3 + 1);  // Color, holes and depth of each frame; render.csv.
  EXPECT_TRUE(RenderedFrames(frames_cluster) == frames);
  const nlohmann::json report = ReadJson(frames_cluster / "report.json")["render"];
  EXPECT_EQ(report["blocks"].size(), 3u);
  EXPECT_EQ(report["stages"].back()["name"], "frames");
}

// A failed task stops the chain: the jobs after it are cancelled, not left pending, and
// --slurm-wait exits with the failure.
TEST(Slurm, AFailedTaskCancelsTheJobsAfterIt) {
  if (::geteuid() != 0) GTEST_SKIP() << "slurmd runs jobs as their user and needs root here";
  const TempDir dir;
  const SlurmCluster cluster(dir.Path() / "cluster");
  if (!cluster.Up()) GTEST_SKIP() << "no one-node Slurm cluster: " << cluster.Message();
  const fs::path workspace = dir.Path() / "ws";
  // The SfM job fails: colmap is not there.
  const CliResult run = RunParallax("reconstruct " + Quote(kSmallImages.string()) + " " + Quote(workspace.string()) +
                                        " --executor slurm --slurm-wait --colmap /no/colmap",
                                    cluster.Environment());
  EXPECT_NE(run.exit_code, 0) << run.output;
  EXPECT_NE(run.output.find("slurm job"), std::string::npos) << run.output;
  EXPECT_NE(run.output.find("ended FAILED"), std::string::npos) << run.output;
  const CliResult queue = RunCommand(cluster.Environment() + " squeue -h");
  EXPECT_EQ(queue.output, "") << "jobs left in the queue";
}

}  // namespace
}  // namespace parallax
