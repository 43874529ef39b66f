#pragma once
// The OpenGL renderer of the viewer: one code path for the window and for offscreen images.
// Every frame is drawn into the renderer's own framebuffer (sRGB-encoded color, a float
// auxiliary target, 32-bit float depth + stencil); the window blits it to the screen, the
// offscreen path reads it back.
//
// Needs a current OpenGL 3.3 core context (HeadlessGlContext or a GLFW window) for its whole
// life. Depth uses reverse-Z (glClipControl, GL 4.5 / ARB_clip_control, which llvmpipe has)
// with an infinite far plane; without it, near and far are fitted to the scene's bounds.
//
// The frame's plain types (FrameSettings, ViewCamera, FrameResult) are in viewer/frame.h; each
// pass of a frame is a class of its own (docs/design.md, viewer/), renderer.cc orchestrates them.
#include <cstddef>
#include <memory>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "core/elapsed.h"
#include "viewer/frame.h"
#include "viewer/viewer_scene.h"

namespace parallax {

class SceneRenderer {
 public:
  // Uploads the scene. `clock` times auto exposure's adaptation. Throws std::runtime_error if a
  // shader does not compile or GL fails.
  explicit SceneRenderer(const ViewerScene& scene, FrameClock clock = SteadySeconds);
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
