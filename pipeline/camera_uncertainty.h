#pragma once
// How well the photos determine the cameras, by the jackknife over folds of the photos: the
// principal point's check (sfm_policy.h) adjusts the model once without each fold, and how far
// the focal length, the principal point and each photo's rotation move from one such adjustment
// to the next, times (K - 1) / K, is the variance of the whole's. Unlike the adjustment's
// covariance it sees what the keypoints' noise model does not: a photo held by a few weak
// matches, a principal point that trades against the rotations. report.json's
// `camera_uncertainty` (docs/cameras.md, "The cameras' uncertainty").
#include <filesystem>
#include <string>
#include <utility>
#include <vector>

#include <nlohmann/json.hpp>

#include "core/sparse_model.h"

namespace parallax {

struct CameraUncertainty {
  int folds = 0;
  // Standard deviations: the focal length's and the principal point's per axis (pixels) of the
  // first camera, and each photo's rotation (degrees, the angle's RMS over the three axes).
  double focal_px = 0;
  double principal_point_px = 0;
  std::vector<std::pair<std::string, double>> rotation_deg;  // In name order.
};

// The uncertainty of `whole`'s cameras from `folds`, each `whole` adjusted without some of its
// photos (cameras and poses; the folds' frames are aligned to the whole's by the photos they
// share). Throws InternalError for fewer than two folds.
CameraUncertainty JackknifeUncertainty(const SparseModel& whole, const std::vector<SparseModel>& folds);

// report.json's `camera_uncertainty`: {"folds", "focal_px", "principal_point_px",
// "rotation_deg": {"median", "max", "max_photo", "photos": {name: deg}}}.
nlohmann::json ToJson(const CameraUncertainty& uncertainty);

// ToJson's object in a file (written to a temporary name and renamed), and back: throws
// BadInputError naming the file where it holds something else.
void WriteCameraUncertainty(const CameraUncertainty& uncertainty, const std::filesystem::path& path);
CameraUncertainty ReadCameraUncertainty(const std::filesystem::path& path);

// The sentence report.json's notes give it.
std::string Describe(const CameraUncertainty& uncertainty);

}  // namespace parallax
