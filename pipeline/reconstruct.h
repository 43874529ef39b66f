#pragma once
// `parallax reconstruct`: photos -> COLMAP features, matches, mapping (or triangulation with
// known cameras) -> undistorted PINHOLE workspace (docs/design.md "Workspace"), checked for
// plausibility -> depth maps -> fused cloud -> textured mesh, each a cached stage of one
// graph (pipeline/stage_graph.h); what each stage did goes to <ws>/report.json.
#include <filesystem>
#include <optional>
#include <string>
#include <vector>

#include "core/progress.h"
#include "mesh/poisson.h"
#include "mvs/mvs.h"
#include "pipeline/reconstruct_options.h"
#include "pipeline/camera_uncertainty.h"
#include "pipeline/stage_graph.h"
#include "sfm/photo_set.h"
#include "sfm/plausibility.h"
#include "sfm/quality_settings.h"

namespace parallax {

struct ReconstructSummary {
  std::vector<StageRecord> stages;
  std::vector<SkippedFile> skipped_files;
  std::string matcher;  // The matcher used, and why.
  std::string mapper;   // The mapper used, and why.
  std::string camera_model;
  // The settings of --quality the photos' features were extracted with: photos registered into
  // the model later (evaluate's held-out photos) are extracted the same way.
  QualitySettings features{};
  int images_found = 0;
  int images_registered = 0;
  std::vector<std::string> unregistered;  // Names of photos not in the model.
  std::vector<std::string> held_out;      // Registered photos held out (Workspace::HeldOut).
  int other_models = 0;                   // Disconnected models besides the one kept.
  size_t points3d = 0;
  double mean_track_length = 0;
  double mean_reprojection_error_px = 0;
  PlausibilityReport plausibility;
  // How well the photos determine the cameras, where the principal point's check measured it.
  std::optional<CameraUncertainty> camera_uncertainty;
  // Multi-view stereo per view: source views chosen, depth range, valid shares (as written
  // to <ws>/depth/views.json); absent when depth was not estimated.
  std::optional<MvsSummary> depth;
  std::optional<MeshSummary> mesh;  // Absent when no mesh was built.
  // The depth stage's working resolution for each photo size, and why.
  std::vector<std::string> depth_resolution;
  std::vector<std::string> notes;  // Decisions worth knowing (e.g. a refinement kept or not).
  std::vector<std::string> warnings;
  // The first warnings_said of them were said through Progress::Warn as they were found.
  size_t warnings_said = 0;
};

// Runs (or with dry_run, plans) the SfM stages into `workspace`. Validates everything before
// starting colmap. Throws BadInputError (bad photos, unwritable workspace, too few images
// registered, implausible under strict), ToolError (colmap missing or failing).
ReconstructSummary Reconstruct(const std::filesystem::path& photos_dir,
                               const std::filesystem::path& workspace,
                               const ReconstructOptions& options, Progress& progress);

}  // namespace parallax
