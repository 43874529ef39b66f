#include "eval/cloud_evaluation.h"

#include <algorithm>
#include <cmath>
#include <limits>

#include <tbb/parallel_for.h>

#include "core/depth_map.h"

namespace parallax {

CloudAccuracy MeasureCloud(const std::vector<Eigen::Vector3f>& points,
                           const SparseModel& truth_model,
                           const std::filesystem::path& truth_depth_dir,
                           const Similarity3d& truth_from_estimate) {
  struct TruthView {
    const Camera* camera;
    Rigid3d cam_from_world;
    DepthMap depth;
  };
  std::vector<TruthView> views;
  for (const SparseImage& image : truth_model.Images()) {
    const auto path = truth_depth_dir / (std::filesystem::path(image.name).stem().string() + ".exr");
    if (!std::filesystem::exists(path)) continue;
    views.push_back({&truth_model.CameraById(image.camera_id), image.cam_from_world, ReadDepthExr(path)});
  }
  const double kUnmeasured = std::numeric_limits<double>::infinity();
  std::vector<double> distances(points.size(), kUnmeasured);
  tbb::parallel_for(size_t{0}, points.size(), [&](size_t i) {
    const Eigen::Vector3d world = truth_from_estimate * points[i].cast<double>();
    for (const TruthView& view : views) {
      const Eigen::Vector3d in_cam = view.cam_from_world * world;
      const std::optional<Eigen::Vector2d> pixel = view.camera->Project(in_cam);
      if (!pixel) continue;
      const int x = static_cast<int>(std::floor(pixel->x())), y = static_cast<int>(std::floor(pixel->y()));
      if (x < 0 || y < 0 || x >= view.depth.Width() || y >= view.depth.Height()) continue;
      const double truth = view.depth.At(x, y);
      if (!(truth > 0) || in_cam.z() > truth * 1.05) continue;
      distances[i] = std::min(distances[i], std::abs(in_cam.z() - truth) / truth);
    }
  });
  CloudAccuracy accuracy;
  accuracy.points = points.size();
  std::vector<double> measured;
  for (const double distance : distances) {
    if (distance != kUnmeasured) measured.push_back(distance);
  }
  accuracy.measured = measured.size();
  if (measured.empty()) return accuracy;
  std::sort(measured.begin(), measured.end());
  accuracy.median_relative_distance = measured[measured.size() / 2];
  accuracy.within_1pct =
      static_cast<double>(std::lower_bound(measured.begin(), measured.end(), 0.01) - measured.begin()) /
      static_cast<double>(measured.size());
  return accuracy;
}

}  // namespace parallax
