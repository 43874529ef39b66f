// Degenerate camera sets for the similarity alignment (issue: numerical stability): one
// camera, identical cameras, centres that coincide up to rounding or nearly so. Each is
// refused with a message saying why, or aligned correctly; never a silently wrong transform.
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <functional>
#include <numbers>
#include <random>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "core/error.h"
#include "tests/random_rotation.h"

#include "geometry/similarity.h"

namespace parallax {
namespace {

using test::RandomRotation;

Rigid3d CameraAt(const Eigen::Quaterniond& rotation, const Eigen::Vector3d& centre) {
  return Rigid3d(rotation, -(rotation * centre));
}

Similarity3d ExampleSimilarity() {
  Similarity3d similarity;
  similarity.scale = 2.5;
  similarity.rotation =
      Eigen::Quaterniond(Eigen::AngleAxisd(0.7, Eigen::Vector3d(1, 2, -1).normalized()));
  similarity.translation = Eigen::Vector3d(3, -1, 0.5);
  return similarity;
}

// The cameras as the similarity moves them: rotation R_cam R^T, centre s R c + t.
std::vector<Rigid3d> Transform(const Similarity3d& similarity, const std::vector<Rigid3d>& cams) {
  std::vector<Rigid3d> moved;
  for (const Rigid3d& cam : cams) {
    moved.push_back(
        CameraAt(cam.rotation * similarity.rotation.conjugate(), similarity * CameraCenter(cam)));
  }
  return moved;
}

// The refusal must be an InternalError whose message contains `fragment`.
void ExpectRefused(const std::function<void()>& call, const std::string& fragment) {
  try {
    call();
    ADD_FAILURE() << "accepted; expected a refusal mentioning '" << fragment << "'";
  } catch (const InternalError& error) {
    EXPECT_NE(std::string(error.what()).find(fragment), std::string::npos) << error.what();
  }
}

TEST(AlignmentStability, ASingleCameraIsRefused) {
  std::mt19937 random(1);
  const std::vector<Rigid3d> one = {CameraAt(RandomRotation(random), {1, 2, 3})};
  ExpectRefused([&] { AlignSimilarity(one, Transform(ExampleSimilarity(), one)); },
                "need at least 3 cameras, got 1");
  ExpectRefused([&] { AlignSimilarity({}, {}); }, "need at least 3 cameras, got 0");
}

TEST(AlignmentStability, IdenticalCamerasAreRefusedAtEveryScale) {
  // All poses equal: the centres coincide exactly, so no scale can be measured. At the origin
  // (magnitude 0), at unit scale and at the extremes of the supported range of scales.
  std::mt19937 random(2);
  for (const double magnitude : {0.0, 1e-8, 1.0, 1e8}) {
    SCOPED_TRACE(magnitude);
    const Rigid3d pose =
        CameraAt(RandomRotation(random), magnitude * Eigen::Vector3d(0.6, -0.8, 0.3));
    const std::vector<Rigid3d> identical(6, pose);
    ExpectRefused([&] { AlignSimilarity(identical, identical); }, "camera centres all coincide");
    // Identical on one side only: still no scale.
    std::vector<Rigid3d> spread;
    for (int i = 0; i < 6; ++i) {
      spread.push_back(CameraAt(RandomRotation(random), {i * 1.0, i * i * 0.5, -i * 0.25}));
    }
    ExpectRefused([&] { AlignSimilarity(identical, spread); },
                  "source camera centres all coincide");
    ExpectRefused([&] { AlignSimilarity(spread, identical); },
                  "target camera centres all coincide");
  }
}

TEST(AlignmentStability, CentresEqualUpToRoundingAreRefused) {
  // One centre 1e8 from the origin seen under different orientations: -R^T t leaves a few ulps
  // (~1e-8) of noise on each centre. That noise must not be taken for a baseline.
  std::mt19937 random(3);
  for (const double magnitude : {1e-8, 1.0, 1e8}) {
    SCOPED_TRACE(magnitude);
    const Eigen::Vector3d centre = magnitude * Eigen::Vector3d(0.3, 0.9, -0.4);
    std::vector<Rigid3d> cams;
    for (int i = 0; i < 6; ++i) cams.push_back(CameraAt(RandomRotation(random), centre));
    ExpectRefused([&] { AlignSimilarity(cams, cams); }, "camera centres all coincide");
  }
}

// Worst error of `estimate` against `truth`: relative scale and the mapped centres relative to
// their spread.
double RelativeError(const Similarity3d& estimate, const Similarity3d& truth,
                     const std::vector<Rigid3d>& cams, double spread) {
  double worst = std::abs(estimate.scale / truth.scale - 1);
  for (const Rigid3d& cam : cams) {
    const Eigen::Vector3d centre = CameraCenter(cam);
    worst = std::max(worst, (estimate * centre - truth * centre).norm() / (truth.scale * spread));
  }
  return worst;
}

TEST(AlignmentStability, NearlyCoincidentCentresAreRefusedOrAlignedCorrectly) {
  // Centres 1e3 from the origin spread over 1e-8..1e-4 (relative 1e-11..1e-7): as few as ~1e5
  // ulps of baseline. Either the alignment refuses, or the answer holds to the precision the
  // baseline allows: ulp(1e3) / spread, times a margin of 1e3 for the solver.
  constexpr double kUlpAt1e3 = 1.14e-13;
  std::mt19937 random(4);
  const Similarity3d truth = ExampleSimilarity();
  std::normal_distribution<double> normal;
  for (const double spread : {1e-8, 1e-6, 1e-4}) {
    SCOPED_TRACE(spread);
    const Eigen::Vector3d base(600, -800, 0);
    std::vector<Rigid3d> cams;
    for (int i = 0; i < 8; ++i) {
      const Eigen::Vector3d offset(normal(random), normal(random), normal(random));
      cams.push_back(CameraAt(RandomRotation(random), base + spread * offset));
    }
    const std::vector<Rigid3d> targets = Transform(truth, cams);
    try {
      const Similarity3d estimate = AlignSimilarity(cams, targets).target_from_source;
      const double allowed = 1e3 * kUlpAt1e3 / spread;
      const double error = RelativeError(estimate, truth, cams, spread);
      const double rotation_deg = RotationAngleDeg(estimate.rotation, truth.rotation);
      std::printf(
          "[ stability ] centres spread %g at 1e3: relative error %.3g, rotation %.3g deg"
          " (bound %.3g)\n",
          spread, error, rotation_deg, allowed);
      EXPECT_LT(error, allowed);
      // The orientations are exact; the centres pull the rotation by at most their error.
      EXPECT_LT(rotation_deg, allowed * 180 / std::numbers::pi);
    } catch (const InternalError& error) {
      EXPECT_NE(std::string(error.what()).find("coincide"), std::string::npos) << error.what();
    }
  }
}

TEST(AlignmentStability, TwoIdenticalCamerasAmongThreeStillAlign) {
  // Two distinct centres and three orientations determine the similarity; the coincident pair
  // must not poison the scale (its distance ratio is 0 / 0).
  std::mt19937 random(5);
  const Rigid3d twin = CameraAt(RandomRotation(random), {1, 0, 0});
  const std::vector<Rigid3d> cams = {twin, twin, CameraAt(RandomRotation(random), {-1, 0.5, 2})};
  const Similarity3d truth = ExampleSimilarity();
  const Similarity3d estimate = AlignSimilarity(cams, Transform(truth, cams)).target_from_source;
  EXPECT_LT(RelativeError(estimate, truth, cams, 2.3), 1e-9);
  EXPECT_LT(RotationAngleDeg(estimate.rotation, truth.rotation), 1e-7);
}

}  // namespace
}  // namespace parallax
