// The novel-view benchmarks' protocol on a bare photo folder: `reconstruct --hold-out` registers
// every photo, keeps the held-out ones out of the dense stages, and `evaluate` (no ground
// truth) renders their cameras and scores them with a loss budget per view. And the principal
// point, refined only where the photos show it: real photos of a facade, cropped to a centred
// pinhole and as taken (its calibrated principal point 0.5% and 0.8% off-centre).
#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

#include <Eigen/Core>
#include <gtest/gtest.h>
#include <nlohmann/json.hpp>
#include <OpenImageIO/imagebuf.h>
#include <OpenImageIO/imagebufalgo.h>

#include "core/sparse_model.h"
#include "core/workspace.h"
#include "tests/cli_runner.h"
#include "tests/temp_dir.h"
#include "tests/test_paths.h"

namespace parallax {
namespace {

namespace fs = std::filesystem;

const fs::path kSmall = SourceDir() / "example_images" / "small";
const fs::path kFacade = SharedDatasets() / "herz-jesu-p8";

nlohmann::json ReadJson(const fs::path& path) {
  std::ifstream file(path);
  return nlohmann::json::parse(file);
}

std::vector<std::string> ImageNames(const fs::path& model) {
  const SparseModel sparse = ReadSparseModel(model);
  std::vector<std::string> names;
  for (const SparseImage& image : sparse.Images()) names.push_back(image.name);
  std::sort(names.begin(), names.end());
  return names;
}

CliResult Reconstruct(const fs::path& photos, const fs::path& workspace, const std::string& flags) {
  return RunParallax("reconstruct " + Quote(photos.string()) + " " + Quote(workspace.string()) + " " + flags);
}

// The budget accounts for the whole frame: the shares sum to one, and the frame's mean squared
// error is the shares' weighted sum of theirs.
void ExpectBudgetAddsUp(const nlohmann::json& view) {
  const nlohmann::json& budget = view["budget"];
  double share = 0, mse = 0;
  for (const char* part : {"covered", "background", "filled"}) {
    const double part_share = budget[part]["share"];
    share += part_share;
    if (part_share > 0) mse += part_share * std::pow(10.0, -budget[part]["psnr"].get<double>() / 10);
  }
  EXPECT_NEAR(share, 1.0, 1e-9) << view.dump();
  EXPECT_NEAR(-10 * std::log10(mse), view["psnr"].get<double>(), 0.01) << view.dump();
  EXPECT_NEAR(budget["exposure_db"].get<double>(),
              view["psnr_exposure_matched"].get<double>() - view["psnr"].get<double>(), 1e-9);
}

// The small scene's 12 photos and its 4 novel ones in one folder, the novel ones held out.
TEST(HeldOut, HeldOutPhotosAreRegisteredKeptOutOfTheDenseStagesAndScored) {
  const TempDir dir;
  const fs::path photos = dir.Path() / "photos";
  fs::create_directories(photos);
  std::string named;
  for (const fs::path& folder : {kSmall / "images", kSmall / "novel" / "images"}) {
    for (const auto& entry : fs::directory_iterator(folder)) fs::copy_file(entry.path(), photos / entry.path().filename());
  }
  const std::vector<std::string> novel = {"novel_0000.png", "novel_0001.png", "novel_0002.png", "novel_0003.png"};
  for (const std::string& name : novel) named += (named.empty() ? "" : ",") + name;

  const fs::path held_out = dir.Path() / "held out";
  const CliResult reconstructed = Reconstruct(photos, held_out, "--quality fast --hold-out-photos " + named);
  ASSERT_EQ(reconstructed.exit_code, 0) << reconstructed.output;
  EXPECT_NE(reconstructed.output.find("4 of 4 held-out photos registered"), std::string::npos) << reconstructed.output;
  const Workspace workspace(held_out);
  EXPECT_EQ(ReadJson(workspace.Report())["reconstruct"]["held_out"].get<std::vector<std::string>>(), novel);
  EXPECT_EQ(ReadJson(workspace.Report())["reconstruct"]["images_registered"], 16);
  EXPECT_EQ(ImageNames(workspace.HeldOut().Sparse()), novel);
  EXPECT_EQ(ImageNames(workspace.Sparse()).size(), 12u);
  for (const std::string& name : novel) {
    EXPECT_TRUE(fs::exists(workspace.HeldOut().Images() / name)) << name;
    EXPECT_FALSE(fs::exists(workspace.Images() / name)) << name;
    EXPECT_FALSE(fs::exists(workspace.Depth(name))) << name;
  }
  const CliResult evaluated = RunParallax("evaluate " + Quote(held_out.string()));
  ASSERT_EQ(evaluated.exit_code, 0) << evaluated.output;
  EXPECT_NE(evaluated.output.find("loss budget"), std::string::npos) << evaluated.output;
  const nlohmann::json scores = ReadJson(workspace.Root() / "evaluation.json")["novel"];
  EXPECT_EQ(scores["views"], 4);
  for (const nlohmann::json& view : scores["per_view"]) ExpectBudgetAddsUp(view);
  // The held-out photos' SfM cameras put the scene within a pixel of where they show it.
  const nlohmann::json& misaligned = scores["budget_mean"]["misalignment_px"];
  std::printf("[ measure ] misalignment at the held-out cameras: median %.3f px, p90 %.3f px\n",
              misaligned["median"].get<double>(), misaligned["p90"].get<double>());
  EXPECT_GT(misaligned["median"].get<double>(), 0);
  EXPECT_LT(misaligned["median"].get<double>(), 1);
  EXPECT_LE(misaligned["median"].get<double>(), misaligned["p90"].get<double>());

  // The textured mesh at the same held-out cameras: its renders and coverage masks written, its
  // whole frames (missed pixels black) below the pixels it covers, and against its own masks
  // (--mesh-common-with the same workspace) the common pixels are its covered ones.
  const nlohmann::json mesh = ReadJson(workspace.Root() / "evaluation.json")["mesh_held_out"];
  std::printf("[ measure ] textured mesh at the held-out cameras: %.2f dB on %.1f%% covered, %.2f dB whole frames\n",
              mesh["covered_psnr_mean"].get<double>(), 100 * mesh["coverage_mean"].get<double>(),
              mesh["psnr_mean"].get<double>());
  ASSERT_EQ(mesh["per_view"].size(), 4u) << mesh.dump();
  EXPECT_GT(mesh["covered_psnr_mean"].get<double>(), 20) << mesh.dump();
  EXPECT_GT(mesh["coverage_mean"].get<double>(), 0.3) << mesh.dump();
  EXPECT_LT(mesh["psnr_mean"].get<double>(), mesh["covered_psnr_mean"].get<double>()) << mesh.dump();
  for (const std::string name : {"novel_0000", "novel_0003"}) {
    EXPECT_TRUE(fs::exists(workspace.Root() / "evaluation" / "mesh_held_out" / (name + ".png"))) << name;
    EXPECT_TRUE(fs::exists(workspace.Root() / "evaluation" / "mesh_held_out" / (name + ".covered.png"))) << name;
  }
  const CliResult common = RunParallax("evaluate " + Quote(held_out.string()) + " --mesh-common-with " +
                                       Quote(held_out.string()) + " --json " + Quote((dir.Path() / "common.json").string()));
  ASSERT_EQ(common.exit_code, 0) << common.output;
  EXPECT_NE(common.output.find("both meshes cover"), std::string::npos) << common.output;
  const nlohmann::json same = ReadJson(dir.Path() / "common.json")["mesh_held_out"];
  EXPECT_NEAR(same["common_psnr_mean"].get<double>(), mesh["covered_psnr_mean"].get<double>(), 1e-9);
  EXPECT_NEAR(same["common_share_mean"].get<double>(), mesh["coverage_mean"].get<double>(), 1e-9);
}

// The scene's cameras, its 12 training photos' and its 4 novel ones', in one model.
SparseModel EveryGroundTruthCamera() {
  SparseModel model = ReadSparseModel(kSmall / "gt" / "sparse");
  const SparseModel novel = ReadSparseModel(kSmall / "novel" / "sparse");
  for (SparseImage image : novel.Images()) {
    EXPECT_EQ(novel.CameraById(image.camera_id).params, model.CameraById(image.camera_id).params);
    image.id += 100;
    model.AddImage(std::move(image));
  }
  return model;
}

// With the ground-truth cameras known, the held-out protocol and the scene folder's (its
// cameras taken as they are) render the same views from the same sources: the same scores.
TEST(HeldOut, AtTheSameCamerasBothProtocolsScoreTheSame) {
  const TempDir dir;
  const fs::path photos = dir.Path() / "photos", known = dir.Path() / "known", workspace = dir.Path() / "ws";
  fs::create_directories(photos);
  for (const fs::path& folder : {kSmall / "images", kSmall / "novel" / "images"}) {
    for (const auto& entry : fs::directory_iterator(folder)) fs::copy_file(entry.path(), photos / entry.path().filename());
  }
  WriteSparseModel(EveryGroundTruthCamera(), known, SparseFormat::kText);
  const CliResult reconstructed =
      Reconstruct(photos, workspace,
                  "--quality fast --no-mesh --known-cameras " + Quote(known.string()) +
                      " --hold-out-photos novel_0000.png,novel_0001.png,novel_0002.png,novel_0003.png");
  ASSERT_EQ(reconstructed.exit_code, 0) << reconstructed.output;
  ASSERT_EQ(RunParallax("evaluate " + Quote(workspace.string())).exit_code, 0);
  const CliResult scene = RunParallax("evaluate " + Quote(workspace.string()) + " --gt " + Quote(kSmall.string()) +
                                      " --no-align --novel-only --novel-poses aligned --json " +
                                      Quote((dir.Path() / "scene.json").string()));
  ASSERT_EQ(scene.exit_code, 0) << scene.output;
  const nlohmann::json held_out = ReadJson(workspace / "evaluation.json")["novel"];
  const nlohmann::json scene_scores = ReadJson(dir.Path() / "scene.json")["novel"];
  std::printf("[ measure ] held out %.3f dB, SSIM %.4f; scene protocol %.3f dB, SSIM %.4f\n",
              held_out["psnr_mean"].get<double>(), held_out["ssim_mean"].get<double>(),
              scene_scores["psnr_mean"].get<double>(), scene_scores["ssim_mean"].get<double>());
  EXPECT_EQ(held_out["views"], 4);
  EXPECT_NEAR(held_out["psnr_mean"].get<double>(), scene_scores["psnr_mean"].get<double>(), 0.01);
  EXPECT_NEAR(held_out["ssim_mean"].get<double>(), scene_scores["ssim_mean"].get<double>(), 0.0005);
}

TEST(HeldOut, UnknownPhotosAndWorkspacesWithoutHeldOutPhotosExitTwo) {
  const TempDir dir;
  const CliResult unknown = Reconstruct(kSmall / "images", dir.Path() / "ws", "--hold-out-photos nope.png");
  EXPECT_EQ(unknown.exit_code, 2) << unknown.output;
  EXPECT_NE(unknown.output.find("--hold-out-photos: nope.png is not one of the photos"), std::string::npos)
      << unknown.output;
  const CliResult too_many = Reconstruct(kSmall / "images", dir.Path() / "ws", "--hold-out 2 --dry-run");
  EXPECT_EQ(too_many.exit_code, 0) << too_many.output;  // 6 of 12: six are left.
  const CliResult usage = Reconstruct(kSmall / "images", dir.Path() / "ws", "--hold-out 1");
  EXPECT_EQ(usage.exit_code, 1) << usage.output;
  fs::create_directories(dir.Path() / "empty" / "sparse");
  const CliResult nothing_held = RunParallax("evaluate " + Quote((dir.Path() / "empty").string()));
  EXPECT_EQ(nothing_held.exit_code, 2) << nothing_held.output;
  EXPECT_NE(nothing_held.output.find("has no held-out photos"), std::string::npos) << nothing_held.output;
}

// The facade's 8 photos at 768x512, and cropped around their calibrated principal point to a
// centred pinhole at 760x503.
void WriteFacadePhotos(const fs::path& as_taken, const fs::path& centred) {
  fs::create_directories(as_taken);
  fs::create_directories(centred);
  for (const auto& entry : fs::directory_iterator(kFacade / "images")) {
    const OIIO::ImageBuf photo(entry.path().string());
    const OIIO::ImageBuf small = OIIO::ImageBufAlgo::resize(photo, "", 0, OIIO::ROI(0, 768, 0, 512));
    ASSERT_TRUE(small.write((as_taken / entry.path().filename()).string())) << small.geterror();
    // The calibrated principal point is (760.595, 503.655) in the 1536x1024 photos.
    OIIO::ImageBuf crop = OIIO::ImageBufAlgo::cut(photo, OIIO::ROI(0, 1521, 0, 1007));
    crop = OIIO::ImageBufAlgo::resize(crop, "", 0, OIIO::ROI(0, 760, 0, 503));
    ASSERT_TRUE(crop.write((centred / entry.path().filename()).string())) << crop.geterror();
  }
}

TEST(HeldOut, RealPhotosPrincipalPointMovesOnlyWhereThePhotosShowIt) {
  if (!fs::is_directory(kFacade)) GTEST_SKIP() << kFacade << " is absent";
  const TempDir dir;
  WriteFacadePhotos(dir.Path() / "as taken", dir.Path() / "centred");

  const CliResult centred = Reconstruct(dir.Path() / "centred", dir.Path() / "centred ws", "--quality fast --no-depth");
  ASSERT_EQ(centred.exit_code, 0) << centred.output;
  EXPECT_NE(centred.output.find("principal point kept at the image centre"), std::string::npos) << centred.output;
  const Camera centred_camera = ReadSparseModel(dir.Path() / "centred ws" / "sparse").Cameras().at(0);
  EXPECT_LT(std::abs(centred_camera.PrincipalX() - 380.0), 0.003 * 760) << centred.output;
  EXPECT_LT(std::abs(centred_camera.PrincipalY() - 251.5), 0.003 * 503) << centred.output;
  // The cameras' uncertainty, by the jackknife over the folds of the principal point's check:
  // the point held, so no deviation of it.
  const nlohmann::json centred_uncertainty =
      ReadJson(Workspace(dir.Path() / "centred ws").Report())["reconstruct"]["camera_uncertainty"];
  EXPECT_EQ(centred_uncertainty["folds"], 8) << centred_uncertainty;
  EXPECT_EQ(centred_uncertainty["principal_point_px"], 0.0) << centred_uncertainty;

  // As taken, with every fourth photo held out: refined towards the calibrated point (7.4 and
  // 8.3 px off-centre at full size), and the held-out photos scored.
  const fs::path workspace = dir.Path() / "ws";
  const CliResult taken = Reconstruct(dir.Path() / "as taken", workspace, "--quality fast --hold-out 4 --no-mesh --mvs-max-size 384");
  ASSERT_EQ(taken.exit_code, 0) << taken.output;
  EXPECT_NE(taken.output.find("principal point refined"), std::string::npos) << taken.output;
  // Nearer the calibrated point than the centre is (5.6 px from it).
  const Camera camera = ReadSparseModel(workspace / "sparse").Cameras().at(0);
  const Eigen::Vector2d calibrated(760.595 / 2, 503.655 / 2), centre(384, 256);
  const Eigen::Vector2d refined(camera.PrincipalX(), camera.PrincipalY());
  EXPECT_LT((refined - calibrated).norm(), 0.5 * (centre - calibrated).norm()) << taken.output;
  // Freed, the point's deviation is a few pixels (the refined one lies 3.7 of them off-centre);
  // the rotations' a few hundredths of a degree (their errors against the calibration are
  // 0.02-0.04 degrees at full size).
  const nlohmann::json uncertainty = ReadJson(Workspace(workspace).Report())["reconstruct"]["camera_uncertainty"];
  std::printf("[ measure ] facade: principal point deviation %.2f px, rotation %.4f deg median\n",
              uncertainty["principal_point_px"].get<double>(), uncertainty["rotation_deg"]["median"].get<double>());
  EXPECT_GT(uncertainty["principal_point_px"].get<double>(), 0.3) << uncertainty;
  EXPECT_LT(uncertainty["principal_point_px"].get<double>(), 5.0) << uncertainty;
  EXPECT_GT(uncertainty["rotation_deg"]["median"].get<double>(), 0.003) << uncertainty;
  EXPECT_LT(uncertainty["rotation_deg"]["median"].get<double>(), 0.2) << uncertainty;
  EXPECT_EQ(uncertainty["rotation_deg"]["photos"].size(), 8u) << uncertainty;
  EXPECT_EQ(ImageNames(Workspace(workspace).HeldOut().Sparse()), std::vector<std::string>({"0000.jpg", "0004.jpg"}));
  const CliResult evaluated = RunParallax("evaluate " + Quote(workspace.string()));
  ASSERT_EQ(evaluated.exit_code, 0) << evaluated.output;
  const nlohmann::json scores = ReadJson(workspace / "evaluation.json")["novel"];
  std::printf("[ measure ] facade, 2 held out: %.2f dB, SSIM %.3f\n", scores["psnr_mean"].get<double>(),
              scores["ssim_mean"].get<double>());
  EXPECT_GT(scores["psnr_mean"].get<double>(), 21.0);
  for (const nlohmann::json& view : scores["per_view"]) ExpectBudgetAddsUp(view);
}

}  // namespace
}  // namespace parallax
