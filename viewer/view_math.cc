#include "viewer/view_math.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <utility>
#include <numbers>

#include "core/angles.h"

namespace parallax {
namespace {

// Maps depth in [near, far] of an orthographic/perspective row to the NDC range in use.
Eigen::Vector2d NdcZRange(DepthRange range) {
  return range == DepthRange::kZeroToOne ? Eigen::Vector2d(0, 1) : Eigen::Vector2d(-1, 1);
}

// A camera frame looking along `forward`, any roll.
Rigid3d LookAlong(const Eigen::Vector3d& eye, const Eigen::Vector3d& forward) {
  const Eigen::Vector3d up =
      std::abs(forward.normalized().z()) < 0.9 ? Eigen::Vector3d::UnitZ() : Eigen::Vector3d::UnitX();
  return LookAt(eye, eye + forward, up);
}

// Rows x and y: ndc_x = 2u/W - 1, ndc_y = 1 - 2v/H with u = fx x/z + cx, v = fy y/z + cy.
Eigen::Matrix4d ImagePlaneRows(const Camera& camera) {
  const double w = static_cast<double>(camera.width), h = static_cast<double>(camera.height);
  Eigen::Matrix4d p = Eigen::Matrix4d::Zero();
  p(0, 0) = 2 * camera.FocalX() / w;
  p(0, 2) = 2 * camera.PrincipalX() / w - 1;
  p(1, 1) = -2 * camera.FocalY() / h;
  p(1, 2) = 1 - 2 * camera.PrincipalY() / h;
  p(3, 2) = 1;  // w = z.
  return p;
}

}  // namespace

Eigen::Matrix4f ViewMatrix(const Rigid3d& cam_from_world) {
  Eigen::Matrix4d m = Eigen::Matrix4d::Identity();
  m.topLeftCorner<3, 3>() = cam_from_world.rotation.toRotationMatrix();
  m.topRightCorner<3, 1>() = cam_from_world.translation;
  return m.cast<float>();
}

Eigen::Matrix4f ReverseZProjection(const Camera& camera, double near) {
  Eigen::Matrix4d p = ImagePlaneRows(camera);
  p(2, 3) = near;  // ndc_z = near / z.
  return p.cast<float>();
}

Eigen::Matrix4f PerspectiveProjection(const Camera& camera, double near, double far,
                                      DepthRange range) {
  const Eigen::Vector2d ndc = NdcZRange(range);
  Eigen::Matrix4d p = ImagePlaneRows(camera);
  // ndc_z = a + b / z with ndc_z(near) = ndc[0], ndc_z(far) = ndc[1].
  const double b = (ndc[0] - ndc[1]) * near * far / (far - near);
  const double a = ndc[1] - b / far;
  p(2, 2) = a;
  p(2, 3) = b;
  return p.cast<float>();
}

Eigen::Matrix4f OrthographicProjection(const Eigen::Vector3d& min, const Eigen::Vector3d& max,
                                       DepthRange range) {
  const Eigen::Vector2d ndc = NdcZRange(range);
  Eigen::Matrix4d p = Eigen::Matrix4d::Identity();
  for (int axis = 0; axis < 2; ++axis) {
    p(axis, axis) = 2 / (max[axis] - min[axis]);
    p(axis, 3) = -(max[axis] + min[axis]) / (max[axis] - min[axis]);
  }
  p(2, 2) = (ndc[1] - ndc[0]) / (max.z() - min.z());
  p(2, 3) = ndc[0] - min.z() * p(2, 2);
  return p.cast<float>();
}

Eigen::Vector2d DepthBounds(const Eigen::AlignedBox3f& box, const Rigid3d& cam_from_world) {
  double near = std::numeric_limits<double>::infinity(), far = 0;
  for (int corner = 0; corner < 8; ++corner) {
    const Eigen::Vector3d z = cam_from_world * box.corner(static_cast<Eigen::AlignedBox3f::CornerType>(corner)).cast<double>();
    near = std::min(near, z.z());
    far = std::max(far, z.z());
  }
  const double size = std::max(1e-9, static_cast<double>(box.diagonal().norm()));
  far = std::max(far, 1e-3 * size) * 1.01;
  near = std::clamp(near * 0.99, 1e-4 * size, far * 0.5);
  return {near, far};
}

Eigen::Matrix4f DirectionalLightMatrix(const Eigen::Vector3d& direction, const std::vector<Eigen::Vector3f>& points,
                                       const Eigen::AlignedBox3f& depth_box, DepthRange range, double outlier_share) {
  Eigen::AlignedBox3f all = depth_box;
  for (const Eigen::Vector3f& p : points) all.extend(p);
  if (all.isEmpty()) all.extend(Eigen::Vector3f::Zero());
  const Eigen::Vector3d centre = all.center().cast<double>();
  const double radius = std::max(1e-9, 0.5 * static_cast<double>(all.diagonal().norm()));
  const Rigid3d light_from_world = LookAlong(centre - 2 * radius * direction.normalized(), direction);
  std::vector<double> across[2];
  Eigen::Vector3d lo = Eigen::Vector3d::Constant(std::numeric_limits<double>::infinity());
  Eigen::Vector3d hi = -lo;
  for (const Eigen::Vector3f& point : points) {
    const Eigen::Vector3d p = light_from_world * point.cast<double>();
    across[0].push_back(p.x());
    across[1].push_back(p.y());
    lo.z() = std::min(lo.z(), p.z());
    hi.z() = std::max(hi.z(), p.z());
  }
  for (int axis = 0; axis < 2; ++axis) {
    std::vector<double>& values = across[axis];
    if (values.empty()) continue;
    const size_t cut = static_cast<size_t>(outlier_share * static_cast<double>(values.size()));
    std::nth_element(values.begin(), values.begin() + static_cast<std::ptrdiff_t>(cut), values.end());
    lo[axis] = values[cut];
    std::nth_element(values.begin(), values.end() - 1 - static_cast<std::ptrdiff_t>(cut), values.end());
    hi[axis] = values[values.size() - 1 - cut];
  }
  for (int corner = 0; corner < 8; ++corner) {
    if (depth_box.isEmpty()) break;
    const auto type = static_cast<Eigen::AlignedBox3f::CornerType>(corner);
    const Eigen::Vector3d p = light_from_world * depth_box.corner(type).cast<double>();
    if (across[0].empty()) {  // No points: the box across the light too.
      lo.head<2>() = lo.head<2>().cwiseMin(p.head<2>());
      hi.head<2>() = hi.head<2>().cwiseMax(p.head<2>());
    }
    lo.z() = std::min(lo.z(), p.z());
    hi.z() = std::max(hi.z(), p.z());
  }
  if (!(lo.array() < hi.array()).all()) {  // One point, or none: a unit square about it.
    lo = lo.cwiseMin(hi) - Eigen::Vector3d::Ones();
    hi = lo + 2 * Eigen::Vector3d::Ones();
  }
  // A sliver of margin so the scene's extreme surfaces are not clipped by the depth range.
  const Eigen::Vector3d margin = 1e-3 * radius * Eigen::Vector3d::Ones();
  return OrthographicProjection(lo - margin, hi + margin, range) * ViewMatrix(light_from_world);
}

Eigen::Matrix4f PointLightMatrix(const Eigen::Vector3d& position, const Eigen::AlignedBox3f& box,
                                 const Eigen::AlignedBox3f& depth_box, DepthRange range) {
  const Eigen::Vector3d centre = box.center().cast<double>();
  const Eigen::Vector3d forward =
      (centre - position).norm() > 1e-9 ? Eigen::Vector3d(centre - position) : Eigen::Vector3d::UnitZ();
  const Rigid3d light_from_world = LookAlong(position, forward);
  // Half-angle that holds every corner in front of the light, capped at 80 degrees (a light
  // inside the scene sees only part of it).
  double tan_half = 0;
  for (int corner = 0; corner < 8; ++corner) {
    const Eigen::Vector3d p =
        light_from_world * box.corner(static_cast<Eigen::AlignedBox3f::CornerType>(corner)).cast<double>();
    if (p.z() <= 1e-9) {
      tan_half = std::tan(Radians(80));
      break;
    }
    tan_half = std::max({tan_half, std::abs(p.x() / p.z()), std::abs(p.y() / p.z())});
  }
  tan_half = std::clamp(tan_half * 1.01, 1e-3, std::tan(Radians(80)));
  const Camera square = MakePinholeCamera(1, 2, 2, 1 / tan_half, 1 / tan_half, 1, 1);
  const Eigen::Vector2d depth = DepthBounds(depth_box.isEmpty() ? box : box.merged(depth_box), light_from_world);
  return PerspectiveProjection(square, depth[0], depth[1], range) * ViewMatrix(light_from_world);
}

Eigen::Matrix4f PlanarShadowMatrix(const GroundPlane& plane, const Eigen::Vector4d& light) {
  const Eigen::Vector4d pi(plane.normal.x(), plane.normal.y(), plane.normal.z(), plane.offset);
  const Eigen::Matrix4d m = pi.dot(light) * Eigen::Matrix4d::Identity() - light * pi.transpose();
  return m.cast<float>();
}

Camera ViewerCamera(int width, int height, double fov_deg) {
  const double focal = 0.5 * width / std::tan(0.5 * Radians(fov_deg));
  return MakePinholeCamera(1, static_cast<uint64_t>(width), static_cast<uint64_t>(height), focal,
                           focal, 0.5 * width, 0.5 * height);
}

Eigen::Vector3d LightDirectionFromAngles(const Eigen::Vector3d& up, double azimuth_deg,
                                         double elevation_deg) {
  const auto [u, v] = GroundAxes(up);
  const double elevation = Radians(elevation_deg), azimuth = Radians(azimuth_deg);
  const Eigen::Vector3d towards_light =
      std::cos(elevation) * (std::cos(azimuth) * u + std::sin(azimuth) * v) + std::sin(elevation) * up;
  return -towards_light.normalized();
}

}  // namespace parallax
