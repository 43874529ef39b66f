#include "pipeline/plausibility.h"

#include <algorithm>
#include <cmath>
#include <cstdarg>
#include <cstdio>
#include <numbers>
#include <stdexcept>
#include <unordered_map>

namespace parallax {
namespace {

constexpr size_t kMaxTrackForAngles = 16;

__attribute__((format(printf, 1, 2))) std::string Format(const char* format, ...) {
  char text[256];
  va_list arguments;
  va_start(arguments, format);
  std::vsnprintf(text, sizeof(text), format, arguments);
  va_end(arguments);
  return text;
}

double Median(std::vector<double> values) {
  if (values.empty()) return 0;
  const auto middle = values.begin() + static_cast<std::ptrdiff_t>(values.size() / 2);
  std::nth_element(values.begin(), middle, values.end());
  return *middle;
}

}  // namespace

void PlausibilityOptions::Check() const {
  if (!(max_focal_ratio_exif > 1)) throw std::invalid_argument("max_focal_ratio_exif must be > 1");
  if (!(max_focal_ratio_default > 1)) {
    throw std::invalid_argument("max_focal_ratio_default must be > 1");
  }
  if (!(min_focal_ratio_default > 0 && min_focal_ratio_default < 1)) {
    throw std::invalid_argument("min_focal_ratio_default must be in (0, 1)");
  }
  if (!(well_triangulated_deg > 0)) throw std::invalid_argument("well_triangulated_deg must be > 0");
  if (!(max_principal_point_offset > 0)) {
    throw std::invalid_argument("max_principal_point_offset must be > 0");
  }
  if (min_points_per_image < 1) throw std::invalid_argument("min_points_per_image must be >= 1");
}

double PrincipalPointOffset(const Camera& camera) {
  return std::max(std::abs(camera.PrincipalX() / static_cast<double>(camera.width) - 0.5),
                  std::abs(camera.PrincipalY() / static_cast<double>(camera.height) - 0.5));
}

std::vector<double> TriangulationAnglesDeg(const SparseModel& model) {
  std::unordered_map<uint32_t, Eigen::Vector3d> centers;
  for (const SparseImage& image : model.Images()) {
    centers[image.id] = CameraCenter(image.cam_from_world);
  }
  std::vector<double> angles;
  angles.reserve(model.Points3D().size());
  for (const Point3D& point : model.Points3D()) {
    const size_t n = std::min(point.track.size(), kMaxTrackForAngles);
    double best = 0;
    for (size_t i = 0; i < n; ++i) {
      const Eigen::Vector3d ray_i = (centers.at(point.track[i].image_id) - point.xyz).normalized();
      for (size_t j = i + 1; j < n; ++j) {
        const Eigen::Vector3d ray_j =
            (centers.at(point.track[j].image_id) - point.xyz).normalized();
        // atan2 of |cross| and dot is accurate for the small angles this check is about.
        best = std::max(best, std::atan2(ray_i.cross(ray_j).norm(), ray_i.dot(ray_j)));
      }
    }
    angles.push_back(best * 180 / std::numbers::pi);
  }
  return angles;
}

PlausibilityReport CheckPlausibility(const SparseModel& model, double focal_prior_px,
                                     bool prior_from_exif, const PlausibilityOptions& options) {
  options.Check();
  PlausibilityReport report;
  report.focal_prior_px = focal_prior_px;
  report.prior_from_exif = prior_from_exif;
  if (model.Cameras().empty() || model.Images().empty()) {
    report.problems.push_back("the model has no cameras or no registered images");
    return report;
  }
  double focal_sum = 0;
  for (const Camera& camera : model.Cameras()) focal_sum += 0.5 * (camera.FocalX() + camera.FocalY());
  report.focal_px = focal_sum / static_cast<double>(model.Cameras().size());
  const double ratio = report.focal_px / focal_prior_px;
  const double low = prior_from_exif ? 1 / options.max_focal_ratio_exif : options.min_focal_ratio_default;
  const double high = prior_from_exif ? options.max_focal_ratio_exif : options.max_focal_ratio_default;
  if (!(ratio >= low && ratio <= high)) {
    report.problems.push_back(Format(
        "estimated focal length %.1f px is %.2fx its prior %.1f px", report.focal_px, ratio,
        focal_prior_px) + (prior_from_exif ? " (from EXIF)" : " (from the image size)"));
  }

  for (const Camera& camera : model.Cameras()) {
    const double offset = PrincipalPointOffset(camera);
    if (offset > options.max_principal_point_offset) {
      report.problems.push_back(Format(
          "camera %u: principal point (%.1f, %.1f) is %.0f%% of the image size off-centre",
          camera.id, camera.PrincipalX(), camera.PrincipalY(), 100 * offset));
    }
  }

  const std::vector<double> angles = TriangulationAnglesDeg(model);
  report.median_triangulation_deg = Median(angles);
  if (angles.empty()) {
    report.problems.push_back("no 3D points were triangulated");
  } else if (report.median_triangulation_deg < options.min_median_triangulation_deg) {
    report.problems.push_back(Format(
        "median triangulation angle %.2f deg is below %.1f deg: the baseline is too small "
        "for reliable depth and focal length", report.median_triangulation_deg,
        options.min_median_triangulation_deg));
  }

  std::unordered_map<uint32_t, int> well_triangulated_per_image;
  for (size_t i = 0; i < angles.size(); ++i) {
    if (angles[i] < options.well_triangulated_deg) continue;
    for (const TrackElement& element : model.Points3D()[i].track) {
      ++well_triangulated_per_image[element.image_id];
    }
  }
  int constrained = 0;
  for (const SparseImage& image : model.Images()) {
    constrained += well_triangulated_per_image[image.id] >= options.min_points_per_image;
  }
  report.well_constrained_image_share =
      static_cast<double>(constrained) / static_cast<double>(model.Images().size());
  if (report.well_constrained_image_share < options.min_well_constrained_share) {
    report.problems.push_back(Format(
        "only %.0f%% of the registered images see %d or more well-triangulated points "
        "(angle >= %.1f deg)", 100 * report.well_constrained_image_share,
        options.min_points_per_image, options.well_triangulated_deg));
  }
  return report;
}

}  // namespace parallax
