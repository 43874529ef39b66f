#pragma once
// Measures reconstructed cameras against ground truth: images matched by name, a similarity
// alignment (geometry/similarity.h), then rotation and camera-centre errors (docs/design.md
// "evaluate's JSON", section "poses").
#include <string>
#include <vector>

#include <nlohmann/json_fwd.hpp>

#include "core/sparse_model.h"
#include "geometry/similarity.h"

namespace parallax {

struct ImagePoseError {
  std::string name;
  double rotation_error_deg = 0;
  double center_error_rel = 0;  // Relative to the ground-truth extent.
};

// `estimate` (a camera's pose in the reconstruction) taken into the truth's frame by `alignment`
// and compared with `truth`; the centre error relative to `extent`.
ImagePoseError PoseError(const std::string& name, const Rigid3d& estimate, const Rigid3d& truth,
                         const Similarity3d& alignment, double extent);

struct PoseEvaluation {
  int registered = 0;  // Ground-truth images present in the reconstruction.
  int total = 0;       // Ground-truth images.
  double rotation_error_mean_deg = 0;
  double rotation_error_median_deg = 0;
  double rotation_error_max_deg = 0;
  double center_error_rel_mean = 0;
  double center_error_rel_max = 0;
  double reprojection_error_px = 0;  // Mean over the reconstruction's 3D points.
  double extent = 0;                 // Largest distance between two ground-truth centres.
  AlignmentResult alignment;         // Ground truth from reconstruction.
  std::vector<ImagePoseError> images;
  std::vector<std::string> missing;  // Ground-truth images the reconstruction lacks.
};

// Throws BadInputError when fewer than 3 images are shared by name (nothing to align).
PoseEvaluation EvaluatePoses(const SparseModel& estimate, const SparseModel& ground_truth);

// The "poses" and "alignment" sections of evaluate's JSON.
void AddPoseSections(const PoseEvaluation& evaluation, nlohmann::json& json);

}  // namespace parallax
