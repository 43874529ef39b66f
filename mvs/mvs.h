#pragma once
// Multi-view stereo over a workspace: for every view of <ws>/sparse (undistorted PINHOLE),
// PatchMatch against its selected source views, then the geometric-consistency filter; writes
// docs/design.md's dense files (COLMAP format under <ws>/stereo, EXR depth + confidence under
// <ws>/depth).
#include <filesystem>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "core/progress.h"
#include "mvs/depth_filter.h"
#include "mvs/patch_match.h"
#include "core/quality.h"
#include "mvs/view_selection.h"
#include "mvs/working_resolution.h"

namespace parallax {

struct MvsOptions {
  ViewSelectionOptions views;
  PatchMatchOptions patch_match;  // Its depth range is set per view from the sparse points.
  GeometricFilterOptions filter;
  // Only these views (image names) get depth maps; empty means every view. Their first
  // `filter_sources` source views are estimated too (photometric only, not written), since
  // the geometric filter checks each depth against its sources' estimates.
  std::vector<std::string> only_views;
  int filter_sources = 2;
  // The working resolution of the estimate: each photo is resampled to `image_scale` of each
  // side (0.25..1), and further so that its long side is at most `max_image_size` pixels (0:
  // no cap). The depth maps are upsampled back (nearest, never blending depths across an
  // edge) so every file keeps the photo's size. The pixel-valued options above (windows,
  // propagation offsets, reprojection tolerances, gap sizes) are in working pixels; a cap
  // keeps that resolution, and so what they mean, alike for photos of any size.
  double image_scale = 1;
  int max_image_size = 0;
  // The share of each side a width x height photo is estimated at.
  double ScaleFor(int width, int height) const;
  void Check() const;
};

// fast: 3 sources, 4x4-sample window, 2 iterations, near neighbours only;
// balanced: 5 sources, 4x4 samples, 3 iterations, near and far neighbours;
// best: 7 sources, 4 iterations. Long side capped at kMaxImageSize (docs/depth.md).
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
};

// <ws>/depth/views.json and report.json's "depth" section: every field under its own name.
// Fields missing from an older file read as their defaults.
NLOHMANN_DEFINE_TYPE_NON_INTRUSIVE_WITH_DEFAULT(MvsViewReport, name, sources, min_depth, max_depth,
                                                working_width, working_height, photometric_share,
                                                geometric_share)
NLOHMANN_DEFINE_TYPE_NON_INTRUSIVE_WITH_DEFAULT(MvsSummary, views, skipped, photometric_seconds,
                                                geometric_seconds)

// Reads <ws>/sparse and <ws>/images. Throws BadInputError for a missing model or image.
// The same as every block of both passes, then FinishMultiViewStereoBlocks.
MvsSummary RunMultiViewStereo(const std::filesystem::path& workspace, const MvsOptions& options,
                              Progress& progress);

// The depth stage in parts that separate processes (cluster jobs, pipeline/slurm.h) can run:
// block `index` of `size` consecutive views of one pass (size 0: every view). Every
// photometric block must be done before a geometric block starts, since a view is checked
// against its sources' estimates.
enum class MvsPass { kPhotometric, kGeometric };
struct MvsBlock {
  MvsPass pass;
  int index = 0;
  int size = 0;
};

// Runs one block. Photometric: PatchMatch, each view's estimate to <ws>/stereo/estimates;
// geometric: the filter, each view's depth maps, then its report beside the estimates. A view
// whose estimate (or report) exists is not computed again, so a resubmitted job redoes only
// what is missing. Returns the number of views in the block (0: past the last one).
int RunMultiViewStereoBlock(const std::filesystem::path& workspace, const MvsOptions& options,
                            const MvsBlock& block, Progress& progress);

// Once every block ran: the summary from the views' reports (seconds left 0), and the
// estimates removed. Throws BadInputError naming a view whose report is missing.
MvsSummary FinishMultiViewStereoBlocks(const std::filesystem::path& workspace, const MvsOptions& options);

// Depth at pixel centres (our convention) -> depth sampled at integer image points (x, y), as
// COLMAP's dense code reads its maps: inverse depth averaged over the four surrounding pixel
// centres where they agree (within 1%), else the pixel's own value.
DepthMap ToColmapSampling(const DepthMap& depth);

}  // namespace parallax
