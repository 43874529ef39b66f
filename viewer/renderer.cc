#include "viewer/renderer.h"

#include <algorithm>
#include <filesystem>
#include <span>
#include <string_view>
#include <utility>
#include <vector>

#include "viewer/blob_shadow_pass.h"
#include "viewer/depth_pass.h"
#include "viewer/frame_context.h"
#include "viewer/gl.h"
#include "viewer/gpu_resources.h"
#include "viewer/overlays.h"
#include "viewer/planar_shadow_pass.h"
#include "viewer/projectors.h"
#include "viewer/shadow_map_pass.h"
#include "viewer/shadow_volume_pass.h"
#include "viewer/surface_pass.h"
#include "viewer/tone_mapper.h"
#include "viewer/view_math.h"

namespace parallax {
namespace {

bool HasExtension(std::string_view name) {
  GLint count = 0;
  glGetIntegerv(GL_NUM_EXTENSIONS, &count);
  for (GLint i = 0; i < count; ++i) {
    if (name == reinterpret_cast<const char*>(glGetStringi(GL_EXTENSIONS, static_cast<GLuint>(i)))) {
      return true;
    }
  }
  return false;
}

// The first `channels` channels of `attachment` of `framebuffer`, a float target of `width` x
// `height`, top row first.
Image ReadFloatAttachment(GLuint framebuffer, GLenum attachment, int width, int height, int channels) {
  std::vector<float> texels(static_cast<size_t>(width) * height * 4);
  glBindFramebuffer(GL_READ_FRAMEBUFFER, framebuffer);
  glReadBuffer(attachment);
  glReadPixels(0, 0, width, height, GL_RGBA, GL_FLOAT, texels.data());
  CheckGlError("SceneRenderer::Render read back");
  Image image(width, height, channels);
  for (int y = 0; y < height; ++y) {
    const size_t row = static_cast<size_t>(height - 1 - y) * width;  // GL rows go bottom-up.
    for (int x = 0; x < width; ++x) {
      for (int c = 0; c < channels; ++c) image.At(x, y, c) = texels[(row + x) * 4 + c];
    }
  }
  return image;
}

}  // namespace

float GroundBand(const ViewerScene& scene) { return 0.01f * scene.FocusRadius(); }

const TriangleMesh& DisplayedMesh(const ViewerScene& scene, int width, int height) {
  constexpr size_t kPixelsPerTriangle = 16;
  const bool too_fine =
      scene.mesh.triangles.size() * kPixelsPerTriangle > static_cast<size_t>(width) * static_cast<size_t>(height);
  return too_fine && !scene.display_mesh.triangles.empty() ? scene.display_mesh : scene.mesh;
}

ViewCamera MovingView(const ViewCamera& view) {
  const uint64_t width = std::max<uint64_t>(1, view.camera.width / 2);
  const uint64_t height = std::max<uint64_t>(1, view.camera.height / 2);
  const double sx = static_cast<double>(width) / static_cast<double>(view.camera.width);
  const double sy = static_cast<double>(height) / static_cast<double>(view.camera.height);
  ViewCamera moving = view;
  moving.camera = MakePinholeCamera(view.camera.id, width, height, view.camera.FocalX() * sx, view.camera.FocalY() * sy,
                                    view.camera.PrincipalX() * sx, view.camera.PrincipalY() * sy);
  return moving;
}

FrameSettings MovingSettings(const FrameSettings& settings, bool light_moving) {
  FrameSettings moving = settings;
  if (light_moving) {
    moving.shadow_map_size = std::max(512, settings.shadow_map_size / 2);
    moving.pcf_radius = 0;
  }
  return moving;
}

ShadowChoice ChooseShadows(const ViewerScene& scene, TextureMode texture) {
  // On a real facade's 32k-triangle display mesh a third of the edges are silhouettes, and
  // the volume cost three PCF frames; up to this many triangles it costs about one.
  constexpr size_t kVolumeTriangles = 4000;
  if (texture == TextureMode::kProjective) {
    return {ShadowMode::kNone, "none: the photos are shown as captured, with their own shadows"};
  }
  const TriangleMesh& mesh = scene.display_mesh.triangles.empty() ? scene.mesh : scene.display_mesh;
  if (mesh.triangles.empty()) return {ShadowMode::kPcf, "pcf: a point cloud casts shadows into a shadow map only"};
  const std::string triangles = std::to_string(mesh.triangles.size()) + " triangles";
  if (mesh.triangles.size() <= kVolumeTriangles) {
    return {ShadowMode::kVolume, "volume: exact shadows, and the mesh is small (" + triangles + ")"};
  }
  return {ShadowMode::kPcf, "pcf: the mesh is too large for shadow volumes to be cheap (" + triangles + ", more than " +
                                std::to_string(kVolumeTriangles) + ")"};
}

std::vector<int> NearestSourceViews(const ViewerScene& scene, const Eigen::Vector3d& eye, int count) {
  const Eigen::Vector3d centre = scene.FocusCentre().cast<double>();
  const Eigen::Vector3d to_eye = (eye - centre).normalized();
  std::vector<std::pair<double, int>> scored;
  for (size_t i = 0; i < scene.sources.size(); ++i) {
    if (!std::filesystem::exists(scene.sources[i].image_path)) continue;
    const Eigen::Vector3d to_source = (CameraCenter(scene.sources[i].cam_from_world) - centre).normalized();
    scored.emplace_back(-to_eye.dot(to_source), static_cast<int>(i));
  }
  std::sort(scored.begin(), scored.end());
  std::vector<int> nearest;
  for (size_t i = 0; i < scored.size() && static_cast<int>(i) < count; ++i) nearest.push_back(scored[i].second);
  return nearest;
}

// The scene on the GPU and one object per pass; Draw sequences them.
struct SceneRenderer::Impl {
  const ViewerScene& scene;
  // glClipControl is available, and then set to zero-to-one but during the eye's pass of a
  // frame without reverse-Z.
  bool clip_control = false;
  gpu::GpuMesh full_mesh, display_mesh;  // display_mesh is empty without a simplified copy.
  gpu::Drawable points;                  // The fused cloud's points.
  std::vector<Eigen::Vector3f> cloud_positions;  // The same on the CPU.
  DepthPass depth;
  ShadowMapPass shadow_map;
  Projectors projectors;
  SurfacePass surfaces;
  PlanarShadowPass planar;
  ShadowVolumePass volume;
  BlobShadowPass blob;
  OverlayPass overlays;
  ToneMapper tone_mapper;
  gpu::EyeTarget eye;
  bool with_aux = false;  // This frame fills the auxiliary target (Render).
  std::vector<std::string> notes, notes_given;

  Impl(const ViewerScene& s, FrameClock clock);
  // NDC depth where the clip control is left: the light's and the projectors' maps.
  DepthRange Range() const { return clip_control ? DepthRange::kZeroToOne : DepthRange::kMinusOneToOne; }
  // Tells the user `note` the first time only (a skipped shadow method is skipped every frame).
  void NoteOnce(const std::string& note);
  // The frame's level of detail, light, eye projection and depth conventions.
  FrameContext MakeFrame(const ViewCamera& view, const FrameSettings& settings) const;
  Eigen::Matrix4f EyeProjection(const ViewCamera& view, bool reverse_z) const;
  // Binds the eye target at the view's size and clears it to the background (depth cleared
  // for the frame's reverse-Z).
  void BeginFrame(const FrameContext& frame);
  void DrawSurfaces(const FrameContext& frame, SurfaceShadow shadow, std::span<const Projector> frame_projectors);
  // The frame's shadow method if it is drawn after the surfaces (planar, volume, blob), or a
  // note why it is skipped.
  void DrawShadowPass(const FrameContext& frame, std::span<const Projector> frame_projectors);
  // Copies the frame to `framebuffer`, scaled to `width` x `height` (0: the frame's size).
  void Blit(int framebuffer, int width, int height) const;
};

SceneRenderer::Impl::Impl(const ViewerScene& s, FrameClock clock)
    : scene(s),
      full_mesh(gpu::UploadMesh(s.mesh, s.ground)),
      display_mesh(gpu::UploadMesh(s.display_mesh, s.ground)),
      overlays(s),
      tone_mapper(std::move(clock)) {
  if (!s.points.empty()) points = gpu::Upload(PointVertices(s.points));
  for (const ColoredPoint& point : s.points) cloud_positions.push_back(point.position);
}

void SceneRenderer::Impl::NoteOnce(const std::string& note) {
  if (std::find(notes_given.begin(), notes_given.end(), note) != notes_given.end()) return;
  notes_given.push_back(note);
  notes.push_back(note);
}

SceneRenderer::SceneRenderer(const ViewerScene& scene, FrameClock clock)
    : impl_(std::make_unique<Impl>(scene, std::move(clock))) {
  impl_->clip_control = HasExtension("GL_ARB_clip_control");
  if (impl_->clip_control) glClipControl(GL_LOWER_LEFT, GL_ZERO_TO_ONE);
  glEnable(GL_PROGRAM_POINT_SIZE);
  CheckGlError("SceneRenderer setup");
}

SceneRenderer::~SceneRenderer() = default;

void SceneRenderer::Finish() const { glFinish(); }

bool SceneRenderer::UsesReverseZ() const { return impl_->clip_control; }

size_t SceneRenderer::ShadowBytes(ShadowMode mode) const {
  switch (mode) {
    case ShadowMode::kMap:
    case ShadowMode::kPcf: return impl_->shadow_map.Bytes();
    case ShadowMode::kVolume: return impl_->volume.Bytes();
    case ShadowMode::kBlob: return impl_->blob.Bytes();
    case ShadowMode::kPlanar: return impl_->planar.Bytes();
    case ShadowMode::kNone: return 0;
  }
  return 0;
}

std::vector<std::string> SceneRenderer::TakeNotes() { return std::exchange(impl_->notes, {}); }

FrameContext SceneRenderer::Impl::MakeFrame(const ViewCamera& view, const FrameSettings& settings) const {
  const bool reverse_z = clip_control && settings.reverse_z;
  const TriangleMesh& cpu_mesh =
      DisplayedMesh(scene, static_cast<int>(view.camera.width), static_cast<int>(view.camera.height));
  return FrameContext{
      .scene = scene,
      .view = view,
      .settings = settings,
      .mesh = &cpu_mesh == &scene.display_mesh ? display_mesh : full_mesh,
      .cpu_mesh = cpu_mesh,
      .points = points,
      .cloud_positions = cloud_positions,
      .light = LightVector(settings.light),
      .clip_from_world = EyeProjection(view, reverse_z) * ViewMatrix(view.cam_from_world),
      .ground_band = GroundBand(scene),
      .range = Range(),
      .reverse_z = reverse_z,
      .hdr = settings.DrawnInFloat(),
  };
}

Eigen::Matrix4f SceneRenderer::Impl::EyeProjection(const ViewCamera& view, bool reverse_z) const {
  if (reverse_z) {
    const double near = view.near > 0 ? view.near : DepthBounds(scene.bounds, view.cam_from_world)[0];
    return ReverseZProjection(view.camera, near);
  }
  // Without reverse-Z the depth range is fitted to what can be seen: the scene's bounds.
  Eigen::Vector2d range = DepthBounds(scene.bounds, view.cam_from_world);
  if (view.near > 0) range[0] = view.near;
  return PerspectiveProjection(view.camera, range[0], std::max(range[1], 4 * range[0]), Range());
}

void SceneRenderer::Impl::BeginFrame(const FrameContext& frame) {
  const int width = static_cast<int>(frame.view.camera.width), height = static_cast<int>(frame.view.camera.height);
  eye.Resize(width, height);
  glBindFramebuffer(GL_FRAMEBUFFER, frame.hdr ? eye.hdr_framebuffer.Get() : eye.framebuffer.Get());
  glViewport(0, 0, width, height);
  const Eigen::Vector3f& linear = frame.settings.background;
  const Eigen::Vector3f background =
      frame.hdr ? linear
                : Eigen::Vector3f(LinearToSrgb(linear.x()), LinearToSrgb(linear.y()), LinearToSrgb(linear.z()));
  const float clear_color[4] = {background.x(), background.y(), background.z(), 1};
  const float clear_aux[4] = {1, 0, 0, 0};
  glClearBufferfv(GL_COLOR, 0, clear_color);
  // The auxiliary target is read back by Render alone: a frame for the window (or a timing)
  // leaves it out, which saves llvmpipe 16 bytes a pixel written.
  const GLenum draw_buffers[2] = {GL_COLOR_ATTACHMENT0, with_aux ? GLenum{GL_COLOR_ATTACHMENT1} : GLenum{GL_NONE}};
  glDrawBuffers(2, draw_buffers);
  if (with_aux) glClearBufferfv(GL_COLOR, 1, clear_aux);
  glClearDepth(frame.reverse_z ? 0.0 : 1.0);
  glClearStencil(0);
  glDepthMask(GL_TRUE);
  glStencilMask(0xff);
  glClear(GL_DEPTH_BUFFER_BIT | GL_STENCIL_BUFFER_BIT);
  glEnable(GL_DEPTH_TEST);
  glDepthFunc(frame.DepthLess());
}

void SceneRenderer::Impl::DrawSurfaces(const FrameContext& frame, SurfaceShadow shadow,
                                       std::span<const Projector> frame_projectors) {
  const SurfaceInputs inputs{shadow_map.ShadowFromWorld(), frame_projectors, planar.Ground(),
                             planar.GroundTolerance()};
  surfaces.Draw(frame, shadow, inputs, depth);
}

void SceneRenderer::Impl::DrawShadowPass(const FrameContext& frame, std::span<const Projector> frame_projectors) {
  const ShadowMode mode = frame.settings.shadows;
  if (mode == ShadowMode::kPlanar) {
    if (scene.ground) {
      planar.Draw(frame, [&] { DrawSurfaces(frame, SurfaceShadow::kPlanarRedraw, frame_projectors); });
    } else {
      NoteOnce("planar shadows skipped: no ground plane was found in the scene");
    }
  } else if (mode == ShadowMode::kBlob) {
    if (scene.ground) {
      blob.Draw(frame);
    } else {
      NoteOnce("blob shadows skipped: no ground plane was found in the scene");
    }
  } else if (mode == ShadowMode::kVolume) {
    if (frame.HasMesh()) {
      volume.Draw(frame, [&] { DrawSurfaces(frame, SurfaceShadow::kVolumeRedraw, frame_projectors); });
    } else {
      NoteOnce("shadow volumes skipped: they need a mesh, and there is only a point cloud");
    }
  }
}

void SceneRenderer::Impl::Blit(int framebuffer, int width, int height) const {
  glBindFramebuffer(GL_READ_FRAMEBUFFER, eye.framebuffer.Get());
  glReadBuffer(GL_COLOR_ATTACHMENT0);
  glBindFramebuffer(GL_DRAW_FRAMEBUFFER, static_cast<GLuint>(framebuffer));
  const int shown_width = width > 0 ? width : eye.width;
  const int shown_height = height > 0 ? height : eye.height;
  glBlitFramebuffer(0, 0, eye.width, eye.height, 0, 0, shown_width, shown_height, GL_COLOR_BUFFER_BIT,
                    shown_width == eye.width && shown_height == eye.height ? GL_NEAREST : GL_LINEAR);
}

void SceneRenderer::Draw(const ViewCamera& view, const FrameSettings& settings, int window_framebuffer,
                         int window_width, int window_height) {
  settings.Check();
  Impl& r = *impl_;
  const FrameContext frame = r.MakeFrame(view, settings);

  // 1. Shadow map from the light (when it changed).
  const SurfaceShadow shadow = r.shadow_map.Update(frame, r.depth);
  glActiveTexture(GL_TEXTURE0 + gpu::kShadowUnit);
  glBindTexture(GL_TEXTURE_2D, r.shadow_map.Texture());
  glActiveTexture(GL_TEXTURE0 + gpu::kAtlasUnit);
  glBindTexture(GL_TEXTURE_2D, frame.mesh.atlas.Get());

  // 2. Projectors' depth maps and photos.
  std::span<const Projector> projectors;
  if (settings.texture == TextureMode::kProjective) {
    const std::vector<int> sources =
        NearestSourceViews(r.scene, CameraCenter(view.cam_from_world), settings.projective_views);
    projectors = r.projectors.SetUp(frame, sources, r.depth);
  }

  // 3. The frame: surfaces, the shadow methods drawn over them, lines; then the tone map.
  r.BeginFrame(frame);
  // glClipControl is global; this frame's projection uses [-1, 1].
  const bool minus_one_to_one = r.clip_control && !frame.reverse_z;
  if (minus_one_to_one) glClipControl(GL_LOWER_LEFT, GL_NEGATIVE_ONE_TO_ONE);
  r.DrawSurfaces(frame, shadow, projectors);
  r.DrawShadowPass(frame, projectors);
  r.overlays.Draw(frame);
  if (minus_one_to_one) glClipControl(GL_LOWER_LEFT, GL_ZERO_TO_ONE);
  if (frame.hdr) r.tone_mapper.Map(settings, r.eye, r.with_aux);

  if (window_framebuffer >= 0) r.Blit(window_framebuffer, window_width, window_height);
  CheckGlError("SceneRenderer::Draw");
}

FrameResult SceneRenderer::Render(const ViewCamera& view, const FrameSettings& settings) {
  impl_->with_aux = true;
  try {
    Draw(view, settings);
  } catch (...) {
    impl_->with_aux = false;
    throw;
  }
  impl_->with_aux = false;
  const int width = static_cast<int>(view.camera.width), height = static_cast<int>(view.camera.height);
  const GLuint frame = impl_->eye.framebuffer.Get();
  glBindFramebuffer(GL_READ_FRAMEBUFFER, frame);
  glPixelStorei(GL_PACK_ALIGNMENT, 1);
  std::vector<uint8_t> bytes(static_cast<size_t>(width) * height * 4);
  glReadBuffer(GL_COLOR_ATTACHMENT0);
  glReadPixels(0, 0, width, height, GL_RGBA, GL_UNSIGNED_BYTE, bytes.data());
  CheckGlError("SceneRenderer::Render read back");
  FrameResult result{Image(width, height, 3), ReadFloatAttachment(frame, GL_COLOR_ATTACHMENT1, width, height, 4),
                     Image()};
  for (int y = 0; y < height; ++y) {
    const size_t row = static_cast<size_t>(height - 1 - y) * width;  // GL rows go bottom-up.
    for (int x = 0; x < width; ++x) {
      for (int c = 0; c < 3; ++c) result.color.At(x, y, c) = bytes[(row + x) * 4 + c] / 255.0f;
    }
  }
  if (settings.DrawnInFloat()) {
    result.linear =
        ReadFloatAttachment(impl_->tone_mapper.LinearFramebuffer(), GL_COLOR_ATTACHMENT0, width, height, 3);
  }
  return result;
}

}  // namespace parallax
