#pragma once
// Where a scene stands and how to circle it, fitted from its geometry and the cameras that took
// its photos: the bounds, the ground and "up", the box the views frame, the rig of cameras
// looking in, and the default orbit. `parallax view --orbit` and `parallax render --path
// orbit:N` both orbit this frame, so their circles are the same.
//
// Conventions: cam_from_world maps world points into the camera frame (x right, y down,
// z forward); a camera's "up" in the world is its -y axis; angles in degrees, lengths in scene
// units. Every function is pure and deterministic.
#include <optional>
#include <utility>
#include <vector>

#include <Eigen/Core>
#include <Eigen/Geometry>

#include "core/camera.h"
#include "core/pose.h"
#include "core/scene_folder.h"
#include "geometry/ground_plane.h"
#include "geometry/triangle_mesh.h"

namespace parallax {

// A camera that photographed the scene: where it stands and how wide it sees.
struct FrameCamera {
  Camera camera;  // Only its width and horizontal focal length are used.
  Rigid3d cam_from_world;
};

// Where the cameras stand when they surround the scene looking in (a ring, a dome, an arc):
// the orbit that frames the scene as the photos do.
struct CameraRig {
  Eigen::Vector3d target = Eigen::Vector3d::Zero();  // LookedAtPoint of the cameras.
  double distance = 0;        // Median distance of the cameras to the target.
  double elevation_deg = 0;   // Median elevation of the cameras seen from the target.
  double half_width_tan = 0;  // Median tan of the photos' horizontal half field of view.
  // The arc of azimuths (OrbitPose's, about up) the cameras stand on: from arc_start_deg over
  // arc_span_deg, the circle less its widest gap between two cameras; 360 with one camera.
  double arc_start_deg = 0;
  double arc_span_deg = 360;
};

struct SceneFrame {
  Eigen::AlignedBox3f bounds;  // Exact bounds of the mesh vertices and the cloud: for clipping.
  // Robust bounds (RobustBounds, 2% outliers a side) of the scene: the mesh (area-weighted
  // samples) when there is one, else the cloud; merged with `focus`. Far outliers of a fused
  // cloud do not count.
  Eigen::AlignedBox3f extent;
  std::optional<GroundPlane> ground;  // Absent when no plane has enough support.
  Eigen::Vector3d up = Eigen::Vector3d::UnitZ();  // Unit; the ground's normal when found.
  // What the views frame: the robust bounds of what stands on the ground (and its footprint),
  // so a large ground does not shrink the objects to a few pixels; `extent` without a ground.
  Eigen::AlignedBox3f focus;
  std::optional<CameraRig> rig;  // Absent without cameras surrounding the scene.

  Eigen::Vector3f Centre() const { return extent.center(); }
  float Radius() const { return 0.5f * extent.diagonal().norm(); }
  Eigen::Vector3f FocusCentre() const { return focus.center(); }
  float FocusRadius() const { return 0.5f * focus.diagonal().norm(); }
};

// The point nearest every camera's optical axis (least squares): what the photos look at.
// The one rule for cameras that look at no point: nullopt with fewer than 3 cameras, or when
// their axes are (nearly) parallel, as on a walk looking ahead: the smallest eigenvalue of
// sum(I - d d^T) over the axes d is below 0.02 per camera (axes spread by less than about 8
// degrees). Callers then frame the scene's focus box instead (DefaultOrbit).
std::optional<Eigen::Vector3d> LookedAtPoint(const std::vector<FrameCamera>& cameras);

// The cameras' mean "up" (-y) in world coordinates; nullopt without cameras or when they
// disagree so much that the mean is meaningless (its length under 0.3 per camera).
std::optional<Eigen::Vector3d> CamerasUp(const std::vector<FrameCamera>& cameras);

// The arc of the circle the azimuths (degrees, any range) cover: the circle less its widest
// gap between neighbouring azimuths, as {start in [0, 360), span}; {0, 360} for fewer than two.
std::pair<double, double> AzimuthArc(std::vector<double> azimuths_deg);

// The rig of cameras looking in at their LookedAtPoint: nullopt when there is no such point,
// or when it is behind more than a quarter of the cameras or farther than half `extent`'s
// diagonal outside it (and for an empty `extent`).
std::optional<CameraRig> FitCameraRig(const std::vector<FrameCamera>& cameras, const Eigen::Vector3d& up,
                                      const Eigen::AlignedBox3f& extent);

// Fits the frame of a scene given by a mesh (its triangles; vertices without triangles only
// widen `bounds` and `focus`) and/or a point cloud's positions, and the cameras: the bounds,
// the robust extent, the ground plane (fitted to the cloud when there is one, the mesh made
// from it, else to points sampled on the mesh by area), up (the ground's normal, else the
// cameras' up, else +z), the focus and the rig.
// Without triangles and without points the cameras alone make the frame: the camera centres
// and their LookedAtPoint (when there is one) stand for the scene, giving bounds, extent and
// focus; no ground is fitted (a ring of camera centres is a plane, but not the ground); up is
// the cameras' up, else +z; the rig is fitted as above. Throws InternalError when
// there are neither triangles, nor points, nor cameras.
SceneFrame FitSceneFrame(const TriangleMesh& mesh, const std::vector<Eigen::Vector3f>& cloud,
                         const std::vector<FrameCamera>& cameras);

// What a scene's frame is fitted to, read from its SceneFiles (core/scene_folder.h): each part
// empty where its file does not exist (a scene folder has neither: its cameras alone make the
// frame).
struct SceneGeometry {
  TriangleMesh mesh;
  TriangleMesh cloud;  // Positions, with normals and colours where the file has them.
};

// Throws BadInputError naming a file that cannot be read.
SceneGeometry ReadSceneGeometry(const SceneFiles& files);

// Two unit axes spanning the plane normal to `up` (unit), the first as close to world x as
// possible: the directions of azimuth 0 and 90 degrees.
std::pair<Eigen::Vector3d, Eigen::Vector3d> GroundAxes(const Eigen::Vector3d& up);

// The azimuth of `offset` about `up` (unit), in degrees in [0, 360): OrbitPose's azimuth of a
// camera at centre + offset.
double AzimuthDeg(const Eigen::Vector3d& offset, const Eigen::Vector3d& up);

// A camera on a circle around `centre`: azimuth about `up` (0 along GroundAxes' first axis),
// elevation above the plane normal to `up` (clamped to +-89), at `distance`, looking at
// `centre` with its image up towards `up`.
Rigid3d OrbitPose(const Eigen::Vector3d& centre, const Eigen::Vector3d& up, double azimuth_deg,
                  double elevation_deg, double distance);

// An orbit about the scene: the point looked at, the distance to it and the elevation above
// the ground (the azimuth is the caller's).
struct Orbit {
  Eigen::Vector3d target = Eigen::Vector3d::Zero();
  double distance = 1;
  double elevation_deg = 30;
};

// The orbit that shows the scene as its photos do: with a camera rig, the rig's target and
// (unless `elevation_deg` is given) elevation, at the rig's distance scaled so `camera` sees
// as wide a slice of the scene as the photos (x0.25..4). Without one, the focus box's centre,
// `elevation_deg` or 30, and the distance at which the focus box's corners fill 80% of
// `camera`'s view from `azimuth_deg` (uses its width, height and focal lengths).
Orbit DefaultOrbit(const SceneFrame& frame, double azimuth_deg, std::optional<double> elevation_deg,
                   const Camera& camera);

// cam_from_world of `camera` at `azimuth_deg` on the DefaultOrbit (OrbitPose about frame.up).
Rigid3d DefaultOrbitPose(const SceneFrame& frame, double azimuth_deg, std::optional<double> elevation_deg,
                         const Camera& camera);

}  // namespace parallax
