#include "sfm/plausibility.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdarg>
#include <cstdio>
#include <numbers>
#include <numeric>
#include <optional>
#include <thread>
#include <unordered_map>
#include <unordered_set>

#include <ceres/ceres.h>

#include "core/error.h"
#include "core/statistics.h"
#include "core/check.h"
#include "sfm/reprojection_residual.h"

namespace parallax {
namespace {

constexpr size_t kMaxTrackForAngles = 16;
// The focal test uses at most this many observations of each point, and this many solver
// iterations: a solve cut short only overstates the error of a wrong focal length (the start
// is already a solution when the focal length is free), so it never hides a problem.
constexpr size_t kMaxTrackForFocalTest = 16;
constexpr int kFocalTestIterations = 25;

__attribute__((format(printf, 1, 2))) std::string Format(const char* format, ...) {
  char text[512];
  va_list arguments;
  va_start(arguments, format);
  std::vsnprintf(text, sizeof(text), format, arguments);
  va_end(arguments);
  return text;
}

// Focal length parameters, then principal point: the parameters the focal test holds.
int NumHeldParams(CameraModel model) {
  return model == CameraModel::kPinhole || model == CameraModel::kOpenCV ? 4 : 3;
}

// `camera` with its focal length scaled by `factor` and its distortion rewritten for
// normalised coordinates divided by `factor` (radial terms of degree 2n scale by factor^2n,
// tangential ones by factor), so the image of the scaled scene is unchanged.
std::vector<double> ScaledIntrinsics(const Camera& camera, double factor) {
  std::vector<double> params = camera.params;
  const double f2 = factor * factor;
  switch (camera.model) {
    case CameraModel::kSimplePinhole: params[0] *= factor; break;
    case CameraModel::kPinhole: params[0] *= factor; params[1] *= factor; break;
    case CameraModel::kSimpleRadial: params[0] *= factor; params[3] *= f2; break;
    case CameraModel::kRadial: params[0] *= factor; params[3] *= f2; params[4] *= f2 * f2; break;
    case CameraModel::kOpenCV:
      params[0] *= factor; params[1] *= factor;
      params[4] *= f2; params[5] *= f2 * f2; params[6] *= factor; params[7] *= factor;
      break;
    default: break;  // Excluded by the caller (no projection).
  }
  return params;
}

// One observation: parameter blocks cam_from_world rotation (w, x, y, z), translation,
// point, camera parameters.
struct ReprojectionResidual {
  Camera camera;
  Eigen::Vector2d observed;

  bool operator()(double const* const* blocks, double* residual) const {
    Camera scratch = camera;
    std::copy(blocks[3], blocks[3] + scratch.params.size(), scratch.params.begin());
    ProjectionResidual(scratch, blocks[0], blocks[1], blocks[2], observed, residual);
    return true;
  }
};

std::vector<size_t> FocalTestPoints(const SparseModel& model, int max_points) {
  std::vector<size_t> usable;
  for (size_t i = 0; i < model.Points3D().size(); ++i) {
    if (model.Points3D()[i].track.size() >= 2) usable.push_back(i);
  }
  const size_t stride = std::max<size_t>(1, (usable.size() + static_cast<size_t>(max_points) - 1) /
                                                static_cast<size_t>(max_points));
  std::vector<size_t> chosen;
  for (size_t i = 0; i < usable.size(); i += stride) chosen.push_back(usable[i]);
  return chosen;
}

double RmsReprojectionError(const SparseModel& model, const std::vector<size_t>& points) {
  double sum = 0;
  size_t count = 0;
  for (const size_t index : points) {
    const Point3D& point = model.Points3D()[index];
    for (size_t k = 0; k < std::min(point.track.size(), kMaxTrackForFocalTest); ++k) {
      const TrackElement& element = point.track[k];
      const SparseImage& image = model.ImageById(element.image_id);
      const std::optional<Eigen::Vector2d> pixel =
          model.CameraById(image.camera_id).Project(image.cam_from_world * point.xyz);
      const Eigen::Vector2d& observed = image.points2d.at(element.point2d_idx).xy;
      sum += pixel ? (*pixel - observed).squaredNorm()
                   : 2 * kUnprojectableResidualPx * kUnprojectableResidualPx;
      ++count;
    }
  }
  return count == 0 ? 0 : std::sqrt(sum / static_cast<double>(count));
}

// Holds each camera's focal length and principal point (NumHeldParams) in `problem`; the
// distortion parameters stay free.
void HoldFocalParameters(const SparseModel& model,
                         std::unordered_map<uint32_t, std::vector<double>>& intrinsics,
                         ceres::Problem& problem) {
  for (const Camera& camera : model.Cameras()) {
    double* block = intrinsics.at(camera.id).data();
    if (!problem.HasParameterBlock(block)) continue;
    const int held = NumHeldParams(camera.model);
    const int size = static_cast<int>(camera.params.size());
    if (held == size) {
      problem.SetParameterBlockConstant(block);
    } else {
      std::vector<int> constant(static_cast<size_t>(held));
      std::iota(constant.begin(), constant.end(), 0);
      problem.SetManifold(block, new ceres::SubsetManifold(size, constant));
    }
  }
}

// The RMS reprojection error (px) after solving `problem` of `residuals` 2D residuals.
double SolvedRms(ceres::Problem& problem, size_t residuals) {
  ceres::Solver::Options options;
  options.linear_solver_type = ceres::SPARSE_SCHUR;
  options.max_num_iterations = kFocalTestIterations;
  options.num_threads = static_cast<int>(std::max(1u, std::thread::hardware_concurrency()));
  options.logging_type = ceres::SILENT;
  ceres::Solver::Summary summary;
  ceres::Solve(options, &problem, &summary);
  const double rms_after = std::sqrt(2 * summary.final_cost / static_cast<double>(residuals));
  return rms_after;
}

}  // namespace

double FocalRmsRatio(const SparseModel& model, double factor, int max_points) {
  if (!(factor > 0) || max_points < 1) {
    throw InternalError("FocalRmsRatio: factor must be > 0 and max_points >= 1");
  }
  for (const Camera& camera : model.Cameras()) {
    if (!IsProjectionSupported(camera.model)) return 0;
  }
  const std::vector<size_t> points = FocalTestPoints(model, max_points);
  if (points.empty() || model.Images().empty()) return 0;
  const double rms_before = RmsReprojectionError(model, points);

  // Start from the exact ambiguity of pure translation: in the frame of the first camera,
  // divide lateral coordinates by `factor` and keep depth; with every camera oriented like the
  // first, the images are unchanged and the solver has nothing to do.
  const Eigen::Matrix3d reference =
      model.Images().front().cam_from_world.rotation.toRotationMatrix();
  const Eigen::Matrix3d squeeze =
      reference.transpose() * Eigen::Vector3d(1 / factor, 1 / factor, 1).asDiagonal() * reference;
  std::unordered_map<uint32_t, std::vector<double>> intrinsics;
  for (const Camera& camera : model.Cameras()) {
    intrinsics[camera.id] = ScaledIntrinsics(camera, factor);
  }
  std::unordered_map<uint32_t, std::array<double, 7>> poses;  // w, x, y, z, t.
  for (const SparseImage& image : model.Images()) {
    const Eigen::Quaterniond& rotation = image.cam_from_world.rotation;
    const Eigen::Vector3d translation = -(rotation * (squeeze * CameraCenter(image.cam_from_world)));
    poses[image.id] = {rotation.w(), rotation.x(), rotation.y(), rotation.z(),
                       translation.x(), translation.y(), translation.z()};
  }
  std::vector<Eigen::Vector3d> xyz;
  xyz.reserve(points.size());
  for (const size_t index : points) xyz.push_back(squeeze * model.Points3D()[index].xyz);

  ceres::Problem problem;
  std::unordered_set<uint32_t> images_used;
  uint32_t gauge_image = 0;
  size_t residuals = 0;
  for (size_t p = 0; p < points.size(); ++p) {
    const std::vector<TrackElement>& track = model.Points3D()[points[p]].track;
    for (size_t k = 0; k < std::min(track.size(), kMaxTrackForFocalTest); ++k) {
      const TrackElement& element = track[k];
      const SparseImage& image = model.ImageById(element.image_id);
      const Camera& camera = model.CameraById(image.camera_id);
      auto* cost = new ceres::DynamicNumericDiffCostFunction<ReprojectionResidual, ceres::CENTRAL>(
          new ReprojectionResidual{camera, image.points2d.at(element.point2d_idx).xy});
      cost->AddParameterBlock(4);
      cost->AddParameterBlock(3);
      cost->AddParameterBlock(3);
      cost->AddParameterBlock(static_cast<int>(camera.params.size()));
      cost->SetNumResiduals(2);
      std::array<double, 7>& pose = poses.at(image.id);
      problem.AddResidualBlock(cost, nullptr,
                               {pose.data(), pose.data() + 4, xyz[p].data(),
                                intrinsics.at(camera.id).data()});
      if (images_used.empty()) gauge_image = image.id;
      images_used.insert(image.id);
      ++residuals;
    }
  }
  for (const uint32_t id : images_used) {
    problem.SetManifold(poses.at(id).data(), new ceres::QuaternionManifold);
  }
  HoldFocalParameters(model, intrinsics, problem);
  // Gauge: one camera held; the scale stays free (the damping copes with that direction).
  problem.SetParameterBlockConstant(poses.at(gauge_image).data());
  problem.SetParameterBlockConstant(poses.at(gauge_image).data() + 4);

  const double rms_after = SolvedRms(problem, residuals);
  return rms_after / std::max(rms_before, 1e-9);
}

void PlausibilityOptions::Check() const {
  RequireOption(max_focal_ratio_exif > 1, "PlausibilityOptions.max_focal_ratio_exif", max_focal_ratio_exif, "> 1");
  RequireOption(max_focal_ratio_default > 1, "PlausibilityOptions.max_focal_ratio_default",
                max_focal_ratio_default, "> 1");
  RequireOption(min_focal_ratio_default > 0 && min_focal_ratio_default < 1,
                "PlausibilityOptions.min_focal_ratio_default", min_focal_ratio_default, "(0, 1)");
  RequireOption(well_triangulated_deg > 0, "PlausibilityOptions.well_triangulated_deg", well_triangulated_deg,
                "> 0");
  RequireOption(max_principal_point_offset > 0, "PlausibilityOptions.max_principal_point_offset",
                max_principal_point_offset, "> 0");
  RequireOption(min_points_per_image >= 1, "PlausibilityOptions.min_points_per_image", min_points_per_image,
                ">= 1");
  RequireOption(focal_test_factor > 1, "PlausibilityOptions.focal_test_factor", focal_test_factor, "> 1");
  RequireOption(min_focal_rms_ratio > 1, "PlausibilityOptions.min_focal_rms_ratio", min_focal_rms_ratio, "> 1");
  RequireOption(focal_test_max_points >= 1, "PlausibilityOptions.focal_test_max_points", focal_test_max_points,
                ">= 1");
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

  if (!prior_from_exif) {
    // Without EXIF the prior is a guess, and a focal length the photos do not determine stays
    // wherever COLMAP's drift left it: 1.5-7x wrong at 0.1 px error on telephoto slider
    // captures (tests/stability/sfm_stability_test.cc), inside the range allowed above.
    report.focal_rms_ratio =
        std::min(FocalRmsRatio(model, options.focal_test_factor, options.focal_test_max_points),
                 FocalRmsRatio(model, 1 / options.focal_test_factor, options.focal_test_max_points));
    if (report.focal_rms_ratio > 0 && report.focal_rms_ratio < options.min_focal_rms_ratio) {
      report.problems.push_back(Format(
          "estimated focal length %.1f px is not determined by the photos: held at %gx or "
          "1/%gx that, the model fits them with %.2fx the reprojection error (the cameras "
          "barely rotate relative to each other: a slider or a tiny baseline)", report.focal_px,
          options.focal_test_factor, options.focal_test_factor, report.focal_rms_ratio));
    }
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
  report.median_triangulation_deg = UpperMedian(angles);
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
