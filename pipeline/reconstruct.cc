#include "pipeline/reconstruct.h"

#include <algorithm>
#include <fstream>
#include <optional>
#include <set>
#include <utility>

#include <nlohmann/json.hpp>

#include "core/atomic_file.h"
#include "core/error.h"
#include "core/sparse_model.h"
#include "core/workspace.h"
#include "core/workspace_lock.h"
#include "pipeline/dense_stages.h"
#include "pipeline/sfm_stages.h"

namespace parallax {
namespace fs = std::filesystem;
namespace {

void CheckWorkspaceWritable(const fs::path& workspace) {
  std::error_code error;
  fs::create_directories(workspace, error);
  if (error || !fs::is_directory(workspace)) {
    throw BadInputError("workspace " + workspace.string() + " cannot be created: " +
                        (error ? error.message() : "not a folder"));
  }
  const fs::path probe = Workspace(workspace).WriteProbe();
  try {
    WriteFileAtomically(probe, "ok");
  } catch (const BadInputError&) {
    throw BadInputError("workspace " + workspace.string() + " is not writable");
  }
  fs::remove(probe, error);
}

// ReconstructOptions::vocab_tree, when given: a file that can be read. Throws BadInputError
// naming it.
void CheckVocabularyTree(const fs::path& tree) {
  if (tree.empty()) return;
  const std::string name = "vocabulary tree " + tree.string();
  std::error_code error;
  if (!fs::exists(tree, error)) throw BadInputError(name + " does not exist");
  if (!fs::is_regular_file(tree, error)) throw BadInputError(name + " is not a file");
  if (fs::file_size(tree, error) == 0) throw BadInputError(name + " is empty");
  if (!std::ifstream(tree, std::ios::binary)) throw BadInputError(name + " cannot be read");
}

// `model`: the workspace's (undistorted) model; `held_out`: the registered photos held out of it.
void FillModelStatistics(const SparseModel& model, const SparseModel& held_out, const PhotoSet& photos,
                         ReconstructSummary& summary) {
  summary.images_registered = static_cast<int>(model.Images().size() + held_out.Images().size());
  summary.held_out.clear();
  for (const SparseImage& image : held_out.Images()) summary.held_out.push_back(image.name);
  std::sort(summary.held_out.begin(), summary.held_out.end());
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
    if (!model.FindImageByName(photo.name) && !held_out.FindImageByName(photo.name)) {
      summary.unregistered.push_back(photo.name);
    }
  }
}

nlohmann::json ReportJson(const ReconstructSummary& summary) {
  nlohmann::json stages = nlohmann::json::array(), timings = nlohmann::json::object();
  for (const StageRecord& stage : summary.stages) {
    stages.push_back({{"name", stage.name}, {"skipped", stage.skipped}, {"reason", stage.reason},
                      {"seconds", stage.seconds}, {"cpu_seconds", stage.cpu_seconds},
                      {"peak_rss_mb", stage.peak_rss_mb}, {"tool_peak_rss_mb", stage.tool_peak_rss_mb}});
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
          {"held_out", summary.held_out},
          {"other_models", summary.other_models},
          {"points3d", summary.points3d},
          {"mean_track_length", summary.mean_track_length},
          {"mean_reprojection_error_px", summary.mean_reprojection_error_px},
          {"matcher", summary.matcher},
          {"mapper", summary.mapper},
          {"camera_model", summary.camera_model},
          {"features",
           {{"max_image_size", summary.features.max_image_size},
            {"max_num_features", summary.features.max_num_features}}},
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
          {"camera_uncertainty",
           summary.camera_uncertainty ? ToJson(*summary.camera_uncertainty) : nlohmann::json()},
          {"depth", summary.depth ? nlohmann::json(*summary.depth) : nlohmann::json()},
          {"mesh", summary.mesh ? nlohmann::json(*summary.mesh) : nlohmann::json()},
          {"depth_resolution", summary.depth_resolution},
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

std::string JoinNames(const std::vector<std::string>& names) {
  std::string joined;
  for (const std::string& name : names) joined += " " + name;
  return joined;
}

// The mapper's model, checked: enough photos registered (else BadInputError), and plausible
// (else a warning, or with `strict` BadInputError after writing the report).
SparseModel CheckRawModel(const SfmContext& sfm, ReconstructSummary& summary) {
  const Workspace& paths = sfm.workspace;
  const SparseModel raw_model = ReadSparseModel(paths.RawModel());
  summary.other_models = OtherModelCount(paths);
  if (summary.other_models > 0) {
    summary.warnings.push_back(
        "COLMAP split the photos into " + std::to_string(summary.other_models + 1) +
        " disconnected models; kept the largest (" + std::to_string(raw_model.Images().size()) +
        " images), the others are in " + paths.Models().string());
  }
  FillModelStatistics(raw_model, SparseModel(), sfm.photos, summary);
  const int num_images = static_cast<int>(sfm.photos.photos.size());
  const int required = std::max(2, (num_images + 1) / 2);
  if (summary.images_registered < required) {
    throw BadInputError("only " + std::to_string(summary.images_registered) + " of " +
                        std::to_string(num_images) + " photos were registered (need " +
                        std::to_string(required) + "); not registered:" +
                        JoinNames(summary.unregistered));
  }
  if (!summary.unregistered.empty()) {
    summary.warnings.push_back(std::to_string(summary.unregistered.size()) +
                               " photos were not registered:" + JoinNames(summary.unregistered));
  }
  const Photo& first = sfm.photos.photos.front();
  summary.plausibility =
      CheckPlausibility(raw_model, sfm.photos.FocalPrior(first), first.exif_focal_px.has_value(),
                        sfm.options.plausibility);
  if (sfm.known || sfm.camera.fixed_intrinsics) {
    // The focal length was given, not estimated: only the geometry checks apply.
    std::erase_if(summary.plausibility.problems,
                  [](const std::string& problem) { return problem.starts_with("estimated focal"); });
  }
  for (const std::string& problem : summary.plausibility.problems) {
    summary.warnings.push_back("implausible reconstruction: " + problem);
  }
  if (sfm.options.strict && !summary.plausibility.Plausible()) {
    WriteReport(paths.Report(), summary);
    throw BadInputError("implausible reconstruction (--strict): " +
                        summary.plausibility.problems.front() + "; see " +
                        paths.Report().string());
  }
  return raw_model;
}

std::vector<std::string> DescribeDepthResolutions(const DepthRequest& request,
                                                  const std::set<std::pair<int, int>>& sizes) {
  std::vector<std::string> descriptions;
  for (const auto& [width, height] : sizes) descriptions.push_back(DescribeDepthResolution(request, width, height));
  return descriptions;
}

// Depth, fusion and (unless --no-mesh) the textured mesh, after undistortion.
void RunDenseStages(const SfmContext& sfm, const std::string& undistort_key, StageGraph& graph,
                    ReconstructSummary& summary) {
  const ReconstructOptions& options = sfm.options;
  const Workspace& paths = sfm.workspace;
  const DepthRequest depth_request = DepthRequestOf(options);
  std::set<std::pair<int, int>> sizes;
  {  // Not kept through the dense stages: with hundreds of photos the model is tens of MB.
    const SparseModel model = ReadSparseModelWithoutKeypoints(paths.Sparse());
    for (const Camera& camera : model.Cameras()) {
      sizes.emplace(static_cast<int>(camera.width), static_cast<int>(camera.height));
    }
  }
  summary.depth_resolution = DescribeDepthResolutions(depth_request, sizes);
  const Stage depth = DepthStage(paths, undistort_key, depth_request, sfm.progress);
  graph.Run(depth);
  summary.depth = nlohmann::json::parse(ReadFileBytes(paths.DepthViews())).get<MvsSummary>();
  const MvsSummary& mvs = *summary.depth;
  if (!graph.Records().back().skipped && mvs.resumed_estimates + mvs.resumed_filtered > 0) {
    summary.notes.push_back("depth: resumed a run cut short: kept " + std::to_string(mvs.resumed_estimates) +
                            " views' PatchMatch estimates and " + std::to_string(mvs.resumed_filtered) +
                            " views' filtered maps, computed the rest");
  }
  std::string gains_note;
  const Stage color_gains = ColorGainsStage(paths, undistort_key, &gains_note);
  graph.Run(color_gains);
  if (!gains_note.empty()) summary.notes.push_back(gains_note);
  graph.Run(FusionStage(paths, depth_request, depth.key, color_gains.key, sfm.progress));
  if (!options.build_mesh) {
    summary.notes.push_back("mesh: not built (--no-mesh)");
    return;
  }
  graph.Run(MeshStage(paths, depth_request, options, depth.key, color_gains.key, sfm.colmap, sfm.progress));
  summary.mesh = nlohmann::json::parse(ReadFileBytes(paths.MeshSummary())).get<MeshSummary>();
}

}  // namespace

ReconstructSummary Reconstruct(const fs::path& photos_dir, const fs::path& workspace,
                               const ReconstructOptions& options, Progress& progress) {
  options.Check();
  // Everything that can be checked is checked before colmap starts.
  const Colmap colmap(options.colmap);
  const PhotoSet photos = ScanPhotos(photos_dir);
  CheckVocabularyTree(options.vocab_tree);
  std::optional<SparseModel> known;
  if (!options.known_cameras.empty()) known = ReadSparseModel(options.known_cameras);
  if (!options.dry_run) CheckWorkspaceWritable(workspace);
  std::optional<WorkspaceLock> lock;
  if (!options.dry_run || fs::is_directory(workspace)) {
    lock.emplace(workspace, options.dry_run ? LockMode::kShared : LockMode::kExclusive, "reconstruct");
  }

  ReconstructSummary summary;
  summary.images_found = static_cast<int>(photos.photos.size());
  summary.skipped_files = photos.skipped;
  // What the input holds is said as it is found, so a run that fails later names it too.
  const auto warn_now = [&](const std::string& warning) {
    progress.Warn(warning);
    summary.warnings.push_back(warning);
    summary.warnings_said = summary.warnings.size();
  };
  for (const SkippedFile& file : photos.skipped) warn_now("skipped " + file.name + ": it " + file.reason);
  for (const Photo& photo : photos.photos) {
    if (!photo.non_finite.empty()) warn_now(photo.name + " has non-finite pixels: " + photo.non_finite);
  }
  const int num_images = summary.images_found;
  const Workspace paths(workspace);
  const SfmContext sfm{ReadablePhotosDir(photos_dir, photos, paths), photos, known ? &*known : nullptr, options, colmap,
                       paths, ChooseCameraSetup(photos, options, known ? &*known : nullptr),
                       MatcherFor(options, num_images), progress,
                       HeldOutPhotos(PhotoNames(photos), options.hold_out_every, options.hold_out_photos)};
  summary.camera_model = DescribeCameraSetup(sfm.camera, photos);
  summary.matcher = PlannedMatcher(options, num_images);
  summary.features = SettingsFor(options.quality);
  if (!options.vocab_tree.empty() && sfm.matcher == MatcherChoice::kExhaustive) {
    summary.notes.push_back("vocabulary tree " + options.vocab_tree.string() +
                            " not used: exhaustive matching pairs every image without one");
  }

  const std::string conversions = DescribeConversions(photos, paths);
  if (!conversions.empty()) summary.notes.push_back(conversions);

  StageGraph graph(sfm.workspace, options.dry_run);
  if (!graph.CacheDamage().empty()) warn_now(graph.CacheDamage());
  const Stage converted = PhotosStage(photos_dir, photos, paths, progress);
  graph.Run(converted);
  const Stage features = FeaturesStage(sfm, converted.key);
  graph.Run(features);
  const Stage vocabulary_tree = VocabularyTreeStage(sfm, features.key);
  graph.Run(vocabulary_tree);
  const Stage matches = MatchesStage(sfm, features.key, vocabulary_tree.key);
  graph.Run(matches);
  // The marker says which matcher ran and why (older workspaces' markers hold only the key).
  if (!options.dry_run) {
    const std::string matched = ReadFileBytes(paths.MatchedMarker());
    if (matched != matches.key) summary.matcher = matched;
  }
  const MapperPlan mapper_plan = PlanMapper(sfm);
  summary.mapper = mapper_plan.description;
  const Stage mapper = MapperStage(sfm, mapper_plan, matches.key, summary.notes);
  graph.Run(mapper);
  if (options.dry_run) {
    graph.Run(UndistortStage(sfm, mapper.key, nullptr));
    if (options.estimate_depth) {
      std::set<std::pair<int, int>> sizes;
      for (const Photo& photo : photos.photos) sizes.emplace(photo.width, photo.height);
      summary.depth_resolution = DescribeDepthResolutions(DepthRequestOf(options), sizes);
    }
    summary.stages = graph.Records();
    return summary;
  }
  summary.stages = graph.Records();  // The report a --strict failure writes lists them.
  if (fs::exists(paths.CameraUncertainty())) {
    summary.camera_uncertainty = ReadCameraUncertainty(paths.CameraUncertainty());
    summary.notes.push_back(Describe(*summary.camera_uncertainty));
  }
  std::string undistort_key;
  {  // The raw model (every photo's keypoints) is not kept through the dense stages.
    const SparseModel raw_model = CheckRawModel(sfm, summary);
    const Stage undistort = UndistortStage(sfm, mapper.key, &raw_model);
    graph.Run(undistort);
    undistort_key = undistort.key;
  }
  const Workspace held_out = sfm.workspace.HeldOut();
  FillModelStatistics(ReadSparseModel(sfm.workspace.Sparse()),
                      sfm.held_out.empty() ? SparseModel() : ReadSparseModel(held_out.Sparse()), photos, summary);
  if (!sfm.held_out.empty()) {
    summary.notes.push_back(std::to_string(summary.held_out.size()) + " of " + std::to_string(sfm.held_out.size()) +
                            " held-out photos registered, kept out of the dense stages and the render sources: " +
                            held_out.Root().string() + " (parallax evaluate scores them)");
  }
  if (options.estimate_depth) RunDenseStages(sfm, undistort_key, graph, summary);
  summary.stages = graph.Records();
  WriteReport(sfm.workspace.Report(), summary);
  return summary;
}

}  // namespace parallax
