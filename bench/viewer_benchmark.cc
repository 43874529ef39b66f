// Google Benchmark of the viewer's frame: a plane and a box at 1280x720 with 2048^2 PCF
// shadows on Mesa llvmpipe, with a still light (the shadow map is reused) and a light that
// moves every frame (the map is re-rendered).
#include <benchmark/benchmark.h>

#include <Eigen/Geometry>

#include "testing/viewer_scenes.h"
#include "viewer/view_cameras.h"

namespace parallax {
namespace {

using viewer_test::Box;
using viewer_test::EnsureGlContext;
using viewer_test::Plane;
using viewer_test::SceneFromObjects;
using viewer_test::ShadowSettings;

void BM_ShadowFrame(benchmark::State& state) {
  const bool moving_light = state.range(0) != 0;
  EnsureGlContext();
  const ViewerScene scene = SceneFromObjects({Plane(10), Box({0.5, 0.2, 1}, {2, 2, 2}, 20)});
  SceneRenderer renderer(scene);
  const ViewCamera view = OrbitViewCamera(scene, 200, 35, 1280, 720, 50);
  const Eigen::Vector3d light = Eigen::Vector3d(-0.5, -0.3, -0.8).normalized();
  FrameSettings settings = ShadowSettings(ShadowMode::kPcf, light);
  renderer.Render(view, settings);  // Shader compilation and allocations, untimed.
  int frame = 0;
  for (auto _ : state) {
    if (moving_light) {
      settings.light.direction = (light + Eigen::Vector3d(0.01 * (++frame % 50), 0, 0)).normalized();
    }
    renderer.Draw(view, settings);
    renderer.Finish();
  }
  state.SetLabel(moving_light ? "light moving (map re-rendered)" : "still light");
}
BENCHMARK(BM_ShadowFrame)->Arg(0)->Arg(1)->Unit(benchmark::kMillisecond)->UseRealTime();

}  // namespace
}  // namespace parallax

BENCHMARK_MAIN();
