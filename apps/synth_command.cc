#include <cstdio>
#include <filesystem>
#include <memory>

#include "apps/commands.h"
#include "apps/terminal_progress.h"
#include "core/atomic_file.h"
#include "synth/synth.h"

namespace parallax {

void RegisterSynthCommand(CLI::App& app) {
  struct Arguments {
    std::filesystem::path scene_json;
    std::filesystem::path out_dir;
    SynthOptions options;
  };
  auto arguments = std::make_shared<Arguments>();
  CLI::App* command = app.add_subcommand(
      "synth",
      "Ray trace a synthetic scene (Embree) into a scene folder: training photos, "
      "ground-truth cameras (COLMAP text) and depth (EXR), and held-out novel views.");
  command->add_option("scene_json", arguments->scene_json,
                      "scene description (format: docs/scene-format.md)")
      ->required();
  command->add_option("out_dir", arguments->out_dir, "scene folder to write (created if missing)")
      ->required();
  command->add_option("--threads", arguments->options.num_threads,
                      "worker threads, 0 = all cores (the output does not depend on it)")
      ->check(CLI::NonNegativeNumber);
  command->callback([arguments] {
    const std::string json = ReadFileBytes(arguments->scene_json);
    const SceneDesc scene = ParseSceneJson(json, arguments->scene_json.string());
    SynthSummary summary;
    {
      TerminalProgress progress;
      summary = RenderSceneFolder(scene, json, arguments->out_dir, arguments->options, progress);
    }
    std::printf("rendered %d training + %d novel views (%dx%d) in %.1f s -> %s\n",
                summary.training_views, summary.novel_views, scene.image.width,
                scene.image.height, summary.seconds, arguments->out_dir.string().c_str());
  });
}

}  // namespace parallax
