#pragma once
// The ground of a scene: the dominant plane, found by RANSAC and refined by robust least
// squares (Ceres, Cauchy loss) on its inliers. The viewer orients the scene so this plane is
// horizontal, draws the grid on it and projects planar shadows onto it.
#include <optional>
#include <vector>

#include <Eigen/Core>

namespace parallax {

struct GroundPlane {
  Eigen::Vector3d normal = Eigen::Vector3d::UnitZ();  // Unit; points "up".
  double offset = 0;  // Plane: normal . x + offset = 0.
  int inliers = 0;

  double SignedDistance(const Eigen::Vector3d& point) const { return normal.dot(point) + offset; }
};

struct GroundPlaneOptions {
  // Inlier distance, as a fraction of the diagonal of the points' robust bounds (RobustBounds).
  double inlier_fraction_of_size = 0.005;
  // A plane needs at least this share of the points (and 30 points) to count as the ground.
  double min_inlier_ratio = 0.15;
  // RANSAC hypotheses (three random points each); deterministic seed.
  int iterations = 400;
  // Planes whose normal is more than this angle from `up_hint` are not the ground (degrees).
  // Only used when an up hint is given.
  double max_tilt_deg = 45;
  void Check() const;  // Throws UsageError naming the field.
};

// Fits the ground plane to `points`. `up_hint` (unit, e.g. the mean "up" of the source cameras)
// restricts the plane's orientation and decides which side is up; without it, the normal is
// turned towards +z (the synthetic scenes' up). std::nullopt when no plane has enough inliers.
std::optional<GroundPlane> FitGroundPlane(const std::vector<Eigen::Vector3f>& points,
                                          const std::optional<Eigen::Vector3d>& up_hint,
                                          const GroundPlaneOptions& options = {});

}  // namespace parallax
