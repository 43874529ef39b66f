#include "viewer/viewer_scene.h"

#include <utility>

#include "core/error.h"
#include "core/sparse_model.h"

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

std::vector<ColoredPoint> ColoredPoints(const TriangleMesh& cloud, const fs::path& file) {
  std::vector<ColoredPoint> points(cloud.vertices.size());
  for (size_t i = 0; i < points.size(); ++i) {
    points[i].position = cloud.vertices[i];
    points[i].normal = cloud.normals.empty() ? Eigen::Vector3f::Zero() : cloud.normals[i];
    points[i].color = cloud.colors.empty() ? std::array<uint8_t, 3>{180, 180, 180} : cloud.colors[i];
    if (!points[i].normal.allFinite()) {
      throw BadInputError(file.string() + ": vertex " + std::to_string(i) + " is NaN or Inf");
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

ViewerScene LoadViewerScene(const ViewerScenePaths& paths) {
  if (!fs::is_directory(paths.folder)) {
    throw BadInputError(paths.folder.string() + ": not a folder (expected a parallax workspace)");
  }
  SceneGeometry geometry = ReadSceneGeometry(paths.geometry);
  ViewerScene scene;
  scene.mesh = std::move(geometry.mesh);
  if (!scene.mesh.triangles.empty() && fs::exists(paths.display_mesh)) {
    scene.display_mesh = ReadTexturedMesh(paths.display_mesh);
  }
  scene.points = ColoredPoints(geometry.cloud, paths.geometry.cloud);
  if (scene.mesh.triangles.empty() && scene.points.empty()) {
    throw BadInputError(paths.folder.string() + ": nothing to show: no " +
                        paths.geometry.mesh.lexically_relative(paths.folder).string() + " and no " +
                        paths.geometry.cloud.lexically_relative(paths.folder).string() +
                        " in this folder (run 'parallax reconstruct' first)");
  }
  if (!paths.photos.sparse.empty() && DetectSparseFormat(paths.photos.sparse)) {
    const ColorGains gains = ReadColorGainsIfPresent(paths.photos.color_gains);
    scene.sources = ReadSources(paths.photos.sparse, paths.photos.images, gains);
  }
  FinishViewerScene(scene);
  return scene;
}

}  // namespace parallax
