#include "pipeline/sfm_stages.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <functional>
#include <map>
#include <optional>
#include <set>
#include <sstream>
#include <utility>

#include <tbb/parallel_for.h>

#include "colmap/database.h"
#include "core/atomic_file.h"
#include "core/error.h"
#include "core/interrupt.h"
#include "core/hash.h"
#include "pipeline/key_photos.h"
#include "sfm/photo_conversion.h"
#include "sfm/undistort.h"

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

struct QualitySettings {
  int max_image_size;
  int max_num_features;
  bool guided_matching;
};

QualitySettings SettingsFor(Quality quality) {
  switch (quality) {
    case Quality::kFast: return {1024, 2048, false};
    case Quality::kBalanced: return {2000, 4096, false};
    case Quality::kBest: return {3200, 8192, true};
  }
  throw std::invalid_argument("unknown quality");
}

// COLMAP publishes trees of 32K words for sets of up to about 1,000 images. parallax builds
// one from the features of at most 30 of the photos: colmap's k-means costs about 140 s of CPU
// for 25 photos' features already, and the cost would grow with the set.
constexpr int kVocabularyTreeWords = 32768;
constexpr int kVocabularyTreeTrainingImages = 30;

// The words of the tree for `num_images` photos with `descriptors` features in all: colmap
// needs at least one descriptor a word among the photos it samples, half of them to be safe
// (the sample is random).
int64_t VocabularyTreeWords(int num_images, int64_t descriptors) {
  const int64_t sampled = descriptors * std::min(num_images, kVocabularyTreeTrainingImages) /
                          std::max(num_images, 1);
  return std::clamp<int64_t>(sampled / 2, 1, kVocabularyTreeWords);
}

std::string Percent(double share) {
  char text[16];
  std::snprintf(text, sizeof(text), "%.0f%%", 100 * share);
  return text;
}

// Why the automatic matcher is not exhaustive for `num_images` photos.
std::string PastTheLimit(const ReconstructOptions& options, int num_images) {
  return std::to_string(num_images) + " images, more than " +
         std::to_string(options.exhaustive_limit) + " for exhaustive matching";
}

// report.json's sentence for the matcher that ran, and why when it was chosen automatically;
// past the exhaustive limit the choice rests on `consecutive_share` (Matching::ConsecutiveShare).
std::string DescribeMatcher(MatcherChoice matcher, const ReconstructOptions& options,
                            int num_images, std::optional<double> consecutive_share) {
  std::string text;
  switch (matcher) {
    case MatcherChoice::kExhaustive:
      text = "exhaustive (" + std::to_string(num_images) + " images, every pair)";
      break;
    case MatcherChoice::kSequential:
      text = "sequential (each image with the next " +
             std::to_string(options.sequential_overlap - 1) +
             " in name order and those a power of two ahead; loops closed by retrieval from a "
             "vocabulary tree built from these photos)";
      break;
    case MatcherChoice::kRetrieval:
      text = "retrieval (each image with its " + std::to_string(options.retrieval_images) +
             " most similar in a vocabulary tree built from these photos)";
      break;
    case MatcherChoice::kAuto: throw std::invalid_argument("the automatic matcher is not decided");
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

// One run of the matches stage: colmap's matchers on the database being written.
struct Matching {
  const SfmContext& sfm;
  fs::path database;
  std::vector<std::string> common;  // Database and matching options every matcher takes.

  // Matches each photo with the next in name order and returns the share of those pairs that
  // verified. The pairs stay in the database; the matchers after skip them.
  double ConsecutiveShare() const {
    std::vector<std::string> arguments = common;
    // colmap's overlap counts the image itself: 2 pairs it with the next one only.
    arguments.insert(arguments.end(), {"--SequentialMatching.overlap", "2",
                                       "--SequentialMatching.quadratic_overlap", "0"});
    Run("sequential_matcher", arguments, "matches, consecutive photos");
    std::set<std::pair<std::string, std::string>> verified;
    for (const VerifiedPair& pair : ReadVerifiedPairs(database)) {
      verified.insert(std::minmax(pair.first, pair.second));
    }
    const std::vector<Photo>& photos = sfm.photos.photos;
    int consecutive = 0;
    for (size_t i = 0; i + 1 < photos.size(); ++i) {
      consecutive += static_cast<int>(verified.count(std::minmax(photos[i].name, photos[i + 1].name)));
    }
    return photos.size() < 2 ? 0 : static_cast<double>(consecutive) / static_cast<double>(photos.size() - 1);
  }

  void Run(MatcherChoice matcher) const {
    std::vector<std::string> arguments = common;
    const std::string tree = sfm.workspace.VocabularyTree().string();
    const std::string neighbours = std::to_string(sfm.options.retrieval_images);
    switch (matcher) {
      case MatcherChoice::kExhaustive: return Run("exhaustive_matcher", arguments, "matches");
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
      case MatcherChoice::kAuto: throw std::invalid_argument("the automatic matcher is not decided");
    }
  }

  void Run(const std::string& command, const std::vector<std::string>& arguments,
           const std::string& label) const {
    sfm.colmap.Run(command, arguments, sfm.workspace.Log("matches"), label,
                   static_cast<int>(sfm.photos.photos.size()), sfm.progress);
  }
};

std::string Join(const std::vector<double>& values) {
  std::ostringstream text;
  text.precision(17);
  for (size_t i = 0; i < values.size(); ++i) text << (i ? "," : "") << values[i];
  return text.str();
}

// The known model rewritten with the ids COLMAP's database gave the photos, so that
// point_triangulator can match its images and cameras to the features and matches.
SparseModel AlignKnownModelToDatabase(const SparseModel& known, const PhotoSet& photos,
                                      const fs::path& known_dir, const fs::path& database) {
  const std::map<std::string, DatabaseImage> ids = ReadDatabaseImages(database);
  const bool single = known.Cameras().size() == 1;
  SparseModel aligned;
  for (const Photo& photo : photos.photos) {
    const SparseImage* image = known.FindImageByName(photo.name);
    if (!image) {
      throw BadInputError("--known-cameras " + known_dir.string() + " has no image named " +
                          photo.name);
    }
    const auto id = ids.find(photo.name);
    if (id == ids.end()) {
      throw BadInputError(database.string() + " has no image named " + photo.name);
    }
    SparseImage copy = *image;
    copy.id = id->second.image_id;
    copy.camera_id = id->second.camera_id;
    copy.points2d.clear();
    // One shared camera in the database when the known model has one (single_camera).
    if (!(single && !aligned.Cameras().empty())) {
      Camera camera = known.CameraById(image->camera_id);
      camera.id = copy.camera_id;
      aligned.AddCamera(camera);
    }
    aligned.AddImage(std::move(copy));
  }
  return aligned;
}

std::vector<std::string> PhotoNames(const PhotoSet& photos) {
  std::vector<std::string> names;
  for (const Photo& photo : photos.photos) names.push_back(photo.name);
  return names;
}

// One feature_extractor run: the photos it reads, and whether they share one camera.
struct ExtractionRun {
  std::vector<std::string> names;
  bool single_camera;
};

// The extractor runs that give the photos the cameras `sharing` asks for: COLMAP shares a
// camera only among the photos of one run. Photos alone in their group are read in one run.
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

std::string ImageListText(const std::vector<std::string>& names) {
  std::string list;
  for (const std::string& name : names) list += name + "\n";
  return list;
}

// The model colmap `command` writes from the raw model (`--input_path`) with `arguments`, through a
// scratch folder. `total`: the units of work its progress lines count (0: none).
SparseModel RunOnRawModel(const Colmap& colmap, const Workspace& paths, const std::string& command,
                          std::vector<std::string> arguments, const std::string& log_name, int total,
                          Progress& progress) {
  const fs::path output = paths.RefinedModelScratch();
  RemoveAll(output);
  fs::create_directories(output);
  arguments.insert(arguments.end(), {"--input_path", paths.RawModel().string(), "--output_path", output.string()});
  colmap.Run(command, arguments, paths.Log(log_name), log_name, total, progress);
  SparseModel model = ReadSparseModel(output);
  RemoveAll(output);
  return model;
}

// The raw model after one colmap bundle_adjuster run with `options`.
SparseModel AdjustRawModel(const Colmap& colmap, const Workspace& paths, const std::vector<std::string>& options,
                           const std::string& log_name, Progress& progress) {
  return RunOnRawModel(colmap, paths, "bundle_adjuster", options, log_name, 0, progress);
}

// A final bundle adjustment that also frees the principal point, kept only when the point
// stays near the image centre: where it is unobservable (a narrow arc of small images) it
// drifts far off and the rotations with it.
std::string RefinePrincipalPoint(const Colmap& colmap, const Workspace& paths,
                                 const ReconstructOptions& options, Progress& progress) {
  const SparseModel model =
      AdjustRawModel(colmap, paths, {"--BundleAdjustment.refine_principal_point", "1"}, "refine", progress);
  double worst_offset = 0;
  for (const Camera& camera : model.Cameras()) {
    worst_offset = std::max(worst_offset, PrincipalPointOffset(camera));
  }
  char note[160];
  if (worst_offset > options.max_refined_principal_point_offset) {
    std::snprintf(note, sizeof(note),
                  "principal point refinement rejected: it drifted %.1f%% of the image size "
                  "off-centre (not observable in these photos)", 100 * worst_offset);
  } else {
    WriteSparseModel(model, paths.RawModel(), SparseFormat::kBinary);
    std::snprintf(note, sizeof(note),
                  "principal point refined in a final bundle adjustment (%.1f%% off-centre)",
                  100 * worst_offset);
  }
  return note;
}

// The raw model with every other photo the database can place registered to its points (colmap
// image_registrator: each photo's pose from its matches with the model's points; no points are
// added and the model is not adjusted).
SparseModel RegisterOtherPhotos(const SfmContext& sfm, const std::vector<std::string>& options) {
  std::vector<std::string> arguments = {"--database_path", sfm.workspace.Database().string()};
  arguments.insert(arguments.end(), options.begin(), options.end());
  return RunOnRawModel(sfm.colmap, sfm.workspace, "image_registrator", arguments, "register",
                       static_cast<int>(sfm.photos.photos.size()), sfm.progress);
}

// The model folders the mapper wrote, in name order. Throws BadInputError when there is none.
std::vector<fs::path> ModelDirs(const Workspace& paths) {
  const fs::path models_dir = paths.Models();
  std::vector<fs::path> dirs;
  for (const auto& entry : fs::directory_iterator(models_dir)) {
    if (entry.is_directory() && DetectSparseFormat(entry.path())) dirs.push_back(entry.path());
  }
  if (dirs.empty()) {
    throw BadInputError("COLMAP could not reconstruct these photos (no image pair with "
                        "enough matches to start from); see " +
                        paths.Log("mapper").string());
  }
  std::sort(dirs.begin(), dirs.end());
  return dirs;
}

// Why the mapper found no pair of photos to start from, where the verified matches show it: no
// pair at all, or only pairs one homography explains (photos from one spot, near-identical
// copies). "" when the matches do not explain it.
std::string NoInitialPairReason(const fs::path& database, int num_images) {
  const std::vector<VerifiedPair> pairs = ReadVerifiedPairs(database);
  if (pairs.empty()) {
    return "the photos share no features: no two of the " + std::to_string(num_images) +
           " photos have enough matching features to pass geometric verification (different "
           "scenes, too little texture or too little overlap)";
  }
  const bool no_parallax = std::all_of(pairs.begin(), pairs.end(), [](const VerifiedPair& pair) {
    return pair.geometry == PairGeometry::kPlanarOrPanoramic || pair.geometry == PairGeometry::kPanoramic;
  });
  if (!no_parallax) return "";
  const VerifiedPair& best = *std::max_element(
      pairs.begin(), pairs.end(), [](const VerifiedPair& a, const VerifiedPair& b) { return a.inliers < b.inliers; });
  return "the photos have no parallax: each of the " + std::to_string(pairs.size()) +
         " matched pairs is explained by a homography (the best, " + best.first + " and " + best.second +
         ", by " + std::to_string(best.inliers) + " matches), as for near-identical photos or photos "
         "taken from one spot; take the photos from positions a step or more apart";
}

// Runs the mapper; where it fails for want of a pair to start from and the matches say why,
// that is bad input (exit 2) rather than a tool failure.
void RunMapper(const SfmContext& sfm, const std::string& command, const std::vector<std::string>& arguments,
               const std::string& name, int num_images) {
  const Workspace& paths = sfm.workspace;
  try {
    sfm.colmap.Run(command, arguments, paths.Log(name), name, num_images, sfm.progress);
  } catch (const ToolError&) {
    const std::string reason = NoInitialPairReason(paths.Database(), num_images);
    if (reason.empty()) throw;
    throw BadInputError("COLMAP could not reconstruct these photos: " + reason + "; see " +
                        paths.Log(name).string());
  }
}

// The model with the most registered images (the first of equals).
SparseModel LargestModel(const std::vector<fs::path>& dirs) {
  SparseModel best;
  for (const fs::path& dir : dirs) {
    SparseModel model = ReadSparseModel(dir);
    if (model.Images().size() > best.Images().size()) best = std::move(model);
  }
  return best;
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

MatcherChoice MatcherFor(const ReconstructOptions& options, int num_images) {
  if (options.matcher == MatcherChoice::kAuto && num_images <= options.exhaustive_limit) {
    return MatcherChoice::kExhaustive;
  }
  return options.matcher;
}

std::string PlannedMatcher(const ReconstructOptions& options, int num_images) {
  const MatcherChoice matcher = MatcherFor(options, num_images);
  if (matcher == MatcherChoice::kAuto) {
    return "sequential or retrieval, as the photos' name order says once consecutive photos are "
           "matched (" + PastTheLimit(options, num_images) + ")";
  }
  return DescribeMatcher(matcher, options, num_images, std::nullopt);
}

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
  // Exhaustive matching keeps the key it had before the other matchers came.
  if (sfm.matcher != MatcherChoice::kExhaustive) {
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
    const Matching matching{sfm, database,
                            {"--database_path", database.string(), "--SiftMatching.use_gpu", "0",
                             "--SiftMatching.guided_matching", quality.guided_matching ? "1" : "0"}};
    MatcherChoice matcher = sfm.matcher;
    std::optional<double> consecutive_share;
    if (matcher == MatcherChoice::kAuto) {
      consecutive_share = matching.ConsecutiveShare();
      matcher = *consecutive_share >= sfm.options.ordered_share ? MatcherChoice::kSequential
                                                                : MatcherChoice::kRetrieval;
    }
    matching.Run(matcher);
    fs::rename(database, paths.Database());
    WriteFileAtomically(paths.MatchedMarker(),
                        DescribeMatcher(matcher, sfm.options, num_images, consecutive_share));
  };
  return stage;
}

namespace {

std::string PercentText(double share) { return std::to_string(static_cast<int>(std::lround(100 * share))) + "%"; }

// Incremental or hierarchical, by the user's choice or the photo count.
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

}  // namespace

MapperPlan PlanMapper(const SfmContext& sfm) {
  const ReconstructOptions& options = sfm.options;
  const int num_images = static_cast<int>(sfm.photos.photos.size());
  if (sfm.known) {
    return {MapperChoice::kIncremental, {}, "point_triangulator (known cameras: only the points are triangulated)"};
  }
  const bool may_use_keys = options.mapper == MapperChoice::kKeyPhotos ||
                            (options.mapper == MapperChoice::kAuto && num_images > options.exhaustive_limit);
  if (!may_use_keys) return PlanByCount(options, num_images);
  const std::string rule = "consecutive keys share at least " + PercentText(options.key_photo_shared) +
                           " of their features in verified matches";
  const fs::path database = sfm.workspace.Database();
  if (!fs::exists(database)) {
    return {MapperChoice::kKeyPhotos, {},
            "key photos where neighbours in name order see nearly the same (" + rule + "), else " +
                PlanByCount(options, num_images).description + "; decided from the matches"};
  }
  const KeyPhotoOptions key_options{options.sequential_overlap - 1, options.key_photo_shared};
  std::vector<std::string> keys =
      KeyPhotos(PhotoNames(sfm.photos), ReadVerifiedPairs(database), ReadFeatureCounts(database), key_options);
  if (static_cast<int>(keys.size()) == num_images) {
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
  const int key_count = static_cast<int>(keys.size());
  return {MapperChoice::kKeyPhotos, std::move(keys),
          "key photos (one incremental model of " + std::to_string(key_count) + " key photos, " + rule +
              "; the other " + std::to_string(num_images - key_count) + " registered to it)" + chosen};
}

Stage MapperStage(const SfmContext& sfm, const MapperPlan& plan, const std::string& matches_key,
                  std::vector<std::string>& notes) {
  const Workspace& paths = sfm.workspace;
  const int num_images = static_cast<int>(sfm.photos.photos.size());
  const bool refine_principal_point =
      sfm.camera.sharing == CameraSharing::kAll && !sfm.camera.fixed_intrinsics &&
      num_images >= sfm.options.refine_principal_point_min_images;
  Stage stage;
  const bool hierarchical = !sfm.known && plan.mapper == MapperChoice::kHierarchical;
  const bool key_photos = !sfm.known && plan.mapper == MapperChoice::kKeyPhotos;
  stage.name = sfm.known ? "triangulate" : "mapper";
  Hasher hasher;
  hasher.Add(matches_key)
      .Add(sfm.camera.fixed_intrinsics)
      .Add(refine_principal_point)
      .Add(sfm.known ? HashFolder(sfm.options.known_cameras) : 0);
  // The incremental mapper keeps the keys it had before there was a choice.
  if (hierarchical) hasher.Add("hierarchical").Add(static_cast<uint64_t>(sfm.options.hierarchical_cluster_images));
  if (key_photos) hasher.Add("key photos").Add(ImageListText(plan.key_photos));
  stage.key = hasher.Hex();
  stage.outputs = {paths.RawModel()};
  stage.run = [&sfm, &notes, paths, num_images, refine_principal_point, hierarchical, key_photos,
               keys = plan.key_photos, name = stage.name] {
    const fs::path models = paths.Models().string() + ".tmp";
    const TemporaryOutput temporary(models);
    RemoveAll(models);
    fs::create_directories(models);
    const std::vector<std::string> common = {"--database_path", paths.Database().string(),
                                             "--image_path", sfm.photos_dir.string()};
    const std::vector<std::string> fixed_intrinsics = {"--Mapper.ba_refine_focal_length", "0",
                                                       "--Mapper.ba_refine_principal_point", "0",
                                                       "--Mapper.ba_refine_extra_params", "0"};
    std::vector<std::string> arguments = common;
    if (sfm.known) {
      WriteSparseModel(AlignKnownModelToDatabase(*sfm.known, sfm.photos, sfm.options.known_cameras,
                                                 paths.Database()),
                       paths.KnownModel(), SparseFormat::kBinary);
      fs::create_directories(models / "0");
      arguments.insert(arguments.end(), {"--input_path", paths.KnownModel().string(),
                                         "--output_path", (models / "0").string()});
      arguments.insert(arguments.end(), fixed_intrinsics.begin(), fixed_intrinsics.end());
      sfm.colmap.Run("point_triangulator", arguments, paths.Log(name), name, num_images,
                     sfm.progress);
    } else {
      arguments.insert(arguments.end(), {"--output_path", models.string()});
      if (hierarchical) {
        // The database holds exactly the listed photos, so no image list is needed (nor taken).
        arguments.insert(arguments.end(), {"--leaf_max_num_images",
                                           std::to_string(sfm.options.hierarchical_cluster_images),
                                           "--image_overlap",
                                           std::to_string(sfm.options.hierarchical_cluster_images / 2)});
      } else if (key_photos) {
        WriteFileAtomically(paths.KeyPhotoList(), ImageListText(keys));
        arguments.insert(arguments.end(), {"--image_list_path", paths.KeyPhotoList().string()});
      } else {
        arguments.insert(arguments.end(), {"--image_list_path", paths.ImageList().string()});
      }
      if (sfm.camera.fixed_intrinsics) {
        arguments.insert(arguments.end(), fixed_intrinsics.begin(), fixed_intrinsics.end());
      }
      RunMapper(sfm, hierarchical ? "hierarchical_mapper" : "mapper", arguments, name,
                key_photos ? static_cast<int>(keys.size()) : num_images);
    }
    ReplaceFolder(models, paths.Models());
    WriteSparseModel(LargestModel(ModelDirs(paths)), paths.RawModel(), SparseFormat::kBinary);
    // With key photos, the principal point is refined on their model: the photos registered
    // to it afterwards are not adjusted (an adjustment of them all costs twice the memory and
    // made the poses worse on the plaza, docs/scale.md).
    if (refine_principal_point) {
      notes.push_back(RefinePrincipalPoint(sfm.colmap, paths, sfm.options, sfm.progress));
    } else if (hierarchical) {
      // The hierarchical mapper merges its clusters' models without a final bundle adjustment,
      // as COLMAP's documentation warns.
      WriteSparseModel(AdjustRawModel(sfm.colmap, paths, {}, "adjust", sfm.progress), paths.RawModel(),
                       SparseFormat::kBinary);
    }
    if (key_photos) {
      WriteSparseModel(RegisterOtherPhotos(sfm, sfm.camera.fixed_intrinsics ? fixed_intrinsics
                                                                             : std::vector<std::string>{}),
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
  Stage stage;
  stage.name = "undistort";
  stage.key = hasher.Hex();
  stage.outputs = {paths.Sparse()};
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
  stage.run = [&sfm, raw_model, paths, supported] {
    const fs::path output = paths.UndistortScratch();
    RemoveAll(output);
    if (supported) {
      WritePinholeWorkspace(*raw_model, sfm.photos_dir, output);
    } else {
      sfm.colmap.Run("image_undistorter",
                     {"--image_path", sfm.photos_dir.string(), "--input_path",
                      paths.RawModel().string(), "--output_path", output.string(),
                      "--output_type", "COLMAP"},
                     paths.Log("undistort"), "undistort",
                     static_cast<int>(sfm.photos.photos.size()), sfm.progress);
    }
    const Workspace undistorted(output);
    ReplaceFolder(undistorted.Images(), paths.Images());
    ReplaceFolder(undistorted.Stereo(), paths.Stereo());
    ReplaceFolder(undistorted.Sparse(), paths.Sparse());
    RemoveAll(output);
  };
  return stage;
}

int OtherModelCount(const Workspace& workspace) {
  // Counting the folders is enough here: the largest model was chosen when mapping.
  return static_cast<int>(ModelDirs(workspace).size()) - 1;
}

}  // namespace parallax
