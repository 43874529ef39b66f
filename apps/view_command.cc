#include <algorithm>
#include <chrono>
#include <cstdio>
#include <filesystem>
#include <map>
#include <memory>
#include <numbers>
#include <optional>
#include <sstream>
#include <stdexcept>
#include <string>
#include <vector>

#include "apps/commands.h"
#include "apps/number_list.h"
#include "core/error.h"
#include "core/image.h"
#include "viewer/egl_context.h"
#include "viewer/renderer.h"
#include "viewer/shadow_reference.h"
#include "viewer/view_cameras.h"
#include "viewer/view_math.h"
#include "viewer/viewer_scene.h"
#include "viewer/window.h"

namespace parallax {
namespace {

struct ViewArguments {
  std::filesystem::path workspace;
  std::filesystem::path screenshot;
  std::string camera;
  std::optional<double> orbit_deg;
  std::optional<double> elevation_deg;  // Default: the source cameras' elevation, else 30.
  double fov_deg = 50;
  std::string size;  // "WxH"
  std::string light = "45,50";  // Azimuth, elevation (degrees) of a directional light.
  std::string point_light;      // "x,y,z" (world): a point light instead.
  ShadowMode shadows = ShadowMode::kPcf;
  TextureMode texture = TextureMode::kAtlas;
  FrameSettings settings;
  bool no_cameras = false;
  bool no_grid = false;
  int timed_frames = 0;  // Extra frames drawn after the screenshot to time the renderer.
  bool shadow_iou = false;  // Compare the screenshot's shadows with Embree ray tracing.
};

std::vector<double> ParseNumbers(const std::string& text, size_t count, const std::string& option) {
  std::vector<double> values = ParseNumberList(text, option);
  if (values.size() != count) {
    throw std::invalid_argument(option + " " + text + ": expected " + std::to_string(count) +
                                " comma-separated numbers");
  }
  return values;
}

std::pair<int, int> ParseSize(const std::string& text) {
  int width = 0, height = 0;
  char x = 0, extra = 0;
  if (std::sscanf(text.c_str(), "%d%c%d%c", &width, &x, &height, &extra) != 3 || x != 'x' || width < 16 ||
      height < 16 || width > 16384 || height > 16384) {
    throw std::invalid_argument("--size " + text + ": expected WxH with 16..16384 pixels per side, e.g. 1280x720");
  }
  return {width, height};
}

FrameSettings Settings(const ViewArguments& a, const ViewerScene& scene) {
  FrameSettings settings = a.settings;
  settings.shadows = a.shadows;
  settings.texture = a.texture;
  settings.show_cameras = !a.no_cameras;
  settings.show_grid = !a.no_grid;
  if (!a.point_light.empty()) {
    const std::vector<double> p = ParseNumbers(a.point_light, 3, "--point-light");
    settings.light.type = LightKind::kPoint;
    settings.light.position = Eigen::Vector3d(p[0], p[1], p[2]);
    // Irradiance 1 at the scene's centre, like the default directional light.
    settings.light.intensity = static_cast<float>((settings.light.position - scene.Centre().cast<double>()).squaredNorm());
  } else {
    const std::vector<double> angles = ParseNumbers(a.light, 2, "--light");
    settings.light.direction = LightDirectionFromAngles(scene.up, angles[0], angles[1]);
  }
  settings.Check();
  return settings;
}

std::optional<int> SourceIndex(const ViewerScene& scene, const std::string& name) {
  if (name.empty()) return std::nullopt;
  SourceViewCamera(scene, name);  // Throws with the known names when there is none.
  for (size_t i = 0; i < scene.sources.size(); ++i) {
    if (scene.sources[i].name == name || std::filesystem::path(scene.sources[i].name).stem() == name) {
      return static_cast<int>(i);
    }
  }
  return std::nullopt;
}

// The median and fastest of `frames` frames, each finished with glFinish; `before_frame(i)` may
// change the settings first.
template <typename BeforeFrame>
std::pair<double, double> TimeFrames(SceneRenderer& renderer, const ViewCamera& view, FrameSettings settings,
                                     int frames, const BeforeFrame& before_frame) {
  std::vector<double> ms;
  for (int i = 0; i < frames; ++i) {
    before_frame(i, settings);
    const auto start = std::chrono::steady_clock::now();
    renderer.Draw(view, settings);
    renderer.Finish();
    ms.push_back(std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count());
  }
  std::sort(ms.begin(), ms.end());
  return {ms[ms.size() / 2], ms[0]};
}

// Draws `frames` more frames of the same view and prints the median and the fastest: the frame
// time of the interactive viewer holding still. With a shadow map, again with the light moving
// a little every frame, so the map is re-rendered each time.
void PrintFrameTimes(SceneRenderer& renderer, const ViewCamera& view, const FrameSettings& settings, int frames) {
  const auto [median, fastest] = TimeFrames(renderer, view, settings, frames, [](int, FrameSettings&) {});
  std::printf("frame time over %d frames (%dx%d): median %.1f ms, min %.1f ms\n", frames,
              static_cast<int>(view.camera.width), static_cast<int>(view.camera.height), median, fastest);
  if (settings.shadows != ShadowMode::kMap && settings.shadows != ShadowMode::kPcf) return;
  const auto [moving, moving_fastest] = TimeFrames(renderer, view, settings, frames, [&](int i, FrameSettings& s) {
    // A tenth of a degree back and forth about the z axis: a new map every frame.
    const Eigen::AngleAxisd turn((i % 2 == 0 ? 1 : -1) * 0.1 * std::numbers::pi / 180, Eigen::Vector3d::UnitZ());
    s.light.position = turn * settings.light.position;
    s.light.direction = turn * settings.light.direction;
  });
  std::printf("frame time with the light moving (shadow map re-rendered): median %.1f ms, min %.1f ms\n", moving,
              moving_fastest);
}

// The frame's shadow mask against Embree's exact one for the mesh it drew.
void PrintShadowAccuracy(const TexturedMesh& drawn, const ViewCamera& view, const FrameSettings& settings,
                         const FrameResult& frame) {
  if (settings.light.type != LightKind::kDirectional || drawn.triangles.empty()) {
    throw BadInputError("--shadow-iou needs a directional light and a mesh");
  }
  const std::vector<ReferencePixel> reference = ReferenceShadows(drawn, view, settings.light.direction);
  const MaskComparison mask = CompareShadowMasks(reference, frame.aux);
  const MaskComparison cast = CompareCastShadows(reference, frame.aux);
  std::printf("shadow IoU against Embree ray tracing: %.4f (%d rendered, %d ray-traced shadowed of %d pixels); "
              "cast shadows alone: %.4f (%d / %d of %d pixels facing the light)\n",
              mask.iou, mask.rendered_shadowed, mask.reference_shadowed, mask.compared, cast.iou,
              cast.rendered_shadowed, cast.reference_shadowed, cast.compared);
}

void TakeScreenshot(const ViewArguments& a, const ViewerScene& scene, const FrameSettings& settings) {
  const std::optional<std::pair<int, int>> size =
      a.size.empty() ? std::nullopt : std::optional(ParseSize(a.size));
  ViewCamera view;
  if (!a.camera.empty()) {
    view = SourceViewCamera(scene, a.camera);
    if (size) view = ScaledSourceViewCamera(scene.sources[*SourceIndex(scene, a.camera)], size->first, size->second);
  } else {
    const auto [width, height] = size.value_or(std::pair{1280, 720});
    view = OrbitViewCamera(scene, a.orbit_deg.value_or(30), a.elevation_deg, width, height, a.fov_deg);
  }
  const HeadlessGlContext context;
  SceneRenderer renderer(scene);
  const auto start = std::chrono::steady_clock::now();
  const FrameResult result = renderer.Render(view, settings);
  const double ms = std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count();
  for (const std::string& note : renderer.TakeNotes()) std::fprintf(stderr, "note: %s\n", note.c_str());
  WriteImage(a.screenshot, result.colour, PixelFormat::kUint8);  // Atomic: temporary + rename.
  std::printf("wrote %s (%dx%d, %.0f ms)\n", a.screenshot.string().c_str(), result.colour.Width(),
              result.colour.Height(), ms);
  const TexturedMesh& drawn = DisplayedMesh(scene, result.colour.Width(), result.colour.Height());
  if (&drawn == &scene.display_mesh) {
    std::printf("level of detail: the display mesh, %zu of %zu triangles\n", drawn.triangles.size(),
                scene.mesh.triangles.size());
  }
  if (a.shadow_iou) PrintShadowAccuracy(drawn, view, settings, result);
  if (a.timed_frames > 0) PrintFrameTimes(renderer, view, settings, a.timed_frames);
}

}  // namespace

void RegisterViewCommand(CLI::App& app) {
  auto a = std::make_shared<ViewArguments>();
  CLI::App* command = app.add_subcommand(
      "view",
      "Shadowed, textured OpenGL viewer of a workspace (mesh and/or fused cloud, source cameras); "
      "--screenshot renders offscreen (EGL, no display needed) into a PNG.");
  command->add_option("workspace", a->workspace, "workspace folder (mesh/mesh.obj and/or fused.ply, sparse/)")
      ->required();
  command->add_option("--screenshot", a->screenshot, "render offscreen into this PNG and exit");
  auto* camera = command->add_option("--camera", a->camera, "view from this source camera (image name or stem)");
  command->add_option("--orbit", a->orbit_deg, "view from an orbit about the scene at this azimuth (degrees); it looks where the source cameras look, "
                 "from as far, when they surround the scene")
      ->excludes(camera);
  command->add_option("--elevation", a->elevation_deg,
                      "orbit elevation above the ground (degrees; default: the source cameras' when they "
                      "surround the scene, else 30)");
  command->add_option("--fov", a->fov_deg, "orbit camera's horizontal field of view (degrees, default 50)")
      ->check(CLI::Range(1.0, 170.0));
  command->add_option("--size", a->size, "image size WxH (default 1280x720; a source camera's own size)");
  const std::map<std::string, ShadowMode> shadows{{"none", ShadowMode::kNone},
                                                  {"planar", ShadowMode::kPlanar},
                                                  {"map", ShadowMode::kMap},
                                                  {"pcf", ShadowMode::kPcf}};
  command->add_option("--shadows", a->shadows, "none|planar|map|pcf (default pcf)")
      ->transform(CLI::CheckedTransformer(shadows, CLI::ignore_case));
  const std::map<std::string, TextureMode> textures{{"atlas", TextureMode::kAtlas},
                                                    {"projective", TextureMode::kProjective},
                                                    {"shaded", TextureMode::kShaded}};
  command->add_option("--texture", a->texture, "atlas|projective|shaded (default atlas)")
      ->transform(CLI::CheckedTransformer(textures, CLI::ignore_case));
  command->add_option("--light", a->light, "directional light azimuth,elevation in degrees (default 45,50)");
  command->add_option("--point-light", a->point_light, "a point light at x,y,z (world) instead");
  command->add_option("--exposure", a->settings.exposure_stops, "exposure in stops (default 0)");
  command->add_option("--shadow-map-size", a->settings.shadow_map_size, "shadow map side in texels (default 2048)")
      ->check(CLI::Range(64, 8192));
  command->add_option("--pcf-radius", a->settings.pcf_radius, "PCF kernel radius in texels (default 1)")
      ->check(CLI::Range(0, 4));
  command->add_option("--time-frames", a->timed_frames,
                      "with --screenshot: draw this many more frames and print the median frame time")
      ->check(CLI::Range(1, 10000));
  command->add_flag("--shadow-iou", a->shadow_iou,
                    "with --screenshot: compare its shadow mask with one ray-traced by Embree for the same "
                    "mesh and light, and print the intersection over union");
  command->add_flag("--no-cameras", a->no_cameras, "hide the source cameras");
  command->add_flag("--no-grid", a->no_grid, "hide the ground grid");
  command->callback([a] {
    const ViewerScene scene = LoadViewerScene(a->workspace);
    const FrameSettings settings = Settings(*a, scene);
    if (!a->screenshot.empty()) {
      TakeScreenshot(*a, scene, settings);
      return;
    }
    WindowOptions options;
    if (!a->size.empty()) std::tie(options.width, options.height) = ParseSize(a->size);
    options.fov_deg = a->fov_deg;
    options.azimuth_deg = a->orbit_deg.value_or(30);
    options.elevation_deg = a->elevation_deg;
    RunViewerWindow(scene, settings, options, SourceIndex(scene, a->camera),
                    [](const std::string& text) {
                      std::fputs(text.c_str(), stdout);
                      std::fflush(stdout);
                    });
  });
}

}  // namespace parallax
