#include "sfm/photo_prediction.h"

#include <algorithm>
#include <cmath>
#include <optional>

#include <ceres/ceres.h>

#include "core/error.h"
#include "sfm/reprojection_residual.h"

namespace parallax {
namespace {

constexpr int kResectionMaxIterations = 50;

// One observation: parameter blocks cam_from_world rotation (w, x, y, z) and translation.
struct PoseResidual {
  const Camera* camera;
  Eigen::Vector3d point;
  Eigen::Vector2d observed;

  bool operator()(const double* rotation, const double* translation, double* residual) const {
    ProjectionResidual(*camera, rotation, translation, point.data(), observed, residual);
    return true;
  }
};

// The distance from `camera`'s projection of `point` under `cam_from_world` to `pixel`.
double ReprojectionError(const Camera& camera, const Rigid3d& cam_from_world, const Eigen::Vector3d& point,
                         const Eigen::Vector2d& pixel) {
  const std::optional<Eigen::Vector2d> projected = camera.Project(cam_from_world * point);
  return projected ? (*projected - pixel).norm() : kUnprojectableResidualPx;
}

}  // namespace

Rigid3d ResectPose(const Camera& camera, const std::vector<Eigen::Vector3d>& points,
                   const std::vector<Eigen::Vector2d>& pixels, const Rigid3d& start, double loss_px) {
  if (points.size() != pixels.size()) throw InternalError("ResectPose: as many points as pixels are needed");
  size_t projecting = 0;
  for (const Eigen::Vector3d& point : points) projecting += camera.Project(start * point).has_value();
  if (projecting < 3) return start;
  const Eigen::Quaterniond& q = start.rotation;
  double rotation[4] = {q.w(), q.x(), q.y(), q.z()};
  Eigen::Vector3d translation = start.translation;
  ceres::Problem problem;
  for (size_t i = 0; i < points.size(); ++i) {
    auto* cost = new ceres::NumericDiffCostFunction<PoseResidual, ceres::CENTRAL, 2, 4, 3>(
        new PoseResidual{&camera, points[i], pixels[i]});
    problem.AddResidualBlock(cost, new ceres::CauchyLoss(loss_px), rotation, translation.data());
  }
  problem.SetManifold(rotation, new ceres::QuaternionManifold);
  ceres::Solver::Options options;
  options.linear_solver_type = ceres::DENSE_QR;
  options.max_num_iterations = kResectionMaxIterations;
  options.logging_type = ceres::SILENT;
  ceres::Solver::Summary summary;
  ceres::Solve(options, &problem, &summary);
  const Eigen::Quaterniond solved(rotation[0], rotation[1], rotation[2], rotation[3]);
  if (!solved.coeffs().allFinite() || !translation.allFinite()) return start;
  return Rigid3d(solved, translation);
}

LeftOutError LeftOutPhotoError(const SparseModel& fitted, const SparseModel& raw, const std::vector<std::string>& names,
                               double clip_px) {
  double clipped_squares = 0;
  size_t observations = 0;
  for (const std::string& name : names) {
    const SparseImage* image = raw.FindImageByName(name);
    if (image == nullptr) throw InternalError("LeftOutPhotoError: no photo " + name + " in the model");
    const Camera& camera = fitted.CameraById(image->camera_id);
    std::vector<Eigen::Vector3d> points;
    std::vector<Eigen::Vector2d> pixels;
    for (const Point2D& keypoint : image->points2d) {
      if (keypoint.point3d_id == kInvalidPoint3DId || !fitted.HasPoint3D(keypoint.point3d_id)) continue;
      points.push_back(fitted.Point3DById(keypoint.point3d_id).xyz);
      pixels.push_back(keypoint.xy);
    }
    const Rigid3d pose = ResectPose(camera, points, pixels, image->cam_from_world, clip_px);
    for (size_t i = 0; i < points.size(); ++i) {
      const double error = std::min(ReprojectionError(camera, pose, points[i], pixels[i]), clip_px);
      clipped_squares += error * error;
    }
    observations += points.size();
  }
  const double rms = observations == 0 ? 0 : std::sqrt(clipped_squares / static_cast<double>(observations));
  return {rms, observations};
}

}  // namespace parallax
