#include "geometry/ground_plane.h"

#include <algorithm>
#include <cmath>
#include <numbers>
#include <random>
#include <stdexcept>

#include <Eigen/Geometry>
#include <ceres/ceres.h>

#include "geometry/robust_bounds.h"
#include "core/check.h"

namespace parallax {
namespace {

struct Plane {
  Eigen::Vector3d normal;
  double offset = 0;
};

// Distance of one point to the plane whose normal is n0 tilted by (a, b) along the tangents
// u, v: a chart around the RANSAC normal, free of the poles of spherical angles.
struct PlaneResidual {
  PlaneResidual(const Eigen::Vector3d& point, const Eigen::Vector3d& n0, const Eigen::Vector3d& u,
                const Eigen::Vector3d& v)
      : point_(point), n0_(n0), u_(u), v_(v) {}

  template <typename T>
  bool operator()(const T* tilt, const T* offset, T* residual) const {
    const Eigen::Matrix<T, 3, 1> n =
        n0_.cast<T>() + tilt[0] * u_.cast<T>() + tilt[1] * v_.cast<T>();
    residual[0] = (n.dot(point_.cast<T>()) + offset[0]) / n.norm();
    return true;
  }

  Eigen::Vector3d point_, n0_, u_, v_;
};

std::vector<int> Inliers(const std::vector<Eigen::Vector3f>& points, const Plane& plane,
                         double threshold) {
  std::vector<int> inliers;
  for (size_t i = 0; i < points.size(); ++i) {
    if (std::abs(plane.normal.dot(points[i].cast<double>()) + plane.offset) < threshold) {
      inliers.push_back(static_cast<int>(i));
    }
  }
  return inliers;
}

Plane Ransac(const std::vector<Eigen::Vector3f>& points, const std::optional<Eigen::Vector3d>& up,
             double threshold, const GroundPlaneOptions& options) {
  std::mt19937 random(0);
  std::uniform_int_distribution<size_t> pick(0, points.size() - 1);
  const double min_cos = std::cos(options.max_tilt_deg * std::numbers::pi / 180);
  Plane best{Eigen::Vector3d::UnitZ(), 0};
  size_t best_count = 0;
  for (int iteration = 0; iteration < options.iterations; ++iteration) {
    const Eigen::Vector3d a = points[pick(random)].cast<double>();
    const Eigen::Vector3d b = points[pick(random)].cast<double>();
    const Eigen::Vector3d c = points[pick(random)].cast<double>();
    const Eigen::Vector3d cross = (b - a).cross(c - a);
    if (cross.norm() < 1e-12) continue;  // Collinear sample.
    Plane plane{cross.normalized(), 0};
    plane.offset = -plane.normal.dot(a);
    if (up && std::abs(plane.normal.dot(*up)) < min_cos) continue;
    // Counting is O(n); cheap next to everything else the viewer loads.
    size_t count = 0;
    for (const Eigen::Vector3f& p : points) {
      count += std::abs(plane.normal.dot(p.cast<double>()) + plane.offset) < threshold;
    }
    if (count > best_count) {
      best_count = count;
      best = plane;
    }
  }
  return best;
}

Plane Refine(const std::vector<Eigen::Vector3f>& points, const std::vector<int>& inliers,
             const Plane& initial, double threshold) {
  const Eigen::Vector3d n0 = initial.normal;
  const Eigen::Vector3d reference =
      std::abs(n0.x()) < 0.9 ? Eigen::Vector3d::UnitX() : Eigen::Vector3d::UnitY();
  const Eigen::Vector3d u = n0.cross(reference).normalized();
  const Eigen::Vector3d v = n0.cross(u);
  double tilt[2] = {0, 0};
  double offset = initial.offset;
  ceres::Problem problem;
  for (int i : inliers) {
    problem.AddResidualBlock(
        new ceres::AutoDiffCostFunction<PlaneResidual, 1, 2, 1>(
            new PlaneResidual(points[i].cast<double>(), n0, u, v)),
        new ceres::CauchyLoss(threshold), tilt, &offset);
  }
  ceres::Solver::Options solver_options;
  solver_options.max_num_iterations = 50;
  solver_options.num_threads = 1;  // Deterministic; the problem is tiny.
  solver_options.logging_type = ceres::SILENT;
  ceres::Solver::Summary summary;
  ceres::Solve(solver_options, &problem, &summary);
  const Eigen::Vector3d n = n0 + tilt[0] * u + tilt[1] * v;
  return Plane{n / n.norm(), offset / n.norm()};
}

}  // namespace

void GroundPlaneOptions::Check() const {
  RequireOption(inlier_fraction_of_size > 0, "GroundPlaneOptions.inlier_fraction_of_size",
                inlier_fraction_of_size, "> 0");
  RequireOption(min_inlier_ratio > 0 && min_inlier_ratio <= 1, "GroundPlaneOptions.min_inlier_ratio",
                min_inlier_ratio, "(0, 1]");
  RequireOption(iterations >= 1, "GroundPlaneOptions.iterations", iterations, ">= 1");
  RequireOption(max_tilt_deg > 0 && max_tilt_deg <= 90, "GroundPlaneOptions.max_tilt_deg", max_tilt_deg, "(0, 90]");
}

std::optional<GroundPlane> FitGroundPlane(const std::vector<Eigen::Vector3f>& points,
                                          const std::optional<Eigen::Vector3d>& up_hint,
                                          const GroundPlaneOptions& options) {
  options.Check();
  constexpr size_t kMinPoints = 30;
  if (points.size() < kMinPoints) return std::nullopt;
  // Robust bounds: a few far outliers of a fused cloud must not loosen the threshold.
  const Eigen::AlignedBox3f box = RobustBounds(points);
  const double threshold = options.inlier_fraction_of_size * static_cast<double>(box.diagonal().norm());
  if (!(threshold > 0)) return std::nullopt;  // All points coincide.

  Plane plane = Ransac(points, up_hint, threshold, options);
  std::vector<int> inliers = Inliers(points, plane, threshold);
  const size_t needed = std::max(
      kMinPoints, static_cast<size_t>(std::ceil(options.min_inlier_ratio * points.size())));
  if (inliers.size() < needed) return std::nullopt;
  plane = Refine(points, inliers, plane, threshold);
  inliers = Inliers(points, plane, threshold);

  const Eigen::Vector3d up = up_hint.value_or(Eigen::Vector3d::UnitZ());
  if (plane.normal.dot(up) < 0) {
    plane.normal = -plane.normal;
    plane.offset = -plane.offset;
  }
  return GroundPlane{plane.normal, plane.offset, static_cast<int>(inliers.size())};
}

}  // namespace parallax
