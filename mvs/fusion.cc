#include "mvs/fusion.h"

#include <cmath>
#include <cstring>
#include <numbers>
#include <stdexcept>

#include "core/atomic_file.h"
#include "core/depth_map.h"
#include "core/error.h"
#include "core/image.h"
#include "core/sparse_model.h"
#include "core/workspace.h"
#include "core/check.h"

namespace parallax {
namespace fs = std::filesystem;
namespace {

struct FusionView {
  Camera camera;
  Rigid3d cam_from_world;
  Eigen::Matrix3d world_from_cam;
  DepthMap depth;
  DenseArray normals;  // Camera frame, channel-major (COLMAP layout).
  Image color;        // Linear RGB.
  std::vector<uint8_t> used;

  size_t Pixels() const { return static_cast<size_t>(depth.Width()) * depth.Height(); }
  Eigen::Vector3d Normal(int x, int y) const {
    const size_t i = static_cast<size_t>(y) * depth.Width() + x;
    return {normals.values[i], normals.values[Pixels() + i], normals.values[2 * Pixels() + i]};
  }
};

std::vector<FusionView> LoadViews(const fs::path& workspace) {
  const Workspace ws(workspace);
  const SparseModel model = ReadSparseModel(ws.Sparse());
  std::vector<FusionView> views;
  for (const SparseImage& image : model.Images()) {
    const fs::path depth_path = ws.Depth(image.name);
    const fs::path normal_path = ws.StereoNormalMap(image.name, StereoPass::kGeometric);
    if (!fs::exists(depth_path) || !fs::exists(normal_path)) continue;
    FusionView view;
    view.camera = model.CameraById(image.camera_id);
    view.cam_from_world = image.cam_from_world;
    view.world_from_cam = image.cam_from_world.rotation.conjugate().toRotationMatrix();
    view.depth = ReadDepthExr(depth_path);
    view.normals = ReadColmapArray(normal_path);
    view.color = SrgbToLinear(ReadImage(ws.Image(image.name)));
    if (view.normals.width != view.depth.Width() || view.normals.height != view.depth.Height() ||
        view.normals.channels != 3 || view.color.Width() != view.depth.Width() ||
        view.color.Height() != view.depth.Height()) {
      throw BadInputError("fusion: depth, normal map and image of " + image.name +
                          " differ in size");
    }
    view.used.assign(view.Pixels(), 0);
    views.push_back(std::move(view));
  }
  return views;
}

}  // namespace

void FusionOptions::Check() const {
  RequireOption(min_views >= 1, "FusionOptions.min_views", min_views, ">= 1");
  RequireOption(max_relative_depth > 0, "FusionOptions.max_relative_depth", max_relative_depth, "> 0");
  RequireOption(max_normal_angle_deg > 0 && max_normal_angle_deg <= 180, "FusionOptions.max_normal_angle_deg",
                max_normal_angle_deg, "(0, 180]");
}

std::vector<FusedPoint> FuseWorkspace(const fs::path& workspace, const FusionOptions& options,
                                      Progress& progress) {
  options.Check();
  std::vector<FusionView> views = LoadViews(workspace);
  const double min_normal_cos = std::cos(options.max_normal_angle_deg * std::numbers::pi / 180);
  std::vector<FusedPoint> points;
  for (size_t i = 0; i < views.size(); ++i) {
    progress.Update("fusion", static_cast<int64_t>(i), static_cast<int64_t>(views.size()));
    FusionView& reference = views[i];
    for (int y = 0; y < reference.depth.Height(); ++y) {
      for (int x = 0; x < reference.depth.Width(); ++x) {
        const size_t pixel = static_cast<size_t>(y) * reference.depth.Width() + x;
        const float depth = reference.depth.At(x, y);
        if (reference.used[pixel] || !(depth > 0)) continue;
        reference.used[pixel] = 1;
        const Eigen::Vector3d point = reference.world_from_cam *
            (*reference.camera.Unproject({x + 0.5, y + 0.5}, depth) - reference.cam_from_world.translation);
        const Eigen::Vector3d normal = reference.world_from_cam * reference.Normal(x, y);
        Eigen::Vector3d position_sum = point, normal_sum = normal, color_sum = Eigen::Vector3d::Zero();
        for (int c = 0; c < 3; ++c) color_sum[c] = reference.color.At(x, y, c);
        int count = 1;
        for (size_t j = 0; j < views.size(); ++j) {
          if (j == i) continue;
          FusionView& other = views[j];
          const Eigen::Vector3d in_other = other.cam_from_world * point;
          const std::optional<Eigen::Vector2d> projected = other.camera.Project(in_other);
          if (!projected) continue;
          const int ox = static_cast<int>(std::floor(projected->x()));
          const int oy = static_cast<int>(std::floor(projected->y()));
          if (ox < 0 || oy < 0 || ox >= other.depth.Width() || oy >= other.depth.Height()) continue;
          const size_t other_pixel = static_cast<size_t>(oy) * other.depth.Width() + ox;
          const double other_depth = other.depth.At(ox, oy);
          if (other.used[other_pixel] || !(other_depth > 0) ||
              std::abs(other_depth - in_other.z()) > options.max_relative_depth * in_other.z()) {
            continue;
          }
          const Eigen::Vector3d other_normal = other.world_from_cam * other.Normal(ox, oy);
          if (other_normal.dot(normal) < min_normal_cos) continue;
          other.used[other_pixel] = 1;
          position_sum += other.world_from_cam *
              (*other.camera.Unproject({ox + 0.5, oy + 0.5}, other_depth) - other.cam_from_world.translation);
          normal_sum += other_normal;
          for (int c = 0; c < 3; ++c) color_sum[c] += static_cast<double>(other.color.At(ox, oy, c));
          ++count;
        }
        if (count < options.min_views) continue;
        FusedPoint fused;
        fused.position = (position_sum / count).cast<float>();
        fused.normal = normal_sum.normalized().cast<float>();
        for (int c = 0; c < 3; ++c) {
          const float encoded = LinearToSrgb(static_cast<float>(color_sum[c] / count));
          fused.color[c] = static_cast<uint8_t>(std::lround(std::clamp(encoded, 0.0f, 1.0f) * 255));
        }
        fused.views = static_cast<uint16_t>(std::min(count, 65535));
        points.push_back(fused);
      }
    }
  }
  progress.Update("fusion", static_cast<int64_t>(views.size()), static_cast<int64_t>(views.size()));
  return points;
}

void WritePly(const fs::path& path, const std::vector<FusedPoint>& points) {
  std::string bytes = "ply\nformat binary_little_endian 1.0\nelement vertex " +
                      std::to_string(points.size()) +
                      "\nproperty float x\nproperty float y\nproperty float z\n"
                      "property float nx\nproperty float ny\nproperty float nz\n"
                      "property uchar red\nproperty uchar green\nproperty uchar blue\nend_header\n";
  const size_t header = bytes.size();
  constexpr size_t kVertexBytes = 6 * sizeof(float) + 3;
  bytes.resize(header + points.size() * kVertexBytes);
  char* out = bytes.data() + header;
  for (const FusedPoint& point : points) {
    std::memcpy(out, point.position.data(), 3 * sizeof(float));
    std::memcpy(out + 3 * sizeof(float), point.normal.data(), 3 * sizeof(float));
    std::memcpy(out + 6 * sizeof(float), point.color.data(), 3);
    out += kVertexBytes;
  }
  WriteFileAtomically(path, bytes);
}

}  // namespace parallax
