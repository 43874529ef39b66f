#pragma once
// Fuses filtered depth maps into one point cloud: each pixel's 3D point is merged with the
// pixels of the other views that see the same surface (depth within 1%, normals within 20
// degrees), and kept when enough views agree. The views are read through a loader as they are
// needed, so memory is bounded by the scene, not the photo count; the loader over a workspace
// is pipeline/fusion_workspace.h's.
#include <array>
#include <cstdint>
#include <deque>
#include <filesystem>
#include <functional>
#include <vector>

#include <Eigen/Core>

#include "core/color_gains.h"
#include "core/depth_map.h"
#include "core/image.h"
#include "core/progress.h"
#include "core/sparse_model.h"

namespace parallax {

struct FusionOptions {
  // Views (the pixel's own included) that must see a point for it to be kept.
  int min_views = 2;
  // Another view's depth agrees when within this relative difference ...
  double max_relative_depth = 0.01;
  // ... and its normal within this angle (degrees).
  double max_normal_angle_deg = 20;
  // A point another reference fused is the same sample when it faces the same way, normals
  // within this angle (looser than the pixels': PatchMatch's normals are noisy; a thin wall's
  // two sides still stay apart) ...
  double max_merge_normal_angle_deg = 60;
  // ... and lies within this many of the fusing pixel's footprints along the surface.
  double merge_spacing_pixels = 1.5;
  // Each view is merged with the views that share the most sparse points with it, at most
  // this many; only they are in memory with it, so memory does not grow with the photo count.
  int max_neighbours = 8;
  // The resolution views are fused at (mvs/working_resolution.h): the depth stage's, since its
  // maps hold no more detail; memory and points then follow the working size, not the photo's
  // megapixels. Colors are area-averaged down to it.
  double image_scale = 1;
  int max_image_size = 0;
  void Check() const;
};

struct FusedPoint {
  Eigen::Vector3f position;
  Eigen::Vector3f normal;         // Unit, world frame.
  std::array<uint8_t, 3> color;  // sRGB.
  uint16_t views = 0;             // How many pixels were merged.
};

// Stored in chunks: the cloud grows without ever being copied whole, as a vector's doubling
// would (it then holds the old and the new array, up to three times the points, at once).
using FusedPoints = std::deque<FusedPoint>;

// What fusion reads of one view: the photo at its size, the maps at the depth stage's working
// size or the photo's.
struct FusionViewMaps {
  DepthMap depth;           // The filtered depth map.
  DenseArray normals;       // The geometric normal map (as large): camera frame, COLMAP's layout.
  Image color;              // The photo as read (sRGB).
  RgbGain gain{1, 1, 1};    // The photo's color gain, applied at the working resolution.
};

// Reads one view's maps; fusion calls it for a view each time it enters the set in memory.
using LoadFusionView = std::function<FusionViewMaps(const SparseImage& image)>;

// Fuses `views` (images of `model`, each with a depth and a normal map), streamed: at most
// max_neighbours + 1 views in memory, each at the working resolution. Neighbours are found from
// the model's 3D points. Throws BadInputError when a view's photo and camera differ in size,
// its depth and normal maps differ or are larger than the photo (and what `load` throws).
// Deterministic.
FusedPoints FuseDepthMaps(const SparseModel& model, const std::vector<const SparseImage*>& views,
                          const LoadFusionView& load, const FusionOptions& options, Progress& progress);

// Binary little-endian PLY with x y z nx ny nz (float) and red green blue (uchar), written
// atomically. The format COLMAP's fused.ply uses.
void WritePly(const std::filesystem::path& path, const FusedPoints& points);

}  // namespace parallax
