// Google Benchmark of multi-view stereo's hot loop: PatchMatch (bilaterally weighted NCC
// through plane homographies, propagation, refinement) on one reference view and one source.
// (pipeline's WindowCost is a test entry point that rebuilds the reference windows of the
// whole image per call, so it is not timed here.)
#include <cmath>

#include <benchmark/benchmark.h>

#include "core/camera.h"
#include "mvs/patch_match.h"

namespace parallax {
namespace {

// A textured grey image (sum of sines), deterministic.
GrayImage Texture(int width, int height, double phase) {
  GrayImage image{width, height, std::vector<float>(static_cast<size_t>(width) * height)};
  for (int y = 0; y < height; ++y) {
    for (int x = 0; x < width; ++x) {
      image.values[static_cast<size_t>(y) * width + x] = static_cast<float>(
          0.5 + 0.2 * std::sin(0.31 * x + phase) * std::cos(0.23 * y) + 0.1 * std::sin(0.07 * (x + y)));
    }
  }
  return image;
}

void BM_PatchMatch320x240(benchmark::State& state) {
  const Camera camera = MakePinholeCamera(1, 320, 240, 250, 250, 160, 120);
  StereoView reference{camera, Rigid3d(), Texture(320, 240, 0)};
  StereoView source{camera, Rigid3d(), Texture(320, 240, 0.4)};
  source.cam_from_world.translation = Eigen::Vector3d(-0.2, 0, 0);
  PatchMatchOptions options;
  options.min_depth = 2;
  options.max_depth = 20;
  for (auto _ : state) {
    benchmark::DoNotOptimize(PatchMatchStereo(reference, {&source}, options));
  }
  state.counters["pixels_per_s"] = benchmark::Counter(
      static_cast<double>(state.iterations()) * 320 * 240, benchmark::Counter::kIsRate);
}
BENCHMARK(BM_PatchMatch320x240)->Unit(benchmark::kMillisecond)->UseRealTime();

}  // namespace
}  // namespace parallax

BENCHMARK_MAIN();
