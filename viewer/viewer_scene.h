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
#include "core/pose.h"
#include "pipeline/textured_mesh.h"
#include "viewer/ground_plane.h"

namespace parallax {

// A photo with the camera that took it (pinhole; distortion is ignored: workspaces hold
// undistorted images).
struct SourceView {
  std::string name;  // Image file name as in the sparse model.
  Camera camera;
  Rigid3d cam_from_world;
  std::filesystem::path image_path;  // May not exist: the view is then never projected.
};

struct ColouredPoint {
  Eigen::Vector3f position;
  Eigen::Vector3f normal;          // Unit, or zero when the file has none.
  std::array<uint8_t, 3> colour;   // sRGB.
};

struct ViewerScene {
  TexturedMesh mesh;                 // No triangles when the workspace has no mesh.
  std::vector<ColouredPoint> points; // Empty when the workspace has no fused.ply.
  std::vector<SourceView> sources;
  Eigen::AlignedBox3f bounds;        // Of the mesh and the points.
  std::optional<GroundPlane> ground; // Absent when no plane has enough support.
  Eigen::Vector3d up = Eigen::Vector3d::UnitZ();  // Unit; the ground's normal when found.

  // What the views frame: the bounds of what stands on the ground (and its footprint), so a
  // large ground plane does not shrink the objects to a few pixels; `bounds` without a ground.
  Eigen::AlignedBox3f focus;

  Eigen::Vector3f Centre() const { return bounds.center(); }
  float Radius() const { return 0.5f * bounds.diagonal().norm(); }
  Eigen::Vector3f FocusCentre() const { return focus.center(); }
  float FocusRadius() const { return 0.5f * focus.diagonal().norm(); }
};

// Reads <ws>/mesh/mesh.obj (+ .mtl, .png), <ws>/fused.ply and the sparse model <ws>/sparse
// with the photos in <ws>/images, then calls FinishViewerScene. Either of the mesh and the
// cloud may be missing, not both. A scene folder (gt/sparse, images/) is accepted for the
// cameras too. Throws BadInputError naming the folder when there is nothing to show, or the
// file that is unreadable.
ViewerScene LoadViewerScene(const std::filesystem::path& workspace);

// Computes the bounds, fits the ground plane (to the cloud, else to points sampled on the mesh)
// and the up direction. Call after filling mesh, points and sources by hand (tests).
// Throws BadInputError if the scene has neither triangles nor points.
void FinishViewerScene(ViewerScene& scene);

// Positions, normals and colours of a binary little-endian PLY vertex element (our fused.ply
// and COLMAP's): float x y z, optional float nx ny nz, optional uchar red green blue.
// Throws BadInputError naming the file.
std::vector<ColouredPoint> ReadColouredPly(const std::filesystem::path& path);

}  // namespace parallax
