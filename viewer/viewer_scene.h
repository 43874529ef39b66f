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
#include "core/scene_folder.h"
#include "geometry/obj.h"
#include "geometry/ground_plane.h"
#include "geometry/scene_frame.h"

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

// The scene and its frame (geometry/scene_frame.h: bounds, extent, ground, up, focus, rig),
// fitted by FinishViewerScene. The grid, the shadow map and the size of the camera frusta
// follow the extent; the views frame the focus.
struct ViewerScene : SceneFrame {
  TriangleMesh mesh;                 // No triangles when the workspace has no mesh.
  // A simplified copy for views whose pixels cannot show every triangle of `mesh`; no
  // triangles when the workspace has none (a small mesh is displayed as it is).
  TriangleMesh display_mesh;
  std::vector<ColoredPoint> points; // Empty when the workspace has no fused.ply.
  std::vector<ViewerSource> sources;
};

// Where the scene the viewer shows is read from.
struct ViewerScenePaths {
  std::filesystem::path folder;  // The folder the user named, for messages.
  SceneFiles geometry;           // The mesh and the cloud (ReadSceneGeometry).
  std::filesystem::path display_mesh;  // The mesh's simplified copy; no file: none.
  ViewSetPaths photos;  // The sparse model, the photos and their color gains; no model: none.
};

// Reads the mesh (+ .mtl, .png), its display copy, the cloud and the photos' cameras of
// `paths`, then calls FinishViewerScene. Either of the mesh and the cloud may be missing, not
// both. Throws BadInputError naming the folder when there is nothing to show, or the file that
// is unreadable.
ViewerScene LoadViewerScene(const ViewerScenePaths& paths);

// Fits the scene's frame to the mesh, the points and the sources (FitSceneFrame: bounds,
// robust extent, ground plane, up, focus, camera rig). Call after filling mesh, points and
// sources by hand (tests). Throws BadInputError if the scene has neither triangles nor points.
void FinishViewerScene(ViewerScene& scene);

// The points of a cloud read from `file` (our fused.ply or COLMAP's): normals zero and colors
// grey where the file has none. Throws BadInputError naming the file for a non-finite normal.
std::vector<ColoredPoint> ColoredPoints(const TriangleMesh& cloud, const std::filesystem::path& file);

// The sources as the scene frame sees them (geometry/scene_frame.h).
std::vector<FrameCamera> FrameCameras(const std::vector<ViewerSource>& sources);

}  // namespace parallax
