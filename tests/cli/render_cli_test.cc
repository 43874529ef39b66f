// `parallax render` through the real executable: outputs, the leave-out of depth estimation,
// and its error paths.
#include <fstream>
#include <tuple>
#include <map>
#include <sstream>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>
#include <opencv2/calib3d.hpp>
#include <opencv2/imgproc.hpp>

#include "core/atomic_file.h"
#include "core/depth_map.h"
#include "core/image.h"
#include "core/image_metrics.h"
#include "core/workspace.h"
#include "geometry/obj.h"
#include "tests/cli_runner.h"
#include "tests/temp_dir.h"
#include "tests/test_paths.h"

namespace parallax {
namespace {

namespace fs = std::filesystem;

const fs::path kSmall = SourceDir() / "example_images" / "small";

std::vector<std::string> Lines(const std::string& text) {
  std::vector<std::string> lines;
  std::istringstream stream(text);
  for (std::string line; std::getline(stream, line);) lines.push_back(line);
  return lines;
}

std::map<std::string, nlohmann::json> ReportStages(const fs::path& out) {
  const nlohmann::json report = nlohmann::json::parse(ReadFileBytes(out / "report.json"));
  std::map<std::string, nlohmann::json> stages;
  for (const nlohmann::json& stage : report.at("render").at("stages")) stages[stage.at("name")] = stage;
  return stages;
}

// Sum over render.csv's rows of the hole ratio before filling (third column).
double HoleRatioSum(const fs::path& out) {
  const std::vector<std::string> rows = Lines(ReadFileBytes(out / "render.csv"));
  double sum = 0;
  for (size_t i = 1; i < rows.size(); ++i) {
    std::istringstream row(rows[i]);
    std::string name, sources, ratio;
    std::getline(row, name, ',');
    std::getline(row, sources, ',');
    std::getline(row, ratio, ',');
    sum += std::stod(ratio);
  }
  return sum;
}

TEST(RenderCli, SceneFolderNovelCamerasWriteImagesMasksDepthAndCsv) {
  const TempDir dir;
  const CliResult result = RunParallax("render " + Quote(kSmall.string()) + " --cameras " +
                                       Quote((kSmall / "novel" / "sparse").string()) + " --out " +
                                       Quote(dir.Path().string()) + " --sources 4");
  ASSERT_EQ(result.exit_code, 0) << result.output;
  const std::vector<std::string> csv = Lines(ReadFileBytes(dir.Path() / "render.csv"));
  ASSERT_EQ(csv.size(), 5u);  // Header + 4 novel views.
  EXPECT_EQ(csv[0].rfind("name,sources,hole_ratio,hole_ratio_filled,", 0), 0u) << csv[0];
  for (const std::string name : {"novel_0000", "novel_0001", "novel_0002", "novel_0003"}) {
    const Image color = ReadImage(dir.Path() / (name + std::string(".png")));
    EXPECT_EQ(color.Width(), 320);
    EXPECT_EQ(color.Height(), 240);
    const Image holes = ReadImage(dir.Path() / (name + std::string(".holes.png")));
    EXPECT_EQ(holes.Channels(), 1);
    const DepthMap depth = ReadDepthExr(dir.Path() / (name + std::string(".depth.exr")));
    EXPECT_EQ(depth.Width(), 320);
  }
}

TEST(RenderCli, WorkspaceWithoutDepthEstimatesOnlyTheSourcesItUses) {
  const TempDir dir;
  const fs::path workspace = dir.Path() / "ws";
  const CliResult sfm = RunParallax(
      "reconstruct " + Quote((kSmall / "images").string()) + " " + Quote(workspace.string()) +
      " --known-cameras " + Quote((kSmall / "gt" / "sparse").string()) + " --no-depth");
  ASSERT_EQ(sfm.exit_code, 0) << sfm.output;
  ASSERT_FALSE(fs::exists(Workspace(workspace).DepthDir()));
  const CliResult render = RunParallax("render " + Quote(workspace.string()) +
                                       " --path between:0003.png,0005.png,2 --sources 2 --out " +
                                       Quote((dir.Path() / "out").string()));
  ASSERT_EQ(render.exit_code, 0) << render.output;
  EXPECT_NE(render.output.find("the other views are not needed"), std::string::npos)
      << render.output;
  size_t maps = 0;
  for (const auto& entry : fs::directory_iterator(Workspace(workspace).DepthDir())) {
    maps += entry.path().string().ends_with(".confidence.exr") ? 0 : 1;
  }
  EXPECT_GE(maps, 2u);
  EXPECT_LE(maps, 4u) << "only the sources of two frames between 0003 and 0005";
  EXPECT_TRUE(fs::exists(dir.Path() / "out" / "between_0001.png"));
  // report.json says what ran and what was left out, and why: no fused cloud, no mesh or atlas.
  std::map<std::string, nlohmann::json> stages = ReportStages(dir.Path() / "out");
  EXPECT_FALSE(stages.at("depth").at("skipped").get<bool>());
  EXPECT_NE(stages.at("depth").at("reason").get<std::string>().find(" of 12 views"), std::string::npos);
  // The render's depth is a stage of the workspace's graph, cached like reconstruct's.
  const nlohmann::json cache = nlohmann::json::parse(ReadFileBytes(Workspace(workspace).Stages()));
  EXPECT_TRUE(cache.contains("depth")) << cache.dump();
  EXPECT_TRUE(cache.contains("undistort")) << cache.dump();
  EXPECT_NE(cache.value("depth", ""), cache.value("undistort", "")) << cache.dump();
  EXPECT_TRUE(stages.at("fusion").at("skipped").get<bool>());
  EXPECT_TRUE(stages.at("mesh").at("skipped").get<bool>());
  EXPECT_NE(stages.at("mesh").at("reason").get<std::string>().find("texture atlas"), std::string::npos);
  EXPECT_NE(stages.at("sources").at("reason").get<std::string>().find(" of 12 source views"), std::string::npos);
  EXPECT_FALSE(fs::exists(Workspace(workspace).MeshDir())) << "the atlas is never made for novel views";
  EXPECT_TRUE(stages.at("depth_holes").at("skipped").get<bool>());
  EXPECT_NE(stages.at("depth_holes").at("reason").get<std::string>().find("mesh.obj"), std::string::npos);
  // How much of the frames the fill made, and where most.
  EXPECT_NE(stages.at("fill").at("reason").get<std::string>().find("% of each frame filled on average, most in between_000"),
            std::string::npos)
      << stages.at("fill").dump();

  // With a mesh in the workspace (here the ground plane, z = 0 in the known cameras' frame),
  // the pixels the depth maps have no depth for take the mesh's: fewer holes.
  TriangleMesh ground;
  ground.vertices = {{-20, -20, 0}, {20, -20, 0}, {20, 20, 0}, {-20, 20, 0}};
  ground.triangles = {{0, 1, 2}, {0, 2, 3}};
  ground.corner_uvs = {{0, 0}, {1, 0}, {1, 1}, {0, 0}, {1, 1}, {0, 1}};
  ground.atlas = Image(2, 2, 3);
  WriteTexturedMesh(Workspace(workspace).MeshDir(), ground);
  const CliResult with_mesh = RunParallax("render " + Quote(workspace.string()) +
                                          " --path between:0003.png,0005.png,2 --sources 2 --out " +
                                          Quote((dir.Path() / "out_mesh").string()));
  ASSERT_EQ(with_mesh.exit_code, 0) << with_mesh.output;
  stages = ReportStages(dir.Path() / "out_mesh");
  EXPECT_FALSE(stages.at("depth_holes").at("skipped").get<bool>());
  const std::string filled = stages.at("depth_holes").at("reason").get<std::string>();
  EXPECT_EQ(filled.rfind("filled ", 0), 0u) << filled;
  EXPECT_GT(std::stod(filled.substr(7)), 0.5) << filled;  // Percent of the sources' pixels.
  EXPECT_LT(HoleRatioSum(dir.Path() / "out_mesh"), HoleRatioSum(dir.Path() / "out"));
}

// `image` (a photo of the small scene's PINHOLE 280 280 160 120 camera) as a camera with the
// OpenCV distortion coefficients `distortion` would have seen it: each distorted pixel takes
// the photo at its undistorted position (OpenCV's model, not parallax's). `inside` marks the
// pixels whose position lies in the photo.
Image DistortedLike(const Image& image, const std::vector<double>& distortion, std::vector<uint8_t>* inside) {
  const int width = image.Width(), height = image.Height();
  const cv::Matx33d k(280, 0, 160, 0, 280, 120, 0, 0, 1);
  std::vector<cv::Point2d> pixels;
  for (int y = 0; y < height; ++y) {
    for (int x = 0; x < width; ++x) pixels.emplace_back(x + 0.5, y + 0.5);
  }
  std::vector<cv::Point2d> undistorted;
  cv::undistortPoints(pixels, undistorted, k, distortion, cv::noArray(), k,
                      cv::TermCriteria(cv::TermCriteria::COUNT | cv::TermCriteria::EPS, 50, 1e-12));
  cv::Mat map_x(height, width, CV_32F), map_y(height, width, CV_32F);
  inside->assign(pixels.size(), 0);
  for (size_t i = 0; i < pixels.size(); ++i) {
    map_x.at<float>(static_cast<int>(i)) = static_cast<float>(undistorted[i].x - 0.5);
    map_y.at<float>(static_cast<int>(i)) = static_cast<float>(undistorted[i].y - 0.5);
    (*inside)[i] = undistorted[i].x >= 1 && undistorted[i].y >= 1 && undistorted[i].x <= width - 1 &&
                   undistorted[i].y <= height - 1;
  }
  const cv::Mat source(height, width, CV_32FC3, const_cast<float*>(image.Pixels().data()));
  Image out(width, height, 3);
  cv::Mat target(height, width, CV_32FC3, out.Pixels().data());
  cv::remap(source, target, map_x, map_y, cv::INTER_LINEAR, cv::BORDER_REPLICATE);
  return out;
}

TEST(RenderCli, CamerasWithLensDistortionAreRenderedThroughIt) {
  const TempDir dir;
  const fs::path out = dir.Path() / "out";
  ASSERT_EQ(RunParallax("render " + Quote(kSmall.string()) + " --cameras " +
                        Quote((kSmall / "novel" / "sparse").string()) + " --out " + Quote((out / "pinhole").string()))
                .exit_code,
            0);
  const Image truth = ReadImage(kSmall / "novel" / "images" / "novel_0000.png");
  const Image pinhole = ReadImage(out / "pinhole" / "novel_0000.png");
  const double pinhole_psnr = Psnr(pinhole, truth);
  // About 10 px of distortion at the corners.
  const std::vector<std::tuple<std::string, std::string, std::vector<double>>> models = {
      {"SIMPLE_RADIAL", "280 160 120 0.1", {0.1, 0, 0, 0}},
      {"RADIAL", "280 160 120 0.08 0.05", {0.08, 0.05, 0, 0}},
      {"OPENCV", "280 280 160 120 0.08 0.02 0.002 -0.003", {0.08, 0.02, 0.002, -0.003}}};
  for (const auto& [model, params, distortion] : models) {
    SCOPED_TRACE(model);
    const fs::path cameras = dir.Path() / model;
    fs::copy(kSmall / "novel" / "sparse", cameras);
    std::ofstream(cameras / "cameras.txt") << "1 " << model << " 320 240 " << params << "\n";
    const CliResult result = RunParallax("render " + Quote(kSmall.string()) + " --cameras " +
                                         Quote(cameras.string()) + " --out " + Quote((out / model).string()));
    ASSERT_EQ(result.exit_code, 0) << result.output;
    std::vector<uint8_t> inside;
    const Image distorted_truth = DistortedLike(truth, distortion, &inside);
    const double psnr = Psnr(ReadImage(out / model / "novel_0000.png"), distorted_truth, inside);
    // As close to the distorted photo as the pinhole render is to the photo, and far closer
    // than the pinhole render itself (what ignoring the distortion would give). Measured:
    // 38.2 dB for each model, the pinhole render 36.4 dB to the photo and 26.9-28.0 dB to the
    // distorted photo.
    EXPECT_GT(psnr, pinhole_psnr - 1.5);
    EXPECT_GT(psnr, Psnr(pinhole, distorted_truth, inside) + 6);
    const Image depth = ReadImage(out / model / "novel_0000.depth.exr");
    EXPECT_EQ(depth.Width(), 320);
    EXPECT_EQ(depth.Height(), 240);
  }
}

// Held-out photos taken through a lens with distortion, and their cameras saying so: evaluate
// renders each through its distortion and scores it against the photo as taken.
TEST(RenderCli, EvaluateScoresHeldOutCamerasWithDistortion) {
  const TempDir dir;
  const fs::path scene = dir.Path() / "scene";
  fs::copy(kSmall, scene, fs::copy_options::recursive);
  const fs::path workspace = dir.Path() / "ws";
  ASSERT_EQ(RunParallax("reconstruct " + Quote((scene / "images").string()) + " " + Quote(workspace.string()) +
                        " --known-cameras " + Quote((scene / "gt" / "sparse").string()) + " --no-depth")
                .exit_code,
            0);
  const auto novel_psnr = [&] {
    const CliResult result = RunParallax("evaluate " + Quote(workspace.string()) + " --gt " + Quote(scene.string()) +
                                         " --gt-sources --novel-only");
    EXPECT_EQ(result.exit_code, 0) << result.output;
    std::ifstream file(workspace / "evaluation.json");
    return nlohmann::json::parse(file)["novel"]["psnr_mean"].get<double>();
  };
  const double pinhole = novel_psnr();
  // The photos as a lens with k1 = 0.1 takes them (about 10 px at the corners).
  for (const auto& entry : fs::directory_iterator(scene / "novel" / "images")) {
    std::vector<uint8_t> inside;
    WriteImage(entry.path(), DistortedLike(ReadImage(entry.path()), {0.1, 0, 0, 0}, &inside), PixelFormat::kUint8);
  }
  const double distortion_ignored = novel_psnr();
  std::ofstream(scene / "novel" / "sparse" / "cameras.txt") << "1 SIMPLE_RADIAL 320 240 280 160 120 0.1\n";
  const double distorted = novel_psnr();
  // Measured: pinhole 31.67 dB; the distorted photos 25.06 dB with pinhole cameras, 32.84 dB
  // with their distortion.
  EXPECT_GT(distorted, pinhole - 1.5);
  EXPECT_GT(distorted, distortion_ignored + 4);
}

TEST(RenderCli, BadInputExitsTwoAndNamesTheProblem) {
  const TempDir dir;
  const CliResult empty = RunParallax("render " + Quote(dir.Path().string()) +
                                      " --path orbit:3 --out " + Quote((dir.Path() / "o").string()));
  EXPECT_EQ(empty.exit_code, 2) << empty.output;
  EXPECT_NE(empty.output.find("neither a workspace"), std::string::npos) << empty.output;
  const CliResult path = RunParallax("render " + Quote(kSmall.string()) +
                                     " --path spiral:3 --out " + Quote((dir.Path() / "o").string()));
  EXPECT_EQ(path.exit_code, 2) << path.output;
  EXPECT_NE(path.output.find("expected orbit:N"), std::string::npos) << path.output;
  const CliResult name = RunParallax("render " + Quote(kSmall.string()) +
                                     " --path between:0000.png,nope.png,3 --out " +
                                     Quote((dir.Path() / "o").string()));
  EXPECT_EQ(name.exit_code, 2) << name.output;
  EXPECT_NE(name.output.find("no source image named 'nope.png'"), std::string::npos) << name.output;
  const CliResult no_cameras =
      RunParallax("render " + Quote(kSmall.string()) + " --out " + Quote((dir.Path() / "o").string()));
  EXPECT_EQ(no_cameras.exit_code, 1) << no_cameras.output;
  // Cameras no render can serve: beyond the image size limit, or a distortion that folds every
  // border pixel away.
  for (const auto& [camera, expected] : std::vector<std::pair<std::string, std::string>>{
           {"1 PINHOLE 100000 100000 280 280 160 120", "is 100000x100000, over the 128 MP"},
           {"1 SIMPLE_RADIAL 320 240 280 160 120 -50", "cannot be rendered"}}) {
    const fs::path cameras = dir.Path() / "cameras";
    fs::remove_all(cameras);
    fs::copy(kSmall / "novel" / "sparse", cameras);
    std::ofstream(cameras / "cameras.txt") << camera << "\n";
    const CliResult result = RunParallax("render " + Quote(kSmall.string()) + " --cameras " + Quote(cameras.string()) +
                                         " --out " + Quote((dir.Path() / "o").string()));
    EXPECT_EQ(result.exit_code, 2) << result.output;
    EXPECT_NE(result.output.find(expected), std::string::npos) << result.output;
  }
}

}  // namespace
}  // namespace parallax
