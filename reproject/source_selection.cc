#include "reproject/source_selection.h"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <numbers>
#include <optional>
#include <stdexcept>
#include <string>
#include <vector>

#include "core/statistics.h"
#include "core/check.h"

namespace parallax {
namespace {

Eigen::Vector3d ViewDirection(const Rigid3d& cam_from_world) {
  return cam_from_world.rotation.inverse() * Eigen::Vector3d::UnitZ();
}

// Depth along the target axis where it passes closest to each source axis (skipping
// near-parallel axes and points behind either camera); median of those.
double EstimateSceneDepth(const std::vector<PosedCamera>& sources, const PosedCamera& target) {
  const Eigen::Vector3d c0 = CameraCenter(target.cam_from_world);
  const Eigen::Vector3d d0 = ViewDirection(target.cam_from_world);
  std::vector<double> depths, distances;
  for (const PosedCamera& source : sources) {
    const Eigen::Vector3d c1 = CameraCenter(source.cam_from_world);
    const Eigen::Vector3d d1 = ViewDirection(source.cam_from_world);
    const double distance = (c1 - c0).norm();
    if (distance > 0) distances.push_back(distance);
    // Closest points of two lines: solve [d0 -d1] [s t]^T ~ c1 - c0.
    const double b = d0.dot(d1);
    const double denom = 1 - b * b;
    if (denom < 1e-6) continue;
    const Eigen::Vector3d w = c0 - c1;
    const double s = (b * d1.dot(w) - d0.dot(w)) / denom;
    const double t = (d1.dot(w) - b * d0.dot(w)) / denom;
    if (s > 0 && t > 0 && std::isfinite(s)) depths.push_back(s);
  }
  if (!depths.empty()) return UpperMedian(depths);
  return distances.empty() ? 1.0 : UpperMedian(distances);
}

// The angle (degrees) at point `p` between the rays to it from a source's centre and from
// `target_center`, both in that source's camera frame (its centre at the origin); nullopt when
// `p` is not in front of the source and inside its frame.
std::optional<double> SeenAngleDeg(const Pinhole& source, const Eigen::Vector3d& p,
                                   const Eigen::Vector3d& target_center) {
  if (!(p.z() > 1e-9 * p.norm())) return std::nullopt;
  const double u = source.fx * p.x() / p.z() + source.cx, v = source.fy * p.y() / p.z() + source.cy;
  if (!(u >= 0 && v >= 0 && u <= source.width && v <= source.height)) return std::nullopt;
  const double cos_angle = p.normalized().dot((p - target_center).normalized());
  return std::acos(std::clamp(cos_angle, -1.0, 1.0)) * 180.0 / std::numbers::pi;
}

// How well a source sees a point from `angle_deg` off the target's ray: 1 / (1 + angle /
// angle_scale_deg).
double ViewQuality(double angle_deg, const SourceSelectionOptions& options) {
  return 1 / (1 + angle_deg / options.angle_scale_deg);
}

// What one source sees of the target's sample points.
struct SampleViews {
  std::vector<uint8_t> seen;             // Per sample.
  std::vector<float> quality;            // 1 / (1 + angle / angle_scale), 0 where unseen.
  std::vector<Eigen::Vector3f> to_source;  // Unit direction from the point to the source.
};

SourceScore ScoreOne(const PosedCamera& source, const PosedCamera& target, double scene_depth,
                     const SourceSelectionOptions& options, SampleViews* views) {
  const Pinhole t = Pinhole::From(target.camera);
  const Pinhole s = Pinhole::From(source.camera);
  const Rigid3d source_from_target = RelativePose(target.cam_from_world, source.cam_from_world);
  const Eigen::Matrix3d target_from_source_rotation =
      source_from_target.rotation.conjugate().toRotationMatrix();
  const Eigen::Vector3d target_center_in_source = source_from_target.translation;
  SourceScore score;
  int samples = 0, seen = 0;
  double angle_sum = 0;
  for (double factor : {0.7, 1.0, 1.4}) {
    for (int gy = 0; gy < options.grid_rows; ++gy) {
      for (int gx = 0; gx < options.grid_cols; ++gx) {
        ++samples;
        views->seen.push_back(0);
        views->quality.push_back(0);
        views->to_source.push_back(Eigen::Vector3f::Zero());
        const double u = (gx + 0.5) * t.width / options.grid_cols;
        const double v = (gy + 0.5) * t.height / options.grid_rows;
        const Eigen::Vector3d in_target((u - t.cx) / t.fx * scene_depth * factor,
                                        (v - t.cy) / t.fy * scene_depth * factor,
                                        scene_depth * factor);
        const Eigen::Vector3d p = source_from_target * in_target;
        const std::optional<double> angle = SeenAngleDeg(s, p, target_center_in_source);
        if (!angle) continue;
        ++seen;
        angle_sum += *angle;
        views->seen.back() = 1;
        views->quality.back() = static_cast<float>(ViewQuality(*angle, options));
        // In the target frame, so that directions of different sources compare.
        views->to_source.back() = (target_from_source_rotation * -p.normalized()).cast<float>();
      }
    }
  }
  score.overlap = samples > 0 ? static_cast<double>(seen) / samples : 0;
  score.mean_angle_deg = seen > 0 ? angle_sum / seen : 180;
  score.score = score.overlap / (1 + score.mean_angle_deg / options.angle_scale_deg);
  return score;
}

std::vector<SourceScore> ScoreAll(const std::vector<PosedCamera>& sources,
                                  const PosedCamera& target,
                                  const SourceSelectionOptions& options,
                                  std::vector<SampleViews>* views) {
  options.Check();
  const double scene_depth =
      options.scene_depth > 0 ? options.scene_depth : EstimateSceneDepth(sources, target);
  std::vector<SourceScore> scores;
  views->assign(sources.size(), {});
  for (size_t i = 0; i < sources.size(); ++i) {
    SourceScore score = ScoreOne(sources[i], target, scene_depth, options, &(*views)[i]);
    score.index = static_cast<int>(i);
    scores.push_back(score);
  }
  return scores;
}

}  // namespace

void SourceSelectionOptions::Check() const {
  RequireOption(num_sources >= 1, "SourceSelectionOptions.num_sources", num_sources, ">= 1");
  RequireOption(scene_depth >= 0 && std::isfinite(scene_depth), "SourceSelectionOptions.scene_depth", scene_depth,
                ">= 0");
  RequireOption(grid_cols >= 1, "SourceSelectionOptions.grid_cols", grid_cols, ">= 1");
  RequireOption(grid_rows >= 1, "SourceSelectionOptions.grid_rows", grid_rows, ">= 1");
  RequireOption(min_overlap > 0 && min_overlap <= 1, "SourceSelectionOptions.min_overlap", min_overlap, "(0, 1]");
  RequireOption(angle_scale_deg > 0 && std::isfinite(angle_scale_deg), "SourceSelectionOptions.angle_scale_deg",
                angle_scale_deg, "> 0");
  RequireOption(hole_sources >= 0, "SourceSelectionOptions.hole_sources", hole_sources, ">= 0");
  RequireOption(diversity_angle_deg >= 0 && diversity_angle_deg <= 180,
                "SourceSelectionOptions.diversity_angle_deg", diversity_angle_deg, "[0, 180]");
}

std::vector<SourceScore> ScoreSources(const std::vector<PosedCamera>& sources,
                                      const PosedCamera& target,
                                      const SourceSelectionOptions& options) {
  std::vector<SampleViews> views;
  return ScoreAll(sources, target, options, &views);
}

std::vector<int> SelectSources(const std::vector<PosedCamera>& sources, const PosedCamera& target,
                               const SourceSelectionOptions& options) {
  std::vector<SampleViews> views;
  const std::vector<SourceScore> scores = ScoreAll(sources, target, options, &views);
  std::vector<int> candidates;
  for (const SourceScore& score : scores) {
    if (score.overlap >= options.min_overlap) candidates.push_back(score.index);
  }
  const size_t samples = views.empty() ? 0 : views.front().seen.size();
  // Per sample, how much of it the chosen sources already see from each direction: the
  // largest similarity exp(-(angle / diversity_angle)^2) to the chosen sources' rays.
  const double sigma_rad = options.diversity_angle_deg * std::numbers::pi / 180;
  std::vector<int> chosen;
  while (static_cast<int>(chosen.size()) < options.num_sources && !candidates.empty()) {
    double best_gain = -1;
    size_t best = 0;
    for (size_t c = 0; c < candidates.size(); ++c) {
      const SampleViews& view = views[static_cast<size_t>(candidates[c])];
      double gain = 0;
      for (size_t p = 0; p < samples; ++p) {
        if (view.seen[p] == 0) continue;
        double covered = 0;
        for (int other : chosen) {
          const SampleViews& o = views[static_cast<size_t>(other)];
          if (o.seen[p] == 0 || sigma_rad <= 0) continue;
          const double angle = std::acos(std::clamp(
              static_cast<double>(view.to_source[p].dot(o.to_source[p])), -1.0, 1.0));
          covered = std::max(covered, std::exp(-(angle / sigma_rad) * (angle / sigma_rad)));
        }
        gain += static_cast<double>(view.quality[p]) * (1 - covered);
      }
      // Ties (and diversity 0, where every gain is the plain score) keep the score order.
      const double key = sigma_rad > 0 ? gain : scores[static_cast<size_t>(candidates[c])].score;
      if (key > best_gain) {
        best_gain = key;
        best = c;
      }
    }
    chosen.push_back(candidates[best]);
    candidates.erase(candidates.begin() + static_cast<std::ptrdiff_t>(best));
  }
  return chosen;
}

int SourceSeeingMost(const std::vector<PosedCamera>& sources, const PosedCamera& target,
                     const std::vector<Eigen::Vector3d>& points, const std::vector<int>& exclude,
                     int min_points, const SourceSelectionOptions& options) {
  options.Check();
  const Eigen::Vector3d target_center = CameraCenter(target.cam_from_world);
  int best = -1;
  double best_score = 0;
  for (size_t i = 0; i < sources.size(); ++i) {
    if (std::find(exclude.begin(), exclude.end(), static_cast<int>(i)) != exclude.end()) continue;
    const Pinhole s = Pinhole::From(sources[i].camera);
    const Rigid3d& cam_from_world = sources[i].cam_from_world;
    const Eigen::Vector3d target_center_in_source = cam_from_world * target_center;
    int inside = 0;
    double score = 0;
    for (const Eigen::Vector3d& point : points) {
      const std::optional<double> angle_deg =
          SeenAngleDeg(s, cam_from_world * point, target_center_in_source);
      if (!angle_deg) continue;
      ++inside;
      score += ViewQuality(*angle_deg, options);
    }
    if (inside >= min_points && score > best_score) {
      best_score = score;
      best = static_cast<int>(i);
    }
  }
  return best;
}

}  // namespace parallax
