// The float paths of numerically sensitive routines against double references on random
// inputs (issue: numerical stability). Each test reports its worst error (a printed line and
// a RecordProperty in the XML) and asserts it under a bound stated as float roundings times
// the condition number of the computation.
//
// kEps is float's machine epsilon (tests/stability/float_reference.h). The viewer's matrices
// are in viewer_float_reference_test.cc.
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>
#include <numbers>
#include <optional>
#include <ostream>
#include <random>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "mvs/patch_match.h"
#include "reproject/forward_warp.h"
#include "tests/stability/float_reference.h"

namespace parallax {

// "fastest" or "portable": in the tests' names and their reports.
void PrintTo(CostKernel kernel, std::ostream* out) {
  *out << (kernel == CostKernel::kFastest ? "fastest" : "portable");
}

namespace {

using stability_test::kEps;
using stability_test::Report;

// ---- PatchMatch's bilaterally weighted NCC (WindowCost, float) ---------------------------

// A smooth random texture of mean `mean` and contrast `contrast`.
GrayImage RandomWindowImage(int size, double mean, double contrast, std::mt19937& random) {
  std::uniform_real_distribution<double> unit(0, 1);
  double kx[4], ky[4], phase[4];
  for (int k = 0; k < 4; ++k) {
    const double wavelength = 3 + 9 * unit(random), angle = 2 * std::numbers::pi * unit(random);
    kx[k] = 2 * std::numbers::pi / wavelength * std::cos(angle);
    ky[k] = 2 * std::numbers::pi / wavelength * std::sin(angle);
    phase[k] = 2 * std::numbers::pi * unit(random);
  }
  GrayImage image{size, size, {}};
  for (int y = 0; y < size; ++y) {
    for (int x = 0; x < size; ++x) {
      double value = 0;
      for (int k = 0; k < 4; ++k) value += std::sin(kx[k] * x + ky[k] * y + phase[k]);
      image.values.push_back(static_cast<float>(std::clamp(mean + contrast * value / 2, 0.0, 1.0)));
    }
  }
  return image;
}

double Bilinear(const GrayImage& image, double u, double v) {
  const int x0 = static_cast<int>(u), y0 = static_cast<int>(v);
  const double ax = u - x0, ay = v - y0;
  const auto at = [&](int x, int y) { return static_cast<double>(image.At(x, y)); };
  return (1 - ay) * ((1 - ax) * at(x0, y0) + ax * at(x0 + 1, y0)) +
         ay * ((1 - ax) * at(x0, y0 + 1) + ax * at(x0 + 1, y0 + 1));
}

// WindowCost in double with two-pass (centred) moments, which do not cancel. `kappa` gets
// the condition number of the float formulas, E[I^2] - E[I]^2 style: (mean^2 + var) / var of
// the worse of the two windows. `near_threshold` is set where a float rounding could flip one
// of WindowCost's decisions (textured or not, inside the image or not): those samples are
// not comparable.
double ReferenceCost(const GrayImage& reference, int x, int y, const GrayImage& source,
                     const Eigen::Matrix3d& h, const PatchMatchOptions& options, double* kappa,
                     bool* near_threshold) {
  struct Sample {
    double weight, i, j;
  };
  std::vector<Sample> samples;
  const double sigma_spatial = static_cast<double>(options.sigma_spatial_px);
  const double sigma_color = static_cast<double>(options.sigma_color);
  const double min_std = static_cast<double>(options.min_texture_std);
  const double centre = static_cast<double>(reference.At(x, y));
  double weight_sum = 0;
  *near_threshold = false;
  for (int dy = -options.window_radius; dy <= options.window_radius; dy += options.window_step) {
    for (int dx = -options.window_radius; dx <= options.window_radius; dx += options.window_step) {
      const double i = static_cast<double>(reference.At(
          std::clamp(x + dx, 0, reference.width - 1), std::clamp(y + dy, 0, reference.height - 1)));
      const double weight =
          std::exp(-(dx * dx + dy * dy) / (2 * sigma_spatial * sigma_spatial)) *
          std::exp(-(i - centre) * (i - centre) / (2 * sigma_color * sigma_color));
      const Eigen::Vector3d p = h * Eigen::Vector3d(x + 0.5 + dx, y + 0.5 + dy, 1);
      const double u = p.x() / p.z() - 0.5, v = p.y() / p.z() - 0.5;
      const double max_u = source.width - 1, max_v = source.height - 1;
      if (std::min({u, v, max_u - u, max_v - v}) < 1e-3) *near_threshold = true;
      if (!(u >= 0 && v >= 0 && u < max_u && v < max_v)) return 2;
      samples.push_back({weight, i, Bilinear(source, u, v)});
      weight_sum += weight;
    }
  }
  double mean_i = 0, mean_j = 0;
  for (Sample& s : samples) {
    s.weight /= weight_sum;
    mean_i += s.weight * s.i;
    mean_j += s.weight * s.j;
  }
  double var_i = 0, var_j = 0, covariance = 0;
  for (const Sample& s : samples) {
    var_i += s.weight * (s.i - mean_i) * (s.i - mean_i);
    var_j += s.weight * (s.j - mean_j) * (s.j - mean_j);
    covariance += s.weight * (s.i - mean_i) * (s.j - mean_j);
  }
  // Flat windows (var 0) make kappa infinite: they are refused by both, with no error.
  const double tiny = 1e-30;
  *kappa = std::max((mean_i * mean_i + var_i) / std::max(var_i, tiny),
                    (mean_j * mean_j + var_j) / std::max(var_j, tiny));
  const double min_var = min_std * min_std;
  if (std::abs(var_i / min_var - 1) < 0.05 || std::abs(var_j / min_var - 1) < 0.05) {
    *near_threshold = true;
  }
  if (std::sqrt(var_i) < min_std || !(var_j > min_var)) return 2;
  return 1 - std::clamp(covariance / std::sqrt(var_i * var_j), -1.0, 1.0);
}

// A homography near the identity about the window centre: shift up to 3 px, rotation up to
// 10 degrees, scale 0.85..1.15, and a little perspective.
Eigen::Matrix3d RandomNearIdentity(double centre, std::mt19937& random) {
  std::uniform_real_distribution<double> unit(-1, 1);
  const double angle = 0.17 * unit(random), scale = 1 + 0.15 * unit(random);
  Eigen::Matrix3d about = Eigen::Matrix3d::Identity(), back = Eigen::Matrix3d::Identity();
  about.col(2) << -centre, -centre, 1;
  back.col(2) << centre + 3 * unit(random), centre + 3 * unit(random), 1;
  Eigen::Matrix3d warp = Eigen::Matrix3d::Identity();
  warp.topLeftCorner<2, 2>() << scale * std::cos(angle), -scale * std::sin(angle),
      scale * std::sin(angle), scale * std::cos(angle);
  warp(2, 0) = 2e-3 * unit(random);
  warp(2, 1) = 2e-3 * unit(random);
  return back * warp * about;
}

class WindowCostKernels : public testing::TestWithParam<CostKernel> {};

TEST_P(WindowCostKernels, AgreeWithCentredDoubleMomentsWithinTheirConditioning) {
  // WindowCost computes variances and the covariance as E[I^2] - E[I]^2 in float: each
  // cancels catastrophically when the mean is large against the contrast, losing a factor
  // kappa = (mean^2 + var) / var. Windows of mean 0.05..0.95 and contrast down to the texture
  // threshold (std 0.004, so kappa up to ~5e4) meet a randomly warped, relit source.
  // Bound: |cost error| <= 16 kEps kappa: 16 samples, each adding a rounding of its products
  // to the sums before the cancellation, which then divides by var. Both kernels (eight
  // samples at a time, and one) are held to it.
  std::mt19937 random(21);
  std::uniform_real_distribution<double> unit(0, 1);
  const PatchMatchOptions options;
  constexpr int kSize = 24;
  double worst = 0, worst_scaled = 0;
  int compared = 0, skipped = 0;
  for (int trial = 0; trial < 3000; ++trial) {
    const double mean = 0.05 + 0.9 * unit(random);
    const double contrast = std::exp(std::log(0.006) + unit(random) * std::log(0.3 / 0.006));
    const uint32_t seed = static_cast<uint32_t>(random());
    std::mt19937 texture_random(seed);
    const GrayImage reference = RandomWindowImage(kSize, mean, contrast, texture_random);
    texture_random.seed(seed);
    // The same texture relit: another mean and contrast, so the NCC stays high when the
    // homography happens to be mild.
    const GrayImage source = RandomWindowImage(kSize, 0.05 + 0.9 * unit(random),
                                               contrast * (0.5 + unit(random)), texture_random);
    const Eigen::Matrix3d h = RandomNearIdentity(kSize / 2.0, random);
    double kappa = 1;
    bool near_threshold = false;
    const double expected =
        ReferenceCost(reference, kSize / 2, kSize / 2, source, h, options, &kappa, &near_threshold);
    const double actual = WindowCost(reference, kSize / 2, kSize / 2, source, h, options, GetParam());
    ASSERT_TRUE(std::isfinite(actual));
    if (near_threshold) {
      ++skipped;
      continue;
    }
    ++compared;
    const double error = std::abs(actual - expected);
    worst = std::max(worst, error);
    worst_scaled = std::max(worst_scaled, error / (kEps * kappa));
    EXPECT_LE(error, 16 * kEps * kappa)
        << "kappa " << kappa << " expected " << expected << " got " << actual;
  }
  const std::string kernel = testing::PrintToString(GetParam());
  Report("window_cost_" + kernel + "_worst_abs_error", worst, 0);
  Report("window_cost_" + kernel + "_worst_error_over_eps_kappa", worst_scaled, 16);
  EXPECT_GT(compared, 2700) << skipped << " near a threshold";
}
INSTANTIATE_TEST_SUITE_P(FloatReference, WindowCostKernels,
                         testing::Values(CostKernel::kFastest, CostKernel::kPortable),
                         [](const testing::TestParamInfo<CostKernel>& kernel) {
                           return testing::PrintToString(kernel.param);
                         });

// ---- Forward warp: a source pixel with depth reprojected into the target (float) ----------

Eigen::Quaterniond RandomRotation(std::mt19937& random, double max_angle_rad) {
  std::normal_distribution<double> normal;
  const Eigen::Vector3d axis =
      Eigen::Vector3d(normal(random), normal(random), normal(random)).normalized();
  return Eigen::Quaterniond(Eigen::AngleAxisd(
      max_angle_rad * std::uniform_real_distribution<double>(0, 1)(random), axis));
}

// Sparse source samples (every 4th pixel, each alone) with log-uniform random depths in
// [0.2, 200], colored with their own pixel coordinates so the target tells which landed.
SourceView SparseLabelledSource(std::mt19937& random) {
  const Camera camera = MakePinholeCamera(1, 160, 120, 150, 140, 81.3, 58.7);
  SourceView source{"sparse", camera, Rigid3d(), Image(160, 120, 3), DepthMap(160, 120), {}, 0, {}};
  std::uniform_real_distribution<double> log_depth(std::log(0.2), std::log(200.0));
  for (int y = 1; y < 120; y += 4) {
    for (int x = 1; x < 160; x += 4) {
      source.depth.At(x, y) = static_cast<float>(std::exp(log_depth(random)));
      source.color.At(x, y, 0) = static_cast<float>(x) / 256;  // Exact in float.
      source.color.At(x, y, 1) = static_cast<float>(y) / 256;
    }
  }
  return source;
}

struct ProjectionErrors {
  double depth_scaled = 0;  // Relative depth error over kappa.
  double depth_relative = 0;
  double weight_scaled = 0;  // Relative error of WarpBuffer::Weight over its bound.
  double pixel_miss = 0;  // How far the true projection lies outside the pixel written.
  int samples = 0;
};

// Compares every sample that landed in `buffer` with the double projection of its source pixel.
void CompareProjections(const SourceView& source, const PosedCamera& target,
                        const WarpBuffer& buffer, const ForwardWarpOptions& options,
                        ProjectionErrors* errors) {
  const Rigid3d target_from_source = RelativePose(source.cam_from_world, target.cam_from_world);
  const Eigen::Matrix3d rotation = target_from_source.rotation.toRotationMatrix();
  const Camera& s = source.camera;
  const Camera& t = target.camera;
  for (int ty = 0; ty < buffer.Height(); ++ty) {
    for (int tx = 0; tx < buffer.Width(); ++tx) {
      const size_t i = static_cast<size_t>(ty) * buffer.Width() + tx;
      const float z = buffer.Depth(i);
      ASSERT_TRUE(z == 0 || (z > 0 && std::isfinite(z))) << z;
      if (z == 0) continue;
      const int x = static_cast<int>(std::lround(buffer.Color(i)[0] * 256));
      const int y = static_cast<int>(std::lround(buffer.Color(i)[1] * 256));
      const Eigen::Vector3d ray((x + 0.5 - s.PrincipalX()) / s.FocalX(),
                                (y + 0.5 - s.PrincipalY()) / s.FocalY(), 1);
      const Eigen::Vector3d point = rotation * (static_cast<double>(source.depth.At(x, y)) * ray) +
                                    target_from_source.translation;
      // Condition of z = depth (r_2 . ray) + t_2: the magnitudes summed against the result.
      const double kappa = (static_cast<double>(source.depth.At(x, y)) *
                                (rotation.row(2).cwiseAbs() * ray.cwiseAbs())(0) +
                            std::abs(target_from_source.translation.z())) /
                           point.z();
      const double relative = std::abs(static_cast<double>(z) / point.z() - 1);
      errors->depth_relative = std::max(errors->depth_relative, relative);
      errors->depth_scaled = std::max(errors->depth_scaled, relative / (kEps * kappa));
      // The weight of an isolated splat: its stretch is that of a fronto-parallel patch,
      // (target focal / source focal)^2 (depth / z)^2.
      const double chord = (point.normalized() - (rotation * ray).normalized()).norm();
      const double depth_ratio = static_cast<double>(source.depth.At(x, y)) / point.z();
      const double stretch = t.FocalX() / s.FocalX() * t.FocalY() / s.FocalY() * depth_ratio * depth_ratio;
      const double epsilon = options.angle_epsilon_rad;
      const double weight = 1 / ((chord + epsilon) * std::max(1.0, stretch));
      // The chord's error is absolute (a difference of unit vectors, ~8 kEps), the stretch's
      // twice z's relative error (8 kEps kappa), plus a few roundings and the half float it
      // is stored in.
      const double bound = 8 * kEps / (chord + epsilon) + (16 * kappa + 4) * kEps + WarpBuffer::kHalfRounding;
      errors->weight_scaled = std::max(
          errors->weight_scaled, std::abs(static_cast<double>(buffer.Weight(i)) / weight - 1) / bound);
      const double u = t.FocalX() * point.x() / point.z() + t.PrincipalX();
      const double v = t.FocalY() * point.y() / point.z() + t.PrincipalY();
      errors->pixel_miss =
          std::max({errors->pixel_miss, tx - u, u - (tx + 1), ty - v, v - (ty + 1)});
      ++errors->samples;
    }
  }
}

TEST(FloatReference, ForwardWarpReprojectionAgreesWithDoubleWithinItsConditioning) {
  // Each isolated source sample is splatted onto exactly one target pixel (max_splat_px 1):
  // its depth is the float z of ProjectSpan, its weight from the float chord between unit rays.
  // z = depth (r_2 . ray) + t_2 sums terms that can cancel (a target far off to the side),
  // so its error is a few roundings times kappa = (|depth r_2 . ray| + |t_2|) / z. Bound:
  // 8 kEps kappa (the pose and ray rounded to float, ~5 operations, 1 / z twice). The chord
  // is a difference of unit vectors, so its error is absolute: 8 kEps; the weight's bound
  // follows (CompareProjections).
  std::mt19937 random(5);
  std::uniform_real_distribution<double> unit(-1, 1);
  ProjectionErrors errors;
  ForwardWarpOptions options;
  options.method = WarpMethod::kSplat;
  options.max_splat_px = 1;
  options.background_at_infinity = false;
  WarpBuffer buffer;
  for (int trial = 0; trial < 12; ++trial) {
    const SourceView source = SparseLabelledSource(random);
    const Camera target_camera = MakePinholeCamera(1, 200, 150, 170, 175, 99.1, 76.4);
    const Eigen::Quaterniond rotation = RandomRotation(random, 0.5);
    const Eigen::Vector3d centre(2 * unit(random), 2 * unit(random), 2 * unit(random));
    const PosedCamera target{target_camera, Rigid3d(rotation, -(rotation * centre))};
    ForwardWarp(source, target, options, &buffer);
    CompareProjections(source, target, buffer, options, &errors);
  }
  Report("warp_depth_worst_relative_error", errors.depth_relative, 0);
  Report("warp_depth_worst_error_over_eps_kappa", errors.depth_scaled, 8);
  Report("warp_weight_worst_error_over_bound", errors.weight_scaled, 1);
  Report("warp_pixel_worst_miss_px", errors.pixel_miss, 1e-3);
  EXPECT_GT(errors.samples, 2000);
  EXPECT_LT(errors.depth_scaled, 8);
  EXPECT_LT(errors.weight_scaled, 1);
  // Which pixel a sample lands in: float u is off by ~kEps |u| ~ 2e-5 px.
  EXPECT_LT(errors.pixel_miss, 1e-3);
}

// A random plane n . x = d in front of a camera at the origin looking along +z.
struct RandomPlane {
  Eigen::Vector3d normal;
  double offset;
};

RandomPlane MakeRandomPlane(std::mt19937& random) {
  std::uniform_real_distribution<double> unit(-1, 1);
  // Normals within ~50 degrees of the view axis, the plane crossing it at depth 2..20.
  const Eigen::Vector3d normal =
      Eigen::Vector3d(0.8 * unit(random), 0.8 * unit(random), -1).normalized();
  const double depth = std::exp(std::log(2.0) + (unit(random) + 1) / 2 * std::log(10.0));
  return {normal, normal.dot(Eigen::Vector3d(0, 0, depth))};
}

// Depth (camera z) where the ray of pixel (x, y) of `camera` meets the plane, in double; 0
// where it does not (or behind).
double PlaneDepth(const RandomPlane& plane, const PosedCamera& camera, double x, double y) {
  const Eigen::Vector3d ray_in_cam((x + 0.5 - camera.camera.PrincipalX()) / camera.camera.FocalX(),
                                   (y + 0.5 - camera.camera.PrincipalY()) / camera.camera.FocalY(),
                                   1);
  const Eigen::Vector3d ray = camera.cam_from_world.rotation.conjugate() * ray_in_cam;
  const Eigen::Vector3d centre = CameraCenter(camera.cam_from_world);
  const double denominator = plane.normal.dot(ray);
  if (std::abs(denominator) < 1e-12) return 0;
  const double t = (plane.offset - plane.normal.dot(centre)) / denominator;
  return t > 0 ? t : 0;
}

TEST(FloatReference, MeshWarpOfAPlaneAgreesWithDoubleRayCasting) {
  // The mesh interpolates 1 / z perspective-correctly, exact on a plane, so what remains is
  // float rounding: the source depth stored as float (kEps / 2), the vertex projection (see
  // above, kappa ~ 1 here) and the barycentric interpolation. Target pixels near the source's
  // border are left out (the border is splatted, flat). Bound on the relative depth error:
  // 64 kEps (measured ~8e-7: the interpolation weights come from target coordinates of ~100
  // px rounded to ~1e-5 px, over triangles a pixel wide).
  std::mt19937 random(8);
  std::uniform_real_distribution<double> unit(-1, 1);
  const Camera camera = MakePinholeCamera(1, 96, 72, 90, 90, 48, 36);
  const PosedCamera source_camera{camera, Rigid3d()};
  double worst = 0;
  long compared = 0;
  WarpBuffer buffer;
  for (int trial = 0; trial < 20; ++trial) {
    const RandomPlane plane = MakeRandomPlane(random);
    SourceView source{"plane", camera, Rigid3d(), Image(96, 72, 3), DepthMap(96, 72), {}, 0, {}};
    for (int y = 0; y < 72; ++y) {
      for (int x = 0; x < 96; ++x) {
        source.depth.At(x, y) = static_cast<float>(PlaneDepth(plane, source_camera, x, y));
      }
    }
    const Eigen::Quaterniond rotation = RandomRotation(random, 0.3);
    const Eigen::Vector3d centre =
        0.1 * plane.offset * Eigen::Vector3d(unit(random), unit(random), unit(random));
    const PosedCamera target{camera, Rigid3d(rotation, -(rotation * centre))};
    ForwardWarp(source, target, {}, &buffer);
    for (int y = 0; y < 72; ++y) {
      for (int x = 0; x < 96; ++x) {
        const float z = buffer.Depth(static_cast<size_t>(y) * 96 + x);
        ASSERT_TRUE(z == 0 || (z > 0 && std::isfinite(z))) << z;
        if (z == 0) continue;
        const double truth = PlaneDepth(plane, target, x, y);
        ASSERT_GT(truth, 0);
        // Where the point lies in the source: leave out the splatted border.
        const Eigen::Vector3d ray = target.cam_from_world.rotation.conjugate() *
                                    Eigen::Vector3d((x + 0.5 - 48) / 90, (y + 0.5 - 36) / 90, 1);
        const std::optional<Eigen::Vector2d> in_source =
            camera.Project(CameraCenter(target.cam_from_world) + truth * ray);
        if (!in_source || in_source->x() < 1.5 || in_source->y() < 1.5 || in_source->x() > 94.5 ||
            in_source->y() > 70.5)
          continue;
        worst = std::max(worst, std::abs(static_cast<double>(z) / truth - 1));
        ++compared;
      }
    }
  }
  Report("mesh_warp_plane_worst_relative_depth_error", worst, 64 * kEps);
  EXPECT_GT(compared, 20000);
  EXPECT_LT(worst, 64 * kEps);
}

}  // namespace
}  // namespace parallax
