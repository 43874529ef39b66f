#include "geometry/similarity.h"

#include <algorithm>
#include <cmath>
#include <numbers>
#include <optional>
#include <sstream>
#include <string>
#include <utility>
#include <vector>

#include <Eigen/SVD>
#include <ceres/ceres.h>
#include <ceres/rotation.h>

#include "core/error.h"
#include "core/statistics.h"
#include "core/check.h"

namespace parallax {
namespace {

constexpr double kDegToRad = std::numbers::pi / 180.0;

// Centres whose largest offset from their median is below this fraction of their magnitude
// differ only by rounding: CameraCenter alone leaves a few ulps of noise on equal centres.
constexpr double kCoincidentRelative = 1e-12;
// A median spread below this fraction of the largest one means most centres coincide; the
// largest spread then conditions the normalisation better.
constexpr double kMinMedianSpreadFraction = 1e-3;
// Umeyama is skipped when the second singular value of the centred centres is below this
// fraction of the first: the rotation about the (near) line is then fixed by noise alone.
constexpr double kCollinearRatio = 1e-6;
// The orientation start tries at most this many seeds, so its cost is linear in the cameras.
constexpr int kMaxOrientationSeeds = 256;
// Scale-ratio pairs: all pairs up to this many cameras, beyond it a fixed number of partners
// per camera, so the median stays cheap for large sets.
constexpr int kAllPairsLimit = 128;
constexpr int kPartnersPerCamera = 16;
// Pairs closer than this (normalised units, spread = 1) say nothing reliable about scale.
constexpr double kMinPairDistance = 1e-9;

std::string Format(double value) {
  std::ostringstream stream;
  stream.precision(17);
  stream << value;
  return stream.str();
}

bool IsFinitePose(const Rigid3d& pose) {
  const double norm = pose.rotation.norm();
  return std::isfinite(norm) && norm > 0 && pose.translation.allFinite();
}

void ValidateCameras(const std::vector<Rigid3d>& source_cams,
                     const std::vector<Rigid3d>& target_cams) {
  if (source_cams.size() != target_cams.size()) {
    throw InternalError("AlignSimilarity: " + std::to_string(source_cams.size()) +
                        " source cameras but " + std::to_string(target_cams.size()) +
                        " target cameras; they must correspond one to one");
  }
  if (source_cams.size() < 3) {
    throw InternalError("AlignSimilarity: need at least 3 cameras, got " +
                        std::to_string(source_cams.size()));
  }
  for (size_t i = 0; i < source_cams.size(); ++i) {
    for (const auto& [cams, frame] :
         {std::pair{&source_cams, "source"}, std::pair{&target_cams, "target"}}) {
      if (!IsFinitePose((*cams)[i])) {
        throw InternalError(std::string("AlignSimilarity: ") + frame + " camera " +
                            std::to_string(i) +
                            " has a non-finite or zero-quaternion pose");
      }
    }
  }
}

// Robust to outlying cameras, unlike the centroid.
Eigen::Vector3d CoordinateWiseMedian(const std::vector<Eigen::Vector3d>& points) {
  Eigen::Vector3d median;
  std::vector<double> coordinates(points.size());
  for (int axis = 0; axis < 3; ++axis) {
    for (size_t i = 0; i < points.size(); ++i) coordinates[i] = points[i][axis];
    median[axis] = Median(coordinates);
  }
  return median;
}

// Centres as (c - center) / spread, so the solver sees unit-sized, origin-centred data
// whatever the scene's scale and offset.
struct NormalisedCentres {
  std::vector<Eigen::Vector3d> points;
  Eigen::Vector3d center = Eigen::Vector3d::Zero();
  double spread = 1;
};

NormalisedCentres Normalise(const std::vector<Eigen::Vector3d>& centres, const char* frame) {
  NormalisedCentres result;
  result.center = CoordinateWiseMedian(centres);
  std::vector<double> distances;
  double magnitude = 0;
  for (const Eigen::Vector3d& centre : centres) {
    distances.push_back((centre - result.center).norm());
    magnitude = std::max(magnitude, centre.norm());
  }
  const double largest = *std::max_element(distances.begin(), distances.end());
  if (!(largest > kCoincidentRelative * magnitude)) {
    throw InternalError(std::string("AlignSimilarity: the ") + frame +
                        " camera centres all coincide (largest offset " + Format(largest) +
                        " at magnitude " + Format(magnitude) +
                        "), so the scale is undetermined");
  }
  const double median = Median(distances);
  result.spread = median >= kMinMedianSpreadFraction * largest ? median : largest;
  for (const Eigen::Vector3d& centre : centres) {
    result.points.push_back((centre - result.center) / result.spread);
  }
  return result;
}

double LargestDistance(const std::vector<Eigen::Vector3d>& points) {
  double largest = 0;
  for (size_t i = 0; i < points.size(); ++i) {
    for (size_t j = i + 1; j < points.size(); ++j) {
      largest = std::max(largest, (points[i] - points[j]).norm());
    }
  }
  return largest;
}

// The alignment problem in normalised coordinates: target = s R source + t.
struct NormalisedProblem {
  std::vector<Eigen::Vector3d> source;
  std::vector<Eigen::Vector3d> target;
  // Per camera, R_target^T R_source: the target_from_source rotation that camera implies.
  std::vector<Eigen::Quaterniond> rotations;
  double extent = 1;  // Largest distance between two normalised target centres.
};

bool IsNearlyCollinear(const std::vector<Eigen::Vector3d>& points) {
  Eigen::Matrix3Xd centred(3, points.size());
  for (size_t i = 0; i < points.size(); ++i) centred.col(i) = points[i];
  centred.colwise() -= centred.rowwise().mean();
  const Eigen::Vector3d singular = Eigen::JacobiSVD<Eigen::Matrix3Xd>(centred).singularValues();
  return !(singular[1] > kCollinearRatio * singular[0]);
}

std::optional<Similarity3d> UmeyamaStart(const NormalisedProblem& problem) {
  if (IsNearlyCollinear(problem.source) || IsNearlyCollinear(problem.target)) return {};
  Eigen::Matrix3Xd source(3, problem.source.size()), target(3, problem.target.size());
  for (size_t i = 0; i < problem.source.size(); ++i) {
    source.col(i) = problem.source[i];
    target.col(i) = problem.target[i];
  }
  const Eigen::Matrix4d transform = Eigen::umeyama(source, target, true);
  Similarity3d start;
  const Eigen::Matrix3d scaled_rotation = transform.topLeftCorner<3, 3>();
  start.scale = scaled_rotation.col(0).norm();
  if (!(start.scale > 0) || !std::isfinite(start.scale)) return {};
  start.rotation = Eigen::Quaterniond(Eigen::Matrix3d(scaled_rotation / start.scale));
  start.rotation.normalize();
  start.translation = transform.topRightCorner<3, 1>();
  return start;
}

std::vector<int> AgreeingCameras(const std::vector<Eigen::Quaterniond>& rotations,
                                 const Eigen::Quaterniond& reference, double agree_deg) {
  std::vector<int> members;
  for (size_t j = 0; j < rotations.size(); ++j) {
    if (RotationAngleDeg(reference, rotations[j]) <= agree_deg) members.push_back(int(j));
  }
  return members;
}

// Sign-aligned mean: q and -q are one rotation, and for rotations a few degrees apart the
// normalised mean of aligned quaternions is the chordal L2 mean.
Eigen::Quaterniond AverageRotation(const std::vector<Eigen::Quaterniond>& rotations,
                                   const std::vector<int>& members,
                                   const Eigen::Quaterniond& reference) {
  Eigen::Vector4d sum = Eigen::Vector4d::Zero();
  for (int j : members) {
    const Eigen::Vector4d& coeffs = rotations[j].coeffs();
    sum += coeffs.dot(reference.coeffs()) < 0 ? Eigen::Vector4d(-coeffs) : coeffs;
  }
  return Eigen::Quaterniond(sum).normalized();
}

// The rotation most cameras agree on (a mode, not a mean, so wrong poses cannot drag it),
// with the cameras that agree.
Eigen::Quaterniond ConsensusRotation(const std::vector<Eigen::Quaterniond>& rotations,
                                     double agree_deg, std::vector<int>* members) {
  const int count = int(rotations.size());
  const int stride = std::max(1, count / kMaxOrientationSeeds);
  int best_seed = 0;
  size_t best_support = 0;
  for (int seed = 0; seed < count; seed += stride) {
    const size_t support = AgreeingCameras(rotations, rotations[seed], agree_deg).size();
    if (support > best_support) {
      best_support = support;
      best_seed = seed;
    }
  }
  // Re-centre once on the mean: the seed itself carries its own noise.
  Eigen::Quaterniond consensus = rotations[best_seed];
  for (int pass = 0; pass < 2; ++pass) {
    *members = AgreeingCameras(rotations, consensus, agree_deg);
    if (members->empty()) break;
    consensus = AverageRotation(rotations, *members, consensus);
  }
  if (members->empty()) *members = AgreeingCameras(rotations, rotations[best_seed], agree_deg);
  return consensus;
}

// Median of target/source distance ratios: robust to cameras with a good orientation but a
// wrong centre, and defined for collinear centres, unlike a spread ratio about a centroid.
double RobustScale(const NormalisedProblem& problem, const std::vector<int>& members) {
  const int count = int(members.size());
  const int partners = count <= kAllPairsLimit ? count - 1 : kPartnersPerCamera;
  const int step = count <= kAllPairsLimit ? 1 : std::max(1, count / (kPartnersPerCamera + 1));
  std::vector<double> ratios;
  for (int a = 0; a < count; ++a) {
    for (int k = 1; k <= partners; ++k) {
      const int b = (a + k * step) % count;
      // All pairs are visited from their lower end only; strided partners both ways.
      if (count <= kAllPairsLimit && b < a) continue;
      const double source_distance =
          (problem.source[members[a]] - problem.source[members[b]]).norm();
      if (!(source_distance > kMinPairDistance)) continue;
      ratios.push_back((problem.target[members[a]] - problem.target[members[b]]).norm() /
                       source_distance);
    }
  }
  // Normalised sets have unit spread, so 1 is the scale when nothing better is known.
  return ratios.empty() ? 1.0 : Median(ratios);
}

Similarity3d OrientationStart(const NormalisedProblem& problem, double agree_deg) {
  std::vector<int> members;
  Similarity3d start;
  start.rotation = ConsensusRotation(problem.rotations, agree_deg, &members);
  start.scale = RobustScale(problem, members);
  std::vector<Eigen::Vector3d> offsets;
  for (int j : members) {
    offsets.push_back(problem.target[j] - start.scale * (start.rotation * problem.source[j]));
  }
  start.translation = CoordinateWiseMedian(offsets);
  return start;
}

// (s R c_source + t - c_target) / robust scale.
struct CentreResidual {
  CentreResidual(const Eigen::Vector3d& source, const Eigen::Vector3d& target, double scale)
      : source_(source), target_(target), inverse_scale_(1 / scale) {}

  template <typename T>
  bool operator()(const T* rotation, const T* translation, const T* log_scale, T* residual) const {
    const T source[3] = {T(source_[0]), T(source_[1]), T(source_[2])};
    T rotated[3];
    ceres::UnitQuaternionRotatePoint(rotation, source, rotated);
    const T scale = exp(log_scale[0]);
    for (int axis = 0; axis < 3; ++axis) {
      residual[axis] =
          (scale * rotated[axis] + translation[axis] - T(target_[axis])) * inverse_scale_;
    }
    return true;
  }

  Eigen::Vector3d source_, target_;
  double inverse_scale_;
};

// Angle-axis of R_i R^T, the rotation between the camera's predicted and actual target
// orientation (R_source R^T against R_target), over the robust scale.
struct OrientationResidual {
  OrientationResidual(const Eigen::Quaterniond& measured, double scale)
      : measured_{measured.w(), measured.x(), measured.y(), measured.z()},
        inverse_scale_(1 / scale) {}

  template <typename T>
  bool operator()(const T* rotation, T* residual) const {
    const T measured[4] = {T(measured_[0]), T(measured_[1]), T(measured_[2]), T(measured_[3])};
    const T inverse[4] = {rotation[0], -rotation[1], -rotation[2], -rotation[3]};
    T difference[4];
    ceres::QuaternionProduct(measured, inverse, difference);
    ceres::QuaternionToAngleAxis(difference, residual);
    for (int axis = 0; axis < 3; ++axis) residual[axis] *= T(inverse_scale_);
    return true;
  }

  double measured_[4];
  double inverse_scale_;
};

// Ceres parameter blocks: quaternion w-first (ceres::QuaternionManifold), log scale so the
// scale stays positive and its steps are relative.
struct Parameters {
  explicit Parameters(const Similarity3d& similarity)
      : rotation{similarity.rotation.w(), similarity.rotation.x(), similarity.rotation.y(),
                 similarity.rotation.z()},
        translation{similarity.translation[0], similarity.translation[1],
                    similarity.translation[2]},
        log_scale(std::log(similarity.scale)) {}

  Similarity3d ToSimilarity() const {
    Similarity3d similarity;
    similarity.scale = std::exp(log_scale);
    similarity.rotation =
        Eigen::Quaterniond(rotation[0], rotation[1], rotation[2], rotation[3]).normalized();
    similarity.translation = Eigen::Vector3d(translation[0], translation[1], translation[2]);
    return similarity;
  }

  double rotation[4];
  double translation[3];
  double log_scale;
};

void BuildProblem(const NormalisedProblem& data, const std::vector<int>& cameras,
                  const AlignmentOptions& options, Parameters* parameters,
                  ceres::Problem* problem) {
  const double centre_scale = options.robust_center_fraction * data.extent;
  const double rotation_scale = options.robust_rotation_deg * kDegToRad;
  // One loss for every block: the problem owns it once, whatever the number of blocks.
  ceres::LossFunction* loss = new ceres::CauchyLoss(1.0);
  for (int i : cameras) {
    problem->AddResidualBlock(new ceres::AutoDiffCostFunction<CentreResidual, 3, 4, 3, 1>(
                                  new CentreResidual(data.source[i], data.target[i], centre_scale)),
                              loss, parameters->rotation, parameters->translation,
                              &parameters->log_scale);
    problem->AddResidualBlock(new ceres::AutoDiffCostFunction<OrientationResidual, 3, 4>(
                                  new OrientationResidual(data.rotations[i], rotation_scale)),
                              loss, parameters->rotation);
  }
  problem->SetManifold(parameters->rotation, new ceres::QuaternionManifold);
}

struct Refined {
  Similarity3d similarity;
  double cost = 0;
};

// Refines `start` over `cameras`; with `solve` false only evaluates the cost there.
Refined Refine(const NormalisedProblem& data, const std::vector<int>& cameras,
               const Similarity3d& start, const AlignmentOptions& options, bool solve) {
  Parameters parameters(start);
  ceres::Problem problem;
  BuildProblem(data, cameras, options, &parameters, &problem);
  Refined refined;
  if (solve) {
    ceres::Solver::Options solver_options;
    solver_options.linear_solver_type = ceres::DENSE_QR;
    solver_options.logging_type = ceres::SILENT;
    solver_options.minimizer_progress_to_stdout = false;
    solver_options.num_threads = 1;
    solver_options.max_num_iterations = 100;
    // Tight tolerances: exact data should come back to rounding, and each iteration is cheap.
    solver_options.function_tolerance = 1e-15;
    solver_options.gradient_tolerance = 1e-15;
    solver_options.parameter_tolerance = 1e-15;
    ceres::Solver::Summary summary;
    ceres::Solve(solver_options, &problem, &summary);
    if (!summary.IsSolutionUsable()) parameters = Parameters(start);
  }
  problem.Evaluate(ceres::Problem::EvaluateOptions(), &refined.cost, nullptr, nullptr, nullptr);
  refined.similarity = parameters.ToSimilarity();
  return refined;
}

std::vector<int> Inliers(const NormalisedProblem& data, const Similarity3d& similarity,
                         const AlignmentOptions& options) {
  std::vector<int> inliers;
  for (size_t i = 0; i < data.source.size(); ++i) {
    const double centre_error = (similarity * data.source[i] - data.target[i]).norm();
    if (centre_error <= options.inlier_center_fraction * data.extent &&
        RotationAngleDeg(data.rotations[i], similarity.rotation) <= options.inlier_rotation_deg) {
      inliers.push_back(int(i));
    }
  }
  return inliers;
}

// Undoes the normalisation: x_target = m_t + d_t (s_n R (x_source - m_s) / d_s + t_n).
Similarity3d Denormalise(const Similarity3d& normalised, const NormalisedCentres& source,
                         const NormalisedCentres& target) {
  Similarity3d result;
  result.rotation = normalised.rotation;
  result.scale = normalised.scale * target.spread / source.spread;
  result.translation = target.center + target.spread * normalised.translation -
                       result.scale * (normalised.rotation * source.center);
  return result;
}

std::vector<int> AllCameras(size_t count) {
  std::vector<int> cameras(count);
  for (size_t i = 0; i < count; ++i) cameras[i] = int(i);
  return cameras;
}

NormalisedProblem MakeNormalisedProblem(const std::vector<Rigid3d>& source_cams,
                                        const std::vector<Rigid3d>& target_cams,
                                        NormalisedCentres* source, NormalisedCentres* target) {
  std::vector<Eigen::Vector3d> source_centres, target_centres;
  NormalisedProblem data;
  for (size_t i = 0; i < source_cams.size(); ++i) {
    source_centres.push_back(CameraCenter(source_cams[i]));
    target_centres.push_back(CameraCenter(target_cams[i]));
    data.rotations.push_back(
        (target_cams[i].rotation.normalized().conjugate() * source_cams[i].rotation.normalized())
            .normalized());
  }
  *source = Normalise(source_centres, "source");
  *target = Normalise(target_centres, "target");
  data.source = source->points;
  data.target = target->points;
  data.extent = LargestDistance(data.target);
  return data;
}

// Refines every closed-form start over all cameras and keeps the lowest robust cost: Umeyama
// wins on clean, well-spread centres, the orientation start on outliers and lines.
Refined RefineBestStart(const NormalisedProblem& data, const AlignmentOptions& options) {
  std::vector<Similarity3d> starts = {OrientationStart(data, options.inlier_rotation_deg)};
  if (const std::optional<Similarity3d> umeyama = UmeyamaStart(data)) starts.push_back(*umeyama);
  const std::vector<int> all = AllCameras(data.source.size());
  Refined best;
  for (size_t k = 0; k < starts.size(); ++k) {
    const Refined refined = Refine(data, all, starts[k], options, true);
    if (k == 0 || refined.cost < best.cost) best = refined;
  }
  return best;
}

}  // namespace

Rigid3d Similarity3d::TransformPose(const Rigid3d& cam_from_source) const {
  // cam_from_source * source_from_target, with the camera frame scaled by `scale` so it stays
  // metric in the target frame: centre s R c + t, rotation R_cam R^T.
  const Eigen::Quaterniond cam_from_target_rotation =
      (cam_from_source.rotation * rotation.conjugate()).normalized();
  const Eigen::Vector3d centre_in_target = *this * CameraCenter(cam_from_source);
  return Rigid3d(cam_from_target_rotation, -(cam_from_target_rotation * centre_in_target));
}

Similarity3d Similarity3d::Inverse() const {
  // x = s R y + t  <=>  y = (1/s) R^T x - (1/s) R^T t.
  Similarity3d inverse;
  inverse.scale = 1 / scale;
  inverse.rotation = rotation.conjugate();
  inverse.translation = -(inverse.scale * (inverse.rotation * translation));
  return inverse;
}

void AlignmentOptions::Check() const {
  const std::pair<const char*, double> fields[] = {
      {"AlignmentOptions.inlier_center_fraction", inlier_center_fraction},
      {"AlignmentOptions.inlier_rotation_deg", inlier_rotation_deg},
      {"AlignmentOptions.robust_center_fraction", robust_center_fraction},
      {"AlignmentOptions.robust_rotation_deg", robust_rotation_deg}};
  for (const auto& [name, value] : fields) {
    RequireOption(value > 0 && std::isfinite(value), name, value, "positive and finite");
  }
}

AlignmentResult AlignSimilarity(const std::vector<Rigid3d>& source_cams,
                                const std::vector<Rigid3d>& target_cams,
                                const AlignmentOptions& options) {
  options.Check();
  ValidateCameras(source_cams, target_cams);
  NormalisedCentres source, target;
  const NormalisedProblem data = MakeNormalisedProblem(source_cams, target_cams, &source, &target);
  Refined best = RefineBestStart(data, options);
  // The robust loss still lets each outlier pull a little; a last solve on the inliers alone
  // recovers the transform they define.
  std::vector<int> inliers = Inliers(data, best.similarity, options);
  if (inliers.size() >= 3 && inliers.size() < data.source.size()) {
    const Similarity3d polished = Refine(data, inliers, best.similarity, options, true).similarity;
    best = Refine(data, AllCameras(data.source.size()), polished, options, false);
    inliers = Inliers(data, best.similarity, options);
  }

  AlignmentResult result;
  result.target_from_source = Denormalise(best.similarity, source, target);
  result.inliers = int(inliers.size());
  result.final_cost = best.cost;
  return result;
}

}  // namespace parallax
