#pragma once
// The reprojection residual the Ceres problems of the SfM checks share (the focal test in
// plausibility.h, the resection in photo_prediction.h): the camera's own projection, whatever
// its lens model, under numeric derivatives.
#include <Eigen/Core>

#include "core/camera.h"

namespace parallax {

// The residual of a point the camera cannot project (behind it, or outside its lens model's
// range): large and constant, so the solver moves away from it instead of failing (a failed
// evaluation ends the solve).
inline constexpr double kUnprojectableResidualPx = 1e3;

// `camera`'s projection of the world point `point` under cam_from_world `rotation` (w, x, y, z)
// and `translation`, minus `observed`, into residual[0] and residual[1];
// kUnprojectableResidualPx in both where it does not project.
void ProjectionResidual(const Camera& camera, const double* rotation, const double* translation, const double* point,
                        const Eigen::Vector2d& observed, double* residual);

}  // namespace parallax
