#include "eval/depth_evaluation.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <exception>
#include <optional>
#include <utility>

#include <nlohmann/json.hpp>
#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include "core/depth_map.h"
#include "core/error.h"
#include "core/image.h"
#include "core/statistics.h"

namespace parallax {
namespace fs = std::filesystem;
namespace {

// The 4 ground-truth depths around a sub-pixel location are interpolated only when they lie
// within this ratio of each other: across a depth edge interpolation would invent a surface.
constexpr double kInterpolationMaxRatio = 1.01;
// abs_rel at which the error color ramp reaches red.
constexpr double kErrorRampMax = 0.02;
constexpr float kNoTruthGrey = 0.5f;

// Where one estimated pixel lands in the ground-truth image.
struct Landing {
  int64_t truth_index = -1;  // Row-major pixel index; -1 when it lands nowhere comparable.
  float z = 0;               // Its z-depth in the ground-truth camera.
  float reference = 0;       // Ground-truth depth at the sub-pixel location it lands on.
};

// The relative errors of one view (or of all views pooled) before they are summarised.
struct ErrorSamples {
  std::vector<double> abs_rel;     // One per ground-truth pixel with an estimate.
  std::vector<double> signed_rel;  // Same order.
  int64_t gt_valid_pixels = 0;
  int64_t within_1pct = 0;
  int64_t within_2pct = 0;
};

struct ViewResult {
  DepthViewErrors errors;
  ErrorSamples samples;
};

fs::path DepthPathFor(const fs::path& dir, const std::string& image_name) {
  return dir / (fs::path(image_name).stem().string() + ".exr");
}

std::string SizeString(int64_t width, int64_t height) {
  return std::to_string(width) + "x" + std::to_string(height);
}

const Camera& ProjectableCamera(const SparseModel& model, const SparseImage& image) {
  const Camera& camera = model.CameraById(image.camera_id);
  if (!IsProjectionSupported(camera.model)) {
    throw BadInputError("image '" + image.name + "': camera " + std::to_string(camera.id) +
                        " has model " + std::string(CameraModelName(camera.model)) +
                        ", which parallax cannot project");
  }
  return camera;
}

DepthMap ReadDepthForCamera(const fs::path& path, const Camera& camera) {
  DepthMap depth = ReadDepthExr(path);
  if (static_cast<uint64_t>(depth.Width()) != camera.width ||
      static_cast<uint64_t>(depth.Height()) != camera.height) {
    throw BadInputError(path.string() + ": depth map is " +
                        SizeString(depth.Width(), depth.Height()) + " but its camera " +
                        std::to_string(camera.id) + " is " +
                        SizeString(static_cast<int64_t>(camera.width),
                                   static_cast<int64_t>(camera.height)));
  }
  return depth;
}

// Lifts every estimated pixel and projects it into the ground-truth camera. Rows run in
// parallel; each writes only its own landings.
std::vector<Landing> ProjectEstimate(const DepthMap& estimate, const Camera& estimate_camera,
                                     const Eigen::Matrix3d& rotation,
                                     const Eigen::Vector3d& translation, const DepthMap& truth,
                                     const Camera& truth_camera) {
  std::vector<Landing> landings(estimate.Values().size());
  tbb::parallel_for(tbb::blocked_range<int>(0, estimate.Height()),
                    [&](const tbb::blocked_range<int>& rows) {
    for (int y = rows.begin(); y < rows.end(); ++y) {
      for (int x = 0; x < estimate.Width(); ++x) {
        const float depth = estimate.At(x, y);
        if (!(depth > 0)) continue;
        const std::optional<Eigen::Vector3d> point_in_estimate_cam =
            estimate_camera.Unproject(Eigen::Vector2d(x + 0.5, y + 0.5), depth);
        if (!point_in_estimate_cam) continue;
        const Eigen::Vector3d point_in_truth_cam = rotation * *point_in_estimate_cam + translation;
        const std::optional<Eigen::Vector2d> pixel = truth_camera.Project(point_in_truth_cam);
        if (!pixel) continue;
        const double px = std::floor(pixel->x());
        const double py = std::floor(pixel->y());
        if (px < 0 || py < 0 || px >= truth.Width() || py >= truth.Height()) continue;
        const int tx = static_cast<int>(px);
        const int ty = static_cast<int>(py);
        // Inverse depth interpolates exactly on planes; at edges the nearest pixel decides.
        const std::optional<double> sampled = SampleDepth(truth, *pixel, kInterpolationMaxRatio);
        if (!sampled) continue;  // Background in the ground truth: not comparable.
        const float reference = static_cast<float>(*sampled);
        Landing& landing = landings[static_cast<size_t>(y) * estimate.Width() + x];
        landing.truth_index = static_cast<int64_t>(ty) * truth.Width() + tx;
        landing.z = static_cast<float>(point_in_truth_cam.z());
        landing.reference = reference;
      }
    }
  });
  return landings;
}

// Keeps, per ground-truth pixel, the landing nearest to the camera; the first one in scan
// order wins ties, so the result does not depend on scheduling.
std::vector<Landing> NearestLandingPerPixel(const std::vector<Landing>& landings,
                                            size_t truth_pixels) {
  std::vector<Landing> nearest(truth_pixels);
  for (const Landing& landing : landings) {
    if (landing.truth_index < 0) continue;
    Landing& slot = nearest[static_cast<size_t>(landing.truth_index)];
    if (slot.truth_index < 0 || landing.z < slot.z) slot = landing;
  }
  return nearest;
}

void Summarise(const ErrorSamples& samples, DepthErrors& errors) {
  errors.abs_rel_median = Median(samples.abs_rel);
  errors.signed_median = Median(samples.signed_rel);
  if (samples.gt_valid_pixels == 0) return;
  const auto valid = static_cast<double>(samples.gt_valid_pixels);
  errors.within_1pct = static_cast<double>(samples.within_1pct) / valid;
  errors.within_2pct = static_cast<double>(samples.within_2pct) / valid;
  errors.completeness = static_cast<double>(samples.abs_rel.size()) / valid;
}

void WriteErrorImage(const fs::path& path, const DepthMap& truth,
                     const std::vector<Landing>& nearest) {
  Image image(truth.Width(), truth.Height(), 3);
  for (int y = 0; y < truth.Height(); ++y) {
    for (int x = 0; x < truth.Width(); ++x) {
      const Landing& landing = nearest[static_cast<size_t>(y) * truth.Width() + x];
      Eigen::Vector3f color = Eigen::Vector3f::Zero();
      if (!(truth.At(x, y) > 0)) {
        color.setConstant(kNoTruthGrey);
      } else if (landing.truth_index >= 0) {
        color = DepthErrorColor(std::abs(landing.z - landing.reference) / landing.reference);
      }
      for (int c = 0; c < 3; ++c) image.At(x, y, c) = color[c];
    }
  }
  WriteImage(path, image, PixelFormat::kUint8);
}

ViewResult EvaluateView(const SparseModel& estimate_model, const SparseImage& estimate_image,
                        const fs::path& estimate_path, const SparseModel& truth_model,
                        const SparseImage& truth_image, const fs::path& truth_depth_dir,
                        const Similarity3d& truth_from_estimate,
                        const fs::path& error_image_dir) {
  const Camera& estimate_camera = ProjectableCamera(estimate_model, estimate_image);
  const Camera& truth_camera = ProjectableCamera(truth_model, truth_image);
  // The depth stage writes its maps at its working size: read at the photo's.
  const DepthMap estimate = ReadDepthExrAt(estimate_path, static_cast<int>(estimate_camera.width),
                                           static_cast<int>(estimate_camera.height));
  const DepthMap truth =
      ReadDepthForCamera(DepthPathFor(truth_depth_dir, truth_image.name), truth_camera);

  // truth_cam_from_estimate_cam = truth_cam_from_truth * truth_from_estimate *
  // estimate_from_estimate_cam, as one affine map.
  const Rigid3d estimate_from_cam = estimate_image.cam_from_world.Inverse();
  const Eigen::Matrix3d truth_cam_rotation = truth_image.cam_from_world.rotation.toRotationMatrix();
  const Eigen::Matrix3d rotation = truth_cam_rotation * truth_from_estimate.scale *
                                   truth_from_estimate.rotation.toRotationMatrix() *
                                   estimate_from_cam.rotation.toRotationMatrix();
  const Eigen::Vector3d translation =
      truth_cam_rotation * (truth_from_estimate * estimate_from_cam.translation) +
      truth_image.cam_from_world.translation;

  const std::vector<Landing> nearest = NearestLandingPerPixel(
      ProjectEstimate(estimate, estimate_camera, rotation, translation, truth, truth_camera),
      truth.Values().size());

  ViewResult result;
  ErrorSamples& samples = result.samples;
  for (size_t i = 0; i < nearest.size(); ++i) {
    if (!(truth.Values()[i] > 0)) continue;
    ++samples.gt_valid_pixels;
    const Landing& landing = nearest[i];
    if (landing.truth_index < 0) continue;
    const double reference = landing.reference;
    const double signed_rel = (static_cast<double>(landing.z) - reference) / reference;
    const double abs_rel = std::abs(signed_rel);
    samples.abs_rel.push_back(abs_rel);
    samples.signed_rel.push_back(signed_rel);
    samples.within_1pct += abs_rel < 0.01;
    samples.within_2pct += abs_rel < 0.02;
  }
  result.errors.name = truth_image.name;
  result.errors.gt_valid_pixels = samples.gt_valid_pixels;
  result.errors.estimated_pixels = static_cast<int64_t>(samples.abs_rel.size());
  Summarise(samples, result.errors);
  if (!error_image_dir.empty()) {
    const fs::path png = error_image_dir / (fs::path(truth_image.name).stem().string() + ".png");
    WriteErrorImage(png, truth, nearest);
  }
  return result;
}

}  // namespace

DepthEvaluation EvaluateDepth(const SparseModel& estimate_model,
                              const fs::path& estimate_depth_dir, const SparseModel& truth_model,
                              const fs::path& truth_depth_dir,
                              const Similarity3d& truth_from_estimate,
                              const fs::path& error_image_dir) {
  struct ViewPair {
    const SparseImage* estimate;
    const SparseImage* truth;
    fs::path estimate_path;
  };
  std::vector<ViewPair> pairs;
  for (const SparseImage& image : estimate_model.Images()) {
    const SparseImage* truth = truth_model.FindImageByName(image.name);
    fs::path path = DepthPathFor(estimate_depth_dir, image.name);
    if (truth && fs::exists(path)) pairs.push_back({&image, truth, std::move(path)});
  }
  std::sort(pairs.begin(), pairs.end(), [](const ViewPair& a, const ViewPair& b) {
    return a.estimate->name < b.estimate->name;
  });

  // Views run in parallel (and rows within each); a failure is kept per view and the first in
  // name order rethrown, so the message does not depend on scheduling.
  std::vector<ViewResult> results(pairs.size());
  std::vector<std::exception_ptr> failures(pairs.size());
  tbb::parallel_for(size_t{0}, pairs.size(), [&](size_t i) {
    try {
      results[i] = EvaluateView(estimate_model, *pairs[i].estimate, pairs[i].estimate_path,
                                truth_model, *pairs[i].truth, truth_depth_dir,
                                truth_from_estimate, error_image_dir);
    } catch (...) {
      failures[i] = std::current_exception();
    }
  });
  for (const std::exception_ptr& failure : failures) {
    if (failure) std::rethrow_exception(failure);
  }

  DepthEvaluation evaluation;
  evaluation.views = static_cast<int>(results.size());
  ErrorSamples pooled;
  for (ViewResult& result : results) {
    ErrorSamples& samples = result.samples;
    pooled.abs_rel.insert(pooled.abs_rel.end(), samples.abs_rel.begin(), samples.abs_rel.end());
    pooled.signed_rel.insert(pooled.signed_rel.end(), samples.signed_rel.begin(),
                             samples.signed_rel.end());
    pooled.gt_valid_pixels += samples.gt_valid_pixels;
    pooled.within_1pct += samples.within_1pct;
    pooled.within_2pct += samples.within_2pct;
    samples = {};  // Free as we go: the pooled copy is what is needed now.
    evaluation.per_view.push_back(std::move(result.errors));
  }
  Summarise(pooled, evaluation);
  return evaluation;
}

Eigen::Vector3f DepthErrorColor(double abs_rel) {
  // Stops at 0, 0.5, 1, 1.5, 2 %: lightness rises from dark blue to yellow-green at 1%, then
  // the hue turns warm so that anything over 1% reads as a warning.
  static const std::array<Eigen::Vector3f, 5> kStops = {
      Eigen::Vector3f(0.08f, 0.10f, 0.45f), Eigen::Vector3f(0.10f, 0.50f, 0.65f),
      Eigen::Vector3f(0.60f, 0.85f, 0.25f), Eigen::Vector3f(0.98f, 0.70f, 0.10f),
      Eigen::Vector3f(0.85f, 0.08f, 0.08f)};
  const double t = std::clamp(abs_rel / kErrorRampMax, 0.0, 1.0) * (kStops.size() - 1);
  const size_t lower = std::min(static_cast<size_t>(t), kStops.size() - 2);
  const auto w = static_cast<float>(t - static_cast<double>(lower));
  return (1 - w) * kStops[lower] + w * kStops[lower + 1];
}

void AddDepthSection(const DepthEvaluation& evaluation, nlohmann::json& json) {
  json["depth"] = {{"views", evaluation.views},
                   {"abs_rel_median", evaluation.abs_rel_median},
                   {"signed_median", evaluation.signed_median},
                   {"within_1pct", evaluation.within_1pct},
                   {"within_2pct", evaluation.within_2pct},
                   {"completeness", evaluation.completeness}};
}

}  // namespace parallax
