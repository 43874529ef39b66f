#include <cstdio>
#include <filesystem>
#include <map>
#include <memory>
#include <optional>
#include <stdexcept>
#include <string>
#include <vector>

#include "apps/commands.h"
#include "apps/number_list.h"
#include "apps/viewer_paths.h"
#include "core/workspace_lock.h"
#include "eval/shadow_reference.h"
#include "viewer/screenshot.h"
#include "viewer/view_cameras.h"
#include "viewer/view_math.h"
#include "viewer/viewer_scene.h"
#include "viewer/window.h"

namespace parallax {
namespace {

struct ViewArguments {
  std::filesystem::path workspace;
  std::filesystem::path screenshot;
  std::filesystem::path screenshot_dir = ".";  // The window's S key.
  double motion_hold_ms = WindowOptions().motion_hold_ms;
  std::string camera;
  std::optional<double> orbit_deg;
  std::optional<double> elevation_deg;  // Default: the source cameras' elevation, else 30.
  double fov_deg = 50;
  std::string size;  // "WxH"
  std::string light = "45,50";  // Azimuth, elevation (degrees) of a directional light.
  std::string point_light;      // "x,y,z" (world): a point light instead.
  std::string shadows = "auto";
  TextureMode texture = TextureMode::kAtlas;
  FrameSettings settings;
  bool no_cameras = false;
  bool no_grid = false;
  std::optional<bool> glare;  // Unset: with auto exposure.
  int timed_frames = 0;  // Extra frames drawn after the screenshot to time the renderer.
  bool shadow_iou = false;  // Compare the screenshot's shadows with Embree ray tracing.
};

FrameSettings Settings(const ViewArguments& a, const ViewerScene& scene) {
  FrameSettings settings = a.settings;
  settings.texture = a.texture;
  const std::map<std::string, ShadowMode> modes{{"none", ShadowMode::kNone},  {"blob", ShadowMode::kBlob},
                                                {"planar", ShadowMode::kPlanar}, {"map", ShadowMode::kMap},
                                                {"pcf", ShadowMode::kPcf},     {"volume", ShadowMode::kVolume}};
  if (a.shadows != "auto") {
    settings.shadows = modes.at(a.shadows);
  } else {
    const ShadowChoice choice = ChooseShadows(scene, a.texture);
    settings.shadows = choice.mode;
    std::printf("shadows: %s (--shadows auto)\n", choice.reason.c_str());
  }
  settings.show_cameras = !a.no_cameras;
  settings.show_grid = !a.no_grid;
  settings.glare = a.glare.value_or(settings.auto_exposure);
  if (!a.point_light.empty()) {
    const std::vector<double> p = ParseNumbers(a.point_light, 3, "--point-light");
    settings.light.type = LightKind::kPoint;
    settings.light.position = Eigen::Vector3d(p[0], p[1], p[2]);
    // The irradiance --light-intensity at the scene's centre, like the directional light's.
    settings.light.intensity *= static_cast<float>((settings.light.position - scene.Centre().cast<double>()).squaredNorm());
  } else {
    const std::vector<double> angles = ParseNumbers(a.light, 2, "--light");
    settings.light.direction = LightDirectionFromAngles(scene.up, angles[0], angles[1]);
  }
  settings.Check();
  return settings;
}

void PrintScreenshot(const ViewArguments& a, const ViewerScene& scene, const FrameSettings& settings) {
  ScreenshotOptions options{a.screenshot, a.camera, a.orbit_deg, a.elevation_deg, a.fov_deg,
                            a.size.empty() ? std::nullopt : std::optional(ParseSize(a.size)),
                            a.timed_frames};
  const Screenshot shot = TakeScreenshot(scene, settings, options);
  for (const std::string& note : shot.notes) std::fprintf(stderr, "note: %s\n", note.c_str());
  std::printf("wrote %s (%dx%d, %.0f ms)\n", a.screenshot.string().c_str(), shot.frame.color.Width(),
              shot.frame.color.Height(), shot.ms);
  if (settings.shadows != ShadowMode::kNone) {
    std::printf("shadow memory: %.2f MB\n", static_cast<double>(shot.shadow_bytes) / (1 << 20));
  }
  if (shot.display_mesh) {
    std::printf("level of detail: the display mesh, %zu of %zu triangles\n", shot.drawn->triangles.size(),
                scene.mesh.triangles.size());
  }
  if (a.shadow_iou) {
    const ShadowAccuracy accuracy = MeasureShadowAccuracy(*shot.drawn, shot.view, settings, shot.frame, scene.ground,
                                                          static_cast<double>(GroundBand(scene)));
    const MaskComparison& mask = accuracy.all;
    const MaskComparison& cast = accuracy.cast;
    std::printf("shadow IoU against Embree ray tracing: %.4f (%d rendered, %d ray-traced shadowed of %d pixels); "
                "cast shadows alone: %.4f (%d / %d of %d pixels facing the light)\n",
                mask.iou, mask.rendered_shadowed, mask.reference_shadowed, mask.compared, cast.iou,
                cast.rendered_shadowed, cast.reference_shadowed, cast.compared);
    if (accuracy.on_ground) {
      std::printf("cast shadows on the ground: %.4f (%d / %d of %d pixels); on the objects: %.4f (%d / %d of %d pixels)\n",
                  accuracy.on_ground->iou, accuracy.on_ground->rendered_shadowed,
                  accuracy.on_ground->reference_shadowed, accuracy.on_ground->compared, accuracy.on_objects->iou,
                  accuracy.on_objects->rendered_shadowed, accuracy.on_objects->reference_shadowed,
                  accuracy.on_objects->compared);
    }
  }
  if (!shot.times) return;
  const FrameTimes& times = *shot.times;
  std::printf("frame time over %d frames (%dx%d): median %.1f ms, min %.1f ms\n", times.frames,
              static_cast<int>(shot.view.camera.width), static_cast<int>(shot.view.camera.height),
              times.median_ms, times.min_ms);
  if (times.moving_median_ms) {
    std::printf("frame time with the light moving: median %.1f ms, min %.1f ms\n",
                *times.moving_median_ms, *times.moving_min_ms);
  }
  std::printf("frame time as the window draws while moving (half resolution%s): camera moving: median %.1f ms",
              times.moving_light_reduced_ms ? ", half the shadow map's side while the light moves" : "",
              times.moving_camera_ms);
  if (times.moving_light_reduced_ms) std::printf(", light moving: median %.1f ms", *times.moving_light_reduced_ms);
  std::printf("\n");
}

// Where the view stands: a source camera or an orbit, and the image size.
void AddViewpointOptions(CLI::App& command, ViewArguments& a) {
  auto* camera = command.add_option("--camera", a.camera, "view from this source camera (image name or stem)");
  command.add_option("--orbit", a.orbit_deg,
                     "view from an orbit about the scene at this azimuth (degrees); it looks where the source "
                     "cameras look, from as far, when they surround the scene")
      ->excludes(camera);
  command.add_option("--elevation", a.elevation_deg,
                     "orbit elevation above the ground (degrees; default: the source cameras' when they "
                     "surround the scene, else 30)");
  command.add_option("--fov", a.fov_deg, "orbit camera's horizontal field of view (degrees, default 50)")
      ->check(CLI::Range(1.0, 170.0));
  command.add_option("--size", a.size, "image size WxH (default 1280x720; a source camera's own size)");
}

// What the frame shows and how: shadows, texture, light, exposure.
void AddLookOptions(CLI::App& command, ViewArguments& a) {
  command.add_option("--shadows", a.shadows,
                     "auto|none|blob|planar|map|pcf|volume (default auto: none for projected photos, "
                     "volume for a mesh of up to 4000 triangles, else pcf; it says which)")
      ->transform(CLI::IsMember({"auto", "none", "blob", "planar", "map", "pcf", "volume"}, CLI::ignore_case));
  const std::map<std::string, TextureMode> textures{{"atlas", TextureMode::kAtlas},
                                                    {"projective", TextureMode::kProjective},
                                                    {"shaded", TextureMode::kShaded},
                                                    {"matcap", TextureMode::kMatcap}};
  command.add_option("--texture", a.texture,
                     "atlas|projective|shaded|matcap (default atlas; matcap: the atlas with a sphere-map "
                     "specular)")
      ->transform(CLI::CheckedTransformer(textures, CLI::ignore_case));
  command.add_option("--light", a.light, "directional light azimuth,elevation in degrees (default 45,50)");
  command.add_option("--point-light", a.point_light, "a point light at x,y,z (world) instead");
  command.add_option("--exposure", a.settings.exposure_stops, "exposure in stops (default 0)");
  const std::map<std::string, ToneMap> tone_maps{
      {"clamp", ToneMap::kClamp}, {"reinhard", ToneMap::kReinhard}, {"aces", ToneMap::kAces}};
  command.add_option("--tone-map", a.settings.tone_map,
                     "clamp|reinhard|aces: how linear light becomes display values (default clamp: values over 1 "
                     "clip; reinhard and aces render into a float frame first)")
      ->transform(CLI::CheckedTransformer(tone_maps, CLI::ignore_case));
  command.add_option("--white", a.settings.white, "reinhard: the exposed value shown as white (default 4)")
      ->check(CLI::Range(1.0, 1e6));
  command.add_flag("--auto-exposure", a.settings.auto_exposure,
                   "expose each frame for its log-average luminance (mid grey 0.18), tone-mapped; in the window "
                   "the eye adapts over half a second");
  command.add_flag("--glare,!--no-glare", a.glare,
                   "spread light over the display's white into a halo before tone mapping, keeping its energy "
                   "(default: on with --auto-exposure)");
  command.add_option("--light-intensity", a.settings.light.intensity,
                     "the light's irradiance, linear (default 1; a point light's at the scene's centre)")
      ->check(CLI::Range(0.0, 1e6));
  command.add_option("--shadow-map-size", a.settings.shadow_map_size, "shadow map side in texels (default 2048)")
      ->check(CLI::Range(64, 8192));
  command.add_option("--pcf-radius", a.settings.pcf_radius, "PCF kernel radius in texels (default 1)")
      ->check(CLI::Range(0, 4));
}

// The screenshot's measurements and the window's controls.
void AddScreenshotAndWindowOptions(CLI::App& command, ViewArguments& a) {
  command.add_option("--time-frames", a.timed_frames,
                     "with --screenshot: draw this many more frames and print the median frame time")
      ->check(CLI::Range(1, 10000));
  command.add_flag("--shadow-iou", a.shadow_iou,
                   "with --screenshot: compare its shadow mask with one ray-traced by Embree for the same "
                   "mesh and light, and print the intersection over union");
  command.add_option("--screenshot-dir", a.screenshot_dir,
                     "in the window: where the S key writes view-<n>.png (default: the current folder)");
  command.add_option("--motion-hold-ms", a.motion_hold_ms,
                     "in the window: how long after a drag or a light move frames are drawn at half "
                     "resolution, to keep the motion smooth (default 200; 0: always full resolution)")
      ->check(CLI::Range(0.0, 60000.0));
  command.add_flag("--no-cameras", a.no_cameras, "hide the source cameras");
  command.add_flag("--no-grid", a.no_grid, "hide the ground grid");
}

// Reads the scene under a shared lock, then writes the screenshot or opens the window.
void RunView(const ViewArguments& a) {
  const ViewerScene scene = [&] {
    const WorkspaceLock lock(a.workspace, LockMode::kShared, "view");  // While it reads.
    return LoadViewerScene(ViewerScenePathsFor(a.workspace));
  }();
  const FrameSettings settings = Settings(a, scene);
  if (!a.screenshot.empty()) {
    PrintScreenshot(a, scene, settings);
    return;
  }
  WindowOptions options;
  if (!a.size.empty()) std::tie(options.width, options.height) = ParseSize(a.size);
  options.fov_deg = a.fov_deg;
  options.azimuth_deg = a.orbit_deg.value_or(30);
  options.elevation_deg = a.elevation_deg;
  const std::vector<double> light = ParseNumbers(a.light, 2, "--light");
  options.light_azimuth_deg = light[0];
  options.light_elevation_deg = light[1];
  options.screenshot_dir = a.screenshot_dir;
  options.motion_hold_ms = a.motion_hold_ms;
  RunViewerWindow(scene, settings, options, SourceIndex(scene, a.camera),
                  [](const std::string& text) {
                    std::fputs(text.c_str(), stdout);
                    std::fflush(stdout);
                  });
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
  AddViewpointOptions(*command, *a);
  AddLookOptions(*command, *a);
  AddScreenshotAndWindowOptions(*command, *a);
  command->callback([a] { RunView(*a); });
}

}  // namespace parallax
