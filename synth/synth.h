#pragma once
// `parallax synth`: renders a scene description into a scene folder (docs/design.md layout):
// training images with ground-truth cameras and depth, and the same for the novel views.
#include <filesystem>
#include <string>

#include "core/camera.h"
#include "core/progress.h"
#include "synth/scene.h"

namespace parallax {

struct SynthOptions {
  // Worker threads; 0 uses every core. The output does not depend on it.
  int num_threads = 0;
  void Check() const;  // Throws UsageError naming the field.
};

struct SynthSummary {
  int training_views = 0;
  int novel_views = 0;
  double seconds = 0;
};

// The pinhole camera every view of the scene shares (principal point at the image centre).
Camera SceneCamera(const SceneDesc& scene);

// Renders every view of `scene` and writes the scene folder `out_dir` (created if missing;
// files already there are replaced one by one, each atomically). `scene_json` is the text
// the scene was parsed from, copied to <out_dir>/scene.json. Throws BadInputError if the
// folder cannot be written.
SynthSummary RenderSceneFolder(const SceneDesc& scene, const std::string& scene_json,
                               const std::filesystem::path& out_dir,
                               const SynthOptions& options, Progress& progress);

}  // namespace parallax
