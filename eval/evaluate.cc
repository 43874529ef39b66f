#include "eval/evaluate.h"

#include <algorithm>

#include <nlohmann/json.hpp>

#include "core/error.h"

namespace parallax {

ImagePoseError PoseError(const std::string& name, const Rigid3d& estimate, const Rigid3d& truth,
                         const Similarity3d& alignment, double extent) {
  const Rigid3d aligned = alignment.TransformPose(estimate);
  return {name, RotationAngleDeg(aligned.rotation, truth.rotation),
          (CameraCenter(aligned) - CameraCenter(truth)).norm() / extent};
}

PoseEvaluation EvaluatePoses(const SparseModel& estimate, const SparseModel& ground_truth) {
  PoseEvaluation evaluation;
  evaluation.total = static_cast<int>(ground_truth.Images().size());
  std::vector<Rigid3d> estimated_cams, true_cams;
  std::vector<std::string> names;
  for (const SparseImage& truth : ground_truth.Images()) {
    const SparseImage* found = estimate.FindImageByName(truth.name);
    if (!found) {
      evaluation.missing.push_back(truth.name);
      continue;
    }
    estimated_cams.push_back(found->cam_from_world);
    true_cams.push_back(truth.cam_from_world);
    names.push_back(truth.name);
  }
  evaluation.registered = static_cast<int>(names.size());
  if (names.size() < 3) {
    throw BadInputError("only " + std::to_string(names.size()) +
                        " reconstructed images match ground-truth images by name; at least 3 "
                        "are needed to align the two");
  }
  evaluation.alignment = AlignSimilarity(estimated_cams, true_cams);
  for (const Rigid3d& a : true_cams) {
    for (const Rigid3d& b : true_cams) {
      evaluation.extent = std::max(evaluation.extent, (CameraCenter(a) - CameraCenter(b)).norm());
    }
  }
  std::vector<double> rotation_errors;
  for (size_t i = 0; i < names.size(); ++i) {
    const ImagePoseError error = PoseError(names[i], estimated_cams[i], true_cams[i],
                                           evaluation.alignment.target_from_source, evaluation.extent);
    evaluation.rotation_error_mean_deg += error.rotation_error_deg / static_cast<double>(names.size());
    evaluation.center_error_rel_mean += error.center_error_rel / static_cast<double>(names.size());
    evaluation.rotation_error_max_deg = std::max(evaluation.rotation_error_max_deg, error.rotation_error_deg);
    evaluation.center_error_rel_max = std::max(evaluation.center_error_rel_max, error.center_error_rel);
    rotation_errors.push_back(error.rotation_error_deg);
    evaluation.images.push_back(error);
  }
  std::sort(rotation_errors.begin(), rotation_errors.end());
  const size_t n = rotation_errors.size();
  evaluation.rotation_error_median_deg =
      n % 2 ? rotation_errors[n / 2] : 0.5 * (rotation_errors[n / 2 - 1] + rotation_errors[n / 2]);
  double error_sum = 0;
  for (const Point3D& point : estimate.Points3D()) error_sum += std::max(0.0, point.error);
  evaluation.reprojection_error_px =
      estimate.Points3D().empty() ? 0 : error_sum / static_cast<double>(estimate.Points3D().size());
  return evaluation;
}

void AddPoseSections(const PoseEvaluation& evaluation, nlohmann::json& json) {
  json["poses"] = {
      {"registered", evaluation.registered},
      {"total", evaluation.total},
      {"rotation_error_deg",
       {{"mean", evaluation.rotation_error_mean_deg},
        {"median", evaluation.rotation_error_median_deg},
        {"max", evaluation.rotation_error_max_deg}}},
      {"center_error_rel",
       {{"mean", evaluation.center_error_rel_mean}, {"max", evaluation.center_error_rel_max}}},
      {"reprojection_error_px", evaluation.reprojection_error_px}};
  json["alignment"] = {{"scale", evaluation.alignment.target_from_source.scale},
                       {"inliers", evaluation.alignment.inliers}};
}

}  // namespace parallax
