#pragma once
// `parallax view --screenshot`: one frame rendered offscreen (EGL) into a PNG, from a source
// camera or an orbit, and optionally the frame time of more frames like it.
#include <filesystem>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "viewer/renderer.h"
#include "viewer/viewer_scene.h"

namespace parallax {

struct ScreenshotOptions {
  std::filesystem::path path;  // The PNG, written atomically.
  std::string camera;          // A source camera (image name or stem); empty: the orbit.
  std::optional<double> orbit_deg;      // Azimuth; default 30.
  std::optional<double> elevation_deg;  // Default: the source cameras', else 30.
  double fov_deg = 50;
  std::optional<std::pair<int, int>> size;  // Default 1280x720, or the source camera's own.
  int timed_frames = 0;  // More frames drawn after the screenshot to time the renderer.
};

// The median and the fastest of the timed frames, with a still light and (with shadows) with
// the light moving a little every frame, so that the map is rendered again each time; and the
// medians of frames as the window draws them while the user moves the camera or the light
// (MovingView, MovingSettings).
struct FrameTimes {
  int frames = 0;
  double median_ms = 0, min_ms = 0;
  std::optional<double> moving_median_ms, moving_min_ms;
  double moving_camera_ms = 0;
  std::optional<double> moving_light_reduced_ms;
};

struct Screenshot {
  FrameResult frame;
  ViewCamera view;
  const TriangleMesh* drawn = nullptr;  // The mesh drawn: the scene's, or its display copy.
  bool display_mesh = false;            // Whether that is the display copy.
  double ms = 0;                        // The first frame, shader compilation included.
  std::vector<std::string> notes;       // What the renderer left out, and why.
  size_t shadow_bytes = 0;              // SceneRenderer::ShadowBytes after the frame.
  std::optional<FrameTimes> times;      // With options.timed_frames > 0.
};

// Renders `scene` with `settings` and writes the PNG. Throws BadInputError for an unknown
// camera name, ToolError when no OpenGL context can be made (egl_context.h).
Screenshot TakeScreenshot(const ViewerScene& scene, const FrameSettings& settings,
                          const ScreenshotOptions& options);

}  // namespace parallax
