#include "mesh/tsdf_volume.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <optional>
#include <string>
#include <vector>

#include <tbb/parallel_for.h>

#include "core/error.h"
#include "mesh/marching_cubes.h"

namespace parallax {
namespace {

// Four depths within this ratio are one surface, interpolated between (core/depth_map.h).
constexpr double kOneSurface = 1.05;

int FloorDiv(int value, int divisor) { return value >= 0 ? value / divisor : -((-value + divisor - 1) / divisor); }

}  // namespace

void TsdfOptions::Check() const {
  if (!(voxel_size > 0) || !std::isfinite(voxel_size)) {
    throw BadInputError("TSDF: the voxel size must be positive, not " + std::to_string(voxel_size));
  }
  if (!(truncation >= voxel_size) || !std::isfinite(truncation)) {
    throw BadInputError("TSDF: the truncation must be at least a voxel (" + std::to_string(voxel_size) + "), not " +
                        std::to_string(truncation));
  }
}

TsdfVolume::TsdfVolume(const TsdfOptions& options) : options_(options) { options_.Check(); }

void TsdfVolume::Integrate(const Camera& camera, const Rigid3d& cam_from_world, const DepthMap& depth, float weight) {
  if (camera.model != CameraModel::kPinhole || camera.width != static_cast<uint64_t>(depth.Width()) ||
      camera.height != static_cast<uint64_t>(depth.Height())) {
    throw BadInputError("TSDF: a depth map of " + std::to_string(depth.Width()) + " x " +
                        std::to_string(depth.Height()) + " needs a pinhole camera of its size");
  }
  const double voxel = options_.voxel_size, truncation = options_.truncation;
  const double block_size = kBlockSide * voxel;
  const double fx = camera.FocalX(), fy = camera.FocalY(), cx = camera.PrincipalX(), cy = camera.PrincipalY();
  const Rigid3d world_from_cam = cam_from_world.Inverse();
  // The blocks within the truncation of a depth: each pixel's ray sampled through the band, at
  // most half a voxel apart.
  std::vector<BlockIndex> touched;
  for (int y = 0; y < depth.Height(); ++y) {
    for (int x = 0; x < depth.Width(); ++x) {
      const double d = depth.At(x, y);
      if (!(d > 0)) continue;
      const Eigen::Vector3d ray((x + 0.5 - cx) / fx, (y + 0.5 - cy) / fy, 1);
      const double step = 0.5 * voxel / ray.norm();
      for (double z = std::max(d - truncation, step); z <= d + truncation; z += step) {
        const Eigen::Vector3d block = (world_from_cam * (z * ray)) / block_size;
        touched.push_back({static_cast<int>(std::floor(block.x())), static_cast<int>(std::floor(block.y())),
                           static_cast<int>(std::floor(block.z()))});
      }
    }
  }
  std::sort(touched.begin(), touched.end());
  touched.erase(std::unique(touched.begin(), touched.end()), touched.end());
  std::vector<std::pair<BlockIndex, Block*>> updated;
  updated.reserve(touched.size());
  for (const BlockIndex& index : touched) updated.emplace_back(index, &blocks_[index]);
  tbb::parallel_for(size_t{0}, updated.size(), [&](size_t i) {
    const auto& [index, block] = updated[i];
    for (int k = 0; k < kBlockSide; ++k) {
      for (int j = 0; j < kBlockSide; ++j) {
        for (int l = 0; l < kBlockSide; ++l) {
          const Eigen::Vector3d centre =
              voxel * (Eigen::Vector3d(index[0] * kBlockSide + l, index[1] * kBlockSide + j, index[2] * kBlockSide + k) +
                       Eigen::Vector3d::Constant(0.5));
          const Eigen::Vector3d p = cam_from_world * centre;
          if (!(p.z() > 0)) continue;
          // The depth interpolated where the four pixels around lie on one surface.
          const std::optional<double> d =
              SampleDepth(depth, Eigen::Vector2d(fx * p.x() / p.z() + cx, fy * p.y() / p.z() + cy), kOneSurface);
          if (!d) continue;
          const double distance = *d - p.z();
          if (distance < -truncation) continue;  // Hidden behind the surface.
          Voxel& cell = (*block)[(k * kBlockSide + j) * kBlockSide + l];
          const double clipped = std::min(1.0, distance / truncation);
          const double old_weight = cell.weight, total = old_weight + static_cast<double>(weight);
          cell.distance = static_cast<float>(
              (static_cast<double>(cell.distance) * old_weight + clipped * static_cast<double>(weight)) / total);
          cell.weight = static_cast<float>(total);
        }
      }
    }
  });
}

TriangleMesh TsdfVolume::Mesh(float min_weight) const {
  constexpr int kSamples = kBlockSide + 1;  // A block's cells reach the first voxels of the next.
  const float unknown = std::numeric_limits<float>::quiet_NaN();
  IsoSurfaceMesher mesher;
  for (const auto& [index, block] : blocks_) {
    SampledField field;
    field.size = Eigen::Vector3i::Constant(kSamples);
    field.first = kBlockSide * Eigen::Vector3i(index[0], index[1], index[2]);
    field.origin = Eigen::Vector3d::Constant(0.5 * options_.voxel_size);  // Voxel centres.
    field.spacing = options_.voxel_size;
    field.values.reserve(kSamples * kSamples * kSamples);
    for (int z = 0; z < kSamples; ++z) {
      for (int y = 0; y < kSamples; ++y) {
        for (int x = 0; x < kSamples; ++x) {
          const Eigen::Vector3i g = field.first + Eigen::Vector3i(x, y, z);
          const BlockIndex owner = {FloorDiv(g.x(), kBlockSide), FloorDiv(g.y(), kBlockSide),
                                    FloorDiv(g.z(), kBlockSide)};
          const Block* holder = &block;
          if (owner != index) {
            const auto found = blocks_.find(owner);
            holder = found == blocks_.end() ? nullptr : &found->second;
          }
          float value = unknown;
          if (holder) {
            const Eigen::Vector3i local = g - kBlockSide * Eigen::Vector3i(owner[0], owner[1], owner[2]);
            const Voxel& cell = (*holder)[(local.z() * kBlockSide + local.y()) * kBlockSide + local.x()];
            if (cell.weight >= min_weight) value = cell.distance;
          }
          field.values.push_back(value);
        }
      }
    }
    mesher.Add(field);
  }
  return mesher.Take();
}

}  // namespace parallax
