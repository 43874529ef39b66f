#pragma once
// Choice of the source views to render a target from, before any image is loaded.
#include <vector>

#include "reproject/view.h"

namespace parallax {

struct SourceSelectionOptions {
  // How many sources to return at most (>= 1).
  int num_sources = 4;
  // Typical distance of the scene along the target's optical axis, in scene units; 0 estimates
  // it as the median depth at which the target's axis passes closest to the sources' axes
  // (cameras look at the scene), else the median distance to the source centres.
  double scene_depth = 0;
  // Target rays sampled on a grid_cols x grid_rows grid, at 0.7, 1 and 1.4 x scene_depth.
  int grid_cols = 16;
  int grid_rows = 12;
  // Sources seeing less than this share of the samples cannot contribute: never returned.
  double min_overlap = 0.05;
  // The score overlap / (1 + mean_angle / angle_scale_deg) halves at this mean angle between
  // source and target rays at the samples (degrees, > 0).
  double angle_scale_deg = 10;
  // Diversity: a target sample that a chosen source already sees from a direction within
  // about this angle (degrees; similarity exp(-(angle / diversity_angle_deg)^2)) gains little
  // from another source seeing it from there, so later picks favour other directions and
  // see behind what the first ones' views hide. 0: plain score order. In [0, 180].
  double diversity_angle_deg = 10;
  // RenderNovelView: after rendering from the chosen sources, up to this many more are added
  // one at a time while holes or surfaces out of view remain, each the source that sees most
  // of what they hide (SourceSeeingMost, of UnseenPoints); >= 0.
  int hole_sources = 2;

  void Check() const;  // Throws UsageError naming the field and value.
};

struct SourceScore {
  int index = -1;       // Into the list given to ScoreSources.
  double overlap = 0;   // Share of the target samples the source sees, [0, 1].
  double mean_angle_deg = 0;  // Mean angle between source and target rays at those samples.
  double score = 0;
};

// Scores of every source, in input order.
std::vector<SourceScore> ScoreSources(const std::vector<PosedCamera>& sources,
                                      const PosedCamera& target,
                                      const SourceSelectionOptions& options);

// Indices of up to num_sources sources, chosen greedily, best first: the first has the best
// score (large overlap with the target's view of the scene, small angles between its rays and
// the target's); each next one adds the most sum over the target's samples it sees of
// 1 / (1 + angle / angle_scale_deg) times how differently from the chosen ones it sees them
// (diversity_angle_deg). Sources with overlap below min_overlap (behind the target's scene,
// looking elsewhere) are never returned, so fewer may come back. Throws InternalError for a non-pinhole camera,
// UsageError for bad options.
std::vector<int> SelectSources(const std::vector<PosedCamera>& sources, const PosedCamera& target,
                               const SourceSelectionOptions& options);

// Index of the source that best sees `points` (world points nobody chosen saw, e.g. the
// background behind a render's holes at the depth the fill gave them): the largest sum over
// the points inside its frame and in front of it of 1 / (1 + angle / angle_scale_deg), the
// angle between its ray and the target's at the point. Sources in `exclude` are skipped;
// occlusion is not known before a source is loaded, so a pick can still fail to see them.
// Returns -1 when no source has at least min_points points inside its frame.
int SourceSeeingMost(const std::vector<PosedCamera>& sources, const PosedCamera& target,
                     const std::vector<Eigen::Vector3d>& points, const std::vector<int>& exclude,
                     int min_points, const SourceSelectionOptions& options);

}  // namespace parallax
