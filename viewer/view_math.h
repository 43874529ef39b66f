#pragma once
// The matrices of the viewer, pure functions: camera and light projections in OpenGL clip
// space, the light frustum fitted to the scene, the planar shadow matrix. (Orbit cameras:
// OrbitPose in geometry/scene_frame.h.)
//
// Conventions: world points are transformed by cam_from_world into the COLMAP camera frame
// (x right, y down, z forward); the projections below map that frame to clip space with NDC y
// up, so pixel (u, v) of the camera (v downward, centres at +0.5) lands on the same pixel of a
// framebuffer read back top row first.
#include <vector>

#include <Eigen/Core>
#include <Eigen/Geometry>

#include "core/camera.h"
#include "core/pose.h"
#include "geometry/ground_plane.h"
#include "geometry/scene_frame.h"

namespace parallax {

// How window depth relates to NDC z: [0, 1] with ARB_clip_control (GL_ZERO_TO_ONE), else
// OpenGL's default [-1, 1].
enum class DepthRange { kZeroToOne, kMinusOneToOne };

// 4x4 [R t; 0 1] of a rigid transform.
Eigen::Matrix4f ViewMatrix(const Rigid3d& cam_from_world);

// Reverse-Z with an infinite far plane (needs kZeroToOne): depth 1 at `near`, 0 at infinity.
// With a float depth buffer the precision is nearly uniform in log depth.
Eigen::Matrix4f ReverseZProjection(const Camera& camera, double near);

// Conventional projection: depth 0 (or -1) at `near`, 1 at `far`.
Eigen::Matrix4f PerspectiveProjection(const Camera& camera, double near, double far,
                                      DepthRange range);

// Orthographic projection of the box [min, max] (in the light's camera frame) to clip space.
Eigen::Matrix4f OrthographicProjection(const Eigen::Vector3d& min, const Eigen::Vector3d& max,
                                       DepthRange range);

// Near and far z of a box's corners in a camera frame; near is clamped to a small positive
// fraction of the box size so a camera inside the box still gets a valid frustum.
Eigen::Vector2d DepthBounds(const Eigen::AlignedBox3f& box, const Rigid3d& cam_from_world);

// light_clip_from_world of a directional light travelling along `direction`: orthographic,
// across the light bounding `points` but the `outlier_share` farthest out on each side of each
// axis (as the light sees them: an axis-aligned box of a tilted scene would waste the map's
// texels); along it, the depth range holds the points and `depth_box` (e.g. the exact bounds:
// casters must not be clipped away from the map).
Eigen::Matrix4f DirectionalLightMatrix(const Eigen::Vector3d& direction, const std::vector<Eigen::Vector3f>& points,
                                       const Eigen::AlignedBox3f& depth_box, DepthRange range,
                                       double outlier_share = 0.005);

// light_clip_from_world of a point light at `position` looking at the box: a square
// perspective frustum that contains the box's corners, near/far fitted to the corners of the
// box and of `depth_box`.
Eigen::Matrix4f PointLightMatrix(const Eigen::Vector3d& position, const Eigen::AlignedBox3f& box,
                                 const Eigen::AlignedBox3f& depth_box, DepthRange range);

// Planar projection onto `plane` along the light: light is (towards-light direction, 0) for a
// directional light or (position, 1) for a point light. M = (pi . l) I - l pi^T.
Eigen::Matrix4f PlanarShadowMatrix(const GroundPlane& plane, const Eigen::Vector4d& light);

// A pinhole camera of `width` x `height` with horizontal field of view `fov_deg`.
Camera ViewerCamera(int width, int height, double fov_deg);

// Unit direction a directional light travels, from azimuth/elevation of the light above the
// ground (about `up`, as OrbitPose of geometry/scene_frame.h).
Eigen::Vector3d LightDirectionFromAngles(const Eigen::Vector3d& up, double azimuth_deg,
                                         double elevation_deg);

}  // namespace parallax
