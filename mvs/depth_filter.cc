#include "mvs/depth_filter.h"

#include <algorithm>
#include <cmath>
#include <optional>
#include <stdexcept>

#include <tbb/parallel_for.h>

#include "core/check.h"

namespace parallax {
namespace {

// Relative depth change whose image motion measures how well a depth is constrained.
constexpr double kSensitivityStep = 0.01;

}  // namespace

void GeometricFilterOptions::Check() const {
  RequireOption(max_reprojection_px > 0, "GeometricFilterOptions.max_reprojection_px", max_reprojection_px, "> 0");
  RequireOption(max_relative_depth > 0, "GeometricFilterOptions.max_relative_depth", max_relative_depth, "> 0");
  RequireOption(min_consistent_views >= 1, "GeometricFilterOptions.min_consistent_views", min_consistent_views,
                ">= 1");
  RequireOption(min_parallax_px > 0, "GeometricFilterOptions.min_parallax_px", min_parallax_px, "> 0");
  RequireOption(fill_gaps_px >= 0, "GeometricFilterOptions.fill_gaps_px", fill_gaps_px, ">= 0");
  RequireOption(gap_max_relative_depth > 0, "GeometricFilterOptions.gap_max_relative_depth",
                gap_max_relative_depth, "> 0");
}

namespace {

// The nearest kept depth from (x, y) along (dx, dy), within `reach` pixels.
struct Neighbour {
  float depth = 0;
  float confidence = 0;
  int distance = 0;
};
Neighbour Nearest(const FilteredDepth& map, int x, int y, int dx, int dy, int reach) {
  for (int step = 1; step <= reach; ++step) {
    const int nx = x + step * dx, ny = y + step * dy;
    if (nx < 0 || ny < 0 || nx >= map.depth.Width() || ny >= map.depth.Height()) break;
    if (map.depth.At(nx, ny) > 0) return {map.depth.At(nx, ny), map.confidence.At(nx, ny), step};
  }
  return {};
}

}  // namespace

void FillGaps(int max_gap_px, double max_relative_depth, FilteredDepth& map) {
  const FilteredDepth kept = map;  // Fill from kept depths only, never from filled ones.
  const int width = map.depth.Width(), height = map.depth.Height();
  constexpr int kAxes[4][2] = {{1, 0}, {0, 1}, {1, 1}, {1, -1}};
  tbb::parallel_for(0, height, [&](int y) {
    for (int x = 0; x < width; ++x) {
      if (kept.depth.At(x, y) > 0) continue;
      double inverse_sum = 0, weight_sum = 0;
      float confidence = 1;
      int enclosing_axes = 0;
      for (const auto& axis : kAxes) {
        const Neighbour a = Nearest(kept, x, y, axis[0], axis[1], max_gap_px);
        const Neighbour b = Nearest(kept, x, y, -axis[0], -axis[1], max_gap_px);
        if (a.distance == 0 || b.distance == 0) continue;
        const float low = std::min(a.depth, b.depth), high = std::max(a.depth, b.depth);
        if (static_cast<double>(high - low) > max_relative_depth * static_cast<double>(low)) continue;
        ++enclosing_axes;
        for (const Neighbour& n : {a, b}) {
          inverse_sum += 1.0 / (static_cast<double>(n.depth) * n.distance);
          weight_sum += 1.0 / n.distance;
          confidence = std::min(confidence, n.confidence);
        }
      }
      if (enclosing_axes < 2) continue;
      map.depth.At(x, y) = static_cast<float>(weight_sum / inverse_sum);
      map.confidence.At(x, y) = 0.5f * confidence;
    }
  });
}

FilteredDepth FilterGeometric(
    const StereoView& reference, const DepthNormalMap& estimate,
    const std::vector<std::pair<const StereoView*, const DepthNormalMap*>>& sources,
    const GeometricFilterOptions& options) {
  options.Check();
  const int width = estimate.depth.Width(), height = estimate.depth.Height();
  FilteredDepth result{DepthMap(width, height), DepthMap(width, height)};
  std::vector<Rigid3d> source_from_ref, ref_from_source;
  for (const auto& [view, map] : sources) {
    source_from_ref.push_back(RelativePose(reference.cam_from_world, view->cam_from_world));
    ref_from_source.push_back(source_from_ref.back().Inverse());
  }
  const double max_error_sq = options.max_reprojection_px * options.max_reprojection_px;
  tbb::parallel_for(0, height, [&](int y) {
    for (int x = 0; x < width; ++x) {
      const float depth = estimate.depth.At(x, y);
      if (!(depth > 0)) continue;
      const Eigen::Vector2d pixel(x + 0.5, y + 0.5);
      const std::optional<Eigen::Vector3d> point = reference.camera.Unproject(pixel, depth);
      if (!point) continue;
      int consistent = 0;
      double sensitivity_px = 0;  // Largest image motion in a source for a 1% depth change.
      for (size_t s = 0; s < sources.size(); ++s) {
        const auto& [view, map] = sources[s];
        const std::optional<Eigen::Vector2d> in_source = view->camera.Project(source_from_ref[s] * *point);
        if (!in_source) continue;
        const std::optional<Eigen::Vector2d> nearer =
            view->camera.Project(source_from_ref[s] * (*point * (1 - kSensitivityStep)));
        if (nearer) sensitivity_px = std::max(sensitivity_px, (*nearer - *in_source).norm());
        // Interpolated: sampling the nearest pixel alone would fail the agreement test on
        // grazing surfaces, whose depth changes by more than that from pixel to pixel.
        const std::optional<double> source_depth = SampleDepth(map->depth, *in_source, 1.05);
        if (!source_depth) continue;
        // Back from where the point landed, at the source's depth, into the reference.
        const std::optional<Eigen::Vector3d> back = view->camera.Unproject(*in_source, *source_depth);
        if (!back) continue;
        const Eigen::Vector3d back_in_ref = ref_from_source[s] * *back;
        const std::optional<Eigen::Vector2d> reprojected = reference.camera.Project(back_in_ref);
        if (!reprojected) continue;
        if ((*reprojected - pixel).squaredNorm() <= max_error_sq &&
            std::abs(back_in_ref.z() - static_cast<double>(depth)) <=
                options.max_relative_depth * static_cast<double>(depth)) {
          ++consistent;
        }
      }
      if (consistent >= options.min_consistent_views) {
        result.depth.At(x, y) = depth;
        const float cost = estimate.cost[static_cast<size_t>(y) * width + x];
        // A depth the views barely constrain (tiny baseline) is not a confident one, however
        // well the windows match: confidence falls with the parallax a 1% change causes.
        const double resolvable = std::min(1.0, sensitivity_px / options.min_parallax_px);
        result.confidence.At(x, y) = static_cast<float>(
            resolvable * consistent / static_cast<double>(sources.size()) *
            (1 - static_cast<double>(cost) / 2));
      }
    }
  });
  if (options.fill_gaps_px > 0) FillGaps(options.fill_gaps_px, options.gap_max_relative_depth, result);
  return result;
}

}  // namespace parallax
