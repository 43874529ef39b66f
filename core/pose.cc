#include "core/pose.h"

#include <algorithm>
#include <cmath>
#include <numbers>

#include "core/error.h"

namespace parallax {

Rigid3d::Rigid3d(const Eigen::Quaterniond& rotation_in, const Eigen::Vector3d& translation_in)
    : rotation(rotation_in), translation(translation_in) {
  const double norm = rotation.norm();
  if (!(norm > 0) || !std::isfinite(norm) || !translation.allFinite()) {
    throw InternalError("Rigid3d: rotation must be a non-zero finite quaternion and translation finite");
  }
  rotation.coeffs() /= norm;
}

Rigid3d Rigid3d::operator*(const Rigid3d& other) const {
  Rigid3d result;
  result.rotation = (rotation * other.rotation).normalized();
  result.translation = rotation * other.translation + translation;
  return result;
}

Rigid3d Rigid3d::Inverse() const {
  Rigid3d result;
  result.rotation = rotation.conjugate();
  result.translation = -(result.rotation * translation);
  return result;
}

Eigen::Matrix<double, 3, 4> Rigid3d::Matrix() const {
  Eigen::Matrix<double, 3, 4> matrix;
  matrix.leftCols<3>() = rotation.toRotationMatrix();
  matrix.col(3) = translation;
  return matrix;
}

Eigen::Vector3d CameraCenter(const Rigid3d& cam_from_world) {
  return -(cam_from_world.rotation.conjugate() * cam_from_world.translation);
}

Rigid3d RelativePose(const Rigid3d& a_from_world, const Rigid3d& b_from_world) {
  return b_from_world * a_from_world.Inverse();
}

std::string LookAtProblem(const Eigen::Vector3d& eye, const Eigen::Vector3d& target,
                          const Eigen::Vector3d& world_up) {
  const Eigen::Vector3d forward = target - eye;
  if (!(forward.norm() > 0)) return "eye and target coincide";
  if (!(forward.normalized().cross(world_up).norm() > 1e-12 * world_up.norm())) {
    return "the viewing direction is parallel to the up vector";
  }
  return "";
}

Rigid3d LookAt(const Eigen::Vector3d& eye, const Eigen::Vector3d& target,
               const Eigen::Vector3d& world_up) {
  if (std::string problem = LookAtProblem(eye, target, world_up); !problem.empty()) {
    throw InternalError("LookAt: " + problem);
  }
  const Eigen::Vector3d z = (target - eye).normalized();
  // Image x = forward x up (right-handed, y down): y = z x x then points away from `up`.
  const Eigen::Vector3d x = z.cross(world_up).normalized();
  const Eigen::Vector3d y = z.cross(x);
  Eigen::Matrix3d cam_from_world_rotation;
  cam_from_world_rotation.row(0) = x;
  cam_from_world_rotation.row(1) = y;
  cam_from_world_rotation.row(2) = z;
  const Eigen::Quaterniond rotation(cam_from_world_rotation);
  return Rigid3d(rotation, -(rotation * eye));
}

Eigen::Quaterniond Slerp(const Eigen::Quaterniond& a_in, const Eigen::Quaterniond& b_in,
                         double t) {
  const Eigen::Quaterniond a = a_in.normalized();
  Eigen::Quaterniond b = b_in.normalized();
  double cos_angle = a.dot(b);
  if (cos_angle < 0) {  // q and -q are one rotation: take the short arc.
    b.coeffs() = -b.coeffs();
    cos_angle = -cos_angle;
  }
  if (cos_angle > 1 - 1e-10) {
    return Eigen::Quaterniond(a.coeffs() * (1 - t) + b.coeffs() * t).normalized();
  }
  // atan2 keeps full precision for small angles, where acos(cos_angle) loses half the digits.
  const double sin_angle = std::sqrt(std::max(0.0, 1 - cos_angle * cos_angle));
  const double angle = std::atan2(sin_angle, cos_angle);
  const double wa = std::sin((1 - t) * angle) / sin_angle;
  const double wb = std::sin(t * angle) / sin_angle;
  return Eigen::Quaterniond(a.coeffs() * wa + b.coeffs() * wb).normalized();
}

Rigid3d InterpolatePose(const Rigid3d& a_from_world, const Rigid3d& b_from_world, double t) {
  const Eigen::Quaterniond rotation = Slerp(a_from_world.rotation, b_from_world.rotation, t);
  const Eigen::Vector3d center =
      (1 - t) * CameraCenter(a_from_world) + t * CameraCenter(b_from_world);
  return Rigid3d(rotation, -(rotation * center));
}

double RotationAngleDeg(const Eigen::Quaterniond& a, const Eigen::Quaterniond& b) {
  const Eigen::Quaterniond difference = a.normalized().conjugate() * b.normalized();
  // 2 atan2(|v|, |w|) is accurate at every angle, unlike 2 acos(w).
  const double angle = 2 * std::atan2(difference.vec().norm(), std::abs(difference.w()));
  return angle * 180.0 / std::numbers::pi;
}

}  // namespace parallax
