#pragma once
// The OpenGL renderer of the viewer: one code path for the window and for offscreen images.
// Every frame is drawn into the renderer's own framebuffer (sRGB-encoded color, a float
// auxiliary target, 32-bit float depth + stencil); the window blits it to the screen, the
// offscreen path reads it back.
//
// Needs a current OpenGL 3.3 core context (HeadlessGlContext or a GLFW window) for its whole
// life. Depth uses reverse-Z (glClipControl, GL 4.5 / ARB_clip_control, which llvmpipe has)
// with an infinite far plane; without it, near and far are fitted to the scene's bounds.
#include <memory>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "core/camera.h"
#include "core/image.h"
#include "core/pose.h"
#include "viewer/viewer_scene.h"

namespace parallax {

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
  int shadow_map_size = 2048;     // Shadow map side in texels, 64..8192.
  int pcf_radius = 1;             // PCF kernel radius in texels (kernel 2r+1 square), 0..4.
  int projective_views = 3;       // Source photos blended in projective mode, 1..3.
  bool show_mesh = true;
  bool show_points = true;        // The fused cloud (drawn only when there is no mesh unless set).
  bool points_with_mesh = false;  // Draw the cloud even when a mesh is present.
  bool show_cameras = true;       // Source cameras as frusta.
  bool show_grid = true;          // Grid on the ground plane.
  float point_size_px = 2;
  bool reverse_z = true;          // Use reverse-Z where glClipControl exists.
  Eigen::Vector3f background{0.32f, 0.36f, 0.42f};  // Linear RGB.
  void Check() const;             // Throws std::invalid_argument naming the field.
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
};

class SceneRenderer {
 public:
  // Uploads the scene. Throws std::runtime_error if a shader does not compile or GL fails.
  explicit SceneRenderer(const ViewerScene& scene);
  ~SceneRenderer();
  SceneRenderer(const SceneRenderer&) = delete;
  SceneRenderer& operator=(const SceneRenderer&) = delete;

  // Draws one frame of the view's camera size into the internal framebuffer and, when
  // `window_framebuffer` >= 0, blits it there (0 is a window's default framebuffer), scaled to
  // `window_width` x `window_height` when given (a frame drawn smaller while moving). The
  // shadow map is re-rendered only when the light, its size or the PCF bias changed (the scene
  // is fixed): moving the eye costs the main pass alone. Only Render fills the auxiliary
  // target; Draw leaves it as it was.
  void Draw(const ViewCamera& view, const FrameSettings& settings, int window_framebuffer = -1,
            int window_width = 0, int window_height = 0);

  // Draws and reads the frame back.
  FrameResult Render(const ViewCamera& view, const FrameSettings& settings);

  // Waits until every GL command issued so far has finished (glFinish), e.g. to time a frame.
  void Finish() const;

  bool UsesReverseZ() const;
  // GPU memory the last frame's shadow method held for itself (bytes): the shadow map, the
  // volume's vertices, the blob texture and quads; planar shadows and volumes' stencil share
  // the frame's depth-stencil buffer.
  size_t ShadowBytes(ShadowMode mode) const;
  // Messages for the user, e.g. that planar shadows are skipped without a ground plane.
  std::vector<std::string> TakeNotes();

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

// Ground within this distance of the fitted plane receives planar and blob shadows (and is
// "the ground" of --shadow-iou's split): 1% of the focus radius.
float GroundBand(const ViewerScene& scene);

// The level of detail a width x height frame draws: scene.display_mesh (when it has triangles)
// if scene.mesh would give a triangle fewer than 16 pixels, else scene.mesh. Finer triangles
// cost llvmpipe vertex and setup work without adding detail the atlas does not already show.
const TriangleMesh& DisplayedMesh(const ViewerScene& scene, int width, int height);

// While the user moves the camera or the light, frames give up detail for speed and the first
// still frame brings it back: half the resolution (a quarter of the pixels, scaled up when
// shown), and while the light moves a shadow map of half the side (at least 512 texels), which
// is rendered again every frame, read without PCF's filter.
ViewCamera MovingView(const ViewCamera& view);
FrameSettings MovingSettings(const FrameSettings& settings, bool light_moving);

// What `--shadows auto` draws for a scene, and why: nothing when the photos are projected as
// captured (they hold their own shadows), a shadow map for a point cloud, shadow volumes (exact)
// for a mesh small enough that their silhouettes cost little fill, else PCF.
struct ShadowChoice {
  ShadowMode mode = ShadowMode::kPcf;
  std::string reason;
};
ShadowChoice ChooseShadows(const ViewerScene& scene, TextureMode texture);

// The source views to project for an eye at `eye`: up to `count` indices into scene.sources,
// with a photo on disk, nearest by the angle their centres make with the eye at the scene
// centre.
std::vector<int> NearestSourceViews(const ViewerScene& scene, const Eigen::Vector3d& eye, int count);

}  // namespace parallax
