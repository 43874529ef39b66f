#include "synth/synth.h"

#include <algorithm>
#include <chrono>
#include <stdexcept>

#include <tbb/task_arena.h>

#include "core/atomic_file.h"
#include "core/depth_map.h"
#include "core/elapsed.h"
#include "core/image.h"
#include "core/scene_folder.h"
#include "core/sparse_model.h"
#include "core/check.h"
#include "synth/ray_tracer.h"

namespace parallax {
namespace fs = std::filesystem;
namespace {

// Linear radiance -> sRGB-encoded values in [0, 1], as 8-bit files store them.
Image EncodeForDisplay(const Image& linear) {
  Image encoded = LinearToSrgb(linear);
  for (float& value : encoded.Pixels()) value = std::clamp(value, 0.0f, 1.0f);
  return encoded;
}

SparseModel GroundTruthModel(const Camera& camera, const std::vector<ViewDesc>& views) {
  SparseModel model;
  model.AddCamera(camera);
  for (size_t i = 0; i < views.size(); ++i) {
    SparseImage image;
    image.id = static_cast<uint32_t>(i + 1);
    image.camera_id = camera.id;
    image.name = views[i].name;
    image.cam_from_world = views[i].cam_from_world;
    model.AddImage(std::move(image));
  }
  return model;
}

}  // namespace

void SynthOptions::Check() const {
  RequireOption(num_threads >= 0, "SynthOptions.num_threads", num_threads, ">= 0");
}

Camera SceneCamera(const SceneDesc& scene) {
  const double f = scene.image.focal_px;
  return MakePinholeCamera(1, static_cast<uint64_t>(scene.image.width),
                           static_cast<uint64_t>(scene.image.height), f, f,
                           scene.image.width / 2.0, scene.image.height / 2.0);
}

SynthSummary RenderSceneFolder(const SceneDesc& scene, const std::string& scene_json,
                               const fs::path& out_dir, const SynthOptions& options,
                               Progress& progress) {
  options.Check();
  const auto start = std::chrono::steady_clock::now();
  const SceneFolder folder{out_dir};
  const Camera camera = SceneCamera(scene);
  WriteFileAtomically(folder.SceneJson(), scene_json);

  const int total = static_cast<int>(scene.training.size() + scene.novel.size());
  int done = 0;
  tbb::task_arena arena(options.num_threads > 0 ? options.num_threads
                                                : tbb::task_arena::automatic);
  arena.execute([&] {
    const RayTracer tracer(scene);
    for (const auto& [views, paths] : {std::pair{&scene.training, folder.Training()},
                                       std::pair{&scene.novel, folder.Novel()}}) {
      if (views->empty()) continue;
      for (const ViewDesc& view : *views) {
        progress.Update("render", done, total);
        const RenderedView rendered = tracer.Render(camera, view.cam_from_world);
        // Small: example scenes are committed (and reproduced byte for byte by a test).
        WriteImage(paths.images / view.name, EncodeForDisplay(rendered.color),
                   PixelFormat::kUint8, PngCompression::kSmall);
        WriteDepthExr(paths.DepthFor(view.name), rendered.depth);
        if (scene.write_normals) {
          WriteImage(paths.NormalFor(view.name), rendered.normal, PixelFormat::kHalf);
        }
        ++done;
      }
      WriteSparseModel(GroundTruthModel(camera, *views), paths.sparse, SparseFormat::kText);
    }
  });
  progress.Update("render", done, total);
  SynthSummary summary;
  summary.training_views = static_cast<int>(scene.training.size());
  summary.novel_views = static_cast<int>(scene.novel.size());
  summary.seconds = SecondsSince(start);
  return summary;
}

}  // namespace parallax
