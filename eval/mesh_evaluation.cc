#include "eval/mesh_evaluation.h"

#include <algorithm>
#include <cmath>

#include "core/error.h"
#include "geometry/raycaster.h"

namespace parallax {
namespace fs = std::filesystem;

Image RenderTexturedMesh(const TriangleMesh& mesh, const MeshRaycaster& raycaster,
                         const Camera& camera, const Rigid3d& cam_from_world,
                         std::vector<uint8_t>& covered) {
  const std::vector<RayHit> hits = raycaster.CastPixels(camera, cam_from_world);
  const int width = static_cast<int>(camera.width), height = static_cast<int>(camera.height);
  Image render(width, height, 3);
  covered.assign(hits.size(), 0);
  for (size_t i = 0; i < hits.size(); ++i) {
    const RayHit& hit = hits[i];
    if (hit.triangle < 0) continue;
    const Eigen::Vector2f* uv = &mesh.corner_uvs[3 * static_cast<size_t>(hit.triangle)];
    const Eigen::Vector2f at = (1 - hit.u - hit.v) * uv[0] + hit.u * uv[1] + hit.v * uv[2];
    const Eigen::Vector3f color = SampleAtlas(mesh.atlas, at);
    for (int c = 0; c < 3; ++c) {
      render.At(static_cast<int>(i % static_cast<size_t>(width)),
                static_cast<int>(i / static_cast<size_t>(width)), c) = color[c];
    }
    covered[i] = 1;
  }
  return render;
}

TexturedMeshScore ScoreTexturedMesh(const TriangleMesh& mesh, const SparseModel& model, const ColorGains& gains,
                                    const fs::path& images_dir, const fs::path& render_dir) {
  TexturedMeshScore score;
  if (!render_dir.empty()) fs::create_directories(render_dir);
  const MeshRaycaster raycaster(mesh.vertices, mesh.triangles);
  for (const SparseImage& image : model.Images()) {
    const Camera& camera = model.CameraById(image.camera_id);
    const Image photo = ReadImage(images_dir / image.name);
    if (static_cast<uint64_t>(photo.Width()) != camera.width ||
        static_cast<uint64_t>(photo.Height()) != camera.height || photo.Channels() < 3) {
      throw BadInputError((images_dir / image.name).string() +
                          ": not an RGB image of its camera's size");
    }
    std::vector<uint8_t> covered;
    Image render = RenderTexturedMesh(mesh, raycaster, camera, image.cam_from_world, covered);
    if (const RgbGain gain = gains.Of(image.name); gain != RgbGain{1, 1, 1}) {
      Image linear = SrgbToLinear(render);
      ApplyGain({1 / gain[0], 1 / gain[1], 1 / gain[2]}, linear);
      render = LinearToSrgb(linear);
      for (float& value : render.Pixels()) value = std::clamp(value, 0.0f, 1.0f);
    }
    double squared_error = 0;
    size_t pixels = 0;
    for (int y = 0; y < render.Height(); ++y) {
      for (int x = 0; x < render.Width(); ++x) {
        if (!covered[static_cast<size_t>(y) * static_cast<size_t>(render.Width()) + static_cast<size_t>(x)]) continue;
        for (int c = 0; c < 3; ++c) {
          const double difference = static_cast<double>(render.At(x, y, c) - photo.At(x, y, c));
          squared_error += difference * difference;
        }
        ++pixels;
      }
    }
    if (!render_dir.empty()) {
      WriteImage(render_dir / (fs::path(image.name).stem().string() + ".png"), render,
                 PixelFormat::kUint8);
    }
    if (pixels == 0) continue;
    const double mse = std::max(squared_error / (3.0 * static_cast<double>(pixels)), 1e-10);
    score.psnr_mean += -10 * std::log10(mse);
    score.coverage_mean += static_cast<double>(pixels) / static_cast<double>(covered.size());
    ++score.views;
  }
  if (score.views > 0) {
    score.psnr_mean /= score.views;
    score.coverage_mean /= score.views;
  }
  return score;
}

}  // namespace parallax
