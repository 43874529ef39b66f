#include "pipeline/reconstruct.h"

#include <algorithm>
#include <chrono>
#include <fstream>
#include <functional>
#include <sstream>

#include <nlohmann/json.hpp>

#include "core/atomic_file.h"
#include "core/error.h"
#include "core/hash.h"
#include "core/sparse_model.h"
#include "pipeline/colmap.h"
#include "pipeline/colmap_database.h"
#include "pipeline/fusion.h"
#include "pipeline/mesh.h"
#include "pipeline/sgbm.h"
#include "pipeline/mvs.h"
#include "pipeline/stage_cache.h"
#include "pipeline/undistort.h"

namespace parallax {
namespace fs = std::filesystem;
namespace {

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

// Where each stage keeps its files inside the workspace.
struct WorkspacePaths {
  fs::path root;
  fs::path Sfm() const { return root / "sfm"; }
  fs::path Database() const { return Sfm() / "database.db"; }
  fs::path ImageList() const { return Sfm() / "image_list.txt"; }
  fs::path KnownModel() const { return Sfm() / "known"; }
  fs::path Models() const { return Sfm() / "models"; }
  fs::path RawModel() const { return Sfm() / "sparse"; }
  fs::path Logs() const { return root / "logs"; }
  fs::path Log(const std::string& stage) const { return Logs() / (stage + ".log"); }
  fs::path Sparse() const { return root / "sparse"; }
  fs::path Images() const { return root / "images"; }
  fs::path Report() const { return root / "report.json"; }
  fs::path Stages() const { return root / "stages.json"; }
};

std::string Join(const std::vector<double>& values) {
  std::ostringstream text;
  text.precision(17);
  for (size_t i = 0; i < values.size(); ++i) text << (i ? "," : "") << values[i];
  return text.str();
}

// Names and contents of the files in `dir`, in name order.
uint64_t HashFolder(const fs::path& dir) {
  std::vector<fs::path> files;
  for (const auto& entry : fs::directory_iterator(dir)) {
    if (entry.is_regular_file()) files.push_back(entry.path());
  }
  std::sort(files.begin(), files.end());
  Hasher hasher;
  for (const fs::path& file : files) hasher.Add(file.filename().string()).Add(ReadFileBytes(file));
  return hasher.Value();
}

// Bump when the depth stage's results change for the same options, so caches recompute.
constexpr const char* kMvsVersion = "patch-match-6";
constexpr const char* kFusionVersion = "fusion-1";
constexpr const char* kMeshVersion = "mesh-2";

nlohmann::json MeshSummaryJson(const MeshSummary& mesh) {
  return {{"poisson_triangles", mesh.poisson_triangles},
          {"triangles", mesh.triangles},
          {"vertices", mesh.vertices},
          {"texels_per_edge", mesh.texels_per_edge},
          {"untextured_triangles", mesh.untextured_triangles},
          {"atlas_size", {mesh.atlas_width, mesh.atlas_height}},
          {"display_triangles", mesh.display_triangles}};
}

nlohmann::json MvsSummaryJson(const MvsSummary& mvs) {
  nlohmann::json views = nlohmann::json::array();
  for (const MvsViewReport& view : mvs.views) {
    views.push_back({{"name", view.name},
                     {"sources", view.sources},
                     {"min_depth", view.min_depth},
                     {"max_depth", view.max_depth},
                     {"photometric_share", view.photometric_share},
                     {"geometric_share", view.geometric_share}});
  }
  return {{"views", views},
          {"skipped", mvs.skipped},
          {"photometric_seconds", mvs.photometric_seconds},
          {"geometric_seconds", mvs.geometric_seconds}};
}

void CheckWorkspaceWritable(const fs::path& workspace) {
  std::error_code error;
  fs::create_directories(workspace, error);
  if (error || !fs::is_directory(workspace)) {
    throw BadInputError("workspace " + workspace.string() + " cannot be created: " +
                        (error ? error.message() : "not a folder"));
  }
  const fs::path probe = workspace / ".parallax_write_test";
  try {
    WriteFileAtomically(probe, "ok");
  } catch (const BadInputError&) {
    throw BadInputError("workspace " + workspace.string() + " is not writable");
  }
  fs::remove(probe, error);
}

// Removes a folder left by an interrupted stage, or the previous result a stage replaces.
void RemoveAll(const fs::path& path) {
  std::error_code error;
  fs::remove_all(path, error);
  if (error) throw BadInputError("cannot remove " + path.string() + ": " + error.message());
}

// Moves `from` to `to`, replacing what was there (directory rename is atomic).
void Replace(const fs::path& from, const fs::path& to) {
  RemoveAll(to);
  fs::rename(from, to);
}

// The COLMAP image model the extractor starts from, and its parameters when they are fixed.
struct CameraSetup {
  CameraModel model;
  std::string params;  // Empty: COLMAP estimates them, from EXIF or the image size.
  bool single_camera;
  bool fixed_intrinsics;
};

CameraSetup ChooseCameraSetup(const PhotoSet& photos, const ReconstructOptions& options,
                              const SparseModel* known) {
  const bool shared = photos.SharesOneCamera();
  if (known) {
    const bool single = known->Cameras().size() == 1;
    const Camera& first = known->Cameras().front();
    return {single ? first.model : options.camera_model, single ? Join(first.params) : "",
            single, true};
  }
  if (options.intrinsics.empty()) return {options.camera_model, "", shared, false};
  if (!shared && options.intrinsics.size() == 1) {
    throw BadInputError("--intrinsics f needs photos of one size (the principal point is put at "
                        "the image centre); give fx,fy,cx,cy or photos of one size");
  }
  const Photo& photo = photos.photos.front();
  if (options.intrinsics.size() == 1) {
    return {CameraModel::kSimplePinhole,
            Join({options.intrinsics[0], photo.width / 2.0, photo.height / 2.0}), true, true};
  }
  return {CameraModel::kPinhole, Join(options.intrinsics), true, true};
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

// What `colmap image_undistorter --output_type COLMAP` writes: the photos undistorted into
// PINHOLE cameras of the same size and intrinsics (copied as they are where a camera has no
// distortion; UndistortPhoto says why not COLMAP's resampling), the model with those cameras,
// and the stereo/ folder layout with the configuration files COLMAP's dense tools read.
void WritePinholeWorkspace(const SparseModel& model, const fs::path& photos_dir, const fs::path& output) {
  fs::create_directories(output / "images");
  fs::create_directories(output / "stereo" / "depth_maps");
  fs::create_directories(output / "stereo" / "normal_maps");
  fs::create_directories(output / "stereo" / "consistency_graphs");
  SparseModel pinhole;
  for (const Camera& camera : model.Cameras()) pinhole.AddCamera(PinholeOf(camera));
  std::string patch_match, fusion;
  for (const SparseImage& image : model.Images()) {
    pinhole.AddImage(image);
    fs::create_directories((output / "images" / image.name).parent_path());
    const Camera& camera = model.CameraById(image.camera_id);
    if (camera.HasDistortion()) {
      UndistortPhoto(camera, photos_dir / image.name, output / "images" / image.name);
    } else {
      fs::copy_file(photos_dir / image.name, output / "images" / image.name,
                    fs::copy_options::overwrite_existing);
    }
    patch_match += image.name + "\n__auto__, 20\n";
    fusion += image.name + "\n";
  }
  for (const Point3D& point : model.Points3D()) pinhole.AddPoint3D(point);
  WriteSparseModel(pinhole, output / "sparse", SparseFormat::kBinary);
  WriteFileAtomically(output / "stereo" / "patch-match.cfg", patch_match);
  WriteFileAtomically(output / "stereo" / "fusion.cfg", fusion);
}

class StageRunner {
 public:
  StageRunner(const WorkspacePaths& paths, bool dry_run, ReconstructSummary& summary)
      : cache_(paths.Stages()), dry_run_(dry_run), summary_(summary) {}

  // Runs `body` unless the stage completed before with the same key and its output exists.
  // A non-empty `not_needed` says why the stage's real work is not needed for this scene
  // (`body` then does only the little that remains): the stage is reported as skipped, with
  // that reason.
  void Run(const std::string& name, const std::string& key, const fs::path& output,
           const std::function<void()>& body, const std::string& not_needed = "") {
    StageRecord record{name, false, "", 0};
    if (cache_.IsDone(name, key) && fs::exists(output)) {
      record.skipped = true;
      record.reason = "inputs and options unchanged since the last run";
    } else if (dry_run_) {
      record.skipped = !not_needed.empty();
      record.reason = !not_needed.empty()  ? not_needed
                      : fs::exists(output) ? "inputs or options changed"
                                           : "not run yet";
    } else {
      const auto start = std::chrono::steady_clock::now();
      body();
      record.seconds =
          std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
      cache_.MarkDone(name, key);
      record.skipped = !not_needed.empty();
      record.reason = not_needed;
    }
    summary_.stages.push_back(record);
  }

 private:
  StageCache cache_;
  bool dry_run_;
  ReconstructSummary& summary_;
};

// A final bundle adjustment that also frees the principal point, kept only when the point
// stays near the image centre: where it is unobservable (a narrow arc of small images) it
// drifts far off and the rotations with it (6.6 degrees on example_images/small).
std::string RefinePrincipalPoint(const Colmap& colmap, const WorkspacePaths& paths,
                                 const ReconstructOptions& options, Progress& progress) {
  const fs::path refined = paths.Sfm() / "refined.tmp";
  RemoveAll(refined);
  fs::create_directories(refined);
  colmap.Run("bundle_adjuster",
             {"--input_path", paths.RawModel().string(), "--output_path", refined.string(),
              "--BundleAdjustment.refine_principal_point", "1"},
             paths.Log("refine"), "refine", 0, progress);
  const SparseModel model = ReadSparseModel(refined);
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
  RemoveAll(refined);
  return note;
}

// The model folders the mapper wrote, in name order. Throws BadInputError when there is none.
std::vector<fs::path> ModelDirs(const fs::path& models_dir) {
  std::vector<fs::path> dirs;
  for (const auto& entry : fs::directory_iterator(models_dir)) {
    if (entry.is_directory() && DetectSparseFormat(entry.path())) dirs.push_back(entry.path());
  }
  if (dirs.empty()) {
    throw BadInputError("COLMAP could not reconstruct these photos (no image pair with "
                        "enough matches to start from); see " +
                        (models_dir.parent_path().parent_path() / "logs" / "mapper.log").string());
  }
  std::sort(dirs.begin(), dirs.end());
  return dirs;
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

void FillModelStatistics(const SparseModel& model, const PhotoSet& photos,
                         ReconstructSummary& summary) {
  summary.images_registered = static_cast<int>(model.Images().size());
  summary.points3d = model.Points3D().size();
  double track_sum = 0, error_sum = 0;
  for (const Point3D& point : model.Points3D()) {
    track_sum += static_cast<double>(point.track.size());
    error_sum += std::max(0.0, point.error);
  }
  const double n = std::max<double>(1, static_cast<double>(model.Points3D().size()));
  summary.mean_track_length = track_sum / n;
  summary.mean_reprojection_error_px = error_sum / n;
  summary.unregistered.clear();
  for (const Photo& photo : photos.photos) {
    if (!model.FindImageByName(photo.name)) summary.unregistered.push_back(photo.name);
  }
}

nlohmann::json ReportJson(const ReconstructSummary& summary) {
  nlohmann::json stages = nlohmann::json::array(), timings = nlohmann::json::object();
  for (const StageRecord& stage : summary.stages) {
    stages.push_back({{"name", stage.name}, {"skipped", stage.skipped},
                      {"reason", stage.reason}, {"seconds", stage.seconds}});
    timings[stage.name] = stage.seconds;
  }
  nlohmann::json skipped_files = nlohmann::json::array();
  for (const SkippedFile& file : summary.skipped_files) {
    skipped_files.push_back({{"name", file.name}, {"reason", file.reason}});
  }
  const PlausibilityReport& plausibility = summary.plausibility;
  return {{"images_found", summary.images_found},
          {"images_registered", summary.images_registered},
          {"unregistered", summary.unregistered},
          {"other_models", summary.other_models},
          {"points3d", summary.points3d},
          {"mean_track_length", summary.mean_track_length},
          {"mean_reprojection_error_px", summary.mean_reprojection_error_px},
          {"matcher", summary.matcher},
          {"camera_model", summary.camera_model},
          {"skipped_files", skipped_files},
          {"stages", stages},
          {"timings_s", timings},
          {"plausibility",
           {{"plausible", plausibility.Plausible()},
            {"focal_px", plausibility.focal_px},
            {"focal_prior_px", plausibility.focal_prior_px},
            {"prior_from_exif", plausibility.prior_from_exif},
            {"median_triangulation_deg", plausibility.median_triangulation_deg},
            {"focal_rms_ratio", plausibility.focal_rms_ratio},
            {"well_constrained_image_share", plausibility.well_constrained_image_share},
            {"problems", plausibility.problems}}},
          {"depth", summary.depth_views},
          {"mesh", summary.mesh},
          {"notes", summary.notes},
          {"warnings", summary.warnings}};
}

// Keeps what later stages wrote into report.json; replaces the "reconstruct" section.
void WriteReport(const fs::path& path, const ReconstructSummary& summary) {
  nlohmann::json report = nlohmann::json::object();
  if (fs::exists(path)) {
    try {
      report = nlohmann::json::parse(ReadFileBytes(path));
    } catch (const std::exception&) {
      report = nlohmann::json::object();
    }
    if (!report.is_object()) report = nlohmann::json::object();
  }
  report["reconstruct"] = ReportJson(summary);
  WriteFileAtomically(path, report.dump(2) + "\n");
}

}  // namespace

void ReconstructOptions::Check() const {
  if (!intrinsics.empty() && intrinsics.size() != 1 && intrinsics.size() != 4) {
    throw std::invalid_argument("intrinsics must be f or fx,fy,cx,cy");
  }
  for (const double value : intrinsics) {
    if (!(value > 0) || !std::isfinite(value)) {
      throw std::invalid_argument("intrinsics must be positive numbers");
    }
  }
  if (!intrinsics.empty() && !known_cameras.empty()) {
    throw std::invalid_argument("intrinsics and known_cameras exclude each other");
  }
  if (!IsProjectionSupported(camera_model)) {
    throw std::invalid_argument("camera_model " + std::string(CameraModelName(camera_model)) +
                                " is not supported");
  }
  if (exhaustive_limit < 2) throw std::invalid_argument("exhaustive_limit must be >= 2");
  if (sequential_overlap < 1) throw std::invalid_argument("sequential_overlap must be >= 1");
  if (refine_principal_point_min_images < 1) {
    throw std::invalid_argument("refine_principal_point_min_images must be >= 1");
  }
  if (!(max_refined_principal_point_offset > 0)) {
    throw std::invalid_argument("max_refined_principal_point_offset must be > 0");
  }
  if (!(mvs_scale >= 0.25 && mvs_scale <= 1)) throw std::invalid_argument("mvs_scale must be in [0.25, 1]");
  plausibility.Check();
}

ReconstructSummary Reconstruct(const fs::path& photos_dir, const fs::path& workspace,
                               const ReconstructOptions& options, Progress& progress) {
  options.Check();
  // Everything that can be checked is checked before colmap starts.
  const Colmap colmap(options.colmap);
  const PhotoSet photos = ScanPhotos(photos_dir);
  std::optional<SparseModel> known;
  if (!options.known_cameras.empty()) known = ReadSparseModel(options.known_cameras);
  if (!options.dry_run) CheckWorkspaceWritable(workspace);

  const WorkspacePaths paths{workspace};
  ReconstructSummary summary;
  summary.images_found = static_cast<int>(photos.photos.size());
  summary.skipped_files = photos.skipped;
  for (const SkippedFile& file : photos.skipped) {
    summary.warnings.push_back("skipped " + file.name + ": it " + file.reason);
  }
  const CameraSetup camera = ChooseCameraSetup(photos, options, known ? &*known : nullptr);
  summary.camera_model = std::string(CameraModelName(camera.model)) +
                         (camera.single_camera ? ", one shared camera" : ", one camera per image") +
                         (camera.fixed_intrinsics ? ", intrinsics fixed" : "");
  const int num_images = static_cast<int>(photos.photos.size());
  const bool sequential =
      options.matcher == MatcherChoice::kSequential ||
      (options.matcher == MatcherChoice::kAuto && num_images > options.exhaustive_limit);
  summary.matcher =
      sequential ? "sequential (overlap " + std::to_string(options.sequential_overlap) +
                       ", first and last images matched for loop closure)"
                 : "exhaustive (" + std::to_string(num_images) + " images, every pair)";
  if (options.matcher == MatcherChoice::kAuto) summary.matcher += ", chosen automatically";
  const QualitySettings quality = SettingsFor(options.quality);
  StageRunner stages(paths, options.dry_run, summary);

  // Features.
  const std::string features_key =
      Hasher()
          .Add(photos.ContentHash())
          .Add(CameraModelName(camera.model))
          .Add(camera.params)
          .Add(camera.single_camera)
          .Add(static_cast<uint64_t>(quality.max_image_size))
          .Add(static_cast<uint64_t>(quality.max_num_features))
          .Hex();
  stages.Run("features", features_key, paths.Database(), [&] {
    fs::create_directories(paths.Sfm());
    std::string list;
    for (const Photo& photo : photos.photos) list += photo.name + "\n";
    WriteFileAtomically(paths.ImageList(), list);
    const fs::path database = paths.Database().string() + ".tmp";
    RemoveAll(database);
    std::vector<std::string> arguments = {
        "--database_path", database.string(), "--image_path", photos_dir.string(),
        "--image_list_path", paths.ImageList().string(),
        "--ImageReader.camera_model", std::string(CameraModelName(camera.model)),
        "--ImageReader.single_camera", camera.single_camera ? "1" : "0",
        "--SiftExtraction.use_gpu", "0",
        "--SiftExtraction.max_image_size", std::to_string(quality.max_image_size),
        "--SiftExtraction.max_num_features", std::to_string(quality.max_num_features)};
    if (!camera.params.empty()) {
      arguments.insert(arguments.end(), {"--ImageReader.camera_params", camera.params});
    }
    colmap.Run("feature_extractor", arguments, paths.Log("features"), "features", num_images,
               progress);
    fs::rename(database, paths.Database());
  });

  // Matches.
  const std::string matches_key = Hasher()
                                      .Add(features_key)
                                      .Add(sequential)
                                      .Add(static_cast<uint64_t>(options.sequential_overlap))
                                      .Add(quality.guided_matching)
                                      .Hex();
  const fs::path matched_marker = paths.Sfm() / "matched";
  stages.Run("matches", matches_key, matched_marker, [&] {
    const fs::path database = paths.Database().string() + ".tmp";
    fs::copy_file(paths.Database(), database, fs::copy_options::overwrite_existing);
    const std::vector<std::string> common = {
        "--database_path", database.string(), "--SiftMatching.use_gpu", "0",
        "--SiftMatching.guided_matching", quality.guided_matching ? "1" : "0"};
    if (sequential) {
      std::vector<std::string> arguments = common;
      arguments.insert(arguments.end(),
                       {"--SequentialMatching.overlap", std::to_string(options.sequential_overlap),
                        "--SequentialMatching.loop_detection", "0"});
      colmap.Run("sequential_matcher", arguments, paths.Log("matches"), "matches", num_images,
                 progress);
      // Without a vocabulary tree, a ring closes only if its ends are matched explicitly.
      std::string pairs;
      const int ends = std::min(options.sequential_overlap / 2 + 1, num_images / 2);
      for (int i = 0; i < ends; ++i) {
        for (int j = num_images - ends; j < num_images; ++j) {
          pairs += photos.photos[static_cast<size_t>(i)].name + " " +
                   photos.photos[static_cast<size_t>(j)].name + "\n";
        }
      }
      const fs::path pairs_path = paths.Sfm() / "loop_pairs.txt";
      WriteFileAtomically(pairs_path, pairs);
      arguments = common;
      arguments.insert(arguments.end(), {"--match_list_path", pairs_path.string(),
                                         "--match_type", "pairs"});
      colmap.Run("matches_importer", arguments, paths.Log("matches"), "loop closure",
                 num_images, progress);
    } else {
      colmap.Run("exhaustive_matcher", common, paths.Log("matches"), "matches", num_images,
                 progress);
    }
    fs::rename(database, paths.Database());
    WriteFileAtomically(matched_marker, matches_key);
  });

  // Mapping, or triangulation from known cameras.
  const bool refine_principal_point =
      camera.single_camera && !camera.fixed_intrinsics &&
      num_images >= options.refine_principal_point_min_images;
  const std::string mapper_key =
      Hasher()
          .Add(matches_key)
          .Add(camera.fixed_intrinsics)
          .Add(refine_principal_point)
          .Add(known ? HashFolder(options.known_cameras) : 0)
          .Hex();
  const std::string mapper_stage = known ? "triangulate" : "mapper";
  stages.Run(mapper_stage, mapper_key, paths.RawModel(), [&] {
    const fs::path models = paths.Models().string() + ".tmp";
    RemoveAll(models);
    fs::create_directories(models);
    const std::vector<std::string> common = {"--database_path", paths.Database().string(),
                                             "--image_path", photos_dir.string()};
    if (known) {
      WriteSparseModel(AlignKnownModelToDatabase(*known, photos, options.known_cameras,
                                                 paths.Database()),
                       paths.KnownModel(), SparseFormat::kBinary);
      fs::create_directories(models / "0");
      std::vector<std::string> arguments = common;
      arguments.insert(arguments.end(),
                       {"--input_path", paths.KnownModel().string(), "--output_path",
                        (models / "0").string(), "--Mapper.ba_refine_focal_length", "0",
                        "--Mapper.ba_refine_principal_point", "0",
                        "--Mapper.ba_refine_extra_params", "0"});
      colmap.Run("point_triangulator", arguments, paths.Log(mapper_stage), mapper_stage,
                 num_images, progress);
    } else {
      std::vector<std::string> arguments = common;
      arguments.insert(arguments.end(), {"--output_path", models.string(),
                                         "--image_list_path", paths.ImageList().string()});
      if (camera.fixed_intrinsics) {
        arguments.insert(arguments.end(), {"--Mapper.ba_refine_focal_length", "0",
                                           "--Mapper.ba_refine_principal_point", "0",
                                           "--Mapper.ba_refine_extra_params", "0"});
      }
      colmap.Run("mapper", arguments, paths.Log(mapper_stage), mapper_stage, num_images,
                 progress);
    }
    Replace(models, paths.Models());
    WriteSparseModel(LargestModel(ModelDirs(paths.Models())), paths.RawModel(),
                     SparseFormat::kBinary);
    if (refine_principal_point) {
      summary.notes.push_back(RefinePrincipalPoint(colmap, paths, options, progress));
    }
  });

  // "undistort-2": our own resampling replaced image_undistorter's for supported models; models
  // without distortion parameters copy the photos as before, and keep their key (and depth).
  const bool may_distort =
      camera.model != CameraModel::kPinhole && camera.model != CameraModel::kSimplePinhole;
  Hasher undistort_hasher;
  undistort_hasher.Add(mapper_key);
  if (may_distort) undistort_hasher.Add("undistort-2");
  const std::string undistort_key = undistort_hasher.Hex();
  if (options.dry_run) {
    stages.Run("undistort", undistort_key, paths.Sparse(), [] {});
    return summary;
  }

  const SparseModel raw_model = ReadSparseModel(paths.RawModel());
  // Counting the folders is enough here: the largest model was chosen when mapping.
  summary.other_models = static_cast<int>(ModelDirs(paths.Models()).size()) - 1;
  if (summary.other_models > 0) {
    summary.warnings.push_back(
        "COLMAP split the photos into " + std::to_string(summary.other_models + 1) +
        " disconnected models; kept the largest (" + std::to_string(raw_model.Images().size()) +
        " images), the others are in " + paths.Models().string());
  }
  FillModelStatistics(raw_model, photos, summary);
  const int required = std::max(2, (num_images + 1) / 2);
  if (summary.images_registered < required) {
    std::string names;
    for (const std::string& name : summary.unregistered) names += " " + name;
    throw BadInputError("only " + std::to_string(summary.images_registered) + " of " +
                        std::to_string(num_images) + " photos were registered (need " +
                        std::to_string(required) + "); not registered:" + names);
  }
  if (!summary.unregistered.empty()) {
    std::string names;
    for (const std::string& name : summary.unregistered) names += " " + name;
    summary.warnings.push_back(std::to_string(summary.unregistered.size()) +
                               " photos were not registered:" + names);
  }
  const Photo& first = photos.photos.front();
  summary.plausibility =
      CheckPlausibility(raw_model, photos.FocalPrior(first), first.exif_focal_px.has_value(),
                        options.plausibility);
  if (known || camera.fixed_intrinsics) {
    // The focal length was given, not estimated: only the geometry checks apply.
    std::erase_if(summary.plausibility.problems,
                  [](const std::string& problem) { return problem.starts_with("estimated focal"); });
  }
  for (const std::string& problem : summary.plausibility.problems) {
    summary.warnings.push_back("implausible reconstruction: " + problem);
  }
  if (options.strict && !summary.plausibility.Plausible()) {
    WriteReport(paths.Report(), summary);
    throw BadInputError("implausible reconstruction (--strict): " +
                        summary.plausibility.problems.front() + "; see " +
                        paths.Report().string());
  }

  // Undistortion into the workspace layout (PINHOLE images and model). Cameras without
  // distortion need no resampling: the photos are copied as they are. Models whose projection
  // core implements are resampled by WritePinholeWorkspace; COLMAP's undistorter is left for
  // the others (fisheye models).
  const auto all_cameras = [&](const std::function<bool(const Camera&)>& test) {
    return std::all_of(raw_model.Cameras().begin(), raw_model.Cameras().end(), test);
  };
  const bool distortion_free = all_cameras([](const Camera& c) { return !c.HasDistortion(); });
  const bool supported = all_cameras([](const Camera& c) { return IsProjectionSupported(c.model); });
  stages.Run(
      "undistort", undistort_key, paths.Sparse(),
      [&] {
        const fs::path output = workspace / ".undistort.tmp";
        RemoveAll(output);
        if (supported) {
          WritePinholeWorkspace(raw_model, photos_dir, output);
        } else {
          colmap.Run("image_undistorter",
                     {"--image_path", photos_dir.string(), "--input_path",
                      paths.RawModel().string(), "--output_path", output.string(),
                      "--output_type", "COLMAP"},
                     paths.Log("undistort"), "undistort", num_images, progress);
        }
        Replace(output / "images", paths.Images());
        Replace(output / "stereo", workspace / "stereo");
        Replace(output / "sparse", paths.Sparse());
        RemoveAll(output);
      },
      distortion_free ? "the cameras have no lens distortion: photos copied, not resampled "
                        "(colmap image_undistorter not needed)"
                      : "");
  const SparseModel model = ReadSparseModel(paths.Sparse());
  FillModelStatistics(model, photos, summary);

  if (options.estimate_depth) {
    const std::string depth_key = Hasher()
                                      .Add(undistort_key)
                                      .Add(kMvsVersion)
                                      .Add(static_cast<uint64_t>(options.quality))
                                      .Add(static_cast<uint64_t>(options.stereo))
                                      .Add(static_cast<uint64_t>(options.mvs_sources))
                                      .Add(options.mvs_scale == 1 ? "" : "scale " + std::to_string(options.mvs_scale))
                                      .Hex();
    const fs::path views_file = workspace / "depth" / "views.json";
    stages.Run("depth", depth_key, views_file, [&] {
      MvsOptions mvs_options = MvsOptionsFor(options.quality);
      if (options.mvs_sources > 0) mvs_options.views.max_sources = options.mvs_sources;
      mvs_options.image_scale = options.mvs_scale;
      const MvsSummary mvs =
          options.stereo == StereoMethod::kSgbm
              ? RunSgbmStereo(workspace, mvs_options.views, {}, progress)
              : RunMultiViewStereo(workspace, mvs_options, progress);
      WriteFileAtomically(views_file, MvsSummaryJson(mvs).dump(2) + "\n");
    });
    summary.depth_views = nlohmann::json::parse(ReadFileBytes(views_file));

    const fs::path fused = workspace / "fused.ply";
    stages.Run("fusion", Hasher().Add(depth_key).Add(kFusionVersion).Hex(), fused, [&] {
      WritePly(fused, FuseWorkspace(workspace, {}, progress));
    });

    if (options.build_mesh) {
      const fs::path mesh_file = workspace / "mesh" / "summary.json";
      const std::string mesh_key = Hasher()
                                       .Add(depth_key)
                                       .Add(kFusionVersion)
                                       .Add(kMeshVersion)
                                       .Add(static_cast<uint64_t>(options.quality))
                                       .Hex();
      stages.Run("mesh", mesh_key, mesh_file, [&] {
        const MeshSummary mesh =
            MeshWorkspace(workspace, colmap, MeshOptionsFor(options.quality), progress);
        WriteFileAtomically(mesh_file, MeshSummaryJson(mesh).dump(2) + "\n");
      });
      summary.mesh = nlohmann::json::parse(ReadFileBytes(mesh_file));
    } else {
      summary.notes.push_back("mesh: not built (--no-mesh)");
    }
  }
  WriteReport(paths.Report(), summary);
  return summary;
}

}  // namespace parallax
