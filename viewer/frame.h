#pragma once
// The plain data of a viewer frame: what to draw (shadows, texture, light, tone map), where from
// (ViewCamera) and what comes back (FrameResult). No GL here: evaluation code (eval/) and other
// CPU code share these types with the renderer without linking OpenGL (library
// parallax::viewer_frame).
#include <functional>

#include <Eigen/Core>

#include "core/camera.h"
#include "core/image.h"
#include "core/pose.h"

namespace parallax {

// Seconds on a monotonic clock, read once a frame: auto exposure adapts over the time between
// frames (SceneRenderer's clock: the steady clock's, or a test's that steps time itself).
using FrameClock = std::function<double()>;

// The most source photos projective texturing blends (FrameSettings::projective_views).
constexpr int kMaxProjectors = 3;

enum class ShadowMode {
  kNone,
  kBlob,    // A soft ellipse on the ground under each object, pushed along the light.
  kPlanar,  // Geometry flattened onto the fitted ground along the light, stencil-masked.
  kMap,     // Shadow map, hardware depth comparison (bilinear between 4 texels).
  kPcf,     // Shadow map filtered over (2r+1)^2 texels (tent weights, (2r)^2 bilinear taps).
  kVolume,  // Shadow volumes counted in the stencil, z-fail (viewer/shadow_volume.h).
};

enum class TextureMode {
  kAtlas,       // The mesh's texture atlas (points: their colors), lit.
  kProjective,  // Source photos projected from their cameras, shown as captured.
  kShaded,      // Uniform grey albedo, lit: shows the geometry and the shadows.
  kMatcap,      // The atlas lit, with the specular of a sphere map (viewer/matcap.h).
};

enum class LightKind { kDirectional, kPoint };

// How linear light becomes a display value. kClamp draws straight into the 8-bit frame (values
// over 1 clip); the others render into a float frame first and map it: extended Reinhard on
// luminance (1 maps to about 0.5, `white` to 1), or the ACES filmic curve (Narkowicz's fit).
enum class ToneMap { kClamp, kReinhard, kAces };

struct LightSettings {
  LightKind type = LightKind::kDirectional;
  Eigen::Vector3d direction = Eigen::Vector3d(-0.4, -0.3, -0.87);  // Directional: travel direction (world).
  Eigen::Vector3d position = Eigen::Vector3d::Zero();              // Point light (world).
  Eigen::Vector3f color{1, 1, 1};  // Linear RGB.
  float intensity = 1;  // Irradiance (directional) or intensity (point, falls off as 1/d^2).
};

struct FrameSettings {
  ShadowMode shadows = ShadowMode::kPcf;
  TextureMode texture = TextureMode::kAtlas;
  LightSettings light;
  float ambient = 0.2f;           // Ambient irradiance, linear.
  float specular = 0.15f;         // Blinn-Phong specular weight.
  float shininess = 32;           // Blinn-Phong exponent.
  float exposure_stops = 0;       // Linear color is scaled by 2^stops before sRGB encoding.
  ToneMap tone_map = ToneMap::kClamp;
  float white = 4;                // Reinhard: the linear value (after exposure) shown as white.
  // Exposure from the frame: its log-average luminance is brought to 0.18 (mid grey), on top
  // of exposure_stops; the frame is then tone-mapped (kClamp counts as Reinhard here).
  bool auto_exposure = false;
  // Time constant of the eye's adaptation to a new brightness (seconds); 0 adapts at once.
  float adaptation_seconds = 0;
  // Light over the display's white spread into a halo before tone mapping (viewer/glare.h),
  // through the float frame.
  bool glare = false;
  int shadow_map_size = 2048;     // Shadow map side in texels, 64..8192.
  int pcf_radius = 1;             // PCF kernel radius in texels (kernel 2r+1 square), 0..4.
  int projective_views = 3;       // Source photos blended in projective mode, 1..kMaxProjectors.
  bool show_mesh = true;
  bool show_points = true;        // The fused cloud (drawn only when there is no mesh unless set).
  bool points_with_mesh = false;  // Draw the cloud even when a mesh is present.
  bool show_cameras = true;       // Source cameras as frusta.
  bool show_grid = true;          // Grid on the ground plane.
  float point_size_px = 2;
  bool reverse_z = true;          // Use reverse-Z where glClipControl exists.
  Eigen::Vector3f background{0.32f, 0.36f, 0.42f};  // Linear RGB.
  void Check() const;             // Throws UsageError naming the field.
  // Whether the frame is drawn in linear light into the float frame, then tone-mapped.
  bool DrawnInFloat() const { return tone_map != ToneMap::kClamp || auto_exposure || glare; }
};

// Where the frame is seen from. The camera is used as a pinhole (distortion ignored).
struct ViewCamera {
  Camera camera;
  Rigid3d cam_from_world;
  double near = 0;  // Near plane (scene units); 0 fits it to the scene bounds.
};

struct FrameResult {
  Image color;  // sRGB-encoded RGB, top row first.
  // Per pixel: light visibility in [0, 1] (1 lit; shadow map/PCF/planar), n.l (the normal
  // turned towards the eye), eye z-depth, coverage (1 where a surface was drawn).
  Image aux;
  // The float frame in linear light before exposure (after the glare where there is one), RGB
  // top row first; empty where the frame was drawn straight into the 8-bit frame.
  Image linear;
};

}  // namespace parallax
