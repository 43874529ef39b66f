#include "geometry/similarity.h"

#include <algorithm>
#include <cmath>
#include <functional>
#include <limits>
#include <numbers>
#include <random>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "core/error.h"
#include "tests/random_rotation.h"

namespace parallax {
namespace {

// Exact data comes back to rounding: every error is relative (centres to the target extent,
// scale to itself), and the solver works in normalised coordinates, so one bound fits all
// scales. Measured worst: about 1e-15 relative and 1e-13 degrees.
constexpr double kExactRelative = 1e-10;
constexpr double kExactDeg = 1e-8;
// Offsets of 1e6 on a unit-sized scene leave only ~1e-10 absolute precision in each centre
// (the ulp at 1e6), i.e. ~1e-10 relative to the extent and ~1e-8 degrees of rotation through
// the centres. Measured worst: 4e-10 relative, 4e-9 degrees.
constexpr double kLargeOffsetRelative = 1e-7;
constexpr double kLargeOffsetDeg = 1e-6;
// Centres on a line (exactly, or with 1e-9 jitter) leave the roll about the line to the
// orientations; those are exact here, so this is loose. Measured worst: 5e-15 relative.
constexpr double kCollinearRelative = 1e-8;
constexpr double kCollinearDeg = 1e-6;

using test::RandomRotation;

Eigen::Vector3d RandomVector(std::mt19937& random, double sigma) {
  std::normal_distribution<double> normal(0, sigma);
  return {normal(random), normal(random), normal(random)};
}

Rigid3d CameraAt(const Eigen::Quaterniond& rotation, const Eigen::Vector3d& centre) {
  return Rigid3d(rotation, -(rotation * centre));
}

// Random orientations, centres uniform in [-1, 1]^3.
std::vector<Rigid3d> BoxCameras(int count, std::mt19937& random) {
  std::uniform_real_distribution<double> uniform(-1, 1);
  std::vector<Rigid3d> cams;
  for (int i = 0; i < count; ++i) {
    const Eigen::Vector3d centre(uniform(random), uniform(random), uniform(random));
    cams.push_back(CameraAt(RandomRotation(random), centre));
  }
  return cams;
}

// A coplanar ring of cameras looking at the origin, as a turntable capture.
std::vector<Rigid3d> RingCameras(int count) {
  std::vector<Rigid3d> cams;
  for (int i = 0; i < count; ++i) {
    const double angle = 2 * std::numbers::pi * i / count;
    const Eigen::Vector3d eye(3 * std::cos(angle), 3 * std::sin(angle), 0);
    cams.push_back(LookAt(eye, Eigen::Vector3d::Zero(), Eigen::Vector3d::UnitZ()));
  }
  return cams;
}

// Centres evenly spaced on a line through (0.3, -0.2, 0.1), each moved off it by `jitter`.
std::vector<Rigid3d> LineCameras(int count, double jitter, std::mt19937& random) {
  const Eigen::Vector3d direction = Eigen::Vector3d(1, 2, -0.5).normalized();
  std::vector<Rigid3d> cams;
  for (int i = 0; i < count; ++i) {
    const Eigen::Vector3d centre = Eigen::Vector3d(0.3, -0.2, 0.1) +
                                   (-1 + 2.0 * i / (count - 1)) * direction +
                                   RandomVector(random, jitter);
    cams.push_back(CameraAt(RandomRotation(random), centre));
  }
  return cams;
}

Similarity3d MakeSimilarity(double scale, const Eigen::Vector3d& translation,
                            double angle_rad = 1.1) {
  Similarity3d similarity;
  similarity.scale = scale;
  similarity.rotation =
      Eigen::Quaterniond(Eigen::AngleAxisd(angle_rad, Eigen::Vector3d(1, -2, 3).normalized()));
  similarity.translation = translation;
  return similarity;
}

// From first principles, not via TransformPose (tested against this): rotation R_cam R^T,
// centre s R c + t.
std::vector<Rigid3d> Transform(const Similarity3d& similarity, const std::vector<Rigid3d>& cams) {
  std::vector<Rigid3d> transformed;
  for (const Rigid3d& cam : cams) {
    transformed.push_back(
        CameraAt(cam.rotation * similarity.rotation.conjugate(), similarity * CameraCenter(cam)));
  }
  return transformed;
}

double TargetExtent(const std::vector<Rigid3d>& cams) {
  double extent = 0;
  for (const Rigid3d& a : cams) {
    for (const Rigid3d& b : cams) {
      extent = std::max(extent, (CameraCenter(a) - CameraCenter(b)).norm());
    }
  }
  return extent;
}

struct AlignmentError {
  double rotation_deg = 0;
  double scale_relative = 0;
  double centre_relative = 0;  // Worst mapped source centre, relative to the target extent.
};

AlignmentError Compare(const Similarity3d& estimate, const Similarity3d& truth,
                       const std::vector<Rigid3d>& source_cams) {
  const double extent = TargetExtent(Transform(truth, source_cams));
  AlignmentError error;
  error.rotation_deg = RotationAngleDeg(estimate.rotation, truth.rotation);
  error.scale_relative = std::abs(estimate.scale / truth.scale - 1);
  for (const Rigid3d& cam : source_cams) {
    const Eigen::Vector3d centre = CameraCenter(cam);
    error.centre_relative =
        std::max(error.centre_relative, (estimate * centre - truth * centre).norm() / extent);
  }
  return error;
}

void ExpectRecovered(const Similarity3d& estimate, const Similarity3d& truth,
                     const std::vector<Rigid3d>& source_cams, double relative, double deg) {
  const AlignmentError error = Compare(estimate, truth, source_cams);
  EXPECT_LT(error.rotation_deg, deg);
  EXPECT_LT(error.scale_relative, relative);
  EXPECT_LT(error.centre_relative, relative);
}

void ExpectExactRecovery(const std::vector<Rigid3d>& source_cams, const Similarity3d& truth,
                         double relative = kExactRelative, double deg = kExactDeg) {
  const std::vector<Rigid3d> target_cams = Transform(truth, source_cams);
  const AlignmentResult result = AlignSimilarity(source_cams, target_cams);
  ExpectRecovered(result.target_from_source, truth, source_cams, relative, deg);
  EXPECT_EQ(result.inliers, int(source_cams.size()));
  EXPECT_LT(result.final_cost, 1e-12);
}

// `call` throws an Error whose message contains `fragment`.
template <typename Error = InternalError>
void ExpectRefused(const std::function<void()>& call, const std::string& fragment) {
  try {
    call();
    ADD_FAILURE() << "accepted; expected a refusal mentioning '" << fragment << "'";
  } catch (const Error& error) {
    EXPECT_NE(std::string(error.what()).find(fragment), std::string::npos) << error.what();
  }
}

TEST(AlignSimilarity, RecoversExactTransformOfRandomCameras) {
  std::mt19937 random(1);
  ExpectExactRecovery(BoxCameras(20, random), MakeSimilarity(2.5, {1, -2, 3}));
}

TEST(AlignSimilarity, RecoversExactTransformOfACoplanarRing) {
  ExpectExactRecovery(RingCameras(12), MakeSimilarity(0.4, {-3, 0.5, 7}));
}

TEST(AlignSimilarity, RecoversTransformOfThreeCameras) {
  std::mt19937 random(2);
  ExpectExactRecovery(BoxCameras(3, random), MakeSimilarity(1.7, {0.2, 0.1, -0.4}));
}

TEST(AlignSimilarity, RecoversTransformAtScaleOneMillionth) {
  std::mt19937 random(3);
  ExpectExactRecovery(BoxCameras(15, random), MakeSimilarity(1e-6, {2e-6, 0, -1e-6}));
}

TEST(AlignSimilarity, RecoversTransformAtScaleOneMillion) {
  std::mt19937 random(4);
  ExpectExactRecovery(BoxCameras(15, random), MakeSimilarity(1e6, {3e6, -1e6, 0}));
}

TEST(AlignSimilarity, RecoversTransformAtScalesOf1eMinus8And1e8) {
  std::mt19937 random(5);
  const std::vector<Rigid3d> cams = BoxCameras(15, random);
  ExpectExactRecovery(cams, MakeSimilarity(1e-8, {1e-8, 2e-8, 0}));
  ExpectExactRecovery(cams, MakeSimilarity(1e8, {0, 1e8, -2e8}));
}

TEST(AlignSimilarity, RecoversTranslationOfOneMillion) {
  std::mt19937 random(6);
  ExpectExactRecovery(BoxCameras(15, random), MakeSimilarity(1.3, {1e6, -1e6, 5e5}),
                      kLargeOffsetRelative, kLargeOffsetDeg);
}

TEST(AlignSimilarity, RecoversSourceFarFromTheOrigin) {
  std::mt19937 random(7);
  std::vector<Rigid3d> cams = BoxCameras(15, random);
  for (Rigid3d& cam : cams)
    cam = CameraAt(cam.rotation, CameraCenter(cam) + Eigen::Vector3d(1e6, 2e6, 0));
  ExpectExactRecovery(cams, MakeSimilarity(0.5, {-5e5, -1e6, 0}), kLargeOffsetRelative,
                      kLargeOffsetDeg);
}

TEST(AlignSimilarity, NearlyCollinearCentresAreResolvedByTheOrientations) {
  std::mt19937 random(8);
  const std::vector<Rigid3d> source_cams = LineCameras(10, 1e-9, random);
  const Similarity3d truth = MakeSimilarity(3, {1, 2, 3});
  const AlignmentResult result = AlignSimilarity(source_cams, Transform(truth, source_cams));
  ExpectRecovered(result.target_from_source, truth, source_cams, kCollinearRelative, kCollinearDeg);
  EXPECT_EQ(result.inliers, 10);
}

TEST(AlignSimilarity, ExactlyCollinearCentresAreResolvedByTheOrientations) {
  std::mt19937 random(9);
  const std::vector<Rigid3d> source_cams = LineCameras(10, 0, random);
  const Similarity3d truth = MakeSimilarity(0.2, {-1, 0, 4});
  const AlignmentResult result = AlignSimilarity(source_cams, Transform(truth, source_cams));
  ExpectRecovered(result.target_from_source, truth, source_cams, kCollinearRelative, kCollinearDeg);
  EXPECT_EQ(result.inliers, 10);
}

// Centres on a line say nothing about the roll about it (so there is no Umeyama start), and a
// third of the orientations are wrong: the agreeing two thirds must fix the rotation, here
// one of nearly 180 degrees.
TEST(AlignSimilarity, CollinearCentresWithOutliersAreResolvedByTheAgreeingOrientations) {
  std::mt19937 random(18);
  const std::vector<Rigid3d> source_cams = LineCameras(12, 0, random);
  const Similarity3d truth = MakeSimilarity(3, {1, 2, 3}, 3.0);
  std::vector<Rigid3d> target_cams = Transform(truth, source_cams);
  std::vector<Rigid3d> inlier_source_cams;
  for (int i = 0; i < 12; ++i) {
    if (i % 3 == 0) {
      target_cams[i] = CameraAt(RandomRotation(random), truth * RandomVector(random, 1));
    } else {
      inlier_source_cams.push_back(source_cams[i]);
    }
  }
  const AlignmentResult result = AlignSimilarity(source_cams, target_cams);
  EXPECT_EQ(result.inliers, 8);
  ExpectRecovered(result.target_from_source, truth, inlier_source_cams, kCollinearRelative,
                  kCollinearDeg);
}

TEST(AlignSimilarity, ThirtyPercentOutliersAreRejectedAndTheInliersDefineTheTransform) {
  std::mt19937 random(10);
  const std::vector<Rigid3d> source_cams = BoxCameras(30, random);
  const Similarity3d truth = MakeSimilarity(4, {10, -3, 2});
  std::vector<Rigid3d> target_cams = Transform(truth, source_cams);
  // Wrong poses drawn from the same region, so no centre is an obvious far-away outlier.
  std::uniform_real_distribution<double> uniform(-1, 1);
  std::vector<Rigid3d> inlier_source_cams;
  for (int i = 0; i < 30; ++i) {
    if (i % 10 < 3) {
      const Eigen::Vector3d centre(uniform(random), uniform(random), uniform(random));
      target_cams[i] = CameraAt(RandomRotation(random), truth * centre);
    } else {
      inlier_source_cams.push_back(source_cams[i]);
    }
  }
  const AlignmentResult result = AlignSimilarity(source_cams, target_cams);
  EXPECT_EQ(result.inliers, 21);
  ExpectRecovered(result.target_from_source, truth, inlier_source_cams, kExactRelative, kExactDeg);
}

TEST(AlignSimilarity, GaussianNoiseGivesErrorsWithinAFewSigmas) {
  constexpr int kCount = 60;
  // Noise: 1e-3 of the target extent on each centre coordinate, 0.1 degrees per rotation axis.
  constexpr double kCentreSigmaRelative = 1e-3;
  constexpr double kRotationSigmaDeg = 0.1;
  // An estimate from n cameras has about sigma / sqrt(n) error per axis; allow 4 such sigmas
  // on the norm of three axes.
  const double bound = 4 * std::sqrt(3.0 / kCount);
  std::mt19937 random(11);
  const std::vector<Rigid3d> source_cams = BoxCameras(kCount, random);
  const Similarity3d truth = MakeSimilarity(2, {0, 1, -1});
  std::vector<Rigid3d> target_cams = Transform(truth, source_cams);
  const double extent = TargetExtent(target_cams);
  for (Rigid3d& cam : target_cams) {
    const Eigen::Vector3d axis_angle =
        RandomVector(random, kRotationSigmaDeg * std::numbers::pi / 180);
    const Eigen::Quaterniond noise(Eigen::AngleAxisd(axis_angle.norm(), axis_angle.normalized()));
    cam = CameraAt(noise * cam.rotation,
                   CameraCenter(cam) + RandomVector(random, kCentreSigmaRelative * extent));
  }
  const AlignmentResult result = AlignSimilarity(source_cams, target_cams);
  EXPECT_EQ(result.inliers, kCount);
  const AlignmentError error = Compare(result.target_from_source, truth, source_cams);
  EXPECT_LT(error.rotation_deg, bound * kRotationSigmaDeg);
  EXPECT_LT(error.scale_relative, bound * kCentreSigmaRelative);
  EXPECT_LT(error.centre_relative, bound * kCentreSigmaRelative);
}

TEST(Similarity3d, TransformPoseMapsEachSourceCameraOntoItsTargetPose) {
  std::mt19937 random(12);
  const std::vector<Rigid3d> source_cams = BoxCameras(10, random);
  const Similarity3d truth = MakeSimilarity(5, {1, 1, 1});
  const std::vector<Rigid3d> target_cams = Transform(truth, source_cams);
  const Similarity3d estimate = AlignSimilarity(source_cams, target_cams).target_from_source;
  for (size_t i = 0; i < source_cams.size(); ++i) {
    for (const Similarity3d& similarity : {truth, estimate}) {
      const Rigid3d cam_from_target = similarity.TransformPose(source_cams[i]);
      EXPECT_LT(RotationAngleDeg(cam_from_target.rotation, target_cams[i].rotation), kExactDeg);
      EXPECT_LT((CameraCenter(cam_from_target) - CameraCenter(target_cams[i])).norm(),
                kExactRelative * 5);
    }
  }
  // A point keeps its camera-frame direction, and its depth scales with the similarity.
  const Eigen::Vector3d point_in_source(0.3, -0.4, 2);
  const Eigen::Vector3d point_in_cam = source_cams[0] * point_in_source;
  const Eigen::Vector3d point_in_scaled_cam =
      truth.TransformPose(source_cams[0]) * (truth * point_in_source);
  EXPECT_LT((point_in_scaled_cam - truth.scale * point_in_cam).norm(), 1e-12);
}

TEST(AlignSimilarity, RejectsFewerThanThreeCameras) {
  std::mt19937 random(13);
  const std::vector<Rigid3d> cams = BoxCameras(2, random);
  ExpectRefused([&] { AlignSimilarity(cams, cams); }, "at least 3 cameras");
}

TEST(AlignSimilarity, RejectsMismatchedCounts) {
  std::mt19937 random(14);
  const std::vector<Rigid3d> source_cams = BoxCameras(5, random);
  const std::vector<Rigid3d> target_cams = BoxCameras(4, random);
  ExpectRefused([&] { AlignSimilarity(source_cams, target_cams); },
                        "5 source cameras but 4 target cameras");
}

TEST(AlignSimilarity, RejectsTargetCentresThatAllCoincide) {
  std::mt19937 random(15);
  const std::vector<Rigid3d> source_cams = BoxCameras(5, random);
  std::vector<Rigid3d> target_cams;
  for (int i = 0; i < 5; ++i) target_cams.push_back(CameraAt(RandomRotation(random), {1e3, 2, 3}));
  ExpectRefused([&] { AlignSimilarity(source_cams, target_cams); },
                        "target camera centres all coincide");
  ExpectRefused([&] { AlignSimilarity(target_cams, source_cams); },
                        "source camera centres all coincide");
}

TEST(AlignSimilarity, RejectsNonFinitePoses) {
  std::mt19937 random(16);
  const std::vector<Rigid3d> source_cams = BoxCameras(5, random);
  std::vector<Rigid3d> target_cams = source_cams;
  target_cams[3].translation.y() = std::numeric_limits<double>::quiet_NaN();
  ExpectRefused([&] { AlignSimilarity(source_cams, target_cams); }, "target camera 3");
  target_cams[3] = source_cams[3];
  target_cams[1].rotation.w() = std::numeric_limits<double>::infinity();
  ExpectRefused([&] { AlignSimilarity(target_cams, source_cams); }, "source camera 1");
}

TEST(AlignmentOptions, CheckRejectsNonPositiveOrNonFiniteFields) {
  EXPECT_NO_THROW(AlignmentOptions().Check());
  AlignmentOptions options;
  options.inlier_center_fraction = 0;
  ExpectRefused<UsageError>([&] { options.Check(); }, "inlier_center_fraction");
  options = {};
  options.inlier_rotation_deg = -1;
  ExpectRefused<UsageError>([&] { options.Check(); }, "inlier_rotation_deg");
  options = {};
  options.robust_center_fraction = std::numeric_limits<double>::quiet_NaN();
  ExpectRefused<UsageError>([&] { options.Check(); }, "robust_center_fraction");
  options = {};
  options.robust_rotation_deg = std::numeric_limits<double>::infinity();
  ExpectRefused<UsageError>([&] { options.Check(); }, "robust_rotation_deg");
  std::mt19937 random(17);
  const std::vector<Rigid3d> cams = BoxCameras(4, random);
  ExpectRefused<UsageError>([&] { AlignSimilarity(cams, cams, options); }, "robust_rotation_deg");
}

}  // namespace
}  // namespace parallax

namespace parallax {
namespace {

TEST(Similarity3d, InverseUndoesPointsAndPoses) {
  Similarity3d similarity;
  similarity.scale = 3.5;
  similarity.rotation = Eigen::Quaterniond(Eigen::AngleAxisd(0.7, Eigen::Vector3d(1, 2, 3).normalized()));
  similarity.translation = Eigen::Vector3d(-4, 5, 0.25);
  const Similarity3d inverse = similarity.Inverse();
  const Eigen::Vector3d point(1.5, -2, 7);
  EXPECT_LT((inverse * (similarity * point) - point).norm(), 1e-12);
  const Rigid3d pose = LookAt({1, 2, 3}, {0, 0, 0}, {0, 0, 1});
  const Rigid3d back = inverse.TransformPose(similarity.TransformPose(pose));
  EXPECT_LT(RotationAngleDeg(back.rotation, pose.rotation), 1e-9);
  EXPECT_LT((CameraCenter(back) - CameraCenter(pose)).norm(), 1e-12);
}

}  // namespace
}  // namespace parallax
