#include <cstdio>
#include <map>
#include <memory>
#include <optional>

#include "apps/commands.h"
#include "apps/number_list.h"
#include "apps/slurm_cli.h"
#include "apps/terminal_progress.h"
#include "core/error.h"
#include "pipeline/reconstruct.h"

namespace parallax {
namespace {

void PrintSummary(const ReconstructSummary& summary, const std::filesystem::path& workspace,
                  bool dry_run) {
  std::printf("%s: %d photos; matcher: %s; mapper: %s; camera: %s\n", dry_run ? "plan" : "reconstruct",
              summary.images_found, summary.matcher.c_str(), summary.mapper.c_str(), summary.camera_model.c_str());
  for (const StageRecord& stage : summary.stages) {
    if (stage.skipped) {
      std::printf("  %-12s skipped: %s\n", stage.name.c_str(), stage.reason.c_str());
    } else if (dry_run) {
      std::printf("  %-12s will run: %s\n", stage.name.c_str(), stage.reason.c_str());
    } else {
      std::printf("  %-12s %7.1f s %7.0f MB", stage.name.c_str(), stage.seconds, stage.peak_rss_mb);
      if (stage.tool_peak_rss_mb > 0) std::printf(" (colmap %.0f MB)", stage.tool_peak_rss_mb);
      std::printf("\n");
    }
  }
  if (!dry_run) {
    std::printf("registered %d/%d photos, %zu 3D points, mean track length %.2f, mean "
                "reprojection error %.3f px\n",
                summary.images_registered, summary.images_found, summary.points3d,
                summary.mean_track_length, summary.mean_reprojection_error_px);
    std::printf("focal length %.1f px (prior %.1f px), median triangulation angle %.1f deg\n",
                summary.plausibility.focal_px, summary.plausibility.focal_prior_px,
                summary.plausibility.median_triangulation_deg);
  }
  for (const std::string& line : summary.depth_resolution) std::printf("depth: %s\n", line.c_str());
  for (const std::string& note : summary.notes) std::printf("note: %s\n", note.c_str());
  for (size_t i = summary.warnings_said; i < summary.warnings.size(); ++i) {
    std::fprintf(stderr, "WARNING: %s\n", summary.warnings[i].c_str());
  }
  if (!dry_run) std::printf("workspace: %s (report.json)\n", workspace.string().c_str());
}

struct ReconstructArguments {
  std::filesystem::path photos;
  std::filesystem::path workspace;
  std::string intrinsics;
  std::string camera_model = "SIMPLE_RADIAL";
  bool no_depth = false;
  bool no_mesh = false;
  SlurmCli slurm;
  ReconstructOptions options;
};

// Structure from motion: features, matching, mapping, the cameras.
void AddSfmOptions(CLI::App& command, ReconstructArguments& arguments) {
  const std::map<std::string, Quality> qualities = {
      {"fast", Quality::kFast}, {"balanced", Quality::kBalanced}, {"best", Quality::kBest}};
  command.add_option("--quality", arguments.options.quality,
                     "fast: images <= 1024 px, 2048 features; balanced (default): <= 2000 px, "
                     "4096 features; best: <= 3200 px, 8192 features, guided matching")
      ->transform(CLI::CheckedTransformer(qualities, CLI::ignore_case));
  const std::map<std::string, MatcherChoice> matchers = {{"auto", MatcherChoice::kAuto},
                                                         {"exhaustive", MatcherChoice::kExhaustive},
                                                         {"sequential", MatcherChoice::kSequential},
                                                         {"retrieval", MatcherChoice::kRetrieval}};
  command.add_option("--matcher", arguments.options.matcher,
                     "auto (default): exhaustive (every pair) up to " +
                         std::to_string(ReconstructOptions().exhaustive_limit) +
                         " photos; past that sequential (name-order neighbours, loops closed "
                         "by retrieval) when consecutive photos match, else retrieval (each "
                         "photo with its most similar, from a vocabulary tree built from the "
                         "photos)")
      ->transform(CLI::CheckedTransformer(matchers, CLI::ignore_case));
  command.add_option("--vocab-tree", arguments.options.vocab_tree,
                     "vocabulary tree for sequential and retrieval matching, used instead of "
                     "building one from the photos: one colmap vocab_tree_builder wrote (e.g. "
                     "<ws>/sfm/vocab_tree.bin of an earlier workspace), or one of COLMAP's "
                     "pre-built trees (vocab_tree_flickr100K_words32K.bin and the like) for "
                     "COLMAP 3.8; unused by exhaustive matching")
      ->type_name("FILE");
  const std::map<std::string, MapperChoice> mappers = {{"auto", MapperChoice::kAuto},
                                                       {"incremental", MapperChoice::kIncremental},
                                                       {"hierarchical", MapperChoice::kHierarchical},
                                                       {"keys", MapperChoice::kKeyPhotos}};
  command.add_option("--mapper", arguments.options.mapper,
                     "auto (default): past " + std::to_string(ReconstructOptions().exhaustive_limit) +
                         " photos, keys (an incremental model of key photos, the others "
                         "registered to it) where consecutive photos see nearly the same; else "
                         "incremental (one model, image by image) up to " +
                         std::to_string(ReconstructOptions().hierarchical_limit) +
                         " photos and hierarchical (clusters of the match graph mapped "
                         "apart, then merged) past that")
      ->transform(CLI::CheckedTransformer(mappers, CLI::ignore_case));
  command.add_option("--key-photo-share", arguments.options.key_photo_shared,
                     "with key photos: the share of their features consecutive keys still share "
                     "in verified matches (lower: fewer keys, less memory and time, less "
                     "accurate poses)")
      ->capture_default_str()
      ->check(CLI::Range(0.01, 1.0));
  command.add_option("--track-rounds", arguments.options.max_retriangulations,
                     "after the final adjustments, build the tracks afresh from the adjusted cameras, "
                     "filter and adjust again, until the cameras settle or for at most this many rounds "
                     "(0: keep the mapper's tracks; each round costs a bundle adjustment)")
      ->capture_default_str()
      ->check(CLI::Range(0, 100));
  command.add_option("--camera-model", arguments.camera_model,
                     "COLMAP camera model for SfM (default SIMPLE_RADIAL: single focal length)");
  command.add_option("--intrinsics", arguments.intrinsics,
                     "known intrinsics held fixed: f (principal point at the centre) or "
                     "fx,fy,cx,cy, in pixels");
  command.add_option("--known-cameras", arguments.options.known_cameras,
                     "COLMAP model folder with known intrinsics and poses: only triangulate")
      ->check(CLI::ExistingDirectory);
  command.add_option("--hold-out", arguments.options.hold_out_every,
                     "hold out every N-th photo in name order, from the first (as novel-view benchmarks do, "
                     "e.g. 8): registered with the others, then kept out of depth, fusion, the mesh and the "
                     "render sources; `parallax evaluate WS` renders their cameras and scores them")
      ->check(CLI::Range(2, 100000));
  command.add_option("--hold-out-photos", arguments.options.hold_out_photos,
                     "hold out these photos (names in the folder, comma-separated), as --hold-out does")
      ->delimiter(',');
}

// Multi-view stereo and the mesh.
void AddDenseOptions(CLI::App& command, ReconstructArguments& arguments) {
  command.add_flag("--no-depth", arguments.no_depth, "stop after structure from motion (no multi-view stereo)");
  const std::map<std::string, StereoMethod> stereo_methods = {
      {"patchmatch", StereoMethod::kPatchMatch}, {"sgbm", StereoMethod::kSgbm}};
  command.add_option("--stereo", arguments.options.stereo,
                     "depth method: patchmatch (default) or sgbm (OpenCV StereoSGBM on "
                     "rectified pairs, the baseline)")
      ->transform(CLI::CheckedTransformer(stereo_methods, CLI::ignore_case));
  command.add_option("--mvs-sources", arguments.options.mvs_sources,
                     "source views per depth map (default: as --quality says: 3, 5, 7)")
      ->check(CLI::Range(1, 32));
  CLI::Option* scale = command.add_option(
      "--mvs-scale", arguments.options.mvs_scale,
      "resolution of the depth estimate as a share of each photo side, no cap (1: full size; "
      "default: as --quality caps the long side: 768, 1024, 1600 px; depth maps are written at "
      "that resolution and read back at the photo's size)");
  scale->check(CLI::Range(0.25, 1.0));
  command.add_option("--mvs-max-size", arguments.options.mvs_max_size,
                     "cap on the long side of the depth estimate, in pixels (default: as --quality says)")
      ->check(CLI::Range(64, 100000))
      ->excludes(scale);
  command.add_option("--mvs-seed", arguments.options.mvs_seed,
                     "seed of the depth stage's random search (default 0): runs with other seeds "
                     "measure the run-to-run spread of the depth and of what is built from it");
  command.add_flag("--no-mesh", arguments.no_mesh, "stop after depth maps and the fused cloud (no textured mesh)");
  const std::map<std::string, Mesher> meshers{{"poisson", Mesher::kPoisson}, {"tsdf", Mesher::kTsdf}};
  command.add_option("--mesher", arguments.options.mesher,
                     "poisson|tsdf: the mesh's surface from the fused cloud by screened Poisson (default), or "
                     "from the depth maps fused into a truncated signed-distance volume by marching cubes")
      ->transform(CLI::CheckedTransformer(meshers, CLI::ignore_case));
  command.add_option("--tsdf-voxel", arguments.options.tsdf_voxel_pixels,
                     "--mesher tsdf: the voxel in depth-map pixels at the maps' median depth (default 4)")
      ->check(CLI::Range(0.25, 64.0));
  command.add_option("--tsdf-weight", arguments.options.tsdf_min_weight,
                     "--mesher tsdf: how many depth maps must have written each voxel of a cell for it to make "
                     "surface (default 2)")
      ->check(CLI::Range(0.5, 1000.0));
}

// The options as the command line set them, checked; submitted to Slurm or run here.
void RunReconstruct(const ReconstructArguments& arguments, const CLI::App& command) {
  ReconstructOptions options = arguments.options;
  const std::optional<CameraModel> camera_model = CameraModelNamed(arguments.camera_model);
  if (!camera_model) throw UsageError("--camera-model: unknown camera model '" + arguments.camera_model + "'");
  options.camera_model = *camera_model;
  options.estimate_depth = !arguments.no_depth;
  options.build_mesh = !arguments.no_depth && !arguments.no_mesh;
  if (!arguments.intrinsics.empty()) options.intrinsics = ParseNumberList(arguments.intrinsics, "--intrinsics");
  if (arguments.slurm.OnSlurm()) {
    options.Check();
    const SlurmOptions slurm = arguments.slurm.Resolve();
    const SlurmSubmission submission =
        SubmitReconstructToSlurm(arguments.photos, arguments.workspace, options, ThisExecutable(),
                                 JobArguments(command, {arguments.photos, arguments.workspace},
                                              {"--known-cameras", "--vocab-tree"}),
                                 slurm);
    PrintSubmission(submission, slurm.wait);
    return;
  }
  ReconstructSummary summary;
  {
    TerminalProgress progress;
    summary = Reconstruct(arguments.photos, arguments.workspace, options, progress);
  }
  PrintSummary(summary, arguments.workspace, options.dry_run);
}

}  // namespace

void RegisterReconstructCommand(CLI::App& app) {
  auto arguments = std::make_shared<ReconstructArguments>();
  CLI::App* command = app.add_subcommand(
      "reconstruct",
      "Photos folder -> workspace: COLMAP features, matching, mapping and undistortion "
      "(CPU), checked for plausibility. Re-running skips stages whose inputs and options are "
      "unchanged.");
  command->add_option("photos_dir", arguments->photos, "folder of photos (not recursive)")->required();
  command->add_option("workspace", arguments->workspace, "output folder (created if missing)")->required();
  AddSfmOptions(*command, *arguments);
  AddDenseOptions(*command, *arguments);
  command->add_flag("--strict", arguments->options.strict,
                    "an implausible reconstruction is an error (exit 2), not a warning");
  command->add_flag("--dry-run", arguments->options.dry_run,
                    "print the plan (stages to run or skip, and why) and stop");
  command->add_option("--colmap", arguments->options.colmap, "colmap executable (default: colmap on PATH)");
  AddSlurmOptions(*command, arguments->slurm, "SfM, the depth passes as job arrays and the rest",
                  "views per depth task");
  command->callback([arguments, command] { RunReconstruct(*arguments, *command); });
}

}  // namespace parallax
