#include <chrono>
#include <cmath>
#include <csignal>
#include <cstdlib>
#include <filesystem>
#include <functional>
#include <string>
#include <thread>

#include <gtest/gtest.h>

#include "core/atomic_file.h"
#include "core/image.h"
#include "core/workspace.h"
#include "tests/cli_runner.h"
#include "tests/temp_dir.h"
#include "testing/viewer_scenes.h"
#include "tests/test_paths.h"

namespace parallax {
namespace {
namespace fs = std::filesystem;

const fs::path kSmall = SourceDir() / "example_images" / "small";

// A workspace holding the small scene's own geometry as mesh/, its cameras and photos.
void MakeWorkspace(const fs::path& ws) {
  const SceneDesc desc = ReadSceneJson(kSmall / "scene.json");
  const ViewerScene scene = viewer_test::SceneFromObjects(desc.objects);
  WriteTexturedMesh(Workspace(ws).MeshDir(), scene.mesh);
  fs::copy(kSmall / "gt" / "sparse", ws / "sparse", fs::copy_options::recursive);
  fs::copy(kSmall / "images", ws / "images", fs::copy_options::recursive);
}

TEST(ViewCli, ScreenshotWritesAPng) {
  const TempDir dir;
  MakeWorkspace(dir.Path() / "ws");
  const fs::path png = dir.Path() / "shot.png";
  const CliResult result = RunParallax("view " + Quote((dir.Path() / "ws").string()) + " --screenshot " +
                                       Quote(png.string()) + " --orbit 40 --size 320x200 --shadows pcf");
  ASSERT_EQ(result.exit_code, 0) << result.output;
  ASSERT_TRUE(fs::exists(png));
  EXPECT_GT(fs::file_size(png), 1000u);
  const Image image = ReadImage(png);
  EXPECT_EQ(image.Width(), 320);
  EXPECT_EQ(image.Height(), 200);

  const fs::path from_camera = dir.Path() / "camera.png";
  const CliResult camera = RunParallax("view " + Quote((dir.Path() / "ws").string()) + " --screenshot " +
                                       Quote(from_camera.string()) + " --camera 0003 --texture projective");
  ASSERT_EQ(camera.exit_code, 0) << camera.output;
  EXPECT_EQ(ReadImage(from_camera).Width(), 320);  // The source camera's own size.
}

TEST(ViewCli, BadInputExitsTwoNamingTheProblem) {
  const TempDir dir;
  const CliResult empty = RunParallax("view " + Quote(dir.Path().string()) + " --screenshot x.png");
  EXPECT_EQ(empty.exit_code, 2) << empty.output;
  EXPECT_NE(empty.output.find(dir.Path().string()), std::string::npos) << empty.output;

  MakeWorkspace(dir.Path() / "ws");
  const CliResult camera = RunParallax("view " + Quote((dir.Path() / "ws").string()) +
                                       " --screenshot x.png --camera nosuchview");
  EXPECT_EQ(camera.exit_code, 2) << camera.output;
  EXPECT_NE(camera.output.find("nosuchview"), std::string::npos) << camera.output;
  EXPECT_EQ(RunParallax("view " + Quote(dir.Path().string()) + " --shadows soft").exit_code, 1);
}

TEST(ViewCli, WindowWithoutADisplaySuggestsScreenshot) {
  const TempDir dir;
  MakeWorkspace(dir.Path() / "ws");
  const CliResult result =
      RunParallax("view " + Quote((dir.Path() / "ws").string()), "env -u DISPLAY -u WAYLAND_DISPLAY");
  EXPECT_EQ(result.exit_code, 3) << result.output;
  EXPECT_NE(result.output.find("--screenshot"), std::string::npos) << result.output;
}

// A virtual X display (Xvfb) for one test, stopped whatever happens.
class VirtualDisplay {
 public:
  VirtualDisplay() {
    int number = 90;
    while (fs::exists("/tmp/.X11-unix/X" + std::to_string(number)) ||
           fs::exists("/tmp/.X" + std::to_string(number) + "-lock")) {
      ++number;
    }
    name_ = ":" + std::to_string(number);
    const CliResult started = RunCommand("Xvfb " + name_ + " -screen 0 1024x768x24 -nolisten tcp >/dev/null 2>&1 & echo $!");
    pid_ = std::atoi(started.output.c_str());
    for (int tries = 0; tries < 100 && !Ready(); ++tries) std::this_thread::sleep_for(std::chrono::milliseconds(100));
  }
  ~VirtualDisplay() {
    if (pid_ > 0) ::kill(pid_, SIGTERM);
  }
  VirtualDisplay(const VirtualDisplay&) = delete;
  VirtualDisplay& operator=(const VirtualDisplay&) = delete;
  bool Ready() const { return RunCommand(Environment() + " xdotool getdisplaygeometry").exit_code == 0; }
  std::string Environment() const { return "DISPLAY=" + name_; }

 private:
  std::string name_;
  int pid_ = 0;
};

// Polls `condition` every 50 ms for up to `seconds`.
bool WaitFor(const std::function<bool()>& condition, double seconds = 20) {
  const auto end = std::chrono::steady_clock::now() + std::chrono::duration<double>(seconds);
  while (std::chrono::steady_clock::now() < end) {
    if (condition()) return true;
    std::this_thread::sleep_for(std::chrono::milliseconds(50));
  }
  return condition();
}

// The number after `key` in the window title, e.g. "view az 30" -> 30.
double TitleNumber(const std::string& title, const std::string& key) {
  const size_t at = title.find(key);
  return at == std::string::npos ? std::nan("") : std::atof(title.c_str() + at + key.size());
}

double MeanValue(const Image& image) {
  double sum = 0;
  for (float v : image.Pixels()) sum += static_cast<double>(v);
  return sum / static_cast<double>(image.Pixels().size());
}

double MeanAbsoluteDifference(const Image& a, const Image& b) {
  double sum = 0;
  for (size_t i = 0; i < a.Pixels().size(); ++i) sum += std::abs(static_cast<double>(a.Pixels()[i] - b.Pixels()[i]));
  return sum / static_cast<double>(a.Pixels().size());
}

// The real window (GLFW on Xvfb, llvmpipe) driven by synthetic input: each key, drag and scroll
// changes the title and the picture as the key help says, S writes the frame, Esc quits.
TEST(ViewWindow, SyntheticInputDrivesEveryControl) {
  if (RunCommand("command -v Xvfb && command -v xdotool").exit_code != 0) {
    GTEST_SKIP() << "needs Xvfb and xdotool (scripts/install-deps installs them)";
  }
  const TempDir dir;
  MakeWorkspace(dir.Path() / "ws");
  const VirtualDisplay display;
  ASSERT_TRUE(display.Ready()) << "Xvfb did not start";
  const fs::path log = dir.Path() / "view.log", exit_file = dir.Path() / "exit";
  RunCommand("(" + display.Environment() + " '" + ParallaxExecutable() + "' view " +
             Quote((dir.Path() / "ws").string()) + " --size 480x300 --motion-hold-ms 5000 --screenshot-dir " +
             Quote(dir.Path().string()) +
             " > " + Quote(log.string()) + " 2>&1; echo $? > " + Quote(exit_file.string()) + ") >/dev/null 2>&1 &");
  const auto xdo = [&](const std::string& arguments) {
    return RunCommand(display.Environment() + " xdotool " + arguments).output;
  };
  std::string window;
  ASSERT_TRUE(WaitFor([&] {
    window = xdo("search --name 'parallax view \\|'");
    return !window.empty() && window.find_first_not_of("0123456789\n") == std::string::npos;
  })) << ReadFileBytes(log);
  window = window.substr(0, window.find('\n'));
  const auto title = [&] { return xdo("getwindowname " + window); };
  const auto title_shows = [&](const std::string& text) {
    return WaitFor([&] { return title().find(text) != std::string::npos; });
  };
  const auto key = [&](const std::string& name) { xdo("key --window " + window + " " + name); };
  int shots = 0;
  const auto screenshot = [&] {
    key("s");
    const fs::path path = dir.Path() / ("view-" + std::to_string(++shots) + ".png");
    EXPECT_TRUE(WaitFor([&] { return fs::exists(path); })) << ReadFileBytes(log);
    return fs::exists(path) ? ReadImage(path) : Image();
  };
  ASSERT_TRUE(title_shows(" ms")) << title();

  key("1");
  ASSERT_TRUE(title_shows("shadows none")) << title();
  const Image unshadowed = screenshot();
  key("5");
  ASSERT_TRUE(title_shows("shadows volume")) << title();
  const Image shadowed = screenshot();
  ASSERT_FALSE(unshadowed.Empty());
  ASSERT_FALSE(shadowed.Empty());
  // Measured: 0.0044 darker on average (the shadows cover a few percent of the frame).
  EXPECT_LT(MeanValue(shadowed), MeanValue(unshadowed) - 0.002) << "shadows darken the picture";

  key("t");
  EXPECT_TRUE(title_shows("texture projective")) << title();
  key("t");
  EXPECT_TRUE(title_shows("texture shaded")) << title();
  key("t");
  EXPECT_TRUE(title_shows("texture matcap")) << title();
  key("t");
  EXPECT_TRUE(title_shows("texture atlas")) << title();
  key("Right");
  EXPECT_TRUE(title_shows("light az 50")) << title();
  key("Up");
  EXPECT_TRUE(title_shows("light az 50 el 55")) << title();
  key("h");
  EXPECT_TRUE(title_shows("| glare")) << title();
  key("h");
  EXPECT_TRUE(WaitFor([&] { return title().find("glare") == std::string::npos; })) << title();

  // A left drag of 100 pixels to the right orbits 30 degrees; the wheel zooms in by 10%.
  const double azimuth = TitleNumber(title(), "view az ");
  xdo("windowfocus " + window);
  xdo("mousemove --window " + window + " 240 150");
  bool reduced_while_moving = false;
  for (const std::string step : {"mousedown 1", "mousemove_relative 50 0", "mousemove_relative 50 0", "mouseup 1"}) {
    std::this_thread::sleep_for(std::chrono::milliseconds(200));
    xdo(step);
    // Frames within --motion-hold-ms of a motion are drawn at half resolution, and say so.
    if (step.rfind("mousemove", 0) == 0) {
      reduced_while_moving |= WaitFor([&] { return title().find("moving: half resolution") != std::string::npos; });
    }
  }
  EXPECT_TRUE(reduced_while_moving) << title();
  EXPECT_TRUE(WaitFor([&] { return title().find("moving") == std::string::npos; })) << "full detail once still";
  EXPECT_TRUE(WaitFor([&] { return std::abs(TitleNumber(title(), "view az ") - (azimuth - 30)) < 0.6; })) << title();
  const Image turned = screenshot();
  ASSERT_FALSE(turned.Empty());
  EXPECT_GT(MeanAbsoluteDifference(turned, shadowed), 0.01) << "the orbit moves the picture";
  const double distance = TitleNumber(title(), "dist ");
  xdo("click --window " + window + " 4");
  EXPECT_TRUE(WaitFor([&] { return std::abs(TitleNumber(title(), "dist ") - 0.9 * distance) < 0.01 * distance; }))
      << title();

  key("Escape");
  ASSERT_TRUE(WaitFor([&] { return fs::exists(exit_file) && fs::file_size(exit_file) > 0; }, 10)) << "Esc must quit";
  EXPECT_EQ(std::atoi(ReadFileBytes(exit_file).c_str()), 0) << ReadFileBytes(log);
  const std::string output = ReadFileBytes(log);
  EXPECT_NE(output.find("S screenshot"), std::string::npos) << "the key help is printed: " << output;
  EXPECT_NE(output.find("wrote " + (dir.Path() / "view-3.png").string()), std::string::npos) << output;
}

}  // namespace
}  // namespace parallax
