#pragma once
// What the viewer shows, on the CPU side: the workspace's textured mesh and/or fused point
// cloud, its source cameras (with their photos), the bounds and the fitted ground plane.
#include <array>
#include <cstdint>
#include <filesystem>
#include <optional>
#include <string>
#include <vector>

#include <Eigen/Core>
#include <Eigen/Geometry>

#include "core/camera.h"
#include "core/color_gains.h"
#include "core/pose.h"
#include "geometry/obj.h"
#include "geometry/ground_plane.h"

namespace parallax {

// A photo with the camera that took it (pinhole; distortion is ignored: workspaces hold
// undistorted images).
struct ViewerSource {
  std::string name;  // Image file name as in the sparse model.
  Camera camera;
  Rigid3d cam_from_world;
  std::filesystem::path image_path;  // May not exist: the view is then never projected.
  // Its color gain (core/color_gains.h): projected photos meet without exposure steps.
  RgbGain gain = {1, 1, 1};
};

struct ColoredPoint {
  Eigen::Vector3f position;
  Eigen::Vector3f normal;          // Unit, or zero when the file has none.
  std::array<uint8_t, 3> color;   // sRGB.
};

// Where the source cameras stand when they surround the scene looking in (a ring, a dome, an
// arc): the orbit that frames the scene as the photos do.
struct CameraRig {
  Eigen::Vector3d target = Eigen::Vector3d::Zero();  // The point nearest every optical axis.
  double distance = 0;       // Median distance of the cameras to the target (scene units).
  double elevation_deg = 0;  // Median elevation of the cameras seen from the target.
  double half_width_tan = 0; // Median tan of the photos' horizontal half field of view.
};

struct ViewerScene {
  TriangleMesh mesh;                 // No triangles when the workspace has no mesh.
  // A simplified copy for views whose pixels cannot show every triangle of `mesh`; no
  // triangles when the workspace has none (a small mesh is displayed as it is).
  TriangleMesh display_mesh;
  std::vector<ColoredPoint> points; // Empty when the workspace has no fused.ply.
  std::vector<ViewerSource> sources;
  Eigen::AlignedBox3f bounds;        // Exact bounds of the mesh and the points: for clipping.
  // Robust bounds (RobustBounds, 2% outliers a side) of what is shown: the mesh (area-weighted
  // samples) when there is one, else the points; merged with `focus`. Far outliers of a fused
  // cloud do not count. The grid, the shadow map and the size of the camera frusta follow it.
  Eigen::AlignedBox3f extent;
  std::optional<GroundPlane> ground; // Absent when no plane has enough support.
  Eigen::Vector3d up = Eigen::Vector3d::UnitZ();  // Unit; the ground's normal when found.

  // What the views frame: the robust bounds of what stands on the ground (and its footprint),
  // so a large ground plane does not shrink the objects to a few pixels; `extent` without a
  // ground.
  Eigen::AlignedBox3f focus;
  std::optional<CameraRig> rig;  // Absent without cameras surrounding the scene.

  Eigen::Vector3f Centre() const { return extent.center(); }
  float Radius() const { return 0.5f * extent.diagonal().norm(); }
  Eigen::Vector3f FocusCentre() const { return focus.center(); }
  float FocusRadius() const { return 0.5f * focus.diagonal().norm(); }
};

// Reads <ws>/mesh/mesh.obj (+ .mtl, .png), <ws>/mesh_display/mesh.obj when present, <ws>/fused.ply and the sparse model <ws>/sparse
// with the photos in <ws>/images, then calls FinishViewerScene. Either of the mesh and the
// cloud may be missing, not both. A scene folder (gt/sparse, images/) is accepted for the
// cameras too. Throws BadInputError naming the folder when there is nothing to show, or the
// file that is unreadable.
ViewerScene LoadViewerScene(const std::filesystem::path& workspace);

// Computes the bounds and the robust extent, fits the ground plane (to the cloud, else to points
// sampled on the mesh), the up direction, the focus and the camera rig. Call after filling mesh, points and sources by hand (tests).
// Throws BadInputError if the scene has neither triangles nor points.
void FinishViewerScene(ViewerScene& scene);

// The points of a PLY cloud (our fused.ply or COLMAP's), read by geometry/ply.h: normals zero
// and colors grey where the file has none. Throws BadInputError naming the file.
std::vector<ColoredPoint> ReadColoredPly(const std::filesystem::path& path);

// The rig of cameras looking in at a common point: nullopt with fewer than 3 cameras, when
// their optical axes do not converge (e.g. a walk looking ahead), or when the point they
// converge to is behind most of them or farther than half `extent`'s diagonal outside it. Pure.
std::optional<CameraRig> FitCameraRig(const std::vector<ViewerSource>& sources, const Eigen::Vector3d& up,
                                      const Eigen::AlignedBox3f& extent);

}  // namespace parallax
