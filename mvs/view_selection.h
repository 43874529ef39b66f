#pragma once
// Which source views each reference view is matched against, and where its depth can lie,
// both read off the sparse model.
#include <cstdint>
#include <string>
#include <vector>

#include "core/sparse_model.h"

namespace parallax {

struct ViewSelectionOptions {
  // Source views per reference view.
  int max_sources = 5;
  // A pair needs this many shared 3D points to be considered.
  int min_shared_points = 10;
  // Triangulation angles below this (degrees) count proportionally less: small baselines
  // give poorly determined depth.
  double good_triangulation_deg = 8;
  // Points seen at more than this angle (degrees) do not count: the views differ too much for
  // window matching.
  double max_triangulation_deg = 60;
  // The depth range is the sparse points' range widened by this factor on each side.
  double depth_margin = 0.3;
  void Check() const;
};

struct ViewPlan {
  uint32_t image_id = 0;
  std::string name;
  std::vector<uint32_t> sources;  // Best first.
  double min_depth = 0;
  double max_depth = 0;
};

// One plan per image that sees enough points (at least 3) and has at least one source view;
// images without are left out (no depth can be estimated for them). Deterministic.
std::vector<ViewPlan> PlanViews(const SparseModel& model, const ViewSelectionOptions& options);

}  // namespace parallax
