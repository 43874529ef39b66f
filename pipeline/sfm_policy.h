#pragma once
// The decisions of the structure-from-motion stages (pipeline/sfm_stages.h) that need neither
// colmap nor files: the camera setup, the extraction runs, the matcher, the mapper plan, what
// each quality asks of colmap, and report.json's sentences on them. Pure functions.
#include <cstdint>
#include <optional>
#include <set>
#include <string>
#include <vector>

#include "colmap/database.h"
#include "core/camera.h"
#include "core/quality.h"
#include "core/sparse_model.h"
#include "core/workspace.h"
#include "pipeline/key_photos.h"
#include "pipeline/reconstruct_options.h"
#include "sfm/photo_prediction.h"
#include "sfm/photo_set.h"
#include "sfm/quality_settings.h"

namespace parallax {

// Which photos share one camera (one set of intrinsics) in COLMAP's database.
enum class CameraSharing {
  kAll,       // One camera for every photo.
  kPerGroup,  // One camera per PhotoSet::CameraGroups group: per size and EXIF camera.
  kPerPhoto,  // One camera each (a known model with a camera per image).
};

// The COLMAP image model the extractor starts from, and its parameters when they are fixed.
struct CameraSetup {
  CameraModel model;
  std::string params;  // Empty: COLMAP estimates them, from EXIF or the image size.
  CameraSharing sharing;
  bool fixed_intrinsics;
};

// report.json's words for the camera setup, e.g. "SIMPLE_RADIAL, one shared camera".
std::string DescribeCameraSetup(const CameraSetup& camera, const PhotoSet& photos);

// The camera model and intrinsics SfM starts from: the known model's, the given intrinsics
// (fixed), or `options.camera_model` estimated. Throws BadInputError for --intrinsics f on
// photos of different sizes.
CameraSetup ChooseCameraSetup(const PhotoSet& photos, const ReconstructOptions& options,
                              const SparseModel* known);

// The photos' names, in name order.
std::vector<std::string> PhotoNames(const PhotoSet& photos);

// One feature_extractor run: the photos it reads, and whether they share one camera.
struct ExtractionRun {
  std::vector<std::string> names;
  bool single_camera;
};

// The extractor runs that give the photos the cameras `sharing` asks for: COLMAP shares a
// camera only among the photos of one run. Photos alone in their group are read in one run,
// after the others.
std::vector<ExtractionRun> ExtractionRuns(const PhotoSet& photos, CameraSharing sharing);

// The sentence report.json notes for the photos converted into the workspace's readable copy
// (Workspace::ReadablePhotos), or "" when there were none.
std::string DescribeConversions(const PhotoSet& photos, const Workspace& workspace);

// COLMAP publishes trees of 32K words for sets of up to about 1,000 images. parallax builds
// one from the features of at most 30 of the photos: colmap's k-means costs about 140 s of CPU
// for 25 photos' features already, and the cost would grow with the set.
constexpr int kVocabularyTreeWords = 32768;
constexpr int kVocabularyTreeTrainingImages = 30;

// The words of the tree for `num_images` photos with `descriptors` features in all: colmap
// needs at least one descriptor a word among the photos it samples, half of them to be safe
// (the sample is random). Between 1 and kVocabularyTreeWords.
int64_t VocabularyTreeWords(int num_images, int64_t descriptors);

// The matcher for `num_images` photos: the user's choice, exhaustive for an automatic choice
// up to the limit, and kAuto past it (sequential or retrieval, decided in the matches stage).
MatcherChoice MatcherFor(const ReconstructOptions& options, int num_images);
// The share of the photos consecutive in name order (`names`) whose pair is among the verified
// `pairs`: 0 for fewer than 2 photos.
double ConsecutiveShare(const std::vector<std::string>& names, const std::vector<VerifiedPair>& pairs);
// The automatic matcher past the exhaustive limit: sequential for an ordered capture (at least
// `options.ordered_share` of the consecutive photos match), else retrieval.
MatcherChoice MatcherForConsecutiveShare(const ReconstructOptions& options, double consecutive_share);
// report.json's sentence for the matcher that ran (never kAuto), and why when it was chosen
// automatically; past the exhaustive limit the choice rests on `consecutive_share`, which must
// then be given. Throws InternalError for kAuto.
std::string DescribeMatcher(MatcherChoice matcher, const ReconstructOptions& options, int num_images,
                            std::optional<double> consecutive_share);
// What report.json says of the matcher before matching (a dry run's plan); the matches stage
// writes what it did into Workspace::MatchedMarker.
std::string PlannedMatcher(const ReconstructOptions& options, int num_images);

// How the model is mapped: the user's choice, or the automatic one and why.
struct MapperPlan {
  MapperChoice mapper = MapperChoice::kIncremental;  // Never kAuto.
  std::vector<std::string> key_photos;                // kKeyPhotos: in name order.
  std::string description;                            // report.json's sentence.
};

// The plan with --known-cameras: nothing to map, only points to triangulate.
MapperPlan TriangulationPlan();
// Incremental or hierarchical, by the user's choice or the photo count (hierarchical past
// `options.hierarchical_limit`).
MapperPlan PlanByCount(const ReconstructOptions& options, int num_images);
// Whether key photos may be mapped: asked for, or chosen automatically past the exhaustive
// limit (where the capture then decides, PlanKeyPhotos).
bool MayUseKeyPhotos(const ReconstructOptions& options, int num_images);
// KeyPhotos' options for `options`: the sequential matcher's window, the shared share.
KeyPhotoOptions KeyPhotoOptionsFor(const ReconstructOptions& options);
// The plan where MayUseKeyPhotos: the key photos `keys` (KeyPhotos, from the verified matches),
// or none yet before matching (a dry run says they are decided from the matches). When every
// photo is a key, PlanByCount's plan, saying so.
MapperPlan PlanKeyPhotos(const ReconstructOptions& options, int num_images,
                         std::optional<std::vector<std::string>> keys);

// The photos held out (ReconstructOptions::hold_out_every, hold_out_photos) among `names` (in
// name order): every `every`-th from the first, and those `named`. Throws BadInputError naming a
// photo that is not among them, or when fewer than two photos would be left.
std::set<std::string> HeldOutPhotos(const std::vector<std::string>& names, int every,
                                    const std::vector<std::string>& named);

// Whether the mapper ends with a bundle adjustment that frees the principal point: one shared
// camera whose intrinsics are estimated, from `options.refine_principal_point_min_images`.
bool RefinesPrincipalPoint(const CameraSetup& camera, const ReconstructOptions& options, int num_images);

// How many folds of the photos the principal point is checked on (every K-th registered photo
// by name left out of each; one photo each where there are no more photos than folds).
inline constexpr size_t kPrincipalPointFolds = 8;

// The registered photos of `model` in `folds` folds: photo i by name in fold i mod
// min(folds, photos).
std::vector<std::vector<std::string>> PhotoFolds(const SparseModel& model, size_t folds);

// One fold of the cross-validation by photos (sfm/photo_prediction.h): the reprojection error of
// the photos it left out, predicted by the other photos adjusted with the principal point at the
// centre and freed.
struct FoldPrediction {
  LeftOutError centre;
  LeftOutError freed;
};

// Whether a refined principal point lies past `options.max_refined_principal_point_offset` of
// the image size from the centre: drifted where the photos do not show it.
bool PrincipalPointDrifted(const SparseModel& refined, const ReconstructOptions& options);

// Whether a model whose principal points were refined is kept, and report.json's note saying
// which and why. Kept where the point has not drifted (PrincipalPointDrifted; `folds` may then
// be empty) and predicts the photos left out of it (`folds`) better than the centre does: by
// the share `options.min_principal_point_prediction_gain` of their reprojection error, or by
// less where it lies `options.min_principal_point_deviations` times `deviation_px` (its
// standard deviation, camera_uncertainty.h) off the centre. Otherwise the centre stays, as
// COLMAP keeps it by default: along a narrow arc a shifted principal point trades against the
// rotations, fits the photos it was adjusted on and predicts no others.
struct PrincipalPointCheck {
  bool keep = false;
  std::string note;
};
PrincipalPointCheck CheckRefinedPrincipalPoint(const SparseModel& refined, const std::vector<FoldPrediction>& folds,
                                               double deviation_px, const ReconstructOptions& options);

}  // namespace parallax
