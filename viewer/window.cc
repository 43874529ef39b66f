#include "viewer/window.h"

// GL prototypes from glcorearb.h (viewer/gl.h); GLFW must not pull in the legacy <GL/gl.h>.
#include "viewer/gl.h"
#define GLFW_INCLUDE_NONE
#include <GLFW/glfw3.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <stdexcept>

#include "core/check.h"
#include "core/elapsed.h"
#include "core/error.h"
#include "core/image.h"
#include "viewer/view_cameras.h"
#include "viewer/view_math.h"

namespace parallax {
namespace {

const char* ShadowName(ShadowMode mode) {
  switch (mode) {
    case ShadowMode::kNone: return "none";
    case ShadowMode::kBlob: return "blob";
    case ShadowMode::kPlanar: return "planar";
    case ShadowMode::kMap: return "map";
    case ShadowMode::kPcf: return "pcf";
    case ShadowMode::kVolume: return "volume";
  }
  return "?";
}

const char* TextureName(TextureMode mode) {
  switch (mode) {
    case TextureMode::kAtlas: return "atlas";
    case TextureMode::kProjective: return "projective";
    case TextureMode::kShaded: return "shaded";
    case TextureMode::kMatcap: return "matcap";
  }
  return "?";
}

// Everything the callbacks change. GLFW callbacks are C functions: they only record input
// here and never throw.
struct WindowState {
  const ViewerScene* scene = nullptr;
  FrameSettings settings;
  double azimuth_deg = 30, elevation_deg = 25, distance = 1;
  Eigen::Vector3d target = Eigen::Vector3d::Zero();
  Orbit home;  // Where R goes back to.
  double light_azimuth_deg = 45, light_elevation_deg = 50;
  std::optional<int> source;  // Looking through this source camera until the mouse moves it.
  bool dragging_orbit = false, dragging_pan = false;
  double last_x = 0, last_y = 0;
  double fov_deg = 50;
  bool screenshot_requested = false;  // The S key: write the next frame to a PNG.
  // When the user last moved the camera or the light: frames drawn soon after give up detail.
  std::chrono::steady_clock::time_point camera_moved, light_moved;
};

WindowState* State(GLFWwindow* window) {
  return static_cast<WindowState*>(glfwGetWindowUserPointer(window));
}

void UpdateLight(WindowState& s) {
  if (s.settings.light.type == LightKind::kDirectional) {
    s.settings.light.direction = LightDirectionFromAngles(s.scene->up, s.light_azimuth_deg, s.light_elevation_deg);
  } else {
    // A point light on a sphere of twice the scene's radius, at the same angles.
    s.settings.light.position = s.scene->FocusCentre().cast<double>() -
                                2.0 * static_cast<double>(s.scene->FocusRadius()) *
                                    LightDirectionFromAngles(s.scene->up, s.light_azimuth_deg, s.light_elevation_deg);
  }
}

void OnKey(GLFWwindow* window, int key, int, int action, int) {
  if (action != GLFW_PRESS && action != GLFW_REPEAT) return;
  WindowState& s = *State(window);
  FrameSettings& settings = s.settings;
  const int sources = static_cast<int>(s.scene->sources.size());
  const double azimuth = s.light_azimuth_deg, elevation = s.light_elevation_deg;
  switch (key) {
    case GLFW_KEY_ESCAPE: glfwSetWindowShouldClose(window, GLFW_TRUE); break;
    case GLFW_KEY_1: settings.shadows = ShadowMode::kNone; break;
    case GLFW_KEY_2: settings.shadows = ShadowMode::kPlanar; break;
    case GLFW_KEY_3: settings.shadows = ShadowMode::kMap; break;
    case GLFW_KEY_4: settings.shadows = ShadowMode::kPcf; break;
    case GLFW_KEY_5: settings.shadows = ShadowMode::kVolume; break;
    case GLFW_KEY_6: settings.shadows = ShadowMode::kBlob; break;
    case GLFW_KEY_T:
      settings.texture = static_cast<TextureMode>((static_cast<int>(settings.texture) + 1) % 4);
      break;
    case GLFW_KEY_S: s.screenshot_requested = true; break;
    case GLFW_KEY_C: settings.show_cameras = !settings.show_cameras; break;
    case GLFW_KEY_P: settings.points_with_mesh = settings.show_points = !settings.show_points; break;
    case GLFW_KEY_M: settings.show_mesh = !settings.show_mesh; break;
    case GLFW_KEY_G: settings.show_grid = !settings.show_grid; break;
    case GLFW_KEY_H: settings.glare = !settings.glare; break;
    case GLFW_KEY_L:
      settings.light.type = settings.light.type == LightKind::kPoint ? LightKind::kDirectional : LightKind::kPoint;
      break;
    case GLFW_KEY_LEFT: s.light_azimuth_deg -= 5; break;
    case GLFW_KEY_RIGHT: s.light_azimuth_deg += 5; break;
    case GLFW_KEY_UP: s.light_elevation_deg = std::min(89.9, s.light_elevation_deg + 5); break;
    case GLFW_KEY_DOWN: s.light_elevation_deg = std::max(0.1, s.light_elevation_deg - 5); break;
    case GLFW_KEY_EQUAL: settings.exposure_stops += 0.25f; break;
    case GLFW_KEY_MINUS: settings.exposure_stops -= 0.25f; break;
    case GLFW_KEY_RIGHT_BRACKET: settings.pcf_radius = std::min(4, settings.pcf_radius + 1); break;
    case GLFW_KEY_LEFT_BRACKET: settings.pcf_radius = std::max(0, settings.pcf_radius - 1); break;
    case GLFW_KEY_N:
      if (sources > 0) s.source = s.source ? (*s.source + 1) % sources : 0;
      break;
    case GLFW_KEY_B:
      if (sources > 0) s.source = s.source ? (*s.source + sources - 1) % sources : sources - 1;
      break;
    case GLFW_KEY_R:
      s.source.reset();
      s.target = s.home.target;
      s.distance = s.home.distance;
      s.elevation_deg = s.home.elevation_deg;
      break;
    default: break;
  }
  if (s.light_azimuth_deg != azimuth || s.light_elevation_deg != elevation) s.light_moved = std::chrono::steady_clock::now();
  UpdateLight(s);
}

void OnMouseButton(GLFWwindow* window, int button, int action, int) {
  WindowState& s = *State(window);
  const bool pressed = action == GLFW_PRESS;
  if (button == GLFW_MOUSE_BUTTON_LEFT) s.dragging_orbit = pressed;
  if (button == GLFW_MOUSE_BUTTON_RIGHT || button == GLFW_MOUSE_BUTTON_MIDDLE) s.dragging_pan = pressed;
  glfwGetCursorPos(window, &s.last_x, &s.last_y);
}

void OnCursor(GLFWwindow* window, double x, double y) {
  WindowState& s = *State(window);
  const double dx = x - s.last_x, dy = y - s.last_y;
  s.last_x = x;
  s.last_y = y;
  if (!s.dragging_orbit && !s.dragging_pan) return;
  s.source.reset();  // Moving the view leaves the source camera.
  s.camera_moved = std::chrono::steady_clock::now();
  if (s.dragging_orbit) {
    s.azimuth_deg -= 0.3 * dx;
    s.elevation_deg = std::clamp(s.elevation_deg + 0.3 * dy, -89.0, 89.0);
  } else {
    // Pan in the view plane, by a distance proportional to the orbit radius.
    const Rigid3d pose = OrbitPose(s.target, s.scene->up, s.azimuth_deg, s.elevation_deg, s.distance);
    const Eigen::Matrix3d world_from_cam = pose.rotation.conjugate().toRotationMatrix();
    s.target += 0.0015 * s.distance * (-dx * world_from_cam.col(0) - dy * world_from_cam.col(1));
  }
}

void OnScroll(GLFWwindow* window, double, double dy) {
  WindowState& s = *State(window);
  s.distance *= std::pow(0.9, dy);
  s.camera_moved = std::chrono::steady_clock::now();
}

// What the window shows, for the user (and the window test): modes, view, light, frame time.
std::string WindowTitle(const WindowState& s, double frame_ms) {
  char view[96];
  if (s.source) {
    std::snprintf(view, sizeof(view), "camera %s", s.scene->sources[*s.source].name.c_str());
  } else {
    std::snprintf(view, sizeof(view), "view az %.0f el %.0f dist %.3g", s.azimuth_deg, s.elevation_deg, s.distance);
  }
  char title[320];
  std::snprintf(title, sizeof(title),
                "parallax view | shadows %s | texture %s | %s | %s light az %.0f el %.0f%s | %.1f ms",
                ShadowName(s.settings.shadows), TextureName(s.settings.texture), view,
                s.settings.light.type == LightKind::kPoint ? "point" : "directional", s.light_azimuth_deg,
                s.light_elevation_deg, s.settings.glare ? " | glare" : "", frame_ms);
  return title;
}

ViewCamera CurrentView(const WindowState& s, int width, int height) {
  if (s.source) return ScaledSourceViewCamera(s.scene->sources[*s.source], width, height);
  return ViewCamera{ViewerCamera(width, height, s.fov_deg),
                    OrbitPose(s.target, s.scene->up, s.azimuth_deg, s.elevation_deg, s.distance), 0};
}

// Owns glfwInit/glfwTerminate and the window, so every exit path releases them.
struct GlfwWindow {
  GLFWwindow* window = nullptr;
  GlfwWindow(int width, int height) {
    if (!glfwInit()) {
      throw ToolError("GLFW cannot initialise (no usable X display?); use --screenshot out.png to render offscreen");
    }
    glfwWindowHint(GLFW_CONTEXT_VERSION_MAJOR, 3);
    glfwWindowHint(GLFW_CONTEXT_VERSION_MINOR, 3);
    glfwWindowHint(GLFW_OPENGL_PROFILE, GLFW_OPENGL_CORE_PROFILE);
    glfwWindowHint(GLFW_OPENGL_FORWARD_COMPAT, GLFW_TRUE);
    window = glfwCreateWindow(width, height, "parallax view", nullptr, nullptr);
    if (!window) {
      glfwTerminate();
      throw ToolError("GLFW cannot open an OpenGL 3.3 core window; use --screenshot out.png to render offscreen");
    }
    glfwMakeContextCurrent(window);
  }
  ~GlfwWindow() {
    glfwDestroyWindow(window);
    glfwTerminate();
  }
  GlfwWindow(const GlfwWindow&) = delete;
  GlfwWindow& operator=(const GlfwWindow&) = delete;
};

}  // namespace

void WindowOptions::Check() const {
  RequireOption(width >= 16, "WindowOptions.width", width, ">= 16");
  RequireOption(height >= 16, "WindowOptions.height", height, ">= 16");
  RequireOption(fov_deg > 1 && fov_deg < 170, "WindowOptions.fov_deg", fov_deg, "(1, 170)");
  RequireOption(motion_hold_ms >= 0 && motion_hold_ms <= 60000, "WindowOptions.motion_hold_ms", motion_hold_ms,
                "[0, 60000]");
}

std::string ViewerKeyHelp() {
  return "keys: mouse left drag orbit | right/middle drag pan | wheel zoom\n"
         "      1 no shadows  2 planar  3 shadow map  4 PCF  5 volumes  6 blob  [ ] PCF radius\n"
         "      T texture atlas/projective/shaded/matcap   C cameras  P points  M mesh  G grid  H glare\n"
         "      arrows move the light  L point/directional light  + - exposure\n"
         "      N / B next / previous source camera   R reset view   S screenshot   Esc quit\n";
}

void RunViewerWindow(const ViewerScene& scene, FrameSettings settings, const WindowOptions& options,
                     std::optional<int> start_source, const std::function<void(const std::string&)>& log) {
  options.Check();
  settings.Check();
  const char* display = std::getenv("DISPLAY");
  const char* wayland = std::getenv("WAYLAND_DISPLAY");
  if ((!display || !*display) && (!wayland || !*wayland)) {
    throw ToolError("no display: DISPLAY is not set, so the viewer window cannot open; render offscreen "
                    "with --screenshot out.png (or run under xvfb-run)");
  }
  GlfwWindow glfw(options.width, options.height);
  glfwSwapInterval(1);
  SceneRenderer renderer(scene);

  WindowState state;
  state.scene = &scene;
  state.settings = settings;
  if (settings.auto_exposure) state.settings.adaptation_seconds = 0.5f;  // As eyes adapt, not at once.
  state.azimuth_deg = options.azimuth_deg;
  state.fov_deg = options.fov_deg;
  state.home = DefaultOrbit(scene, options.azimuth_deg, options.elevation_deg,
                            ViewerCamera(options.width, options.height, options.fov_deg));
  state.target = state.home.target;
  state.distance = state.home.distance;
  state.elevation_deg = state.home.elevation_deg;
  state.source = start_source;
  state.light_azimuth_deg = options.light_azimuth_deg;
  state.light_elevation_deg = options.light_elevation_deg;
  UpdateLight(state);
  glfwSetWindowUserPointer(glfw.window, &state);
  glfwSetKeyCallback(glfw.window, OnKey);
  glfwSetMouseButtonCallback(glfw.window, OnMouseButton);
  glfwSetCursorPosCallback(glfw.window, OnCursor);
  glfwSetScrollCallback(glfw.window, OnScroll);
  log(ViewerKeyHelp());

  const std::chrono::duration<double, std::milli> motion_hold(options.motion_hold_ms);
  double smoothed_ms = 0;
  int screenshots = 0;
  while (!glfwWindowShouldClose(glfw.window)) {
    int width = 0, height = 0;
    glfwGetFramebufferSize(glfw.window, &width, &height);
    if (width > 0 && height > 0) {
      const auto start = std::chrono::steady_clock::now();
      const bool light_moving = start - state.light_moved < motion_hold;
      const bool moving = light_moving || start - state.camera_moved < motion_hold;
      const ViewCamera view = CurrentView(state, width, height);
      if (moving) {
        renderer.Draw(MovingView(view), MovingSettings(state.settings, light_moving), 0, width, height);
      } else {
        renderer.Draw(view, state.settings, 0);
      }
      glFinish();  // So the time measures the frame, not the command submission.
      const double ms = MsSince(start);
      smoothed_ms = smoothed_ms == 0 ? ms : 0.9 * smoothed_ms + 0.1 * ms;
      if (state.screenshot_requested) {
        state.screenshot_requested = false;
        const std::filesystem::path path =
            options.screenshot_dir / ("view-" + std::to_string(++screenshots) + ".png");
        WriteImage(path, renderer.Render(view, state.settings).color, PixelFormat::kUint8);
        log("wrote " + path.string() + "\n");
      }
      for (const std::string& note : renderer.TakeNotes()) log(note + "\n");
      glfwSetWindowTitle(glfw.window, (WindowTitle(state, smoothed_ms) + (moving ? " | moving: half resolution" : "")).c_str());
      glfwSwapBuffers(glfw.window);
    }
    glfwPollEvents();
  }
}

}  // namespace parallax
