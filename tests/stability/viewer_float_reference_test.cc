// The viewer's float matrices against double references (issue: numerical stability): the
// reverse-Z projection and the planar shadow matrix. As float_reference_test.cc, each test
// reports its worst error and asserts it under a bound of float roundings times the
// computation's condition number.
#include <algorithm>
#include <cmath>
#include <numbers>
#include <random>

#include <gtest/gtest.h>

#include "tests/stability/float_reference.h"
#include "viewer/view_math.h"

namespace parallax {
namespace {

using stability_test::kEps;
using stability_test::Report;

// ---- Viewer: reverse-Z projection (float matrices, float depth buffer) --------------------

TEST(FloatReference, ReverseZKeepsFloatDepthPrecisionOverAMillionToOneRange) {
  // ndc_z = near / z, computed as the GPU does: float matrix times float point, then divided
  // by w. No cancellation: near is rounded once, the division once, so the depth read back
  // from the buffer is within 2 roundings (kEps) of the truth at every depth from near to
  // 1e6 near. Pixel positions: |ndc_x error| <= a few kEps, i.e. < 1e-3 px at 640 px.
  // The conventional projection, ndc_z = a + b / z, cancels near far (a ~ 1, b / z ~ -1):
  // its depth error grows to ~kEps far / near, which reverse-Z exists to avoid; checked as a
  // contrast so a swapped projection fails.
  std::mt19937 random(3);
  std::uniform_real_distribution<double> unit(0, 1);
  const Camera camera = MakePinholeCamera(1, 640, 480, 520, 510, 323.5, 236.25);
  double worst_reverse = 0, worst_conventional_far = 0, worst_pixel = 0;
  for (const double near : {1e-3, 0.05, 2.0}) {
    const double far = 1e6 * near;
    const Eigen::Matrix4f reverse = ReverseZProjection(camera, near);
    const Eigen::Matrix4f conventional =
        PerspectiveProjection(camera, near, far, DepthRange::kZeroToOne);
    const double b = -near * far / (far - near), a = -b / near;  // Conventional, in double.
    for (int i = 0; i < 2000; ++i) {
      const double z = near * std::pow(1e6, unit(random));
      const Eigen::Vector4f point(static_cast<float>((640 * unit(random) - 323.5) / 520 * z),
                                  static_cast<float>((480 * unit(random) - 236.25) / 510 * z),
                                  static_cast<float>(z), 1.0f);
      const double zf = point.z();  // The depth the float point really has.
      const Eigen::Vector4f clip = reverse * point;
      const float ndc_z = clip.z() / clip.w();  // What the depth buffer stores.
      worst_reverse =
          std::max(worst_reverse, std::abs((near / static_cast<double>(ndc_z)) / zf - 1));
      const double u = 520 * static_cast<double>(point.x()) / zf + 323.5;
      const double ndc_x = 2 * u / 640 - 1;
      worst_pixel =
          std::max(worst_pixel, std::abs(static_cast<double>(clip.x() / clip.w()) - ndc_x) * 320);
      if (zf > 0.5 * far) {
        const Eigen::Vector4f conventional_clip = conventional * point;
        const double ndc = conventional_clip.z() / conventional_clip.w();
        worst_conventional_far = std::max(worst_conventional_far, std::abs(b / (ndc - a) / zf - 1));
      }
    }
  }
  Report("reverse_z_worst_relative_depth_error", worst_reverse, 2 * kEps);
  Report("reverse_z_worst_pixel_error_px", worst_pixel, 1e-3);
  Report("conventional_z_worst_relative_depth_error_at_far", worst_conventional_far, 0);
  EXPECT_LT(worst_reverse, 2 * kEps);
  EXPECT_LT(worst_pixel, 1e-3);
  EXPECT_GT(worst_conventional_far, 1000 * worst_reverse);
}

TEST(FloatReference, ReverseZSeparatesDepthsOnePartInAMillionApartAtEveryRange) {
  // No z-fighting anywhere in near..1e6 near: two surfaces 1e-6 apart (relative) get
  // different, correctly ordered float depths. 1e-6 is 8 to 16 ulps of ndc_z; after rounding
  // z itself they must stay at least 4 ulps apart.
  const Camera camera = MakePinholeCamera(1, 640, 480, 520, 520, 320, 240);
  const double near = 0.01;
  const Eigen::Matrix4f reverse = ReverseZProjection(camera, near);
  for (double z = near; z <= 1e6 * near; z *= 1.37) {
    const float z_near = static_cast<float>(z), z_far = static_cast<float>(z * (1 + 1e-6));
    const float front = (reverse * Eigen::Vector4f(0, 0, z_near, 1)).z() / z_near;
    const float back = (reverse * Eigen::Vector4f(0, 0, z_far, 1)).z() / z_far;
    ASSERT_GT(front, back) << "at depth " << z;
    EXPECT_GE(front - back, 4 * std::nextafter(back, 2.0f) - 4 * back) << "at depth " << z;
  }
}

// ---- Viewer: planar shadow matrix (float) ---------------------------------------------------

TEST(FloatReference, PlanarShadowsAgreeWithDoubleUpToGrazingLight) {
  // S = M X / w with M = (pi . l) I - l pi^T, for a directional light up to 89.9 degrees from
  // the ground's normal (shadows 573 times longer than the caster is high). Row i of the
  // float product sums terms bounded by |pi . l| |X_i| + |l_i| sum_j |pi_j X_j|, each entry
  // and product rounded, then divides by w = pi . l (exact up to one rounding). Relative to
  // the shadow's length |S - X|, the error is a few roundings times
  // kappa = (|X|_1 + sum_j |pi_j X_j| / |pi . l|) / |S - X| + 1. Bound: 8 kEps kappa.
  std::mt19937 random(4);
  std::uniform_real_distribution<double> unit(-1, 1);
  GroundPlane ground;
  ground.normal = Eigen::Vector3d(0.1, -0.05, 1).normalized();
  ground.offset = 0.3;
  double worst_scaled = 0, worst_relative = 0;
  for (const double angle_deg : {0.0, 30.0, 60.0, 85.0, 89.0, 89.9}) {
    const double angle = angle_deg * std::numbers::pi / 180;
    // Towards the light: tilted `angle` from the normal.
    const Eigen::Vector3d side = ground.normal.cross(Eigen::Vector3d::UnitX()).normalized();
    const Eigen::Vector3d towards = std::cos(angle) * ground.normal + std::sin(angle) * side;
    const Eigen::Vector4d light(towards.x(), towards.y(), towards.z(), 0);
    const Eigen::Matrix4f m = PlanarShadowMatrix(ground, light);
    const Eigen::Vector4d pi(ground.normal.x(), ground.normal.y(), ground.normal.z(),
                             ground.offset);
    for (int i = 0; i < 500; ++i) {
      // Casters up to 10 above the ground, over a 20 x 20 area.
      Eigen::Vector3d x(10 * unit(random), 10 * unit(random), 0);
      x += (-ground.offset - ground.normal.dot(x)) * ground.normal;        // On the ground ...
      x += 5 * (1 + unit(random)) * ground.normal + 1e-3 * ground.normal;  // ... then lifted.
      const Eigen::Vector4f xf(static_cast<float>(x.x()), static_cast<float>(x.y()),
                               static_cast<float>(x.z()), 1.0f);
      const Eigen::Vector4d xd = xf.cast<double>();
      const Eigen::Vector4f shadow_f = m * xf;
      const Eigen::Vector3d shadow =
          shadow_f.head<3>().cast<double>() / static_cast<double>(shadow_f.w());
      const Eigen::Vector3d truth = xd.head<3>() - (pi.dot(xd) / pi.dot(light)) * light.head<3>();
      const double length = (truth - xd.head<3>()).norm();
      const double kappa =
          (xd.head<3>().lpNorm<1>() + pi.cwiseProduct(xd).lpNorm<1>() / std::abs(pi.dot(light))) /
              length +
          1;
      const double relative = (shadow - truth).norm() / length;
      worst_relative = std::max(worst_relative, relative);
      worst_scaled = std::max(worst_scaled, relative / (kEps * kappa));
    }
  }
  Report("planar_shadow_worst_relative_error", worst_relative, 0);
  Report("planar_shadow_worst_error_over_eps_kappa", worst_scaled, 8);
  EXPECT_LT(worst_scaled, 8);
}

}  // namespace
}  // namespace parallax
