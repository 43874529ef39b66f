#include "mvs/view_selection.h"

#include <algorithm>
#include <cmath>
#include <map>
#include <numbers>
#include <stdexcept>
#include <unordered_map>

#include "core/check.h"

namespace parallax {

void ViewSelectionOptions::Check() const {
  RequireOption(max_sources >= 1 && max_sources <= 16, "ViewSelectionOptions.max_sources", max_sources, "[1, 16]");
  RequireOption(min_shared_points >= 1, "ViewSelectionOptions.min_shared_points", min_shared_points, ">= 1");
  RequireOption(good_triangulation_deg > 0, "ViewSelectionOptions.good_triangulation_deg", good_triangulation_deg,
                "> 0");
  RequireOption(max_triangulation_deg > good_triangulation_deg, "ViewSelectionOptions.max_triangulation_deg",
                max_triangulation_deg, "> good_triangulation_deg");
  RequireOption(depth_margin >= 0 && depth_margin < 1, "ViewSelectionOptions.depth_margin", depth_margin, "[0, 1)");
}

std::vector<ViewPlan> PlanViews(const SparseModel& model, const ViewSelectionOptions& options) {
  options.Check();
  std::unordered_map<uint32_t, Eigen::Vector3d> centers;
  for (const SparseImage& image : model.Images()) {
    centers[image.id] = CameraCenter(image.cam_from_world);
  }
  // For every ordered pair: shared points and their angle-weighted score.
  std::map<uint32_t, std::map<uint32_t, std::pair<int, double>>> pairs;
  std::unordered_map<uint32_t, std::vector<double>> depths;
  for (const Point3D& point : model.Points3D()) {
    for (const TrackElement& a : point.track) {
      const SparseImage& image = model.ImageById(a.image_id);
      const double z = (image.cam_from_world * point.xyz).z();
      if (z > 0) depths[a.image_id].push_back(z);
      const Eigen::Vector3d ray_a = (centers.at(a.image_id) - point.xyz).normalized();
      for (const TrackElement& b : point.track) {
        if (b.image_id == a.image_id) continue;
        const Eigen::Vector3d ray_b = (centers.at(b.image_id) - point.xyz).normalized();
        const double angle_deg =
            std::atan2(ray_a.cross(ray_b).norm(), ray_a.dot(ray_b)) * 180 / std::numbers::pi;
        auto& [shared, score] = pairs[a.image_id][b.image_id];
        ++shared;
        if (angle_deg <= options.max_triangulation_deg) {
          score += std::min(1.0, angle_deg / options.good_triangulation_deg);
        }
      }
    }
  }
  std::vector<ViewPlan> plans;
  for (const SparseImage& image : model.Images()) {
    std::vector<double>& z = depths[image.id];
    if (z.size() < 3) continue;
    std::vector<std::pair<double, uint32_t>> ranked;
    for (const auto& [other, counts] : pairs[image.id]) {
      if (counts.first >= options.min_shared_points && counts.second > 0) {
        ranked.emplace_back(-counts.second, other);  // Best score first, then lowest id.
      }
    }
    if (ranked.empty()) continue;
    std::sort(ranked.begin(), ranked.end());
    ViewPlan plan;
    plan.image_id = image.id;
    plan.name = image.name;
    for (size_t i = 0; i < ranked.size() && static_cast<int>(i) < options.max_sources; ++i) {
      plan.sources.push_back(ranked[i].second);
    }
    // Robust extremes (1st and 99th percentile), widened in inverse depth.
    std::sort(z.begin(), z.end());
    const double near = z[z.size() / 100];
    const double far = z[z.size() - 1 - z.size() / 100];
    // Background often lies beyond every sparse point (far ground, walls): the far end is
    // doubled as well, which costs little in inverse depth.
    plan.min_depth = near * (1 - options.depth_margin);
    plan.max_depth = 2 * far / (1 - options.depth_margin);
    plans.push_back(std::move(plan));
  }
  return plans;
}

}  // namespace parallax
