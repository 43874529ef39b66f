#pragma once
// `parallax render`: novel views of a workspace or a scene folder, computing only what the
// cameras asked for need: depth for the source views they use that have none, and nothing
// else (no fused cloud, no mesh).
#include <filesystem>
#include <functional>
#include <optional>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "core/progress.h"
#include "reproject/novel_views.h"
#include "reproject/workspace_depth.h"

namespace parallax {

// A stage of the request, as report.json lists it: run (reason says what it did), or skipped
// (reason says why).
struct RequestStage {
  std::string name;
  bool skipped = false;
  std::string reason;
};

struct RenderSummary {
  std::vector<RequestStage> stages;
  std::vector<std::string> depth_estimated;  // Views whose depth this request estimated.
  std::string depth_note;                    // What the depth estimate did, when it ran.
  std::vector<std::string> dropped;          // Views without a depth map, not used.
  size_t views = 0;                          // Cameras rendered.
  size_t source_views = 0;                   // Source views of the input.
  int sources_loaded = 0;                    // Of those, read from disk.
  double hole_ratio_mean = 0;                // Before filling.
  double hole_ratio_filled_mean = 0;         // After.
  double ms_per_view = 0;
};

// The cameras to render: a COLMAP model, or else a path among the sources.
struct RenderTargets {
  std::filesystem::path model;
  std::optional<CameraPath> path;
};

// One part of a request, for a job array (`render --executor slurm`, pipeline/slurm.h).
enum class RenderStep {
  kAll,      // The whole request.
  kPrepare,  // What every frame reads and a frame must not write beside another: the color
             // gains and the depth the cameras need (<out>/blocks/prepare.json says what ran).
  kFrames,   // One block of frames: their files, and <out>/blocks/<block>.csv and .json;
             // nothing when that block's .csv exists (a resubmitted task redoes only what is
             // missing).
  kCollect,  // Every block's rows into render.csv, their reports into report.json.
};

struct RenderPart {
  RenderStep step = RenderStep::kAll;
  int block = 0;       // kFrames: frames [block * block_size, (block + 1) * block_size).
  int block_size = 1;  // kFrames and kCollect.
};

// Called after each view is rendered and written: its index of `count`, camera and view.
using RenderedView = std::function<void(size_t index, size_t count, const NamedCamera& camera,
                                        const NovelView& view)>;

// Renders every camera of `targets` from `input` (a workspace or a scene folder) into `out`:
// <name>.png, <name>.holes.png, <name>.depth.exr (WriteNovelView), render.csv and
// report.json; or one `part` of that. Throws BadInputError for an unusable input (or a
// block missing when collecting), ToolError when a tool fails.
RenderSummary RenderCameras(const std::filesystem::path& input, const RenderTargets& cameras,
                            const NovelViewSettings& settings, const std::filesystem::path& out,
                            Progress& progress, const RenderedView& on_view, const RenderPart& part = {});

// How many cameras `targets` holds for `input`.
size_t CountRenderTargets(const std::filesystem::path& input, const RenderTargets& targets);

void to_json(nlohmann::json& json, const RequestStage& stage);

}  // namespace parallax
