#include "viewer/screenshot.h"

#include <algorithm>
#include <chrono>
#include <numbers>

#include "core/elapsed.h"
#include "core/image.h"
#include "viewer/egl_context.h"
#include "viewer/view_cameras.h"
#include "viewer/view_math.h"

namespace parallax {
namespace {

// The median and fastest of `frames` frames, each finished with glFinish; `before_frame(i)` may
// change the settings and the view first.
template <typename BeforeFrame>
std::pair<double, double> TimeFrames(SceneRenderer& renderer, ViewCamera view, FrameSettings settings, int frames,
                                     const BeforeFrame& before_frame) {
  std::vector<double> ms;
  for (int i = 0; i < frames; ++i) {
    before_frame(i, settings, view);
    const auto start = std::chrono::steady_clock::now();
    renderer.Draw(view, settings);
    renderer.Finish();
    ms.push_back(MsSince(start));
  }
  std::sort(ms.begin(), ms.end());
  return {ms[ms.size() / 2], ms[0]};
}

// A tenth of a degree back and forth about the z axis, every frame.
Eigen::AngleAxisd Wobble(int frame) {
  return Eigen::AngleAxisd((frame % 2 == 0 ? 1 : -1) * 0.1 * std::numbers::pi / 180, Eigen::Vector3d::UnitZ());
}

FrameTimes TimeFrames(SceneRenderer& renderer, const ViewCamera& view, const FrameSettings& settings,
                      int frames) {
  FrameTimes times;
  times.frames = frames;
  const auto still = [](int, FrameSettings&, ViewCamera&) {};
  const auto turn_light = [&](int i, FrameSettings& s, ViewCamera&) {
    s.light.position = Wobble(i) * settings.light.position;
    s.light.direction = Wobble(i) * settings.light.direction;
  };
  const auto turn_camera = [&](int i, FrameSettings&, ViewCamera& v) {
    // About the camera's own centre: its rotation and translation turn together.
    const Eigen::Quaterniond turn(Wobble(i));
    v.cam_from_world = Rigid3d(turn * view.cam_from_world.rotation, turn * view.cam_from_world.translation);
  };
  std::tie(times.median_ms, times.min_ms) = TimeFrames(renderer, view, settings, frames, still);
  times.moving_camera_ms = TimeFrames(renderer, MovingView(view), settings, frames, turn_camera).first;
  // With the light moving, a shadow map is rendered again each frame, a volume built again.
  if (settings.shadows == ShadowMode::kNone) return times;
  std::tie(times.moving_median_ms, times.moving_min_ms) = TimeFrames(renderer, view, settings, frames, turn_light);
  times.moving_light_reduced_ms =
      TimeFrames(renderer, MovingView(view), MovingSettings(settings, true), frames, turn_light).first;
  return times;
}

ViewCamera ScreenshotCamera(const ViewerScene& scene, const ScreenshotOptions& options) {
  if (options.camera.empty()) {
    const auto [width, height] = options.size.value_or(std::pair{1280, 720});
    return OrbitViewCamera(scene, options.orbit_deg.value_or(30), options.elevation_deg, width, height,
                           options.fov_deg);
  }
  if (!options.size) return SourceViewCamera(scene, options.camera);  // Throws for an unknown name.
  const ViewerSource& source = scene.sources[static_cast<size_t>(*SourceIndex(scene, options.camera))];
  return ScaledSourceViewCamera(source, options.size->first, options.size->second);
}

}  // namespace

Screenshot TakeScreenshot(const ViewerScene& scene, const FrameSettings& settings,
                          const ScreenshotOptions& options) {
  Screenshot shot;
  shot.view = ScreenshotCamera(scene, options);
  const HeadlessGlContext context;
  SceneRenderer renderer(scene);
  const auto start = std::chrono::steady_clock::now();
  shot.frame = renderer.Render(shot.view, settings);
  shot.ms = MsSince(start);
  shot.notes = renderer.TakeNotes();
  shot.shadow_bytes = renderer.ShadowBytes(settings.shadows);
  WriteImage(options.path, shot.frame.color, PixelFormat::kUint8);  // Atomic: temporary + rename.
  shot.drawn = &DisplayedMesh(scene, shot.frame.color.Width(), shot.frame.color.Height());
  shot.display_mesh = shot.drawn == &scene.display_mesh;
  if (options.timed_frames > 0) shot.times = TimeFrames(renderer, shot.view, settings, options.timed_frames);
  return shot;
}

}  // namespace parallax
