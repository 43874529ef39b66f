#include "eval/depth_evaluation.h"

#include <cmath>
#include <functional>
#include <string>
#include <tuple>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "core/depth_map.h"
#include "core/error.h"
#include "core/image.h"
#include "tests/temp_dir.h"

namespace parallax {
namespace {
namespace fs = std::filesystem;

constexpr int kWidth = 64;
constexpr int kHeight = 48;
// Depths are stored as float32: one rounding each (~6e-8 relative) bounds every error on
// exact data. Measured: 0 (the reprojected z rounds to the stored float), also through the
// similarity.
constexpr double kExact = 1e-6;

// A tilted plane n . x = offset that fills every test view.
const Eigen::Vector3d kPlaneNormal = Eigen::Vector3d(0.1, -0.2, 1.0).normalized();
const double kPlaneOffset = kPlaneNormal.dot(Eigen::Vector3d(0, 0, 5));

Camera TestCamera(double principal_shift_px = 0) {
  return MakePinholeCamera(1, kWidth, kHeight, 60, 62, 32 + principal_shift_px,
                           24 - principal_shift_px);
}

// One PINHOLE camera, two views of the plane.
SparseModel TruthModel(const Camera& camera = TestCamera()) {
  SparseModel model;
  model.AddCamera(camera);
  const Eigen::Vector3d target(0, 0, 5);
  const Eigen::Vector3d up(0, -1, 0);
  SparseImage a;
  a.id = 1;
  a.camera_id = camera.id;
  a.name = "a.png";
  a.cam_from_world = LookAt(Eigen::Vector3d(0, 0, 0), target, up);
  model.AddImage(a);
  SparseImage b = a;
  b.id = 2;
  b.name = "b.png";
  b.cam_from_world = LookAt(Eigen::Vector3d(1.0, 0.3, 0.2), target, up);
  model.AddImage(b);
  return model;
}

// The plane's z-depth at every pixel centre, analytically: along the ray r = (x, y, 1) in
// the camera, the world point is C + lambda R^T r, and lambda is the z-depth.
DepthMap PlaneDepth(const Camera& camera, const Rigid3d& cam_from_world) {
  DepthMap depth(static_cast<int>(camera.width), static_cast<int>(camera.height));
  const Eigen::Vector3d centre = CameraCenter(cam_from_world);
  for (int y = 0; y < depth.Height(); ++y) {
    for (int x = 0; x < depth.Width(); ++x) {
      const Eigen::Vector3d ray = *camera.Unproject(Eigen::Vector2d(x + 0.5, y + 0.5));
      const Eigen::Vector3d ray_in_world = cam_from_world.rotation.conjugate() * ray;
      depth.At(x, y) = static_cast<float>((kPlaneOffset - kPlaneNormal.dot(centre)) /
                                          kPlaneNormal.dot(ray_in_world));
    }
  }
  return depth;
}

DepthMap Scaled(DepthMap depth, double factor) {
  for (float& value : depth.Values()) value = static_cast<float>(static_cast<double>(value) * factor);
  return depth;
}

fs::path DepthFile(const fs::path& dir, const SparseImage& image) {
  return dir / (fs::path(image.name).stem().string() + ".exr");
}

// Writes the ground truth of `model` into <dir>/truth and the estimate each view's depth
// function gives into <dir>/estimate.
struct Fixture {
  TempDir dir;
  SparseModel truth = TruthModel();
  fs::path TruthDir() const { return dir.Path() / "truth"; }
  fs::path EstimateDir() const { return dir.Path() / "estimate"; }

  Fixture() {
    for (const SparseImage& image : truth.Images()) {
      WriteDepthExr(DepthFile(TruthDir(), image),
                    PlaneDepth(truth.Cameras().front(), image.cam_from_world));
    }
  }

  void WriteEstimates(const SparseModel& estimate,
                      const std::function<DepthMap(DepthMap)>& modify = [](DepthMap d) {
                        return d;
                      }) const {
    for (const SparseImage& image : estimate.Images()) {
      const Camera& camera = estimate.CameraById(image.camera_id);
      WriteDepthExr(DepthFile(EstimateDir(), image),
                    modify(PlaneDepth(camera, image.cam_from_world)));
    }
  }

  DepthEvaluation Evaluate(const SparseModel& estimate, const Similarity3d& truth_from_estimate = {},
                           const fs::path& error_images = {}) const {
    return EvaluateDepth(estimate, EstimateDir(), truth, TruthDir(), truth_from_estimate,
                         error_images);
  }
};

Similarity3d Inverse(const Similarity3d& similarity) {
  Similarity3d inverse;
  inverse.scale = 1 / similarity.scale;
  inverse.rotation = similarity.rotation.conjugate();
  inverse.translation = -(inverse.scale * (inverse.rotation * similarity.translation));
  return inverse;
}

TEST(DepthEvaluation, EstimateEqualToTruthHasNoErrorAndFullCompleteness) {
  const Fixture fixture;
  fixture.WriteEstimates(fixture.truth);
  const DepthEvaluation evaluation = fixture.Evaluate(fixture.truth);
  EXPECT_EQ(evaluation.views, 2);
  EXPECT_NEAR(evaluation.abs_rel_median, 0, kExact);
  EXPECT_NEAR(evaluation.signed_median, 0, kExact);
  EXPECT_DOUBLE_EQ(evaluation.within_1pct, 1);
  EXPECT_DOUBLE_EQ(evaluation.within_2pct, 1);
  EXPECT_DOUBLE_EQ(evaluation.completeness, 1);
  ASSERT_EQ(evaluation.per_view.size(), 2u);
  EXPECT_EQ(evaluation.per_view[0].name, "a.png");
  EXPECT_EQ(evaluation.per_view[1].name, "b.png");
  for (const DepthViewErrors& view : evaluation.per_view) {
    EXPECT_EQ(view.gt_valid_pixels, kWidth * kHeight);
    EXPECT_EQ(view.estimated_pixels, kWidth * kHeight);
    EXPECT_DOUBLE_EQ(view.completeness, 1);
  }
}

TEST(DepthEvaluation, EstimateTooFarByOnePointTwoPercentShowsThatBias) {
  const Fixture fixture;
  fixture.WriteEstimates(fixture.truth, [](DepthMap d) { return Scaled(std::move(d), 1.012); });
  const DepthEvaluation evaluation = fixture.Evaluate(fixture.truth);
  EXPECT_NEAR(evaluation.signed_median, 0.012, kExact);
  EXPECT_NEAR(evaluation.abs_rel_median, 0.012, kExact);
  EXPECT_DOUBLE_EQ(evaluation.within_1pct, 0);
  EXPECT_DOUBLE_EQ(evaluation.within_2pct, 1);
  EXPECT_DOUBLE_EQ(evaluation.completeness, 1);
}

TEST(DepthEvaluation, EstimateTooNearHasANegativeSignedMedian) {
  const Fixture fixture;
  fixture.WriteEstimates(fixture.truth, [](DepthMap d) { return Scaled(std::move(d), 0.97); });
  const DepthEvaluation evaluation = fixture.Evaluate(fixture.truth);
  EXPECT_NEAR(evaluation.signed_median, -0.03, kExact);
  EXPECT_NEAR(evaluation.abs_rel_median, 0.03, kExact);
  EXPECT_DOUBLE_EQ(evaluation.within_2pct, 0);
  EXPECT_DOUBLE_EQ(evaluation.completeness, 1);
}

TEST(DepthEvaluation, EstimateInAnotherFrameIsExactThroughItsSimilarity) {
  const Fixture fixture;
  // The estimate's world is the truth's under estimate_from_truth: 2.5 times larger, rotated
  // and moved; its camera frames scale with it, so its depths are 2.5 times the truth's.
  Similarity3d estimate_from_truth;
  estimate_from_truth.scale = 2.5;
  estimate_from_truth.rotation =
      Eigen::Quaterniond(Eigen::AngleAxisd(0.7, Eigen::Vector3d(0.3, -1, 0.4).normalized()));
  estimate_from_truth.translation = Eigen::Vector3d(3, -7, 11);
  SparseModel estimate = fixture.truth;
  for (SparseImage& image : estimate.MutableImages()) {
    image.cam_from_world = estimate_from_truth.TransformPose(image.cam_from_world);
  }
  fixture.WriteEstimates(fixture.truth, [](DepthMap d) { return Scaled(std::move(d), 2.5); });

  const DepthEvaluation evaluation = fixture.Evaluate(estimate, Inverse(estimate_from_truth));
  EXPECT_EQ(evaluation.views, 2);
  EXPECT_NEAR(evaluation.abs_rel_median, 0, kExact);
  EXPECT_NEAR(evaluation.signed_median, 0, kExact);
  EXPECT_DOUBLE_EQ(evaluation.within_1pct, 1);
  EXPECT_DOUBLE_EQ(evaluation.completeness, 1);

  // Without the alignment the same estimate is far off.
  const DepthEvaluation unaligned = fixture.Evaluate(estimate);
  EXPECT_LT(unaligned.within_2pct, 0.1);
}

TEST(DepthEvaluation, SubPixelLandingsInterpolateInverseDepthExactlyOnAPlane) {
  const Fixture fixture;
  // An estimate camera whose pixel centres fall 0.3 px off the truth's: every landing is
  // between truth pixel centres.
  const SparseModel estimate = TruthModel(TestCamera(0.3));
  fixture.WriteEstimates(estimate);
  const DepthEvaluation evaluation = fixture.Evaluate(estimate);
  EXPECT_NEAR(evaluation.abs_rel_median, 0, kExact);
  for (const DepthViewErrors& view : evaluation.per_view) {
    EXPECT_NEAR(view.abs_rel_median, 0, kExact);
    // The ring of border pixels reached by no estimate or without 4 neighbours may differ.
    EXPECT_GT(view.within_1pct, 0.95);
    EXPECT_GT(view.completeness, 0.95);
  }
}

TEST(DepthEvaluation, MissingEstimatesLowerCompletenessAndViewsWithoutFilesAreSkipped) {
  const Fixture fixture;
  fixture.WriteEstimates(fixture.truth, [](DepthMap d) {
    for (int y = 0; y < d.Height(); ++y) {
      for (int x = 0; x < d.Width() / 2; ++x) d.At(x, y) = 0;
    }
    return d;
  });
  fs::remove(DepthFile(fixture.EstimateDir(), fixture.truth.Images()[1]));
  const DepthEvaluation evaluation = fixture.Evaluate(fixture.truth);
  EXPECT_EQ(evaluation.views, 1);
  ASSERT_EQ(evaluation.per_view.size(), 1u);
  EXPECT_EQ(evaluation.per_view[0].name, "a.png");
  EXPECT_DOUBLE_EQ(evaluation.completeness, 0.5);
  EXPECT_DOUBLE_EQ(evaluation.within_1pct, 0.5);
  EXPECT_NEAR(evaluation.abs_rel_median, 0, kExact);
}

TEST(DepthEvaluation, TruthBackgroundIsNeitherCountedNorCompared) {
  const Fixture fixture;
  fixture.WriteEstimates(fixture.truth);
  // The top rows become sky in the truth; the estimate still has depth there.
  for (const SparseImage& image : fixture.truth.Images()) {
    DepthMap truth = ReadDepthExr(DepthFile(fixture.TruthDir(), image));
    for (int y = 0; y < kHeight / 4; ++y) {
      for (int x = 0; x < kWidth; ++x) truth.At(x, y) = 0;
    }
    WriteDepthExr(DepthFile(fixture.TruthDir(), image), truth);
  }
  const DepthEvaluation evaluation = fixture.Evaluate(fixture.truth);
  EXPECT_DOUBLE_EQ(evaluation.completeness, 1);
  EXPECT_NEAR(evaluation.abs_rel_median, 0, kExact);
  for (const DepthViewErrors& view : evaluation.per_view) {
    EXPECT_EQ(view.gt_valid_pixels, kWidth * kHeight * 3 / 4);
  }
}

TEST(DepthEvaluation, NearestOfSeveralEstimatesLandingInOnePixelCounts) {
  const Fixture fixture;
  // The estimate camera has twice the resolution: 4 estimated pixels land in each truth
  // pixel. The upper-left of each 2x2 block is 5% too near, the others 5% too far.
  const Camera fine = MakePinholeCamera(1, 2 * kWidth, 2 * kHeight, 120, 124, 64, 48);
  const SparseModel estimate = TruthModel(fine);
  fixture.WriteEstimates(estimate, [](DepthMap d) {
    for (int y = 0; y < d.Height(); ++y) {
      for (int x = 0; x < d.Width(); ++x) {
        d.At(x, y) *= (x % 2 == 0 && y % 2 == 0) ? 0.95f : 1.05f;
      }
    }
    return d;
  });
  const DepthEvaluation evaluation = fixture.Evaluate(estimate);
  EXPECT_NEAR(evaluation.signed_median, -0.05, 1e-3);
  EXPECT_DOUBLE_EQ(evaluation.completeness, 1);
}

// A smaller map of the photo's shape is a working size, read at the photo's; one larger than
// the photo or of another shape is an error.
TEST(DepthEvaluation, DepthMapOfTheWrongSizeIsBadInputNamingTheFile) {
  const Fixture fixture;
  fixture.WriteEstimates(fixture.truth);
  const fs::path wrong = DepthFile(fixture.EstimateDir(), fixture.truth.Images()[1]);
  for (const auto& [width, height, size] :
       {std::tuple{kWidth / 2, kHeight, "32x48"}, std::tuple{kWidth * 2, kHeight * 2, "128x96"}}) {
    WriteDepthExr(wrong, DepthMap(width, height));
    try {
      fixture.Evaluate(fixture.truth);
      ADD_FAILURE() << "expected BadInputError for a " << size << " map";
    } catch (const BadInputError& error) {
      EXPECT_NE(std::string(error.what()).find(wrong.string()), std::string::npos) << error.what();
      EXPECT_NE(std::string(error.what()).find(size), std::string::npos) << error.what();
    }
  }
}

TEST(DepthEvaluation, MissingTruthDepthIsBadInput) {
  const Fixture fixture;
  fixture.WriteEstimates(fixture.truth);
  fs::remove(DepthFile(fixture.TruthDir(), fixture.truth.Images()[0]));
  EXPECT_THROW(fixture.Evaluate(fixture.truth), BadInputError);
}

TEST(DepthEvaluation, ErrorImagesHaveTheTruthSizeAndMarkMissingAndBackground) {
  const Fixture fixture;
  fixture.WriteEstimates(fixture.truth, [](DepthMap d) {
    d.At(10, 20) = 0;       // No estimate: black.
    d.At(40, 30) *= 1.05f;  // 5% error: red.
    return d;
  });
  const fs::path truth_a = DepthFile(fixture.TruthDir(), fixture.truth.Images()[0]);
  DepthMap truth = ReadDepthExr(truth_a);
  truth.At(0, 0) = 0;  // Background: grey.
  WriteDepthExr(truth_a, truth);

  const fs::path out = fixture.dir.Path() / "errors";
  fixture.Evaluate(fixture.truth, {}, out);
  for (const char* name : {"a.png", "b.png"}) {
    const Image image = ReadImage(out / name);
    EXPECT_EQ(image.Width(), kWidth);
    EXPECT_EQ(image.Height(), kHeight);
    EXPECT_EQ(image.Channels(), 3);
  }
  const Image image = ReadImage(out / "a.png");
  const auto pixel = [&](int x, int y) {
    return Eigen::Vector3f(image.At(x, y, 0), image.At(x, y, 1), image.At(x, y, 2));
  };
  const auto difference = [](const Eigen::Vector3f& a, const Eigen::Vector3f& b) {
    return (a - b).cwiseAbs().maxCoeff();
  };
  const float step = 1.0f / 255;  // 8-bit rounding.
  EXPECT_LE(difference(pixel(10, 20), Eigen::Vector3f::Zero()), step);
  EXPECT_LE(difference(pixel(0, 0), Eigen::Vector3f::Constant(0.5f)), step);
  EXPECT_LE(difference(pixel(40, 30), DepthErrorColor(1)), step);
  EXPECT_LE(difference(pixel(5, 5), DepthErrorColor(0)), step);
}

TEST(DepthEvaluation, ErrorColorsRunFromDarkBlueToRedAndSaturate) {
  const Eigen::Vector3f zero = DepthErrorColor(0);
  const Eigen::Vector3f red = DepthErrorColor(0.02);
  EXPECT_GT(zero.z(), zero.x());  // Blue.
  EXPECT_GT(red.x(), 2 * red.y());
  EXPECT_TRUE(DepthErrorColor(0.5).isApprox(red));
  EXPECT_GT(DepthErrorColor(0.01).y(), 0.7f);  // Bright at 1%.
}

TEST(DepthEvaluation, JsonSectionHasTheDesignKeys) {
  DepthEvaluation evaluation;
  evaluation.views = 3;
  evaluation.abs_rel_median = 0.004;
  evaluation.completeness = 0.9;
  nlohmann::json json = nlohmann::json::object();
  AddDepthSection(evaluation, json);
  const nlohmann::json& depth = json.at("depth");
  EXPECT_EQ(depth.at("views"), 3);
  EXPECT_DOUBLE_EQ(depth.at("abs_rel_median").get<double>(), 0.004);
  EXPECT_DOUBLE_EQ(depth.at("completeness").get<double>(), 0.9);
  for (const char* key : {"signed_median", "within_1pct", "within_2pct"}) {
    EXPECT_TRUE(depth.contains(key)) << key;
  }
  EXPECT_EQ(depth.size(), 6u);
}

}  // namespace
}  // namespace parallax
