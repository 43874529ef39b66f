#pragma once
// How well a model fitted without some photos predicts them: cross-validation by photos. Each
// left-out photo keeps only its pose free (refitted to its observations of the model's points,
// the model's camera held), so what the model learned from the other photos (points, focal
// length, principal point, distortion) is judged on photos it has not seen. A principal point
// that only trades against the rotations along a narrow arc fits the photos it was adjusted on
// and predicts the others no better than the centre does; one the photos determine predicts
// them better (docs/cameras.md, "The principal point by prediction").
#include <string>
#include <vector>

#include <Eigen/Core>

#include "core/camera.h"
#include "core/pose.h"
#include "core/sparse_model.h"

namespace parallax {

// `start` refitted so that `camera` projects `points` onto `pixels` (Cauchy loss of scale
// `loss_px`: the keypoints of a raw model still hold mismatches, and a Cauchy loss all but
// ignores them where a Huber loss would still be pulled); `start` where fewer than three points
// project.
Rigid3d ResectPose(const Camera& camera, const std::vector<Eigen::Vector3d>& points,
                   const std::vector<Eigen::Vector2d>& pixels, const Rigid3d& start, double loss_px);

// The left-out photos' reprojection error: each photo named in `names` of `raw` (poses, keypoints
// and their point ids) refitted by ResectPose to its observations of the points `fitted` still
// has (same ids), with `fitted`'s camera; each residual clipped at `clip_px` so that mismatches
// count as much as an error of `clip_px` and no more; the RMS over every observation. Throws
// InternalError for a name `raw` does not have.
struct LeftOutError {
  double rms_px = 0;
  size_t observations = 0;
};
LeftOutError LeftOutPhotoError(const SparseModel& fitted, const SparseModel& raw, const std::vector<std::string>& names,
                               double clip_px);

}  // namespace parallax
