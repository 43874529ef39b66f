#include "pipeline/sfm_stages.h"

#include <algorithm>
#include <array>
#include <cstdio>
#include <fstream>
#include <functional>
#include <numbers>
#include <optional>
#include <set>
#include <string_view>
#include <utility>

#include <tbb/parallel_for.h>
#include <tbb/task_arena.h>

#include "colmap/database.h"
#include "colmap/raw_model.h"
#include "colmap/verification.h"
#include "core/atomic_file.h"
#include "core/error.h"
#include "core/interrupt.h"
#include "core/hash.h"
#include "core/pose.h"
#include "pipeline/camera_uncertainty.h"
#include "pipeline/key_photos.h"
#include "pipeline/raw_model_workspace.h"
#include "pipeline/undistort_workspace.h"
#include "sfm/pair_matching.h"
#include "sfm/photo_conversion.h"

namespace parallax {
namespace fs = std::filesystem;
namespace {

// A colmap database being written, and the files SQLite keeps beside it: an interrupted run
// removes them all (core/interrupt.h).
struct TemporaryDatabase {
  explicit TemporaryDatabase(const fs::path& path)
      : file(path), wal(path.string() + "-wal"), shm(path.string() + "-shm"), journal(path.string() + "-journal") {}
  TemporaryOutput file, wal, shm, journal;
};

// The vocabulary tree sequential and retrieval matching read: the user's, or the one the
// vocabulary tree stage built.
fs::path VocabularyTreeFile(const SfmContext& sfm) {
  return sfm.options.vocab_tree.empty() ? sfm.workspace.VocabularyTree() : sfm.options.vocab_tree;
}

// The content of `file`, read in pieces (COLMAP's largest pre-built tree is about 1 GB).
// Throws BadInputError naming a file that cannot be read.
std::string HashFileContent(const fs::path& file) {
  std::ifstream stream(file, std::ios::binary);
  if (!stream) throw BadInputError("cannot read " + file.string());
  Hasher hasher;
  std::string piece(1 << 20, '\0');
  while (stream) {
    stream.read(piece.data(), static_cast<std::streamsize>(piece.size()));
    hasher.Add(std::string_view(piece.data(), static_cast<size_t>(stream.gcount())));
  }
  if (stream.bad()) throw BadInputError("cannot read " + file.string());
  return hasher.Hex();
}

// One run of the matches stage: colmap's matchers on the database being written.
struct Matching {
  const SfmContext& sfm;
  fs::path database;
  std::vector<std::string> options;  // Matching options every matcher takes, beside the database.

  // Matches each photo with the next in name order and returns the share of those pairs that
  // verified. The pairs stay in the database; the matchers after skip them.
  double MatchConsecutive() const {
    std::vector<std::string> arguments = Arguments();
    // colmap's overlap counts the image itself: 2 pairs it with the next one only.
    arguments.insert(arguments.end(), {"--SequentialMatching.overlap", "2",
                                       "--SequentialMatching.quadratic_overlap", "0"});
    Run("sequential_matcher", arguments, "matches, consecutive photos");
    return ConsecutiveShare(PhotoNames(sfm.photos), ReadVerifiedPairs(database));
  }

  void Run(MatcherChoice matcher) const {
    std::vector<std::string> arguments = Arguments();
    const std::string tree = VocabularyTreeFile(sfm).string();
    const std::string neighbours = std::to_string(sfm.options.retrieval_images);
    switch (matcher) {
      case MatcherChoice::kExhaustive:
        return VerifyMatches(sfm.colmap, database, MatchEveryPair(), tbb::this_task_arena::max_concurrency(),
                             options, sfm.workspace.Log("matches"), "matches, verification", sfm.progress);
      case MatcherChoice::kSequential:
        arguments.insert(arguments.end(),
                         {"--SequentialMatching.overlap", std::to_string(sfm.options.sequential_overlap),
                          "--SequentialMatching.loop_detection", "1",
                          "--SequentialMatching.loop_detection_num_images", neighbours,
                          "--SequentialMatching.vocab_tree_path", tree});
        return Run("sequential_matcher", arguments, "matches");
      case MatcherChoice::kRetrieval:
        arguments.insert(arguments.end(), {"--VocabTreeMatching.num_images", neighbours,
                                           "--VocabTreeMatching.vocab_tree_path", tree});
        return Run("vocab_tree_matcher", arguments, "matches");
      case MatcherChoice::kAuto: throw InternalError("the automatic matcher is not decided");
    }
  }

  // Matches every pair of photos in the database by brute force (sfm/pair_matching.h), pairs on
  // all cores, and stores the matches for colmap to verify. Returns the pairs (image ids, in
  // their order).
  std::vector<std::array<uint32_t, 2>> MatchEveryPair() const {
    std::vector<uint32_t> ids;
    for (const auto& [name, image] : ReadDatabaseImages(database)) ids.push_back(image.image_id);
    std::sort(ids.begin(), ids.end());
    std::vector<std::array<uint32_t, 2>> pairs;
    for (size_t i = 0; i < ids.size(); ++i) {
      for (size_t j = i + 1; j < ids.size(); ++j) pairs.push_back({ids[i], ids[j]});
    }
    const auto total = static_cast<int64_t>(pairs.size());
    sfm.progress.Update("matches", 0, total);
    MatchAndStorePairs(database, pairs,
                       [&](size_t done) { sfm.progress.Update("matches", static_cast<int64_t>(done), total); });
    return pairs;
  }

  std::vector<std::string> Arguments() const {
    std::vector<std::string> arguments = {"--database_path", database.string()};
    arguments.insert(arguments.end(), options.begin(), options.end());
    return arguments;
  }

  void Run(const std::string& command, const std::vector<std::string>& arguments,
           const std::string& label) const {
    sfm.colmap.Run(command, arguments, sfm.workspace.Log("matches"), label,
                   static_cast<int>(sfm.photos.photos.size()), sfm.progress);
  }
};

std::string ImageListText(const std::vector<std::string>& names) {
  std::string list;
  for (const std::string& name : names) list += name + "\n";
  return list;
}

// How many of the photos' pixels one pixel of the photos as SIFT saw them spans (1 where
// SIFT saw them whole): keypoints of downscaled photos are that much coarser.
double ExtractionScale(const SparseModel& model, Quality quality) {
  const double extracted_px = SettingsFor(quality).max_image_size;
  double scale = 1;
  for (const Camera& camera : model.Cameras()) {
    scale = std::max(scale, static_cast<double>(std::max(camera.width, camera.height)) / extracted_px);
  }
  return scale;
}

// After mapping, observations farther than this from their point's projection (in pixels of
// the photos as SIFT saw them) are dropped and the model is adjusted again. colmap's mapper keeps
// up to 4 px, and under squared errors that tail of mismatched or coarse keypoints sets the
// poses (docs/cameras.md, "The tail of the observations").
// The same bound clips a left-out photo's residuals where the principal point is judged by
// prediction.
constexpr double kMaxReprojectionErrorPx = 1;

// A final bundle adjustment that also frees the principal point, written over the raw model
// only where CheckRefinedPrincipalPoint keeps it, after the same adjustment with the centre and
// freed on each fold of the photos left out (PhotoFolds; a point that drifted past the limit is
// not kept whatever the folds say, and they are adjusted with the centre only). Returns the
// check (keep, report.json's note) and writes the kept cameras' uncertainty by the jackknife
// over the folds.
PrincipalPointCheck RefinePrincipalPoint(const SfmContext& sfm) {
  const std::vector<std::string> refine = {"--BundleAdjustment.refine_principal_point", "1"};
  const SparseModel model = AdjustRawModel(sfm.colmap, sfm.workspace, refine, "refine", sfm.progress);
  const SparseModel raw = ReadSparseModel(sfm.workspace.RawModel());
  // The folds' adjustments stop where the cost changes by less than a millionth: colmap's
  // default (none) took 36 iterations instead of 6 on herz-jesu-p8 to move the point 0.06 px.
  const std::vector<std::string> centred = {"--BundleAdjustment.function_tolerance", "1e-6"};
  std::vector<std::string> freed_options = centred;
  freed_options.insert(freed_options.end(), refine.begin(), refine.end());
  const bool drifted = PrincipalPointDrifted(model, sfm.options);
  const double clip_px = kMaxReprojectionErrorPx * ExtractionScale(raw, sfm.options.quality);
  std::vector<FoldPrediction> folds;
  std::vector<SparseModel> centred_folds, freed_folds;
  for (const std::vector<std::string>& left_out : PhotoFolds(raw, kPrincipalPointFolds)) {
    const std::set<std::string> names(left_out.begin(), left_out.end());
    const SparseModel centre = AdjustModel(sfm.colmap, sfm.workspace, SelectImages(raw, names, false), centred,
                                           "predict_centre", sfm.progress);
    centred_folds.push_back(CamerasAndPoses(centre));
    if (drifted) continue;
    // From the whole's refined point, which the fold's is near.
    const SparseModel freed = AdjustModel(sfm.colmap, sfm.workspace, SelectImages(model, names, false),
                                          freed_options, "predict_freed", sfm.progress);
    folds.push_back(
        {LeftOutPhotoError(centre, raw, left_out, clip_px), LeftOutPhotoError(freed, raw, left_out, clip_px)});
    freed_folds.push_back(CamerasAndPoses(freed));
  }
  const CameraUncertainty freed = drifted ? CameraUncertainty{} : JackknifeUncertainty(model, freed_folds);
  const PrincipalPointCheck check = CheckRefinedPrincipalPoint(model, folds, freed.principal_point_px, sfm.options);
  if (check.keep) WriteSparseModel(model, sfm.workspace.RawModel(), SparseFormat::kBinary);
  const CameraUncertainty kept = check.keep ? freed : JackknifeUncertainty(raw, centred_folds);
  WriteCameraUncertainty(kept, sfm.workspace.CameraUncertainty());
  return check;
}

size_t Observations(const SparseModel& model) {
  size_t observations = 0;
  for (const Point3D& point : model.Points3D()) observations += point.track.size();
  return observations;
}

// The raw model without its observations over kMaxReprojectionErrorPx, adjusted again (the
// intrinsics held with `hold_intrinsics`, the principal point always; `adjustment`: more
// bundle_adjuster options); returns report.json's note.
std::string FilterAndAdjustRawModel(const SfmContext& sfm, bool hold_intrinsics,
                                    const std::vector<std::string>& adjustment = {}) {
  const SparseModel raw = ReadSparseModel(sfm.workspace.RawModel());
  const double threshold_px = kMaxReprojectionErrorPx * ExtractionScale(raw, sfm.options.quality);
  const SparseModel filtered = RunOnRawModel(sfm.colmap, sfm.workspace, "point_filtering",
                                             {"--max_reproj_error", std::to_string(threshold_px)}, "filter", 0,
                                             sfm.progress);
  WriteSparseModel(filtered, sfm.workspace.RawModel(), SparseFormat::kBinary);
  std::vector<std::string> options = adjustment;
  if (hold_intrinsics) {
    options.insert(options.end(),
                   {"--BundleAdjustment.refine_focal_length", "0", "--BundleAdjustment.refine_extra_params", "0"});
  }
  WriteSparseModel(AdjustRawModel(sfm.colmap, sfm.workspace, options, "filter_adjust", sfm.progress),
                   sfm.workspace.RawModel(), SparseFormat::kBinary);
  char note[200];
  std::snprintf(note, sizeof note,
                "observations over %.2f px from their points dropped (%zu of %zu) and the model adjusted again",
                threshold_px, Observations(raw) - Observations(filtered), Observations(raw));
  return note;
}

// The mapper built its tracks while the cameras were still moving and kept the observations
// that agreed with the cameras then; the tail filter keeps those that still agree. Where a
// capture holds the poses loosely (castle-p19's loop of facades), those tracks hold the cameras
// near where the mapper left them: tracks built afresh from the verified matches with the
// adjusted cameras, filtered and adjusted again, move them on, round after round
// (docs/cameras.md, "Tracks built afresh").
// Rounds stop once no photo turns against another by more than this from one round to the next
// (in pixels at the focal length, of the photos as SIFT saw them), or after
// ReconstructOptions::max_retriangulations.
constexpr double kSettledTurnPx = 0.5;

// The largest change from `before` to `after` of the rotation between two photos (so whatever
// frame either model is in), in pixels at the largest focal length of `after`'s cameras.
double LargestRelativeTurnPx(const SparseModel& before, const SparseModel& after) {
  double focal_px = 0;
  for (const Camera& camera : after.Cameras()) focal_px = std::max({focal_px, camera.FocalX(), camera.FocalY()});
  std::vector<std::pair<Eigen::Quaterniond, Eigen::Quaterniond>> rotations;  // before, after
  for (const SparseImage& image : after.Images()) {
    const SparseImage* earlier = before.FindImageByName(image.name);
    if (earlier) rotations.emplace_back(earlier->cam_from_world.rotation, image.cam_from_world.rotation);
  }
  double largest_deg = 0;
  for (size_t i = 0; i < rotations.size(); ++i) {
    for (size_t j = i + 1; j < rotations.size(); ++j) {
      const Eigen::Quaterniond was = rotations[i].first * rotations[j].first.conjugate();
      const Eigen::Quaterniond is = rotations[i].second * rotations[j].second.conjugate();
      largest_deg = std::max(largest_deg, RotationAngleDeg(was, is));
    }
  }
  return largest_deg * std::numbers::pi / 180 * focal_px;
}

// Tracks built afresh from the raw model's cameras, then filtered and adjusted with the
// intrinsics held, in rounds until the cameras settle; returns report.json's note.
std::string RetriangulateUntilSettled(const SfmContext& sfm) {
  SparseModel before = ReadSparseModel(sfm.workspace.RawModel());
  const double settled_px = kSettledTurnPx * ExtractionScale(before, sfm.options.quality);
  int rounds = 0;
  double turn_px = 0;
  do {
    WriteSparseModel(RetriangulateRawModel(sfm.colmap, sfm.workspace, sfm.photos_dir, sfm.progress),
                     sfm.workspace.RawModel(), SparseFormat::kBinary);
    // The intrinsics stay as the adjustments before left them: freed here, the focal length
    // traded with the rotations of photos along an arc. Each adjustment stops where the cost
    // changes by less than a millionth (in under half the time): the next round goes on from there.
    FilterAndAdjustRawModel(sfm, true, {"--BundleAdjustment.function_tolerance", "1e-6"});
    SparseModel after = ReadSparseModel(sfm.workspace.RawModel());
    turn_px = LargestRelativeTurnPx(before, after);
    before = std::move(after);
    ++rounds;
    sfm.progress.Update("mapper, tracks built afresh", rounds, sfm.options.max_retriangulations);
  } while (turn_px > settled_px && rounds < sfm.options.max_retriangulations);
  char note[240];
  std::snprintf(note, sizeof note,
                "tracks built afresh from the adjusted cameras, filtered and adjusted again: %d round%s, the "
                "last turning two photos against each other by %.2f px at most%s",
                rounds, rounds == 1 ? "" : "s", turn_px,
                turn_px > settled_px ? " (not settled: the rounds' limit)" : "");
  return note;
}

}  // namespace

fs::path ReadablePhotosDir(const fs::path& photos_dir, const PhotoSet& photos,
                           const Workspace& workspace) {
  return photos.NeedsConversion() ? workspace.ReadablePhotos() : photos_dir;
}

Stage PhotosStage(const fs::path& photos_dir, const PhotoSet& photos, const Workspace& workspace,
                  Progress& progress) {
  Stage stage;
  stage.name = "photos";
  stage.key = Hasher().Add(photos.ContentHash()).Add("photos-1").Hex();
  if (!photos.NeedsConversion()) {
    stage.not_needed = "every photo is an 8-bit RGB JPEG or PNG, upright: colmap reads them as "
                       "they are (nothing converted)";
    stage.run = [] {};
    return stage;
  }
  stage.outputs = {workspace.ReadablePhotos()};
  stage.run = [photos_dir, &photos, workspace, &progress] {
    const fs::path output = workspace.ReadablePhotos().string() + ".tmp";
    const TemporaryOutput temporary(output);
    RemoveAll(output);
    fs::create_directories(output);
    const int total = static_cast<int>(photos.photos.size());
    progress.Update("photos", 0, total);
    // Conversions in parallel, progress from this thread only (core/progress.h).
    for (int start = 0; start < total; start += 16) {
      const int end = std::min(total, start + 16);
      tbb::parallel_for(start, end, [&](int i) {
        const Photo& photo = photos.photos[static_cast<size_t>(i)];
        const fs::path from = photos_dir / photo.name;
        const fs::path to = output / photo.name;
        if (!photo.conversion.empty()) return WriteReadablePhoto(from, to);
        std::error_code error;
        fs::create_hard_link(from, to, error);
        if (error) fs::copy_file(from, to);
      });
      progress.Update("photos", end, total);
    }
    ReplaceFolder(output, workspace.ReadablePhotos());
  };
  return stage;
}

Stage FeaturesStage(const SfmContext& sfm, const std::string& photos_key) {
  const QualitySettings quality = SettingsFor(sfm.options.quality);
  const Workspace& paths = sfm.workspace;
  Stage stage;
  stage.name = "features";
  Hasher hasher;
  // Without conversions the photos stage changes nothing COLMAP reads (and keeps old keys).
  if (sfm.photos.NeedsConversion()) hasher.Add(photos_key);
  if (sfm.camera.sharing == CameraSharing::kPerGroup) hasher.Add("camera per group");
  stage.key = hasher
                  .Add(sfm.photos.ContentHash())
                  .Add(CameraModelName(sfm.camera.model))
                  .Add(sfm.camera.params)
                  .Add(sfm.camera.sharing == CameraSharing::kAll)
                  .Add(static_cast<uint64_t>(quality.max_image_size))
                  .Add(static_cast<uint64_t>(quality.max_num_features))
                  .Hex();
  stage.outputs = {paths.Database()};
  stage.run = [&sfm, quality, paths] {
    fs::create_directories(paths.Sfm());
    const std::vector<ExtractionRun> runs = ExtractionRuns(sfm.photos, sfm.camera.sharing);
    WriteFileAtomically(paths.ImageList(), ImageListText(PhotoNames(sfm.photos)));
    const fs::path database = paths.Database().string() + ".tmp";
    const TemporaryDatabase temporary(database);
    RemoveAll(database);
    const fs::path run_list = paths.Sfm() / "image_list_camera.txt";
    const TemporaryOutput temporary_list(run_list);
    for (size_t i = 0; i < runs.size(); ++i) {
      WriteFileAtomically(run_list, ImageListText(runs[i].names));
      std::vector<std::string> arguments = {
          "--database_path", database.string(), "--image_path", sfm.photos_dir.string(),
          "--image_list_path", run_list.string(),
          "--ImageReader.camera_model", std::string(CameraModelName(sfm.camera.model)),
          "--ImageReader.single_camera", runs[i].single_camera ? "1" : "0",
          "--SiftExtraction.use_gpu", "0",
          "--SiftExtraction.max_image_size", std::to_string(quality.max_image_size),
          "--SiftExtraction.max_num_features", std::to_string(quality.max_num_features)};
      if (!sfm.camera.params.empty()) {
        arguments.insert(arguments.end(), {"--ImageReader.camera_params", sfm.camera.params});
      }
      const std::string label =
          runs.size() == 1 ? "features"
                           : "features, camera group " + std::to_string(i + 1) + "/" + std::to_string(runs.size());
      sfm.colmap.Run("feature_extractor", arguments, paths.Log("features"), label,
                     static_cast<int>(runs[i].names.size()), sfm.progress);
    }
    fs::remove(run_list);
    NumberImagesByName(database);
    fs::rename(database, paths.Database());
  };
  return stage;
}

Stage VocabularyTreeStage(const SfmContext& sfm, const std::string& features_key) {
  const Workspace& paths = sfm.workspace;
  Stage stage;
  stage.name = "vocabulary tree";
  stage.key = Hasher()
                  .Add(features_key)
                  .Add("vocab-tree-1")
                  .Add(static_cast<uint64_t>(kVocabularyTreeWords))
                  .Add(static_cast<uint64_t>(kVocabularyTreeTrainingImages))
                  .Hex();
  if (sfm.matcher == MatcherChoice::kExhaustive) {
    stage.not_needed = "exhaustive matching pairs every image without one";
    stage.run = [] {};
    return stage;
  }
  if (!sfm.options.vocab_tree.empty()) {
    // The matches stage chains this key: another tree, or this one changed, matches again.
    stage.key =
        Hasher().Add(features_key).Add("vocab-tree-file").Add(HashFileContent(sfm.options.vocab_tree)).Hex();
    stage.not_needed = "the vocabulary tree " + sfm.options.vocab_tree.string() + " is used (--vocab-tree)";
    stage.run = [] {};
    return stage;
  }
  stage.outputs = {paths.VocabularyTree()};
  stage.run = [&sfm, paths] {
    const int num_images = static_cast<int>(sfm.photos.photos.size());
    const fs::path tree = paths.VocabularyTree().string() + ".tmp";
    const TemporaryOutput temporary(tree);
    sfm.colmap.Run("vocab_tree_builder",
                   {"--database_path", paths.Database().string(), "--vocab_tree_path",
                    tree.string(), "--num_visual_words",
                    std::to_string(VocabularyTreeWords(num_images, CountDescriptors(paths.Database()))),
                    "--max_num_images",  // colmap refuses more than there are.
                    std::to_string(std::min(num_images, kVocabularyTreeTrainingImages))},
                   paths.Log("vocabulary_tree"), "vocabulary tree", num_images, sfm.progress);
    fs::rename(tree, paths.VocabularyTree());
  };
  return stage;
}

Stage MatchesStage(const SfmContext& sfm, const std::string& features_key,
                   const std::string& vocabulary_tree_key) {
  const QualitySettings quality = SettingsFor(sfm.options.quality);
  const Workspace& paths = sfm.workspace;
  Stage stage;
  stage.name = "matches";
  Hasher hasher;
  hasher.Add(features_key)
      .Add(sfm.matcher != MatcherChoice::kExhaustive)
      .Add(static_cast<uint64_t>(sfm.options.sequential_overlap))
      .Add(quality.guided_matching);
  if (sfm.matcher == MatcherChoice::kExhaustive) {
    hasher.Add("sift-brute-force");  // parallax's matching, colmap's verification.
  } else {
    hasher.Add(vocabulary_tree_key)
        .Add(static_cast<uint64_t>(sfm.matcher))
        .Add(static_cast<uint64_t>(sfm.options.retrieval_images))
        .Add(sfm.options.ordered_share);
  }
  stage.key = hasher.Hex();
  stage.outputs = {paths.MatchedMarker()};
  stage.run = [&sfm, quality, paths] {
    const int num_images = static_cast<int>(sfm.photos.photos.size());
    const fs::path database = paths.Database().string() + ".tmp";
    const TemporaryDatabase temporary(database);
    fs::copy_file(paths.Database(), database, fs::copy_options::overwrite_existing);
    const Matching matching{
        sfm, database, {"--SiftMatching.use_gpu", "0", "--SiftMatching.guided_matching", quality.guided_matching ? "1" : "0"}};
    MatcherChoice matcher = sfm.matcher;
    std::optional<double> consecutive_share;
    if (matcher == MatcherChoice::kAuto) {
      consecutive_share = matching.MatchConsecutive();
      matcher = MatcherForConsecutiveShare(sfm.options, *consecutive_share);
    }
    matching.Run(matcher);
    fs::rename(database, paths.Database());
    WriteFileAtomically(paths.MatchedMarker(),
                        DescribeMatcher(matcher, sfm.options, num_images, consecutive_share));
  };
  return stage;
}

MapperPlan PlanMapper(const SfmContext& sfm) {
  const ReconstructOptions& options = sfm.options;
  const int num_images = static_cast<int>(sfm.photos.photos.size());
  if (sfm.known) return TriangulationPlan();
  if (!MayUseKeyPhotos(options, num_images)) return PlanByCount(options, num_images);
  const fs::path database = sfm.workspace.Database();
  if (!fs::exists(database)) return PlanKeyPhotos(options, num_images, std::nullopt);
  return PlanKeyPhotos(options, num_images,
                       KeyPhotos(PhotoNames(sfm.photos), ReadVerifiedPairs(database), ReadFeatureCounts(database),
                                 KeyPhotoOptionsFor(options)));
}

Stage MapperStage(const SfmContext& sfm, const MapperPlan& plan, const std::string& matches_key,
                  std::vector<std::string>& notes) {
  const Workspace& paths = sfm.workspace;
  const int num_images = static_cast<int>(sfm.photos.photos.size());
  const bool refine_principal_point = RefinesPrincipalPoint(sfm.camera, sfm.options, num_images);
  Stage stage;
  const bool hierarchical = !sfm.known && plan.mapper == MapperChoice::kHierarchical;
  const bool key_photos = !sfm.known && plan.mapper == MapperChoice::kKeyPhotos;
  stage.name = sfm.known ? "triangulate" : "mapper";
  Hasher hasher;
  hasher.Add(matches_key)
      .Add(sfm.camera.fixed_intrinsics)
      .Add(refine_principal_point)
      .Add(sfm.known ? HashFolder(sfm.options.known_cameras) : 0);
  // Only a refining mapper's key changed with the principal point's check.
  if (refine_principal_point) hasher.Add("checked by predicting left-out photos");
  // The incremental mapper keeps the keys it had before there was a choice.
  if (hierarchical) {
    hasher.Add("hierarchical").Add(static_cast<uint64_t>(sfm.options.hierarchical_cluster_images)).Add("adjusted-2");
  }
  if (key_photos) hasher.Add("key photos").Add(ImageListText(plan.key_photos));
  if (!sfm.known) hasher.Add("filtered and adjusted-1");
  const bool retriangulates = !sfm.known && !hierarchical && !key_photos && sfm.options.max_retriangulations > 0;
  if (retriangulates) hasher.Add("tracks built afresh-1").Add(static_cast<uint64_t>(sfm.options.max_retriangulations));
  stage.key = hasher.Hex();
  stage.outputs = {paths.RawModel()};
  stage.run = [&sfm, &notes, paths, num_images, refine_principal_point, hierarchical, key_photos, retriangulates,
               keys = plan.key_photos, name = stage.name] {
    const fs::path models = paths.Models().string() + ".tmp";
    const TemporaryOutput temporary(models);
    fs::remove(paths.CameraUncertainty());  // Written again where the principal point's check runs.
    RemoveAll(models);
    fs::create_directories(models);
    if (sfm.known) {
      WriteSparseModel(AlignKnownModelToDatabase(*sfm.known, PhotoNames(sfm.photos), sfm.options.known_cameras,
                                                 paths.Database()),
                       paths.KnownModel(), SparseFormat::kBinary);
      fs::create_directories(models / "0");
      sfm.colmap.Run("point_triangulator", PointTriangulatorArguments(paths, sfm.photos_dir, models / "0"),
                     paths.Log(name), name, num_images, sfm.progress);
    } else if (hierarchical) {
      RunMapper(sfm.colmap, paths, "hierarchical_mapper",
                HierarchicalMapperArguments(paths, sfm.photos_dir, models, sfm.options.hierarchical_cluster_images,
                                            sfm.camera.fixed_intrinsics),
                name, num_images, sfm.progress);
    } else {
      if (key_photos) WriteFileAtomically(paths.KeyPhotoList(), ImageListText(keys));
      RunMapper(sfm.colmap, paths, "mapper",
                MapperArguments(paths, sfm.photos_dir, models, key_photos ? paths.KeyPhotoList() : paths.ImageList(),
                                sfm.camera.fixed_intrinsics),
                name, key_photos ? static_cast<int>(keys.size()) : num_images, sfm.progress);
    }
    ReplaceFolder(models, paths.Models());
    WriteSparseModel(LargestModel(ModelDirs(paths)), paths.RawModel(), SparseFormat::kBinary);
    // With key photos, the principal point is refined on their model: the photos registered
    // to it afterwards are not adjusted (an adjustment of them all costs twice the memory and
    // made the poses worse on the plaza, docs/scale.md).
    bool adjusted = false;
    if (refine_principal_point) {
      const PrincipalPointCheck check = RefinePrincipalPoint(sfm);
      notes.push_back(check.note);
      adjusted = check.keep;
    }
    if (hierarchical && !adjusted) {
      // The hierarchical mapper merges its clusters' models without a final bundle adjustment,
      // as COLMAP's documentation warns; a rejected refinement left the merged model as it was.
      WriteSparseModel(AdjustRawModel(sfm.colmap, paths, {}, "adjust", sfm.progress), paths.RawModel(),
                       SparseFormat::kBinary);
    }
    // After the principal point's check: filtered first, entry-p10's point moved from 0.8% to
    // 0.6% off-centre and the cameras with it (docs/cameras.md, "colmap's accuracy options").
    if (!sfm.known) notes.push_back(FilterAndAdjustRawModel(sfm, sfm.camera.fixed_intrinsics));
    if (retriangulates) notes.push_back(RetriangulateUntilSettled(sfm));
    if (key_photos) {
      WriteSparseModel(RegisterOtherPhotos(sfm.colmap, paths,
                                           sfm.camera.fixed_intrinsics ? FixedIntrinsicsArguments()
                                                                       : std::vector<std::string>{},
                                           num_images, sfm.progress),
                       paths.RawModel(), SparseFormat::kBinary);
    }
  };
  return stage;
}

Stage UndistortStage(const SfmContext& sfm, const std::string& mapper_key,
                     const SparseModel* raw_model) {
  const Workspace& paths = sfm.workspace;
  // "undistort-2": our own resampling replaced image_undistorter's for supported models;
  // models without distortion parameters copy the photos as before, and keep their key (and
  // depth).
  const bool may_distort = sfm.camera.model != CameraModel::kPinhole &&
                           sfm.camera.model != CameraModel::kSimplePinhole;
  Hasher hasher;
  hasher.Add(mapper_key);
  if (may_distort) hasher.Add("undistort-2");
  for (const std::string& name : sfm.held_out) hasher.Add("held out").Add(name);
  Stage stage;
  stage.name = "undistort";
  stage.key = hasher.Hex();
  stage.outputs = {paths.Sparse()};
  if (!sfm.held_out.empty()) stage.outputs.push_back(paths.HeldOut().Sparse());
  if (!raw_model) {
    stage.run = [] {};
    return stage;
  }
  // Cameras without distortion need no resampling: the photos are copied as they are. Models
  // whose projection core implements are resampled by WritePinholeWorkspace; COLMAP's
  // undistorter is left for the others (fisheye models).
  const auto all_cameras = [raw_model](const std::function<bool(const Camera&)>& test) {
    return std::all_of(raw_model->Cameras().begin(), raw_model->Cameras().end(), test);
  };
  const bool distortion_free = all_cameras([](const Camera& c) { return !c.HasDistortion(); });
  const bool supported = all_cameras([](const Camera& c) { return IsProjectionSupported(c.model); });
  if (distortion_free) {
    stage.not_needed = "the cameras have no lens distortion: photos copied, not resampled "
                       "(colmap image_undistorter not needed)";
  }
  if (!supported && !sfm.held_out.empty()) {
    throw BadInputError("--hold-out needs a camera model parallax undistorts itself (not " +
                        std::string(CameraModelName(raw_model->Cameras().front().model)) + ")");
  }
  stage.run = [&sfm, raw_model, paths, supported] {
    const fs::path output = paths.UndistortScratch();
    RemoveAll(output);
    const Workspace undistorted(output);
    if (supported) {
      // The held-out photos' cameras beside, without the points (evaluate renders them).
      WritePinholeWorkspace(SelectImages(*raw_model, sfm.held_out, false), sfm.photos_dir, undistorted);
      if (!sfm.held_out.empty()) {
        WritePinholeWorkspace(CamerasAndPoses(SelectImages(*raw_model, sfm.held_out, true)), sfm.photos_dir,
                              undistorted.HeldOut());
        RemoveAll(undistorted.HeldOut().Stereo());
      }
    } else {
      sfm.colmap.Run("image_undistorter",
                     {"--image_path", sfm.photos_dir.string(), "--input_path",
                      paths.RawModel().string(), "--output_path", output.string(),
                      "--output_type", "COLMAP"},
                     paths.Log("undistort"), "undistort",
                     static_cast<int>(sfm.photos.photos.size()), sfm.progress);
    }
    ReplaceFolder(undistorted.Images(), paths.Images());
    ReplaceFolder(undistorted.Stereo(), paths.Stereo());
    ReplaceFolder(undistorted.Sparse(), paths.Sparse());
    if (fs::exists(undistorted.HeldOut().Root())) {
      ReplaceFolder(undistorted.HeldOut().Root(), paths.HeldOut().Root());
    } else {
      RemoveAll(paths.HeldOut().Root());
    }
    RemoveAll(output);
  };
  return stage;
}

int OtherModelCount(const Workspace& workspace) {
  // Counting the folders is enough here: the largest model was chosen when mapping.
  return static_cast<int>(ModelDirs(workspace).size()) - 1;
}

}  // namespace parallax
