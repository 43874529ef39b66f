#pragma once
// The interactive viewer: a GLFW window drawing through the same SceneRenderer as the offscreen
// path, with a trackball (orbit, pan, zoom) and keys for every setting. Key help goes to
// `log` (the terminal); the mode, the view, the light and the frame time go to the window
// title; the S key writes the frame to a PNG.
#include <filesystem>
#include <functional>
#include <optional>
#include <string>

#include "viewer/renderer.h"
#include "viewer/viewer_scene.h"

namespace parallax {

struct WindowOptions {
  int width = 1280;        // Initial window size in screen pixels.
  int height = 720;
  double fov_deg = 50;     // Horizontal field of view of the orbit camera.
  double azimuth_deg = 30; // Initial orbit (DefaultOrbit).
  std::optional<double> elevation_deg;  // Default: the source cameras' elevation, else 30.
  double light_azimuth_deg = 45;    // The light's start (LightDirectionFromAngles); the arrows
  double light_elevation_deg = 50;  // move it from there.
  std::filesystem::path screenshot_dir = ".";  // Where the S key writes view-<n>.png.
  // How long after the camera or the light last moved frames are drawn at half resolution, so
  // that a drag stays smooth where a full frame is slow; 0: always full.
  double motion_hold_ms = 200;
  void Check() const;      // Throws UsageError naming the field.
};

// Runs until the window is closed or Esc is pressed. `start_source` jumps to that source
// camera first (index into scene.sources). Throws ToolError when there is no display (the
// message suggests --screenshot) or GLFW cannot open an OpenGL 3.3 core window.
void RunViewerWindow(const ViewerScene& scene, FrameSettings settings, const WindowOptions& options,
                     std::optional<int> start_source,
                     const std::function<void(const std::string&)>& log);

// The key help printed when the window opens.
std::string ViewerKeyHelp();

}  // namespace parallax
