#include "pipeline/sfm_policy.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <map>
#include <set>
#include <sstream>
#include <utility>

#include "core/error.h"
#include "sfm/plausibility.h"

namespace parallax {
namespace {

// COLMAP's --ImageReader.camera_params: every digit a double holds.
std::string Join(const std::vector<double>& values) {
  std::ostringstream text;
  text.precision(17);
  for (size_t i = 0; i < values.size(); ++i) text << (i ? "," : "") << values[i];
  return text.str();
}

std::string Percent(double share) {
  char text[16];
  std::snprintf(text, sizeof(text), "%.0f%%", 100 * share);
  return text;
}

std::string PercentText(double share) { return std::to_string(static_cast<int>(std::lround(100 * share))) + "%"; }

// Why the automatic matcher is not exhaustive for `num_images` photos.
std::string PastTheLimit(const ReconstructOptions& options, int num_images) {
  return std::to_string(num_images) + " images, more than " +
         std::to_string(options.exhaustive_limit) + " for exhaustive matching";
}

// The vocabulary tree sequential and retrieval matching use.
std::string TreeText(const ReconstructOptions& options) {
  return options.vocab_tree.empty() ? "a vocabulary tree built from these photos"
                                    : "the vocabulary tree " + options.vocab_tree.string();
}

}  // namespace

CameraSetup ChooseCameraSetup(const PhotoSet& photos, const ReconstructOptions& options,
                              const SparseModel* known) {
  const bool shared = photos.SharesOneCamera();
  if (known) {
    const bool single = known->Cameras().size() == 1;
    const Camera& first = known->Cameras().front();
    return {single ? first.model : options.camera_model, single ? Join(first.params) : "",
            single ? CameraSharing::kAll : CameraSharing::kPerPhoto, true};
  }
  if (options.intrinsics.empty()) {
    return {options.camera_model, "", shared ? CameraSharing::kAll : CameraSharing::kPerGroup, false};
  }
  if (!shared && options.intrinsics.size() == 1) {
    throw BadInputError("--intrinsics f needs photos of one size (the principal point is put at "
                        "the image centre); give fx,fy,cx,cy or photos of one size");
  }
  const Photo& photo = photos.photos.front();
  if (options.intrinsics.size() == 1) {
    return {CameraModel::kSimplePinhole,
            Join({options.intrinsics[0], photo.width / 2.0, photo.height / 2.0}), CameraSharing::kAll,
            true};
  }
  return {CameraModel::kPinhole, Join(options.intrinsics), CameraSharing::kAll, true};
}

std::string DescribeCameraSetup(const CameraSetup& camera, const PhotoSet& photos) {
  std::string sharing;
  switch (camera.sharing) {
    case CameraSharing::kAll: sharing = "one shared camera"; break;
    case CameraSharing::kPerGroup:
      sharing = "one camera per photo size and EXIF camera (" +
                std::to_string(photos.CameraGroups().size()) + " cameras)";
      break;
    case CameraSharing::kPerPhoto: sharing = "one camera per image"; break;
  }
  return std::string(CameraModelName(camera.model)) + ", " + sharing +
         (camera.fixed_intrinsics ? ", intrinsics fixed" : "");
}

std::vector<std::string> PhotoNames(const PhotoSet& photos) {
  std::vector<std::string> names;
  for (const Photo& photo : photos.photos) names.push_back(photo.name);
  return names;
}

std::vector<ExtractionRun> ExtractionRuns(const PhotoSet& photos, CameraSharing sharing) {
  if (sharing != CameraSharing::kPerGroup) {
    return {{PhotoNames(photos), sharing == CameraSharing::kAll}};
  }
  std::vector<ExtractionRun> runs;
  ExtractionRun alone{{}, false};
  for (const std::vector<size_t>& group : photos.CameraGroups()) {
    ExtractionRun run{{}, true};
    for (const size_t index : group) run.names.push_back(photos.photos[index].name);
    if (group.size() == 1) {
      alone.names.push_back(run.names.front());
    } else {
      runs.push_back(std::move(run));
    }
  }
  if (!alone.names.empty()) runs.push_back(std::move(alone));
  return runs;
}

std::string DescribeConversions(const PhotoSet& photos, const Workspace& workspace) {
  std::map<std::string, int> count_by_reason;
  int converted = 0;
  for (const Photo& photo : photos.photos) {
    if (photo.conversion.empty()) continue;
    ++converted;
    ++count_by_reason[photo.conversion];
  }
  if (converted == 0) return "";
  std::string note = std::to_string(converted) + " photo(s) converted to 8-bit RGB, upright, in " +
                     workspace.ReadablePhotos().string() + " for colmap (";
  bool first = true;
  for (const auto& [reason, count] : count_by_reason) {
    note += (first ? "" : "; ") + std::to_string(count) + " " + reason;
    first = false;
  }
  return note + ")";
}

int64_t VocabularyTreeWords(int num_images, int64_t descriptors) {
  const int64_t sampled = descriptors * std::min(num_images, kVocabularyTreeTrainingImages) /
                          std::max(num_images, 1);
  return std::clamp<int64_t>(sampled / 2, 1, kVocabularyTreeWords);
}

MatcherChoice MatcherFor(const ReconstructOptions& options, int num_images) {
  if (options.matcher == MatcherChoice::kAuto && num_images <= options.exhaustive_limit) {
    return MatcherChoice::kExhaustive;
  }
  return options.matcher;
}

double ConsecutiveShare(const std::vector<std::string>& names, const std::vector<VerifiedPair>& pairs) {
  std::set<std::pair<std::string, std::string>> verified;
  for (const VerifiedPair& pair : pairs) verified.insert(std::minmax(pair.first, pair.second));
  int consecutive = 0;
  for (size_t i = 0; i + 1 < names.size(); ++i) {
    consecutive += static_cast<int>(verified.count(std::minmax(names[i], names[i + 1])));
  }
  return names.size() < 2 ? 0 : static_cast<double>(consecutive) / static_cast<double>(names.size() - 1);
}

MatcherChoice MatcherForConsecutiveShare(const ReconstructOptions& options, double consecutive_share) {
  return consecutive_share >= options.ordered_share ? MatcherChoice::kSequential : MatcherChoice::kRetrieval;
}

std::string DescribeMatcher(MatcherChoice matcher, const ReconstructOptions& options, int num_images,
                            std::optional<double> consecutive_share) {
  std::string text;
  switch (matcher) {
    case MatcherChoice::kExhaustive:
      text = "exhaustive (" + std::to_string(num_images) + " images, every pair)";
      break;
    case MatcherChoice::kSequential:
      text = "sequential (each image with the next " +
             std::to_string(options.sequential_overlap - 1) +
             " in name order and those a power of two ahead; loops closed by retrieval from " +
             TreeText(options) + ")";
      break;
    case MatcherChoice::kRetrieval:
      text = "retrieval (each image with its " + std::to_string(options.retrieval_images) +
             " most similar in " + TreeText(options) + ")";
      break;
    case MatcherChoice::kAuto: throw InternalError("the automatic matcher is not decided");
  }
  if (options.matcher != MatcherChoice::kAuto) return text;
  if (matcher == MatcherChoice::kExhaustive) {
    return text + ", chosen automatically: at most " + std::to_string(options.exhaustive_limit) +
           " images";
  }
  return text + ", chosen automatically: " + PastTheLimit(options, num_images) + ", and " +
         Percent(consecutive_share.value()) +
         " of the photos consecutive in name order match the next (" +
         (matcher == MatcherChoice::kSequential ? "an ordered capture" : "not an ordered capture") +
         ")";
}

std::string PlannedMatcher(const ReconstructOptions& options, int num_images) {
  const MatcherChoice matcher = MatcherFor(options, num_images);
  if (matcher == MatcherChoice::kAuto) {
    return "sequential or retrieval, as the photos' name order says once consecutive photos are "
           "matched (" + PastTheLimit(options, num_images) + ")";
  }
  return DescribeMatcher(matcher, options, num_images, std::nullopt);
}

MapperPlan TriangulationPlan() {
  return {MapperChoice::kIncremental, {}, "point_triangulator (known cameras: only the points are triangulated)"};
}

MapperPlan PlanByCount(const ReconstructOptions& options, int num_images) {
  const bool automatic = options.mapper == MapperChoice::kAuto;
  const bool hierarchical = options.mapper == MapperChoice::kHierarchical ||
                            (options.mapper == MapperChoice::kAuto && num_images > options.hierarchical_limit);
  const std::string chosen = automatic ? ", chosen automatically: " : "";
  if (!hierarchical) {
    return {MapperChoice::kIncremental, {},
            "incremental (one model grown image by image)" + chosen +
                (chosen.empty() ? "" : "at most " + std::to_string(options.hierarchical_limit) + " images")};
  }
  return {MapperChoice::kHierarchical, {},
          "hierarchical (clusters of at most " + std::to_string(options.hierarchical_cluster_images) +
              " images mapped apart, then merged)" + chosen +
              (chosen.empty() ? "" : std::to_string(num_images) + " images, more than " +
                                         std::to_string(options.hierarchical_limit) + " for one incremental model")};
}

bool MayUseKeyPhotos(const ReconstructOptions& options, int num_images) {
  return options.mapper == MapperChoice::kKeyPhotos ||
         (options.mapper == MapperChoice::kAuto && num_images > options.exhaustive_limit);
}

KeyPhotoOptions KeyPhotoOptionsFor(const ReconstructOptions& options) {
  return {options.sequential_overlap - 1, options.key_photo_shared};
}

MapperPlan PlanKeyPhotos(const ReconstructOptions& options, int num_images,
                         std::optional<std::vector<std::string>> keys) {
  const std::string rule = "consecutive keys share at least " + PercentText(options.key_photo_shared) +
                           " of their features in verified matches";
  if (!keys) {
    return {MapperChoice::kKeyPhotos, {},
            "key photos where neighbours in name order see nearly the same (" + rule + "), else " +
                PlanByCount(options, num_images).description + "; decided from the matches"};
  }
  if (static_cast<int>(keys->size()) == num_images) {
    MapperPlan plan = PlanByCount(options, num_images);
    plan.description += "; every photo is a key photo (consecutive photos share less than " +
                        PercentText(options.key_photo_shared) + " of their features)";
    return plan;
  }
  const std::string chosen = options.mapper == MapperChoice::kAuto
                                 ? ", chosen automatically: " + std::to_string(num_images) + " images, more than " +
                                       std::to_string(options.exhaustive_limit) + ", and neighbours in name order "
                                       "see nearly the same"
                                 : "";
  const int key_count = static_cast<int>(keys->size());
  return {MapperChoice::kKeyPhotos, std::move(*keys),
          "key photos (one incremental model of " + std::to_string(key_count) + " key photos, " + rule +
              "; the other " + std::to_string(num_images - key_count) + " registered to it)" + chosen};
}

std::set<std::string> HeldOutPhotos(const std::vector<std::string>& names, int every,
                                    const std::vector<std::string>& named) {
  std::set<std::string> held_out;
  for (size_t i = 0; every > 0 && i < names.size(); i += static_cast<size_t>(every)) held_out.insert(names[i]);
  for (const std::string& name : named) {
    if (std::find(names.begin(), names.end(), name) == names.end()) {
      throw BadInputError("--hold-out-photos: " + name + " is not one of the photos");
    }
    held_out.insert(name);
  }
  if (!held_out.empty() && names.size() < held_out.size() + 2) {
    throw BadInputError("holding out " + std::to_string(held_out.size()) + " of " + std::to_string(names.size()) +
                        " photos leaves fewer than two to reconstruct from");
  }
  return held_out;
}

bool RefinesPrincipalPoint(const CameraSetup& camera, const ReconstructOptions& options, int num_images) {
  return camera.sharing == CameraSharing::kAll && !camera.fixed_intrinsics &&
         num_images >= options.refine_principal_point_min_images;
}

std::vector<std::vector<std::string>> PhotoFolds(const SparseModel& model, size_t folds) {
  std::vector<std::string> names;
  for (const SparseImage& image : model.Images()) names.push_back(image.name);
  std::sort(names.begin(), names.end());
  std::vector<std::vector<std::string>> result(std::min(folds, names.size()));
  for (size_t i = 0; i < names.size(); ++i) result[i % result.size()].push_back(names[i]);
  return result;
}

namespace {

Eigen::Vector2d PrincipalPoint(const Camera& camera) { return {camera.PrincipalX(), camera.PrincipalY()}; }

Eigen::Vector2d ImageCentre(const Camera& camera) {
  return {0.5 * static_cast<double>(camera.width), 0.5 * static_cast<double>(camera.height)};
}

// The folds' left-out reprojection error together: the RMS over all their observations.
double PooledRms(const std::vector<FoldPrediction>& folds, LeftOutError FoldPrediction::*side) {
  double squares = 0;
  size_t observations = 0;
  for (const FoldPrediction& fold : folds) {
    const LeftOutError& error = fold.*side;
    squares += error.rms_px * error.rms_px * static_cast<double>(error.observations);
    observations += error.observations;
  }
  return observations == 0 ? 0 : std::sqrt(squares / static_cast<double>(observations));
}

}  // namespace

bool PrincipalPointDrifted(const SparseModel& refined, const ReconstructOptions& options) {
  return std::any_of(refined.Cameras().begin(), refined.Cameras().end(), [&](const Camera& camera) {
    return PrincipalPointOffset(camera) > options.max_refined_principal_point_offset;
  });
}

PrincipalPointCheck CheckRefinedPrincipalPoint(const SparseModel& refined, const std::vector<FoldPrediction>& folds,
                                               double deviation_px, const ReconstructOptions& options) {
  // The camera farthest off-centre, and the one least far in standard deviations.
  double worst_offset = 0, least_significance = HUGE_VAL;
  for (const Camera& camera : refined.Cameras()) {
    worst_offset = std::max(worst_offset, PrincipalPointOffset(camera));
    least_significance = std::min(
        least_significance, (PrincipalPoint(camera) - ImageCentre(camera)).norm() / std::max(deviation_px, 1e-9));
  }
  char note[400];
  if (PrincipalPointDrifted(refined, options)) {
    std::snprintf(note, sizeof(note),
                  "principal point kept at the image centre: the refined one drifted %.1f%% of the image size "
                  "off-centre (not observable in these photos)", 100 * worst_offset);
    return {false, note};
  }
  if (folds.size() < 2) throw InternalError("CheckRefinedPrincipalPoint needs two folds or more");
  const double centre_px = PooledRms(folds, &FoldPrediction::centre);
  const double freed_px = PooledRms(folds, &FoldPrediction::freed);
  const double gain = 1 - freed_px / std::max(centre_px, 1e-12);
  const bool keep = gain > 0 && (gain >= options.min_principal_point_prediction_gain ||
                                 least_significance >= options.min_principal_point_deviations);
  const auto better = std::count_if(folds.begin(), folds.end(), [](const FoldPrediction& fold) {
    return fold.freed.rms_px < fold.centre.rms_px;
  });
  std::snprintf(note, sizeof(note),
                "principal point %s: the refined one is %.1f%% off-centre, %.1f standard deviations (%.1f px by the "
                "jackknife over %d folds of the photos), and predicts the photos left out of it at %.3f px against "
                "%.3f px from the centre (better in %d of the folds)",
                keep ? "refined in a final bundle adjustment" : "kept at the image centre", 100 * worst_offset,
                least_significance, deviation_px, static_cast<int>(folds.size()), freed_px, centre_px,
                static_cast<int>(better));
  return {keep, note};
}

}  // namespace parallax
