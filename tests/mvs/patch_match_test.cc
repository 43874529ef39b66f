// Multi-view stereo on constructed cases with known answers: planes rendered by the Embree
// ground-truth tracer, then PatchMatch and the geometric filter.
#include "mvs/patch_match.h"

#include <algorithm>
#include <cmath>
#include <numbers>

#include <gtest/gtest.h>

#include "mvs/depth_filter.h"
#include "synth/ray_tracer.h"
#include "synth/synth.h"

namespace parallax {
namespace {

// A scene of textured objects seen by one camera at `eye` and sources beside it.
struct Rig {
  SceneDesc scene;
  std::vector<StereoView> views;  // views[0] is the reference.
  std::vector<DepthMap> truth;
};

SceneDesc TexturedScene(float contrast = 1.5f) {
  SceneDesc scene;
  scene.image = {160, 120, 150, 2};
  scene.ambient = 1.0f;
  MaterialDesc material;
  material.texture.scale = 0.5f;
  material.texture.octaves = 5;
  material.texture.contrast = contrast;
  material.texture.color_a = {0.05f, 0.05f, 0.05f};
  material.texture.color_b = {0.6f, 0.6f, 0.6f};
  scene.materials["m"] = material;
  return scene;
}

GrayImage ToGray(const Image& linear) {
  GrayImage gray{linear.Width(), linear.Height(), {}};
  for (int y = 0; y < linear.Height(); ++y) {
    for (int x = 0; x < linear.Width(); ++x) {
      gray.values.push_back(std::clamp(LinearToSrgb(linear.At(x, y, 1)), 0.0f, 1.0f));
    }
  }
  return gray;
}

Rig RenderRig(const SceneDesc& scene, const Eigen::Vector3d& eye, const Eigen::Vector3d& target,
              const std::vector<Eigen::Vector3d>& source_offsets) {
  Rig rig{scene, {}, {}};
  const RayTracer tracer(scene);
  const Camera camera = SceneCamera(scene);
  std::vector<Eigen::Vector3d> eyes = {eye};
  for (const Eigen::Vector3d& offset : source_offsets) eyes.push_back(eye + offset);
  for (const Eigen::Vector3d& position : eyes) {
    const Rigid3d pose = LookAt(position, target + (position - eye), Eigen::Vector3d::UnitZ());
    const RenderedView rendered = tracer.Render(camera, pose);
    rig.views.push_back({camera, pose, ToGray(rendered.color)});
    rig.truth.push_back(rendered.depth);
  }
  return rig;
}

struct Accuracy {
  double coverage = 0;   // Share of truth-valid pixels with a depth.
  double within_1pct = 0;  // Share of estimated pixels within 1% of the truth.
  double within_2pct = 0;  // ... within 2%.
};

Accuracy Measure(const DepthMap& estimate, const DepthMap& truth) {
  int valid = 0, estimated = 0, good = 0, fair = 0;
  for (size_t i = 0; i < truth.Values().size(); ++i) {
    const float t = truth.Values()[i], e = estimate.Values()[i];
    EXPECT_TRUE(std::isfinite(e));
    if (!(t > 0)) continue;
    ++valid;
    if (!(e > 0)) continue;
    ++estimated;
    good += std::abs(e - t) / t < 0.01f;
    fair += std::abs(e - t) / t < 0.02f;
  }
  return {static_cast<double>(estimated) / std::max(1, valid),
          static_cast<double>(good) / std::max(1, estimated),
          static_cast<double>(fair) / std::max(1, estimated)};
}

DepthNormalMap EstimateDepth(const Rig& rig, double min_depth, double max_depth) {
  PatchMatchOptions options;
  options.min_depth = min_depth;
  options.max_depth = max_depth;
  std::vector<const StereoView*> sources;
  for (size_t i = 1; i < rig.views.size(); ++i) sources.push_back(&rig.views[i]);
  return PatchMatchStereo(rig.views[0], sources, options);
}

const std::vector<Eigen::Vector3d> kSideBySide = {{-0.5, 0, 0}, {0.5, 0, 0}, {0, 0, 0.4}};

TEST(PatchMatch, FrontoParallelPlaneIsRecovered) {
  SceneDesc scene = TexturedScene();
  scene.objects.push_back({ShapeType::kPlane, "m", {0, 6, 1}, {20, 20, 1}, {0, -1, 0}});
  const Rig rig = RenderRig(scene, {0, 0, 1}, {0, 6, 1}, kSideBySide);
  const Accuracy accuracy = Measure(EstimateDepth(rig, 1, 50).depth, rig.truth[0]);
  EXPECT_GT(accuracy.coverage, 0.85);  // The rest is the border the sources do not see.
  EXPECT_GT(accuracy.within_1pct, 0.95);
}

TEST(PatchMatch, SlantedPlaneIsRecoveredWithItsNormal) {
  SceneDesc scene = TexturedScene();
  const Eigen::Vector3d normal = Eigen::Vector3d(0.6, -0.5, 0.3).normalized();
  scene.objects.push_back({ShapeType::kPlane, "m", {0, 5, 1}, {20, 20, 1}, normal});
  const Rig rig = RenderRig(scene, {0, 0, 1}, {0, 5, 1}, kSideBySide);
  const DepthNormalMap estimate = EstimateDepth(rig, 1, 50);
  const Accuracy accuracy = Measure(estimate.depth, rig.truth[0]);
  EXPECT_GT(accuracy.coverage, 0.85);
  EXPECT_GT(accuracy.within_1pct, 0.9);
  // Normals, in the camera frame, agree with the plane's (median angle under 10 degrees).
  const Eigen::Vector3d expected = rig.views[0].cam_from_world.rotation * normal;
  std::vector<double> angles;
  for (size_t i = 0; i < estimate.cost.size(); ++i) {
    if (!(estimate.depth.Values()[i] > 0)) continue;
    const Eigen::Vector3d n(estimate.normal[3 * i], estimate.normal[3 * i + 1], estimate.normal[3 * i + 2]);
    angles.push_back(std::acos(std::clamp(std::abs(n.dot(expected)), 0.0, 1.0)) * 180 / std::numbers::pi);
  }
  ASSERT_FALSE(angles.empty());
  std::nth_element(angles.begin(), angles.begin() + angles.size() / 2, angles.end());
  EXPECT_LT(angles[angles.size() / 2], 10);
}

// Every view of the rig estimated in turn, then the reference's depth filtered against them.
FilteredDepth EstimateAndFilter(const Rig& rig, double min_depth, double max_depth) {
  std::vector<DepthNormalMap> estimates;
  for (size_t i = 0; i < rig.views.size(); ++i) {
    Rig rotated = rig;
    std::swap(rotated.views[0], rotated.views[i]);
    estimates.push_back(EstimateDepth(rotated, min_depth, max_depth));
  }
  std::vector<std::pair<const StereoView*, const DepthNormalMap*>> sources;
  for (size_t i = 1; i < rig.views.size(); ++i) sources.emplace_back(&rig.views[i], &estimates[i]);
  return FilterGeometric(rig.views[0], estimates[0], sources, {});
}

TEST(PatchMatch, StepEdgeIsNotBlurredIntoIntermediateDepths) {
  SceneDesc scene = TexturedScene();
  scene.objects.push_back({ShapeType::kPlane, "m", {0, 8, 1}, {20, 20, 1}, {0, -1, 0}});
  scene.objects.push_back({ShapeType::kBox, "m", {-0.6, 4, 1}, {1.2, 0.5, 4}});
  const Rig rig = RenderRig(scene, {0, 0, 1}, {0, 6, 1}, kSideBySide);
  // Photometric depths alone: wrong depths at the step stay a fringe, not a smear ...
  const Accuracy photometric = Measure(EstimateDepth(rig, 1, 50).depth, rig.truth[0]);
  EXPECT_GT(photometric.coverage, 0.8);
  EXPECT_GT(photometric.within_1pct, 0.8);
  // ... and the geometric filter (3% agreement) removes most of the fringe (measured: 96.5% of
  // the kept depths within 2%; 97.5% with a 2% agreement, which costs 1.1 points of
  // completeness on the courtyard).
  const Accuracy filtered = Measure(EstimateAndFilter(rig, 1, 50).depth, rig.truth[0]);
  EXPECT_GT(filtered.coverage, 0.7);
  EXPECT_GT(filtered.within_2pct, 0.96);
}

TEST(PatchMatch, TexturelessSurfacesGetNoDepth) {
  SceneDesc scene = TexturedScene(0.0f);  // Contrast 0: a uniform grey wall.
  scene.objects.push_back({ShapeType::kPlane, "m", {0, 6, 1}, {20, 20, 1}, {0, -1, 0}});
  const Rig rig = RenderRig(scene, {0, 0, 1}, {0, 6, 1}, kSideBySide);
  const Accuracy accuracy = Measure(EstimateDepth(rig, 1, 50).depth, rig.truth[0]);
  EXPECT_LT(accuracy.coverage, 0.01);
}

TEST(PatchMatch, HugeDepthRangeStaysFiniteAndMostlyRight) {
  SceneDesc scene = TexturedScene();
  scene.objects.push_back({ShapeType::kPlane, "m", {0, 6, 1}, {20, 20, 1}, {0, -1, 0}});
  const Rig rig = RenderRig(scene, {0, 0, 1}, {0, 6, 1}, kSideBySide);
  const DepthNormalMap estimate = EstimateDepth(rig, 1e-2, 1e4);
  for (const float value : estimate.normal) ASSERT_TRUE(std::isfinite(value));
  for (const float value : estimate.cost) ASSERT_TRUE(std::isfinite(value));
  const Accuracy accuracy = Measure(estimate.depth, rig.truth[0]);
  EXPECT_GT(accuracy.coverage, 0.5);
  EXPECT_GT(accuracy.within_1pct, 0.8);
}

TEST(PatchMatch, TinyBaselineIsFlaggedLowConfidence) {
  SceneDesc scene = TexturedScene();
  scene.objects.push_back({ShapeType::kPlane, "m", {0, 6, 1}, {20, 20, 1}, {0, -1, 0}});
  // Sources 6 mm from the reference: 0.1% of the 6 m depth.
  const Rig rig = RenderRig(scene, {0, 0, 1}, {0, 6, 1}, {{-0.006, 0, 0}, {0.006, 0, 0}});
  const FilteredDepth filtered = EstimateAndFilter(rig, 1, 50);
  int confident = 0, kept = 0;
  for (size_t i = 0; i < filtered.depth.Values().size(); ++i) {
    if (!(filtered.depth.Values()[i] > 0)) continue;
    ++kept;
    confident += filtered.confidence.Values()[i] > 0.2f;
  }
  EXPECT_EQ(confident, 0) << "of " << kept << " kept depths";
}

TEST(PatchMatch, GeometricFilterKeepsConsistentDepthsWithConfidence) {
  SceneDesc scene = TexturedScene();
  scene.objects.push_back({ShapeType::kPlane, "m", {0, 6, 1}, {20, 20, 1}, {0, -1, 0}});
  const Rig rig = RenderRig(scene, {0, 0, 1}, {0, 6, 1}, kSideBySide);
  // The truth itself is perfectly consistent: everything the sources also see is kept.
  std::vector<DepthNormalMap> truths;
  for (const DepthMap& depth : rig.truth) {
    truths.push_back({depth, std::vector<float>(depth.Values().size() * 3, 0.0f),
                      std::vector<float>(depth.Values().size(), 0.0f)});
  }
  std::vector<std::pair<const StereoView*, const DepthNormalMap*>> sources;
  for (size_t i = 1; i < rig.views.size(); ++i) sources.emplace_back(&rig.views[i], &truths[i]);
  const FilteredDepth filtered = FilterGeometric(rig.views[0], truths[0], sources, {});
  EXPECT_GT(Measure(filtered.depth, rig.truth[0]).coverage, 0.9);
  // A depth 5% off is inconsistent with every source (the filter allows 3%) and removed.
  DepthNormalMap wrong = truths[0];
  for (float& value : wrong.depth.Values()) value *= 1.05f;
  EXPECT_LT(Measure(FilterGeometric(rig.views[0], wrong, sources, {}).depth, rig.truth[0]).coverage, 0.01);
}

TEST(PatchMatch, PlaneHomographyMapsPlanePointsToTheirSourcePixels) {
  const Camera camera = MakePinholeCamera(1, 640, 480, 500, 510, 320, 240);
  const Rigid3d source_from_ref(Eigen::Quaterniond(Eigen::AngleAxisd(0.1, Eigen::Vector3d(0.2, 1, 0).normalized())),
                                Eigen::Vector3d(-0.4, 0.05, 0.1));
  const Eigen::Vector3d normal = Eigen::Vector3d(0.1, -0.2, -1).normalized();
  const double rho = normal.dot(Eigen::Vector3d(0.3, -0.2, 5));
  const Eigen::Matrix3d h = PlaneHomography(camera, camera, source_from_ref, normal, rho);
  for (const Eigen::Vector2d& pixel : {Eigen::Vector2d(10.5, 20.5), Eigen::Vector2d(320, 240),
                                       Eigen::Vector2d(600.5, 470.5)}) {
    const Eigen::Vector3d ray = *camera.Unproject(pixel);
    const Eigen::Vector3d point = ray * (rho / normal.dot(ray));  // On the plane.
    const Eigen::Vector2d expected = *camera.Project(source_from_ref * point);
    const Eigen::Vector3d mapped = h * pixel.homogeneous();
    EXPECT_LT((mapped.hnormalized() - expected).norm(), 1e-9);
  }
}

TEST(PatchMatch, InverseDepthSamplingIsUniformInInverseDepth) {
  EXPECT_DOUBLE_EQ(InverseDepthSample(1, 100, 0), 100);
  EXPECT_DOUBLE_EQ(InverseDepthSample(1, 100, 1), 1);
  EXPECT_NEAR(InverseDepthSample(1, 100, 0.5), 1 / (0.5 * (1 + 0.01)), 1e-12);
  EXPECT_NEAR(InverseDepthSample(1e-3, 1e5, 0.5), 1 / (0.5 * (1e3 + 1e-5)), 1e-12);
}

TEST(PatchMatch, WindowCostIsZeroForIdenticalAndAffineRelitWindows) {
  GrayImage image{40, 40, {}};
  for (int y = 0; y < 40; ++y) {
    for (int x = 0; x < 40; ++x) image.values.push_back(0.5f + 0.3f * std::sin(x * 0.9f) * std::cos(y * 0.7f));
  }
  GrayImage relit = image;
  for (float& value : relit.values) value = 0.5f * value + 0.2f;  // Darker, lower contrast.
  PatchMatchOptions options;
  EXPECT_NEAR(WindowCost(image, 20, 20, image, Eigen::Matrix3d::Identity(), options), 0, 1e-4);
  EXPECT_NEAR(WindowCost(image, 20, 20, relit, Eigen::Matrix3d::Identity(), options), 0, 1e-4);
  Eigen::Matrix3d shifted = Eigen::Matrix3d::Identity();
  shifted(0, 2) = 3;  // Three pixels off: a poor match.
  EXPECT_GT(WindowCost(image, 20, 20, image, shifted, options), 0.3f);
  shifted(0, 2) = 100;  // Outside the source image.
  EXPECT_FLOAT_EQ(WindowCost(image, 20, 20, image, shifted, options), 2.0f);
  const GrayImage flat{40, 40, std::vector<float>(1600, 0.5f)};
  EXPECT_FLOAT_EQ(WindowCost(flat, 20, 20, flat, Eigen::Matrix3d::Identity(), options), 2.0f);
}

}  // namespace
}  // namespace parallax

namespace parallax {
namespace {

TEST(DepthFilter, GapsInsideASurfaceAreFilledButDepthEdgesAreNotBridged) {
  FilteredDepth map{DepthMap(20, 10), DepthMap(20, 10)};
  // Left half at depth 2 + x/100 (a slanted plane), right half a wall at 4.
  for (int y = 0; y < 10; ++y) {
    for (int x = 0; x < 20; ++x) {
      map.depth.At(x, y) = x < 10 ? 2.0f + 0.01f * static_cast<float>(x) : 4.0f;
      map.confidence.At(x, y) = 0.8f;
    }
  }
  // A 3x3 gap inside the plane, and a 2-px wide gap along the edge between the halves.
  for (int y = 3; y < 6; ++y) {
    for (int x = 3; x < 6; ++x) map.depth.At(x, y) = map.confidence.At(x, y) = 0;
  }
  for (int y = 0; y < 10; ++y) {
    for (int x = 9; x < 11; ++x) map.depth.At(x, y) = map.confidence.At(x, y) = 0;
  }
  FillGaps(4, 0.02, map);
  for (int y = 3; y < 6; ++y) {
    for (int x = 3; x < 6; ++x) {
      EXPECT_NEAR(map.depth.At(x, y), 2.0f + 0.01f * static_cast<float>(x), 1e-3f) << x << "," << y;
      EXPECT_FLOAT_EQ(map.confidence.At(x, y), 0.4f);
    }
  }
  for (int y = 0; y < 10; ++y) {
    EXPECT_EQ(map.depth.At(9, y), 0.0f) << "the step from 2.08 to 4 is an edge, not a gap";
    EXPECT_EQ(map.depth.At(10, y), 0.0f);
  }
}

}  // namespace
}  // namespace parallax
