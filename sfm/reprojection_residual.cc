#include "sfm/reprojection_residual.h"

#include <optional>

#include <ceres/rotation.h>

namespace parallax {

void ProjectionResidual(const Camera& camera, const double* rotation, const double* translation, const double* point,
                        const Eigen::Vector2d& observed, double* residual) {
  double rotated[3];
  ceres::QuaternionRotatePoint(rotation, point, rotated);
  const Eigen::Vector3d point_in_cam(rotated[0] + translation[0], rotated[1] + translation[1],
                                     rotated[2] + translation[2]);
  const std::optional<Eigen::Vector2d> pixel = camera.Project(point_in_cam);
  residual[0] = pixel ? (*pixel)[0] - observed[0] : kUnprojectableResidualPx;
  residual[1] = pixel ? (*pixel)[1] - observed[1] : kUnprojectableResidualPx;
}

}  // namespace parallax
