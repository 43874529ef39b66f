#include <filesystem>

#include <gtest/gtest.h>

#include "core/image.h"
#include "core/workspace.h"
#include "tests/cli_runner.h"
#include "tests/temp_dir.h"
#include "tests/viewer/viewer_test_util.h"

namespace parallax {
namespace {
namespace fs = std::filesystem;

const fs::path kSmall = fs::path(PARALLAX_SOURCE_DIR) / "example_images" / "small";

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

}  // namespace
}  // namespace parallax
