// Render timings on example_images/courtyard (640x480, ground-truth depth): a novel view from
// its K best training views, per warp method, texture filter and fill method; and the same scene at
// 1920x1080 (every view upsampled 3x, bilinear color, nearest depth, and cropped to 16:9).
// The hot loops alone too: one forward warp, the blend of four, classification and filling;
// and the K=4 render on one thread. Counter: target pixels / s.
#include <benchmark/benchmark.h>

#include <algorithm>
#include <chrono>
#include <stdexcept>
#include <vector>

#include <tbb/global_control.h>

#include "core/scene_folder.h"
#include "reproject/forward_warp.h"
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

// The camera scaled by `scale` and cropped to `height` rows about its centre.
Camera ScaledCamera(const Camera& camera, int scale, int height) {
  const double crop = (static_cast<double>(camera.height) * scale - height) / 2;
  return MakePinholeCamera(camera.id, camera.width * static_cast<uint64_t>(scale),
                           static_cast<uint64_t>(height), camera.FocalX() * scale,
                           camera.FocalY() * scale, camera.PrincipalX() * scale,
                           camera.PrincipalY() * scale - crop);
}

SourceView Upsampled(const SourceView& view, int scale, int height) {
  SourceView out = view;
  out.camera = ScaledCamera(view.camera, scale, height);
  const int width = view.color.Width() * scale;
  const int crop = (view.color.Height() * scale - height) / 2;
  out.color = Image(width, height, 3);
  out.depth = DepthMap(width, height);
  for (int y = 0; y < height; ++y) {
    // Source coordinates of the pixel centre, clamped for the bilinear taps.
    const double sy = std::clamp((y + crop + 0.5) / scale - 0.5, 0.0, view.color.Height() - 1.0);
    const int y0 = std::min(static_cast<int>(sy), view.color.Height() - 2);
    const float fy = static_cast<float>(sy - y0);
    for (int x = 0; x < width; ++x) {
      const double sx = std::clamp((x + 0.5) / scale - 0.5, 0.0, view.color.Width() - 1.0);
      const int x0 = std::min(static_cast<int>(sx), view.color.Width() - 2);
      const float fx = static_cast<float>(sx - x0);
      for (int c = 0; c < 3; ++c) {
        const float top = (1 - fx) * view.color.At(x0, y0, c) + fx * view.color.At(x0 + 1, y0, c);
        const float bottom =
            (1 - fx) * view.color.At(x0, y0 + 1, c) + fx * view.color.At(x0 + 1, y0 + 1, c);
        out.color.At(x, y, c) = (1 - fy) * top + fy * bottom;
      }
      // Bilinear depth on smooth surfaces, nearest across edges and next to depth 0.
      const float d[4] = {view.depth.At(x0, y0), view.depth.At(x0 + 1, y0),
                          view.depth.At(x0, y0 + 1), view.depth.At(x0 + 1, y0 + 1)};
      const float lo = std::min({d[0], d[1], d[2], d[3]}), hi = std::max({d[0], d[1], d[2], d[3]});
      out.depth.At(x, y) =
          lo > 0 && hi < 1.02f * lo
              ? (1 - fy) * ((1 - fx) * d[0] + fx * d[1]) + fy * ((1 - fx) * d[2] + fx * d[3])
              : view.depth.At(x / scale, (y + crop) / scale);
    }
  }
  PrepareSource(&out);  // The copied mask and texture were the small view's.
  return out;
}

// Courtyard at 1920x1080 (sources and targets).
const Scene& CourtyardHd() {
  static const Scene scene = [] {
    const Scene& small = Courtyard();
    Scene s;
    for (const SourceView& view : small.training) s.training.push_back(Upsampled(view, 3, 1080));
    for (const PosedCamera& camera : small.novel) {
      s.novel.push_back({ScaledCamera(camera.camera, 3, 1080), camera.cam_from_world});
    }
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

void BM_Render(benchmark::State& state, WarpMethod method, FillMethod fill, bool hd = false,
               TextureFilter filter = TextureFilter::kAuto) {
  const Scene& scene = hd ? CourtyardHd() : Courtyard();
  const PosedCamera& target = scene.novel.front();
  const std::vector<const SourceView*> sources =
      Sources(scene, target, static_cast<int>(state.range(0)));
  RenderOptions options;
  options.warp.method = method;
  options.fill.method = fill;
  options.warp.texture_filter = filter;
  double warp_ms = 0, blend_ms = 0, classify_ms = 0, fill_ms = 0;
  // Frames of a camera path: buffers are reused, as a viewer or `render --path` would.
  Renderer renderer(options);
  RenderResult result;
  // The first two frames allocate what later ones reuse (the result's images swap with the
  // renderer's), page faults included; timed apart from the frames of a path.
  const auto first_start = std::chrono::steady_clock::now();
  for (int frame = 0; frame < 2; ++frame) renderer.Render(sources, target, &result);
  const double first_ms =
      std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - first_start).count() / 2;
  for (auto _ : state) {
    renderer.Render(sources, target, &result);
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
  state.counters["first_frames_ms"] = first_ms;
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
    ForwardWarp(source, target, options, &buffer, &scratch);
    benchmark::DoNotOptimize(buffer.MutableDepth());
  }
  state.counters["pixels_per_s"] = benchmark::Counter(
      static_cast<double>(source.depth.Width() * source.depth.Height()) *
          static_cast<double>(state.iterations()),
      benchmark::Counter::kIsRate);
}

// The K=4 warps of the first novel view, made once for the blend and fill benchmarks.
struct WarpedSources {
  std::vector<const SourceView*> sources;
  std::vector<WarpBuffer> buffers;
  std::vector<WarpScratch> scratch;
};

const WarpedSources& WarpedForBlend() {
  static const WarpedSources warped = [] {
    const Scene& scene = Courtyard();
    WarpedSources w;
    w.sources = Sources(scene, scene.novel.front(), 4);
    w.buffers.resize(w.sources.size());
    w.scratch.resize(w.sources.size());
    for (size_t i = 0; i < w.sources.size(); ++i) {
      ForwardWarp(*w.sources[i], scene.novel.front(), {}, &w.buffers[i], &w.scratch[i]);
    }
    return w;
  }();
  return warped;
}

void SetPixelRate(benchmark::State& state, const PosedCamera& target) {
  state.counters["pixels_per_s"] = benchmark::Counter(
      static_cast<double>(target.camera.width * target.camera.height) * static_cast<double>(state.iterations()),
      benchmark::Counter::kIsRate);
}

// Four warped sources blended into the target (front-most surface with support, weights).
void BM_Blend(benchmark::State& state) {
  const WarpedSources& warped = WarpedForBlend();
  BlendResult blend;  // Reused, as the renderer reuses its own.
  for (auto _ : state) {
    Blend(warped.buffers, {}, &blend);
    benchmark::DoNotOptimize(blend.color.Pixels().data());
  }
  SetPixelRate(state, Courtyard().novel.front());
}

// Classification of the blended view's empty pixels and depth-aware filling.
void BM_ClassifyAndFill(benchmark::State& state) {
  const WarpedSources& warped = WarpedForBlend();
  const PosedCamera& target = Courtyard().novel.front();
  BlendResult blended;
  Blend(warped.buffers, {}, &blended);
  std::vector<ClassifySource> sources;
  for (size_t i = 0; i < warped.sources.size(); ++i) {
    sources.push_back({warped.sources[i]->Posed(), &warped.sources[i]->depth, &warped.scratch[i].Background()});
  }
  double classify_ms = 0, fill_ms = 0;
  for (auto _ : state) {
    BlendResult blend = blended;
    const auto start = std::chrono::steady_clock::now();
    const ClassMap classes = ClassifyPixels(blend, sources, target, {});
    const auto classified = std::chrono::steady_clock::now();
    FillHoles(classes, target.camera, {}, &blend);
    classify_ms += std::chrono::duration<double, std::milli>(classified - start).count();
    fill_ms += std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - classified).count();
    benchmark::DoNotOptimize(blend.color.Pixels().data());
  }
  const double iterations = static_cast<double>(state.iterations());
  state.counters["classify_ms"] = classify_ms / iterations;
  state.counters["fill_ms"] = fill_ms / iterations;
  SetPixelRate(state, target);
}

// The K=4 render on one thread: against BM_Render/mesh_depth_aware/4, how well it uses the
// two cores.
void BM_RenderOneThread(benchmark::State& state) {
  const tbb::global_control one_thread(tbb::global_control::max_allowed_parallelism, 1);
  BM_Render(state, WarpMethod::kMesh, FillMethod::kDepthAware);
}

BENCHMARK(BM_Blend)->Unit(benchmark::kMillisecond)->UseRealTime();
BENCHMARK(BM_ClassifyAndFill)->Unit(benchmark::kMillisecond)->UseRealTime();
BENCHMARK_CAPTURE(BM_ForwardWarp, mesh, WarpMethod::kMesh)->Unit(benchmark::kMillisecond)->UseRealTime();
BENCHMARK_CAPTURE(BM_ForwardWarp, splat, WarpMethod::kSplat)->Unit(benchmark::kMillisecond)->UseRealTime();
BENCHMARK_CAPTURE(BM_Render, mesh_depth_aware, WarpMethod::kMesh, FillMethod::kDepthAware)
    ->Arg(1)->Arg(2)->Arg(4)->Unit(benchmark::kMillisecond)->UseRealTime();
BENCHMARK_CAPTURE(BM_Render, splat_depth_aware, WarpMethod::kSplat, FillMethod::kDepthAware)
    ->Arg(4)->Unit(benchmark::kMillisecond)->UseRealTime();
BENCHMARK_CAPTURE(BM_Render, mesh_bicubic_depth_aware, WarpMethod::kMesh, FillMethod::kDepthAware,
                  false, TextureFilter::kBicubic)
    ->Arg(4)->Unit(benchmark::kMillisecond)->UseRealTime();
BENCHMARK_CAPTURE(BM_Render, mesh_no_fill, WarpMethod::kMesh, FillMethod::kNone)
    ->Arg(4)->Unit(benchmark::kMillisecond)->UseRealTime();
BENCHMARK_CAPTURE(BM_Render, mesh_inpaint, WarpMethod::kMesh, FillMethod::kInpaint)
    ->Arg(4)->Unit(benchmark::kMillisecond)->UseRealTime();
BENCHMARK(BM_RenderOneThread)->Arg(4)->Unit(benchmark::kMillisecond)->UseRealTime();
BENCHMARK_CAPTURE(BM_Render, mesh_depth_aware_1920x1080, WarpMethod::kMesh, FillMethod::kDepthAware, true)
    ->Arg(4)->Unit(benchmark::kMillisecond)->UseRealTime();

}  // namespace
}  // namespace parallax

BENCHMARK_MAIN();
