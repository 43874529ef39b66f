#include "pipeline/camera_uncertainty.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <map>

#include <Eigen/Geometry>

#include "core/atomic_file.h"
#include "core/error.h"
#include "core/statistics.h"
#include "geometry/similarity.h"

namespace parallax {
namespace {

// The standard deviation of the whole's estimate from the fold estimates `values` (per
// component, RMS over the components), the jackknife's (K - 1) / K times their scatter.
template <typename Vector>
double JackknifeDeviation(const std::vector<Vector>& values, size_t num_folds) {
  if (values.size() < 2) return 0;
  Vector mean = Vector::Zero();
  for (const Vector& value : values) mean += value;
  mean /= static_cast<double>(values.size());
  double squares = 0;
  for (const Vector& value : values) squares += (value - mean).squaredNorm();
  const double k = static_cast<double>(num_folds);
  return std::sqrt((k - 1) / k * squares / static_cast<double>(Vector::RowsAtCompileTime));
}

// `fold`'s poses in `whole`'s frame, by the photos both have: name -> cam_from_world.
std::map<std::string, Rigid3d> AlignedPoses(const SparseModel& fold, const SparseModel& whole) {
  std::vector<Rigid3d> source, target;
  std::vector<std::string> names;
  for (const SparseImage& image : fold.Images()) {
    const SparseImage* same = whole.FindImageByName(image.name);
    if (same == nullptr) continue;
    source.push_back(image.cam_from_world);
    target.push_back(same->cam_from_world);
    names.push_back(image.name);
  }
  std::map<std::string, Rigid3d> aligned;
  if (names.size() < 3) return aligned;
  const Similarity3d whole_from_fold = AlignSimilarity(source, target).target_from_source;
  for (size_t i = 0; i < names.size(); ++i) aligned[names[i]] = whole_from_fold.TransformPose(source[i]);
  return aligned;
}

}  // namespace

CameraUncertainty JackknifeUncertainty(const SparseModel& whole, const std::vector<SparseModel>& folds) {
  if (folds.size() < 2) throw InternalError("JackknifeUncertainty needs two folds or more");
  CameraUncertainty uncertainty;
  uncertainty.folds = static_cast<int>(folds.size());
  if (!whole.Cameras().empty()) {
    const uint32_t id = whole.Cameras().front().id;
    std::vector<Eigen::Matrix<double, 1, 1>> focal;
    std::vector<Eigen::Vector2d> principal_point;
    for (const SparseModel& fold : folds) {
      if (!fold.HasCamera(id)) continue;
      const Camera& camera = fold.CameraById(id);
      focal.push_back(Eigen::Matrix<double, 1, 1>(camera.FocalX()));
      principal_point.push_back({camera.PrincipalX(), camera.PrincipalY()});
    }
    uncertainty.focal_px = JackknifeDeviation(focal, folds.size());
    uncertainty.principal_point_px = JackknifeDeviation(principal_point, folds.size());
  }
  // Each photo's rotation in each fold that kept it, as the rotation vector taking the whole's
  // to the fold's (aligned): small, so its components add like a vector's.
  std::map<std::string, std::vector<Eigen::Vector3d>> turns;
  for (const SparseModel& fold : folds) {
    for (const auto& [name, pose] : AlignedPoses(fold, whole)) {
      const Eigen::AngleAxisd turn(pose.rotation * whole.FindImageByName(name)->cam_from_world.rotation.inverse());
      turns[name].push_back(turn.angle() * turn.axis() * 180 / M_PI);
    }
  }
  for (const auto& [name, values] : turns) {
    // The angle's RMS over the three axes, not per axis: sqrt(3) times JackknifeDeviation.
    uncertainty.rotation_deg.emplace_back(name, std::sqrt(3.0) * JackknifeDeviation(values, folds.size()));
  }
  return uncertainty;
}

nlohmann::json ToJson(const CameraUncertainty& uncertainty) {
  nlohmann::json photos = nlohmann::json::object();
  std::vector<double> rotations;
  std::string max_photo;
  double max_deg = 0;
  for (const auto& [name, deg] : uncertainty.rotation_deg) {
    photos[name] = deg;
    rotations.push_back(deg);
    if (deg >= max_deg) {
      max_deg = deg;
      max_photo = name;
    }
  }
  return {{"folds", uncertainty.folds},
          {"focal_px", uncertainty.focal_px},
          {"principal_point_px", uncertainty.principal_point_px},
          {"rotation_deg",
           {{"median", rotations.empty() ? 0.0 : Median(rotations)},
            {"max", max_deg},
            {"max_photo", max_photo},
            {"photos", photos}}}};
}

void WriteCameraUncertainty(const CameraUncertainty& uncertainty, const std::filesystem::path& path) {
  WriteFileAtomically(path, ToJson(uncertainty).dump(2) + "\n");
}

CameraUncertainty ReadCameraUncertainty(const std::filesystem::path& path) {
  try {
    const nlohmann::json json = nlohmann::json::parse(ReadFileBytes(path));
    CameraUncertainty uncertainty;
    uncertainty.folds = json.at("folds").get<int>();
    uncertainty.focal_px = json.at("focal_px").get<double>();
    uncertainty.principal_point_px = json.at("principal_point_px").get<double>();
    for (const auto& [name, deg] : json.at("rotation_deg").at("photos").items()) {
      uncertainty.rotation_deg.emplace_back(name, deg.get<double>());
    }
    return uncertainty;
  } catch (const nlohmann::json::exception& error) {
    throw BadInputError(path.string() + ": not the cameras' uncertainty parallax writes (" + error.what() + ")");
  }
}

std::string Describe(const CameraUncertainty& uncertainty) {
  const nlohmann::json json = ToJson(uncertainty);
  char text[320];
  std::snprintf(text, sizeof text,
                "cameras' uncertainty (standard deviations by the jackknife over %d folds of the photos): rotation "
                "%.3f deg median, %.3f deg at most (%s); focal length %.1f px; principal point %.1f px",
                uncertainty.folds, json["rotation_deg"]["median"].get<double>(),
                json["rotation_deg"]["max"].get<double>(), json["rotation_deg"]["max_photo"].get<std::string>().c_str(),
                uncertainty.focal_px, uncertainty.principal_point_px);
  return text;
}

}  // namespace parallax
