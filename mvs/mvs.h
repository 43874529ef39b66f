#pragma once
// Multi-view stereo, one view at a time, on cameras and photos in memory: which views get depth
// (PlanDepth), PatchMatch of one view against its sources at the working resolution
// (EstimateViewDepth), then the geometric-consistency filter against the sources' estimates
// (FilterViewDepth). The depth stage that runs this over a workspace, reads its photos and
// writes its dense files is pipeline/depth_workspace.h.
#include <cstdint>
#include <map>
#include <set>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "core/depth_map.h"
#include "core/image.h"
#include "core/sparse_model.h"
#include "mvs/depth_filter.h"
#include "mvs/patch_match.h"
#include "core/quality.h"
#include "mvs/view_selection.h"
#include "mvs/working_resolution.h"

namespace parallax {

struct MvsOptions {
  ViewSelectionOptions views;
  PatchMatchOptions patch_match;  // Its depth range and seed are set per view.
  GeometricFilterOptions filter;
  // Only these views (image names) get depth maps; empty means every view. Their first
  // `filter_sources` source views are estimated too (photometric only, not written), since
  // the geometric filter checks each depth against its sources' estimates.
  std::vector<std::string> only_views;
  int filter_sources = 2;
  // The working resolution of the estimate: each photo is resampled to `image_scale` of each
  // side (0.25..1), and further so that its long side is at most `max_image_size` pixels (0:
  // no cap). The maps stay at that size, in memory and in their files; readers upsample them
  // to the photo's (ReadDepthExrAt: nearest, never blending depths across an edge). The
  // pixel-valued options above (windows, propagation offsets, reprojection tolerances, gap
  // sizes) are in working pixels; a cap keeps that resolution, and so what they mean, alike
  // for photos of any size.
  double image_scale = 1;
  int max_image_size = 0;
  // Each view's PatchMatch seed is its image id plus this.
  uint32_t seed = 0;
  // The share of each side a width x height photo is estimated at.
  double ScaleFor(int width, int height) const;
  void Check() const;
};

// fast: 3 sources, 4x4-sample window, 2 iterations, adjacent neighbours only;
// balanced: 5 sources, 4x4 samples, 3 iterations, neighbours up to 7 px away;
// best: 7 sources, 4 iterations. Long side capped at MaxImageSizeFor(quality) (docs/depth.md).
MvsOptions MvsOptionsFor(Quality quality);

// The working resolution's long-side cap at each quality (MvsOptions::max_image_size).
int MaxImageSizeFor(Quality quality);

struct MvsViewReport {
  std::string name;
  std::vector<std::string> sources;
  double min_depth = 0;
  double max_depth = 0;
  int working_width = 0;  // The resolution the estimate ran at.
  int working_height = 0;
  double photometric_share = 0;  // Share of pixels with a photometric depth.
  double geometric_share = 0;    // Share left after the geometric filter.
};

struct MvsSummary {
  std::vector<MvsViewReport> views;  // The views whose depth maps were written.
  int estimated_views = 0;           // Views PatchMatch ran on (more than `views` with only_views).
  std::vector<std::string> skipped;  // Views without depth, and why.
  double photometric_seconds = 0;
  double geometric_seconds = 0;
  // Views whose PatchMatch estimate, and whose filtered maps, an interrupted run of the same
  // stage (same model and options) had written whole and this run kept.
  int resumed_estimates = 0;
  int resumed_filtered = 0;
};

// <ws>/depth/views.json and report.json's "depth" section: every field under its own name.
// Fields missing from an older file read as their defaults.
NLOHMANN_DEFINE_TYPE_NON_INTRUSIVE_WITH_DEFAULT(MvsViewReport, name, sources, min_depth, max_depth,
                                                working_width, working_height, photometric_share,
                                                geometric_share)
NLOHMANN_DEFINE_TYPE_NON_INTRUSIVE_WITH_DEFAULT(MvsSummary, views, skipped, photometric_seconds,
                                                geometric_seconds, resumed_estimates, resumed_filtered)

// The views whose depth maps are written (`written`) and those PatchMatch runs on
// (`estimated`): the written ones plus the sources the geometric filter checks them against.
struct DepthPlan {
  std::set<std::string> wanted;     // MvsOptions::only_views; empty: every view.
  std::vector<ViewPlan> all;        // Every view that can get depth (PlanViews).
  std::vector<ViewPlan> written;
  std::vector<ViewPlan> estimated;
};

// Throws UsageError for invalid options, BadInputError naming a view of
// options.only_views that the model lacks. Deterministic.
DepthPlan PlanDepth(const SparseModel& model, const MvsOptions& options);

// Why each image of the model gets no depth map under `plan` (MvsSummary::skipped).
std::vector<std::string> SkippedViews(const SparseModel& model, const DepthPlan& plan);

// The camera and pose `image` is estimated with, at the working resolution `options` choose
// for it; no photo yet (that is WorkingGray's).
StereoView WorkingStereoView(const SparseModel& model, const SparseImage& image, const MvsOptions& options);

// `photo` (as read, any channel count) in grey, resampled to `camera`'s size, the working one
// (area averaging, no aliasing).
GrayImage WorkingGray(const Image& photo, const Camera& camera);

// PatchMatch on `plan`'s reference against its sources within its depth range. `views` holds
// the reference and every source, each at the working resolution with its photo.
DepthNormalMap EstimateViewDepth(const ViewPlan& plan, const std::map<uint32_t, StereoView>& views,
                                 const MvsOptions& options);

// One view's depth after both passes, at the working resolution.
struct ViewDepth {
  DepthNormalMap estimate;  // The photometric estimate.
  FilteredDepth filtered;   // What the geometric filter kept, and its confidence.
  MvsViewReport report;     // Its shares are those of the two maps above.
};

// The geometric pass for `view`: its photometric estimate `low` (working resolution) checked
// against its sources' estimates, `source_estimates` by image id (sources without one are left
// out; with none, nothing is kept). Needs no photos, only cameras and poses.
ViewDepth FilterViewDepth(const SparseModel& model, const ViewPlan& view, const DepthNormalMap& low,
                          const std::map<uint32_t, DepthNormalMap>& source_estimates, const MvsOptions& options);

// COLMAP's normal map (3 channels, channel-major) of `map`, 0 where `keep` has no depth.
DenseArray ColmapNormalMap(const DepthNormalMap& map, const DepthMap& keep);

// Depth at pixel centres (our convention) -> depth sampled at integer image points (x, y), as
// COLMAP's dense code reads its maps: inverse depth averaged over the four surrounding pixel
// centres where they agree (within 1%), else the pixel's own value.
DepthMap ToColmapSampling(const DepthMap& depth);

}  // namespace parallax
