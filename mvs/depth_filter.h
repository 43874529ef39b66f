#pragma once
// The geometric-consistency pass of multi-view stereo: a reference depth survives only where
// it agrees with the source views' depth maps (reprojected there and back), and gets a
// confidence from how many agree.
#include <vector>

#include "mvs/patch_match.h"

namespace parallax {

struct GeometricFilterOptions {
  // Round trip reference -> source depth -> reference must land within this many pixels ...
  double max_reprojection_px = 3.0;
  // ... at a depth within this relative difference.
  double max_relative_depth = 0.03;
  // Views that must agree for a depth to be kept.
  int min_consistent_views = 1;
  // Full confidence needs a 1% depth change to move the point at least this many pixels in
  // some source view; below, confidence falls proportionally (tiny baselines).
  double min_parallax_px = 1.0;
  // Gaps of at most this many pixels inside a surface (enclosed on two axes by kept depths
  // that agree within gap_max_relative_depth) are filled by interpolation in inverse depth,
  // at half the neighbours' confidence; 0 disables. Depth edges are never bridged: across
  // them the two sides disagree.
  int fill_gaps_px = 4;
  double gap_max_relative_depth = 0.02;
  void Check() const;
};

struct FilteredDepth {
  DepthMap depth;       // 0 where inconsistent.
  // In [0, 1]: share of agreeing views x (1 - cost / 2) x how well the baseline resolves
  // depth (see min_parallax_px); 0 where there is no depth.
  DepthMap confidence;
};

// `sources[i]` is a source view with its photometric estimate.
FilteredDepth FilterGeometric(
    const StereoView& reference, const DepthNormalMap& estimate,
    const std::vector<std::pair<const StereoView*, const DepthNormalMap*>>& sources,
    const GeometricFilterOptions& options);

// Fills the gaps of `map` as GeometricFilterOptions::fill_gaps_px describes. Exposed for tests.
void FillGaps(int max_gap_px, double max_relative_depth, FilteredDepth& map);

}  // namespace parallax
