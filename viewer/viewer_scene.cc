#include "viewer/viewer_scene.h"

#include "core/atomic_file.h"
#include "core/error.h"
#include "core/scene_folder.h"
#include "core/sparse_model.h"
#include "core/workspace.h"
#include "geometry/ply.h"

namespace parallax {
namespace fs = std::filesystem;
namespace {

std::vector<ViewerSource> ReadSources(const fs::path& sparse_dir, const fs::path& images_dir,
                                      const ColorGains& gains) {
  std::vector<ViewerSource> sources;
  const SparseModel model = ReadSparseModel(sparse_dir);
  for (const SparseImage& image : model.Images()) {
    const Camera& camera = model.CameraById(image.camera_id);
    if (!IsProjectionSupported(camera.model)) continue;
    sources.push_back({image.name, camera, image.cam_from_world, images_dir / image.name, gains.Of(image.name)});
  }
  return sources;
}

}  // namespace

std::vector<ColoredPoint> ReadColoredPly(const fs::path& path) {
  const TriangleMesh cloud = ReadPly(path);
  std::vector<ColoredPoint> points(cloud.vertices.size());
  for (size_t i = 0; i < points.size(); ++i) {
    points[i].position = cloud.vertices[i];
    points[i].normal = cloud.normals.empty() ? Eigen::Vector3f::Zero() : cloud.normals[i];
    points[i].color = cloud.colors.empty() ? std::array<uint8_t, 3>{180, 180, 180} : cloud.colors[i];
    if (!points[i].normal.allFinite()) {
      throw BadInputError(path.string() + ": vertex " + std::to_string(i) + " is NaN or Inf");
    }
  }
  return points;
}

std::vector<FrameCamera> FrameCameras(const std::vector<ViewerSource>& sources) {
  std::vector<FrameCamera> cameras;
  cameras.reserve(sources.size());
  for (const ViewerSource& source : sources) cameras.push_back({source.camera, source.cam_from_world});
  return cameras;
}

void FinishViewerScene(ViewerScene& scene) {
  if (scene.mesh.triangles.empty() && scene.points.empty()) {
    throw BadInputError("the scene has neither a mesh nor a point cloud");
  }
  std::vector<Eigen::Vector3f> positions;
  positions.reserve(scene.points.size());
  for (const ColoredPoint& p : scene.points) positions.push_back(p.position);
  static_cast<SceneFrame&>(scene) = FitSceneFrame(scene.mesh, positions, FrameCameras(scene.sources));
}

ViewerScene LoadViewerScene(const fs::path& workspace) {
  if (!fs::is_directory(workspace)) {
    throw BadInputError(workspace.string() + ": not a folder (expected a parallax workspace)");
  }
  ViewerScene scene;
  const Workspace ws(workspace);
  const fs::path obj = ws.Mesh();
  const fs::path ply = ws.Fused();
  if (fs::exists(obj)) scene.mesh = ReadTexturedMesh(obj);
  const fs::path display = ws.DisplayMesh();
  if (!scene.mesh.triangles.empty() && fs::exists(display)) scene.display_mesh = ReadTexturedMesh(display);
  if (fs::exists(ply)) scene.points = ReadColoredPly(ply);
  if (scene.mesh.triangles.empty() && scene.points.empty()) {
    throw BadInputError(workspace.string() +
                        ": nothing to show: no mesh/mesh.obj and no fused.ply in this folder "
                        "(run 'parallax reconstruct' first)");
  }
  const SceneFolder scene_folder{workspace};
  if (DetectSparseFormat(ws.Sparse())) {
    scene.sources = ReadSources(ws.Sparse(), ws.Images(), ReadWorkspaceColorGains(workspace));
  } else if (DetectSparseFormat(scene_folder.Training().sparse)) {
    scene.sources = ReadSources(scene_folder.Training().sparse, scene_folder.Training().images, {});
  }
  FinishViewerScene(scene);
  return scene;
}

}  // namespace parallax
