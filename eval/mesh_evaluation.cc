#include "eval/mesh_evaluation.h"

#include <algorithm>
#include <cmath>

#include "core/error.h"
#include "core/image_metrics.h"
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

namespace {

// The mask another run wrote for `name` (white where covered), checked against the size.
std::vector<uint8_t> ReadCoverage(const fs::path& path, int width, int height) {
  const Image mask = ReadImage(path);
  if (mask.Width() != width || mask.Height() != height) {
    throw BadInputError(path.string() + ": a coverage mask of " + std::to_string(mask.Width()) + "x" +
                        std::to_string(mask.Height()) + ", the camera is " + std::to_string(width) + "x" +
                        std::to_string(height));
  }
  std::vector<uint8_t> covered(static_cast<size_t>(width) * static_cast<size_t>(height));
  for (int y = 0; y < height; ++y) {
    for (int x = 0; x < width; ++x) {
      covered[static_cast<size_t>(y) * static_cast<size_t>(width) + static_cast<size_t>(x)] = mask.At(x, y, 0) > 0.5f;
    }
  }
  return covered;
}

Image CoverageImage(const std::vector<uint8_t>& covered, int width, int height) {
  Image mask(width, height, 1);
  for (size_t i = 0; i < covered.size(); ++i) mask.Pixels()[i] = covered[i];
  return mask;
}

double Share(const std::vector<uint8_t>& mask) {
  size_t set = 0;
  for (uint8_t value : mask) set += value != 0;
  return mask.empty() ? 0 : static_cast<double>(set) / static_cast<double>(mask.size());
}

// The render at the photo's exposure: divided by its gain, clamped to [0, 1].
void ToPhotoExposure(const RgbGain& gain, Image& render) {
  if (gain == RgbGain{1, 1, 1}) return;
  Image linear = SrgbToLinear(render);
  ApplyGain({1 / gain[0], 1 / gain[1], 1 / gain[2]}, linear);
  render = LinearToSrgb(linear);
  for (float& value : render.Pixels()) value = std::clamp(value, 0.0f, 1.0f);
}

}  // namespace

TexturedMeshScore ScoreTexturedMesh(const TriangleMesh& mesh, const std::vector<NamedCamera>& cameras,
                                    const std::vector<std::string>& image_names, const ColorGains& gains,
                                    const fs::path& images_dir, const fs::path& render_dir,
                                    const fs::path& common_dir) {
  TexturedMeshScore score;
  if (!render_dir.empty()) fs::create_directories(render_dir);
  const MeshRaycaster raycaster(mesh.vertices, mesh.triangles);
  int common_views = 0;
  for (size_t i = 0; i < cameras.size(); ++i) {
    const Camera& camera = cameras[i].camera.camera;
    const fs::path photo_path = images_dir / image_names.at(i);
    const Image photo = ReadImage(photo_path);
    if (static_cast<uint64_t>(photo.Width()) != camera.width ||
        static_cast<uint64_t>(photo.Height()) != camera.height || photo.Channels() < 3) {
      throw BadInputError(photo_path.string() + ": not an RGB image of its camera's size");
    }
    std::vector<uint8_t> covered;
    Image render = RenderTexturedMesh(mesh, raycaster, camera, cameras[i].camera.cam_from_world, covered);
    ToPhotoExposure(gains.Of(image_names[i]), render);
    TexturedMeshView view;
    view.name = cameras[i].name;
    view.psnr = Psnr(render, photo);
    view.ssim = Ssim(render, photo);
    view.coverage = Share(covered);
    if (view.coverage > 0) view.psnr_covered = Psnr(render, photo, covered);
    if (!common_dir.empty()) {
      std::vector<uint8_t> common = ReadCoverage(common_dir / (view.name + ".covered.png"), render.Width(), render.Height());
      for (size_t p = 0; p < common.size(); ++p) common[p] = common[p] != 0 && covered[p] != 0;
      view.common_share = Share(common);
      if (view.common_share > 0) {
        view.psnr_common = Psnr(render, photo, common);
        score.common_psnr_mean += view.psnr_common;
        score.common_share_mean += view.common_share;
        ++common_views;
      }
    }
    if (!render_dir.empty()) {
      WriteImage(render_dir / (view.name + ".png"), render, PixelFormat::kUint8);
      WriteImage(render_dir / (view.name + ".covered.png"), CoverageImage(covered, render.Width(), render.Height()),
                 PixelFormat::kUint8);
    }
    score.frame_psnr_mean += view.psnr;
    score.frame_ssim_mean += view.ssim;
    if (view.coverage > 0) {
      score.psnr_mean += view.psnr_covered;
      score.coverage_mean += view.coverage;
      ++score.views;
    }
    score.per_view.push_back(view);
  }
  if (score.views > 0) {
    score.psnr_mean /= score.views;
    score.coverage_mean /= score.views;
  }
  if (!cameras.empty()) {
    score.frame_psnr_mean /= static_cast<double>(cameras.size());
    score.frame_ssim_mean /= static_cast<double>(cameras.size());
  }
  if (common_views > 0) {
    score.common_psnr_mean /= common_views;
    score.common_share_mean /= common_views;
  }
  return score;
}

}  // namespace parallax
