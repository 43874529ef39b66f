// Structure from motion on a stiff capture (issue: numerical stability): cameras that translate
// by a tiny baseline without rotating, looking at depths from 1 m to 1 km. COLMAP registers
// such a capture at about 0.1 px reprojection error with whatever focal length it drifted to
// (docs/design.md, measured pitfalls), which the images do not determine. parallax must flag it
// instead of passing wrong cameras on.
#include <cmath>
#include <cstdio>
#include <fstream>
#include <numbers>
#include <random>
#include <string>
#include <vector>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "core/camera.h"
#include "core/pose.h"
#include "core/progress.h"
#include "core/scene_folder.h"
#include "core/sparse_model.h"
#include "sfm/plausibility.h"
#include "pipeline/reconstruct.h"
#include "tests/cli_runner.h"
#include "tests/temp_dir.h"

namespace parallax {
namespace {

namespace fs = std::filesystem;

bool HasProblem(const PlausibilityReport& report, const std::string& text) {
  for (const std::string& problem : report.problems) {
    if (problem.find(text) != std::string::npos) return true;
  }
  return false;
}

// Points spread over depths 5..60 seen by `cams_from_world` through a 320x240 camera of focal
// length 300 px, observed with 0.2 px Gaussian noise; points seen fewer than twice are dropped.
SparseModel ObservedModel(const std::vector<Rigid3d>& cams_from_world) {
  SparseModel model;
  Camera camera;
  camera.id = 1;
  camera.model = CameraModel::kSimpleRadial;
  camera.width = 320;
  camera.height = 240;
  camera.params = {300, 160, 120, 0};
  model.AddCamera(camera);
  std::mt19937 random(7);
  std::uniform_real_distribution<double> unit(-1, 1);
  std::normal_distribution<double> noise(0, 0.2);
  std::vector<SparseImage> images(cams_from_world.size());
  for (size_t i = 0; i < images.size(); ++i) {
    images[i].id = static_cast<uint32_t>(i + 1);
    images[i].camera_id = 1;
    images[i].name = std::to_string(i) + ".png";
    images[i].cam_from_world = cams_from_world[i];
  }
  for (uint64_t id = 1; id <= 600; ++id) {
    const double depth = 5 * std::pow(12.0, 0.5 * (unit(random) + 1));  // 5..60, log-uniform.
    Point3D point;
    point.id = id;
    point.xyz = Eigen::Vector3d(0.45 * depth * unit(random), 0.35 * depth * unit(random), depth);
    std::vector<std::pair<size_t, Eigen::Vector2d>> seen;
    for (size_t i = 0; i < images.size(); ++i) {
      const auto pixel = camera.Project(images[i].cam_from_world * point.xyz);
      if (!pixel || (*pixel)[0] < 0 || (*pixel)[0] > 320 || (*pixel)[1] < 0 || (*pixel)[1] > 240) {
        continue;
      }
      seen.emplace_back(i, *pixel + Eigen::Vector2d(noise(random), noise(random)));
    }
    if (seen.size() < 2) continue;
    for (const auto& [i, pixel] : seen) {
      point.track.push_back({images[i].id, static_cast<uint32_t>(images[i].points2d.size())});
      images[i].points2d.push_back({pixel, id});
    }
    model.AddPoint3D(point);
  }
  for (SparseImage& image : images) model.AddImage(std::move(image));
  return model;
}

TEST(SfmStability, FocalLengthOfCamerasThatOnlyTranslateIsReportedUndetermined) {
  // Eight cameras over 60 cm looking the same way: any focal length fits (with the lateral
  // coordinates scaled to match) ...
  std::vector<Rigid3d> slider;
  for (int i = 0; i < 8; ++i) {
    const Eigen::Vector3d centre(-0.3 + 0.6 * i / 7.0, 0.05 * (i % 2), 0);
    slider.emplace_back(Eigen::Quaterniond::Identity(), -centre);
  }
  const SparseModel translating = ObservedModel(slider);
  ASSERT_GT(translating.Points3D().size(), 300u);
  // ... and eight on a 40-degree arc around the points: the focal length is pinned down.
  std::vector<Rigid3d> arc;
  const Eigen::Vector3d target(0, 0, 20);
  for (int i = 0; i < 8; ++i) {
    const double angle = (-20 + 40 * i / 7.0) * std::numbers::pi / 180;
    const Eigen::Vector3d eye = target + 20 * Eigen::Vector3d(std::sin(angle), 0, -std::cos(angle));
    arc.push_back(LookAt(eye, target, Eigen::Vector3d(0, -1, 0)));
  }
  const SparseModel rotating = ObservedModel(arc);
  ASSERT_GT(rotating.Points3D().size(), 300u);

  for (const double factor : {2.0, 0.5}) {
    SCOPED_TRACE(factor);
    const double translating_ratio = FocalRmsRatio(translating, factor, 2000);
    const double rotating_ratio = FocalRmsRatio(rotating, factor, 2000);
    std::printf("[ measure ] focal x%.1f: reprojection error x%.3f translating, x%.2f on the arc\n",
                factor, translating_ratio, rotating_ratio);
    EXPECT_GT(translating_ratio, 0);
    EXPECT_LT(translating_ratio, 1.05);
    EXPECT_GT(rotating_ratio, 3);
  }

  const PlausibilityReport flagged = CheckPlausibility(translating, 384, false);
  EXPECT_FALSE(flagged.Plausible());
  EXPECT_TRUE(HasProblem(flagged, "is not determined by the photos")) << flagged.problems.size();
  EXPECT_LT(flagged.focal_rms_ratio, 1.05);
  const PlausibilityReport pinned = CheckPlausibility(rotating, 384, false);
  EXPECT_FALSE(HasProblem(pinned, "not determined")) << pinned.problems.front();
  EXPECT_GT(pinned.focal_rms_ratio, 3);
  // Against an EXIF prior the ratio check bounds the focal length; the test is not run.
  const PlausibilityReport exif = CheckPlausibility(translating, 300, true);
  EXPECT_FALSE(HasProblem(exif, "not determined"));
  EXPECT_EQ(exif.focal_rms_ratio, 0);
}

// A telephoto series (15 degrees across) from a slider: eight parallel views over 28 cm (zig-
// zagging 10 cm vertically), a box and a ball at 1-2 m, textured ground out to a wall at 1 km.
// The baseline is 0.03% of the depth of the wall; nothing rotates, so the focal length is free.
std::string TelephotoSliderScene() {
  std::string poses;
  for (int i = 0; i < 8; ++i) {
    const double x = -0.14 + 0.04 * i;
    const double z = i % 2 ? 1.55 : 1.45;
    char pose[160];
    std::snprintf(pose, sizeof(pose), R"(%s{"eye": [%.2f, 0, %.2f], "look_at": [%.2f, 20, %.2f]})",
                  i ? ", " : "", x, z, x, z - 0.3);
    poses += pose;
  }
  return R"({
  "image": {"width": 320, "height": 240, "focal_px": 1200, "supersampling": 2},
  "sky": {"zenith": [0.2, 0.38, 0.8], "horizon": [0.7, 0.78, 0.88]},
  "ambient": 0.35,
  "lights": [{"type": "directional", "direction": [-0.3, 0.5, -0.8], "intensity": 1.2,
              "color": [1, 0.96, 0.9]}],
  "materials": {
    "ground": {"texture": {"type": "fbm", "colors": [[0.03, 0.025, 0.02], [0.6, 0.5, 0.4]],
                           "scale": 0.5, "octaves": 8, "contrast": 1.5, "seed": 1}},
    "wall": {"texture": {"type": "fbm", "colors": [[0.05, 0.05, 0.08], [0.8, 0.8, 0.7]],
                         "scale": 125, "octaves": 8, "contrast": 1.6, "seed": 5}},
    "crate": {"texture": {"type": "checker", "colors": [[0.55, 0.2, 0.08], [0.85, 0.65, 0.3]],
                          "scale": 0.12, "seed": 2}},
    "ball": {"texture": {"type": "fbm", "colors": [[0.05, 0.2, 0.45], [0.7, 0.85, 0.95]],
                         "scale": 0.2, "octaves": 6, "seed": 3}}
  },
  "objects": [
    {"type": "plane", "material": "ground", "center": [0, 500, 0], "size": [2000, 1200]},
    {"type": "plane", "material": "wall", "center": [0, 1000, 250], "size": [3000, 1000],
     "normal": [0, -1, 0]},
    {"type": "box", "material": "crate", "center": [-0.2, 1.0, 0.5], "size": [0.8, 0.8, 1.0],
     "yaw_deg": 20},
    {"type": "sphere", "material": "ball", "center": [0.32, 1.6, 0.7], "radius": 0.7},
    {"type": "box", "material": "crate", "center": [1.5, 4.0, 1.0], "size": [2, 2, 2],
     "yaw_deg": 40}
  ],
  "cameras": {"training": [{"rig": "poses", "poses": [)" +
         poses + "]}]}\n}\n";
}

TEST(SfmStability, TelephotoSliderCaptureThatColmapRegistersWithAWrongFocalIsFlagged) {
  const TempDir dir;
  const fs::path scene_json = dir.Path() / "slider.json";
  std::ofstream(scene_json) << TelephotoSliderScene();
  const fs::path scene = dir.Path() / "scene";
  const CliResult synth = RunParallax("synth " + Quote(scene_json.string()) + " " +
                                      Quote(scene.string()));
  ASSERT_EQ(synth.exit_code, 0) << synth.output;
  const double true_focal =
      ReadSparseModel(SceneFolder{scene}.Training().sparse).Cameras().front().FocalX();

  // COLMAP "succeeds": every photo registered, sub-pixel error (it throws otherwise).
  const fs::path workspace = dir.Path() / "ws";
  ReconstructOptions options;
  options.estimate_depth = false;
  options.build_mesh = false;
  SilentProgress progress;
  const ReconstructSummary summary =
      Reconstruct(scene / "images", workspace, options, progress);
  const PlausibilityReport& plausibility = summary.plausibility;
  std::printf("[ measure ] registered %d/%d, %zu points, reprojection error %.3f px; focal "
              "%.1f px (true %.0f, %.2fx; prior %.0f), median triangulation angle %.1f deg, "
              "focal x2 or /2 changes the error x%.3f\n",
              summary.images_registered, summary.images_found, summary.points3d,
              summary.mean_reprojection_error_px, plausibility.focal_px, true_focal,
              plausibility.focal_px / true_focal, plausibility.focal_prior_px,
              plausibility.median_triangulation_deg, plausibility.focal_rms_ratio);
  for (const std::string& problem : plausibility.problems) {
    std::printf("[ measure ] problem: %s\n", problem.c_str());
  }
  EXPECT_EQ(summary.images_registered, 8);
  EXPECT_LT(summary.mean_reprojection_error_px, 0.5);

  // parallax flags it, in the summary and in report.json ...
  EXPECT_FALSE(plausibility.Plausible());
  EXPECT_TRUE(HasProblem(plausibility, "estimated focal length"));
  EXPECT_GT(plausibility.focal_rms_ratio, 0);
  EXPECT_LT(plausibility.focal_rms_ratio, 1.2);
  bool warned = false;
  for (const std::string& warning : summary.warnings) {
    warned |= warning.starts_with("implausible reconstruction: estimated focal length");
  }
  EXPECT_TRUE(warned);
  const nlohmann::json report = nlohmann::json::parse(std::ifstream(workspace / "report.json"));
  const nlohmann::json& reported = report.at("reconstruct").at("plausibility");
  EXPECT_FALSE(reported.at("plausible").get<bool>());
  ASSERT_FALSE(reported.at("problems").empty());

  // ... and `--strict` refuses it with exit code 2, naming the problem (the SfM stages are
  // cached: this run only checks again).
  const CliResult strict = RunParallax("reconstruct " + Quote((scene / "images").string()) + " " +
                                       Quote(workspace.string()) + " --no-depth --strict");
  EXPECT_EQ(strict.exit_code, 2) << strict.output;
  EXPECT_NE(strict.output.find("implausible reconstruction (--strict): estimated focal length"),
            std::string::npos)
      << strict.output;
  EXPECT_NE(strict.output.find("report.json"), std::string::npos) << strict.output;
}

}  // namespace
}  // namespace parallax
