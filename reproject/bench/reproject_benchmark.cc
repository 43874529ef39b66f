// Render timings on example_images/courtyard (640x480, ground-truth depth): a novel view from
// its K best training views, per warp method and fill method. Counter: target pixels / s.
#include <benchmark/benchmark.h>

#include <stdexcept>
#include <vector>

#include "core/scene_folder.h"
#include "reproject/render.h"
#include "reproject/scene_views.h"
#include "reproject/source_selection.h"

namespace parallax {
namespace {

struct Scene {
  std::vector<SourceView> training;
  std::vector<PosedCamera> novel;
};

const Scene& Courtyard() {
  static const Scene scene = [] {
    const SceneFolder folder{std::filesystem::path(PARALLAX_SOURCE_DIR) / "example_images" / "courtyard"};
    Scene s;
    s.training = ReadSourceViews(folder.Training());
    s.novel = ReadPosedCameras(folder.Novel(), nullptr);
    return s;
  }();
  return scene;
}

std::vector<const SourceView*> Sources(const Scene& scene, const PosedCamera& target, int k) {
  std::vector<PosedCamera> cameras;
  for (const SourceView& view : scene.training) cameras.push_back(view.Posed());
  SourceSelectionOptions options;
  options.num_sources = k;
  std::vector<const SourceView*> sources;
  for (int i : SelectSources(cameras, target, options)) {
    sources.push_back(&scene.training[static_cast<size_t>(i)]);
  }
  return sources;
}

void BM_Render(benchmark::State& state, WarpMethod method, FillMethod fill) {
  const Scene& scene = Courtyard();
  const PosedCamera& target = scene.novel.front();
  const std::vector<const SourceView*> sources =
      Sources(scene, target, static_cast<int>(state.range(0)));
  RenderOptions options;
  options.warp.method = method;
  options.fill.method = fill;
  double warp_ms = 0, blend_ms = 0, classify_ms = 0, fill_ms = 0;
  // Frames of a camera path: buffers are reused, as a viewer or `render --path` would.
  Renderer renderer(options);
  for (auto _ : state) {
    const RenderResult result = renderer.Render(sources, target);
    benchmark::DoNotOptimize(result.color.Pixels().data());
    warp_ms += result.timings.warp_ms;
    blend_ms += result.timings.blend_ms;
    classify_ms += result.timings.classify_ms;
    fill_ms += result.timings.fill_ms;
  }
  const double pixels = static_cast<double>(target.camera.width * target.camera.height);
  const double iterations = static_cast<double>(state.iterations());
  state.counters["pixels_per_s"] =
      benchmark::Counter(pixels * iterations, benchmark::Counter::kIsRate);
  state.counters["warp_ms"] = warp_ms / iterations;
  state.counters["blend_ms"] = blend_ms / iterations;
  state.counters["classify_ms"] = classify_ms / iterations;
  state.counters["fill_ms"] = fill_ms / iterations;
}

// One source into the target, alone (the render warps its sources two at a time on 2 cores).
void BM_ForwardWarp(benchmark::State& state, WarpMethod method) {
  const Scene& scene = Courtyard();
  const PosedCamera& target = scene.novel.front();
  const SourceView& source = *Sources(scene, target, 1).front();
  ForwardWarpOptions options;
  options.method = method;
  WarpBuffer buffer;
  WarpScratch scratch;
  for (auto _ : state) {
    ForwardWarp(source, 0, target, options, &buffer, &scratch);
    benchmark::DoNotOptimize(buffer.MutableDepth());
  }
  state.counters["pixels_per_s"] = benchmark::Counter(
      static_cast<double>(source.depth.Width() * source.depth.Height()) *
          static_cast<double>(state.iterations()),
      benchmark::Counter::kIsRate);
}

BENCHMARK_CAPTURE(BM_ForwardWarp, mesh, WarpMethod::kMesh)->Unit(benchmark::kMillisecond)->UseRealTime();
BENCHMARK_CAPTURE(BM_ForwardWarp, splat, WarpMethod::kSplat)->Unit(benchmark::kMillisecond)->UseRealTime();
BENCHMARK_CAPTURE(BM_Render, mesh_depth_aware, WarpMethod::kMesh, FillMethod::kDepthAware)
    ->Arg(1)->Arg(2)->Arg(4)->Unit(benchmark::kMillisecond)->UseRealTime();
BENCHMARK_CAPTURE(BM_Render, splat_depth_aware, WarpMethod::kSplat, FillMethod::kDepthAware)
    ->Arg(4)->Unit(benchmark::kMillisecond)->UseRealTime();
BENCHMARK_CAPTURE(BM_Render, mesh_no_fill, WarpMethod::kMesh, FillMethod::kNone)
    ->Arg(4)->Unit(benchmark::kMillisecond)->UseRealTime();
BENCHMARK_CAPTURE(BM_Render, mesh_inpaint, WarpMethod::kMesh, FillMethod::kInpaint)
    ->Arg(4)->Unit(benchmark::kMillisecond)->UseRealTime();

}  // namespace
}  // namespace parallax

BENCHMARK_MAIN();
