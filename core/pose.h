#pragma once
// Rigid transforms. A camera pose is `cam_from_world`: x_cam = R * x_world + t, stored as a
// unit quaternion (w first on disk, as COLMAP writes it) and a translation.
#include <string>

#include <Eigen/Core>
#include <Eigen/Geometry>

namespace parallax {

struct Rigid3d {
  Eigen::Quaterniond rotation = Eigen::Quaterniond::Identity();
  Eigen::Vector3d translation = Eigen::Vector3d::Zero();

  Rigid3d() = default;
  // Normalises `rotation`; throws InternalError for a zero or non-finite quaternion.
  Rigid3d(const Eigen::Quaterniond& rotation, const Eigen::Vector3d& translation);

  Eigen::Vector3d operator*(const Eigen::Vector3d& point) const {
    return rotation * point + translation;
  }
  // Composition: (a_from_b * b_from_c) = a_from_c. The result's rotation is renormalised so
  // long chains do not drift off the unit sphere.
  Rigid3d operator*(const Rigid3d& other) const;
  Rigid3d Inverse() const;
  Eigen::Matrix<double, 3, 4> Matrix() const;  // [R | t]
};

// Camera centre in world coordinates: -R^T t.
Eigen::Vector3d CameraCenter(const Rigid3d& cam_from_world);

// The pose of camera b relative to camera a: b_from_a = b_from_world * world_from_a.
Rigid3d RelativePose(const Rigid3d& a_from_world, const Rigid3d& b_from_world);

// Builds cam_from_world for a camera at `eye` looking at `target`, with image "up" (-y) as
// close to `world_up` as possible. Throws InternalError with the LookAtProblem unless it is "".
Rigid3d LookAt(const Eigen::Vector3d& eye, const Eigen::Vector3d& target,
               const Eigen::Vector3d& world_up);
// Why LookAt cannot place such a camera (eye and target coincide, or the viewing direction is
// parallel to world_up), or "" when it can.
std::string LookAtProblem(const Eigen::Vector3d& eye, const Eigen::Vector3d& target,
                          const Eigen::Vector3d& world_up);

// Shortest-path spherical interpolation, t in [0, 1]. q and -q are the same rotation, so
// antipodal inputs interpolate over the short arc; nearly equal rotations use normalised
// linear interpolation (slerp divides by sin(angle) ~ 0 there).
Eigen::Quaterniond Slerp(const Eigen::Quaterniond& a, const Eigen::Quaterniond& b, double t);

// Interpolates two camera poses: rotation by Slerp, camera centre linearly (interpolating the
// translation vector directly would swing the centre off the segment between the cameras).
Rigid3d InterpolatePose(const Rigid3d& a_from_world, const Rigid3d& b_from_world, double t);

// Angle of the rotation taking a to b, in degrees, in [0, 180].
double RotationAngleDeg(const Eigen::Quaterniond& a, const Eigen::Quaterniond& b);

}  // namespace parallax
