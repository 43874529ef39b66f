#pragma once
// Slanted-plane PatchMatch stereo on the CPU: per reference pixel a plane (depth + normal),
// scored by bilaterally weighted NCC against several source views, with occlusion-aware
// aggregation (the mean of the best views' costs, so occluded views cannot veto a pixel).
// Red-black propagation (neighbours' planes as candidates) and random refinement, the
// random search sampled in inverse depth.
//
// Conventions: PINHOLE cameras (undistorted images), pixel centres at +0.5, depth is z-depth,
// normals are camera-frame unit vectors facing the camera.
#include <cstdint>
#include <vector>

#include <Eigen/Core>

#include "core/camera.h"
#include "core/depth_map.h"
#include "core/pose.h"

namespace parallax {

// A greyscale image, intensities in [0, 1], row-major.
struct GrayImage {
  int width = 0;
  int height = 0;
  std::vector<float> values;
  float At(int x, int y) const { return values[static_cast<size_t>(y) * width + x]; }
};

struct StereoView {
  Camera camera;  // PINHOLE or SIMPLE_PINHOLE.
  Rigid3d cam_from_world;
  GrayImage image;
};

struct PatchMatchOptions {
  // Matching window: samples every `window_step` pixels within `window_radius` of the centre.
  int window_radius = 3;
  int window_step = 2;
  // Red-black sweeps, each over both colors, at every pyramid level.
  int iterations = 3;
  // Coarse-to-fine levels (each half the size of the next); 1 = full resolution only.
  int pyramid_levels = 3;
  // Propagation takes one plane from each of the 4 directions: that of the neighbour with the
  // lowest cost among those 1, 3, ... up to `propagation_reach` pixels away (1: the adjacent
  // one).
  int propagation_reach = 7;
  // Bilateral weights: intensity difference scale (intensities in [0, 1]) and spatial scale
  // in pixels.
  float sigma_color = 0.12f;
  float sigma_spatial_px = 3.0f;
  // The aggregated cost is the mean of this many lowest view costs (fewer if there are fewer
  // sources). 1 suits a ring of cameras, where many surfaces are seen well by only the
  // neighbour on one side.
  int best_views = 1;
  // Windows whose weighted standard deviation is below this are textureless: no depth.
  float min_texture_std = 0.004f;
  // Pixels whose final cost (1 - NCC, in [0, 2]) exceeds this get depth 0.
  float max_cost = 0.6f;
  // Depth search range (scene units); the random search is uniform in inverse depth.
  double min_depth = 0.1;
  double max_depth = 100;
  // Normals more oblique than this to the viewing ray (degrees) are not proposed.
  double max_normal_angle_deg = 87;
  uint32_t seed = 1;
  void Check() const;  // Throws UsageError naming the field.
};

struct DepthNormalMap {
  DepthMap depth;             // 0 where no depth was found.
  std::vector<float> normal;  // 3 per pixel (camera frame); 0 where no depth.
  std::vector<float> cost;    // Aggregated 1 - NCC per pixel, in [0, 2].
};

// Estimates depth and normal for every pixel of `reference` from `sources` (at least one).
// Uses every thread of the calling TBB arena; the result does not depend on the thread count.
// Throws InternalError for unsupported cameras or size mismatches.
DepthNormalMap PatchMatchStereo(const StereoView& reference,
                                const std::vector<const StereoView*>& sources,
                                const PatchMatchOptions& options);

// Building blocks, exposed for tests.

// The homography mapping reference pixels on the plane {X : n.X = rho} (reference camera frame)
// to source pixels: H = K_s (R + t n^T / rho) K_r^-1 with (R, t) = source_from_reference.
Eigen::Matrix3d PlaneHomography(const Camera& reference, const Camera& source,
                                const Rigid3d& source_from_reference, const Eigen::Vector3d& normal,
                                double rho);

// The implementations of the window cost: the fastest this build has (eight samples at a time
// where mvs/ is compiled for x86-64-v3, cmake/cpu_level.cmake) and the portable one, one
// sample at a time, which tests compare it with.
enum class CostKernel { kFastest, kPortable };

// Bilaterally weighted NCC cost 1 - NCC in [0, 2] between the reference window around
// (x, y) and the source window the homography maps it to; 2 when the source window leaves the
// image or either window is textureless.
float WindowCost(const GrayImage& reference, int x, int y, const GrayImage& source,
                 const Eigen::Matrix3d& homography, const PatchMatchOptions& options,
                 CostKernel kernel = CostKernel::kFastest);

// Depth `fraction` of the way from min to max depth, linear in inverse depth.
double InverseDepthSample(double min_depth, double max_depth, double fraction);

}  // namespace parallax
