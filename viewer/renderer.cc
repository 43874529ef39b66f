#include "viewer/renderer.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <limits>
#include <map>
#include <optional>
#include <tuple>
#include <stdexcept>
#include <string_view>

#include "viewer/blob_shadows.h"
#include "viewer/gl.h"
#include "viewer/matcap.h"
#include "viewer/gpu_resources.h"
#include "viewer/overlays.h"
#include "viewer/shaders.h"
#include "viewer/shadow_volume.h"
#include "viewer/view_math.h"
#include "core/check.h"

namespace parallax {
namespace {

using gpu::DepthTarget;
using gpu::Drawable;
using gpu::EyeTarget;
using gpu::GpuMesh;
using gpu::Upload;
using gpu::Vertex;
using gpu::kAtlasUnit, gpu::kShadowUnit, gpu::kPhotoUnit, gpu::kProjectorDepthUnit;

constexpr int kMaxProjectors = 3;
constexpr int kMaxBlobs = 16;
constexpr int kBlobTextureSize = 64;

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

}  // namespace

void FrameSettings::Check() const {
  RequireOption(shadow_map_size >= 64 && shadow_map_size <= 8192, "FrameSettings.shadow_map_size", shadow_map_size,
                "[64, 8192]");
  RequireOption(pcf_radius >= 0 && pcf_radius <= 4, "FrameSettings.pcf_radius", pcf_radius, "[0, 4]");
  RequireOption(projective_views >= 1 && projective_views <= kMaxProjectors, "FrameSettings.projective_views",
                projective_views, "[1, " + std::to_string(kMaxProjectors) + "]");
  RequireOption(point_size_px > 0, "FrameSettings.point_size_px", point_size_px, "> 0");
  RequireOption(std::isfinite(exposure_stops), "FrameSettings.exposure_stops", exposure_stops, "finite");
  RequireOption(white >= 1 && std::isfinite(white), "FrameSettings.white", white, ">= 1 and finite");
  RequireOption(adaptation_seconds >= 0 && std::isfinite(adaptation_seconds), "FrameSettings.adaptation_seconds",
                adaptation_seconds, ">= 0 and finite");
  if (light.type == LightKind::kDirectional) {
    RequireOption(light.direction.norm() > 0 && light.direction.allFinite(), "FrameSettings.light.direction (norm)",
                  light.direction.norm(), "finite and non-zero");
  }
  RequireOption(light.position.allFinite(), "FrameSettings.light.position (norm)", light.position.norm(), "finite");
}

float GroundBand(const ViewerScene& scene) { return 0.01f * scene.FocusRadius(); }

const TriangleMesh& DisplayedMesh(const ViewerScene& scene, int width, int height) {
  constexpr size_t kPixelsPerTriangle = 16;
  const bool too_fine = scene.mesh.triangles.size() * kPixelsPerTriangle > static_cast<size_t>(width) * static_cast<size_t>(height);
  return too_fine && !scene.display_mesh.triangles.empty() ? scene.display_mesh : scene.mesh;
}

ViewCamera MovingView(const ViewCamera& view) {
  const uint64_t width = std::max<uint64_t>(1, view.camera.width / 2), height = std::max<uint64_t>(1, view.camera.height / 2);
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

// What the shadow map was rendered with; the same key, the same map.
struct ShadowMapKey {
  Eigen::Matrix4f light_clip_from_world;
  int size = 0;
  float slope_bias = 0;
  const GpuMesh* casters = nullptr;  // The level of detail drawn into it.
  bool operator==(const ShadowMapKey& other) const {
    return light_clip_from_world == other.light_clip_from_world && size == other.size &&
           slope_bias == other.slope_bias && casters == other.casters;
  }
};

// What the shadow volume was built for; the same key, the same volume.
struct ShadowVolumeKey {
  Eigen::Vector4d light;
  const TriangleMesh* casters = nullptr;
  bool operator==(const ShadowVolumeKey& other) const {
    return light == other.light && casters == other.casters;
  }
};

struct SceneRenderer::Impl {
  const ViewerScene& scene;
  bool reverse_z = false;  // glClipControl is available (and then always set to zero-to-one).
  GlProgram depth, planar, volume, blob, lines;
  // By (albedo, shadow mode, PCF radius, float output).
  std::map<std::tuple<int, int, int, bool>, GlProgram> surface_programs;
  // What this frame's surface programs need besides the settings.
  Eigen::Matrix4f shadow_from_world = Eigen::Matrix4f::Identity();
  Eigen::Matrix4f projector_from_world[kMaxProjectors];
  Eigen::Vector3f projector_centre[kMaxProjectors];
  Eigen::Vector3f projector_gain[kMaxProjectors];
  Eigen::Vector4f ground_plane = Eigen::Vector4f::Zero();
  float ground_tolerance = 0;
  GpuMesh full_mesh, display_mesh;  // display_mesh is empty without a simplified copy.
  const GpuMesh* mesh = &full_mesh;  // This frame's level of detail (shadows and eye alike).
  const TriangleMesh* cpu_mesh = nullptr;  // The same level of detail on the CPU.
  std::vector<Eigen::Vector3f> cloud_positions;  // The fused cloud's points.
  gpu::HomogeneousTriangles shadow_volume;
  std::optional<ShadowVolumeKey> shadow_volume_key;  // Absent until the volume is built.
  BlobCasters blob_casters;  // The objects on the ground (of the full mesh), when there is one.
  Drawable blob_quads;       // Two triangles a blob, placed for `blob_light`.
  std::optional<Eigen::Vector4d> blob_light;
  GlTexture blob_texture;
  GlTexture matcap;  // For `matcap_key`: the light in camera coordinates, specular, shininess.
  std::optional<std::tuple<Eigen::Vector3d, float, float>> matcap_key;
  void UpdateMatcap(const ViewCamera& view, const FrameSettings& settings);
  Drawable points, frusta, grid;
  double frustum_depth = 0;  // Scene units.
  std::vector<Eigen::Vector3d> source_centres;
  DepthTarget shadow;
  std::optional<ShadowMapKey> shadow_key;  // Absent until the map holds a rendering.
  DepthTarget projector_depth[kMaxProjectors];
  std::map<int, GlTexture> photos;  // By source index, loaded on first use.
  EyeTarget eye;
  std::vector<std::string> notes;
  // Tells the user `note` the first time only (a skipped shadow method is skipped every frame).
  void NoteOnce(const std::string& note) {
    if (std::find(notes_given.begin(), notes_given.end(), note) != notes_given.end()) return;
    notes_given.push_back(note);
    notes.push_back(note);
  }
  std::vector<std::string> notes_given;
  bool with_aux = false;       // This frame fills the auxiliary target (Render).
  bool hdr_now = false;        // This frame is drawn into the float frame, then tone-mapped.
  GlProgram tone_map;
  GlVertexArray empty_vao;     // The tone-mapping triangle has no vertex buffer.
  GlTexture meter;             // The float frame shrunk, to read its brightness back.
  GlFramebuffer meter_framebuffer;
  std::optional<double> adapted_luminance;  // What the eye is adapted to (auto exposure).
  std::chrono::steady_clock::time_point last_adaptation;
  bool reverse_z_now = false;  // This frame's depth is reverse-Z (cleared to 0, GL_GREATER).

  explicit Impl(const ViewerScene& s) : scene(s) {}
  DepthRange Range() const { return reverse_z ? DepthRange::kZeroToOne : DepthRange::kMinusOneToOne; }
  Eigen::Vector2f NdcToDepth() const {
    return reverse_z ? Eigen::Vector2f(1, 0) : Eigen::Vector2f(0.5f, 0.5f);
  }
  Eigen::Vector4d LightVector(const LightSettings& light) const {
    if (light.type == LightKind::kPoint) return {light.position.x(), light.position.y(), light.position.z(), 1};
    const Eigen::Vector3d towards = -light.direction.normalized();
    return {towards.x(), towards.y(), towards.z(), 0};
  }
  Eigen::Matrix4f LightMatrix(const LightSettings& light) const {
    // A directional light's map covers what it sees of the geometry drawn but its outermost
    // half percent (its resolution is not spent on outliers), a point light's the robust
    // extent; the depth range holds everything, so no caster is clipped away.
    if (light.type == LightKind::kPoint) return PointLightMatrix(light.position, scene.extent, scene.bounds, Range());
    return DirectionalLightMatrix(light.direction, mesh->triangles > 0 ? cpu_mesh->vertices : cloud_positions,
                                  scene.bounds, Range());
  }
  // What casts shadows and occludes projectors: the mesh when there is one, else the points.
  void DrawCasters(const FrameSettings& settings, const GlProgram& program) {
    if (mesh->triangles > 0 && &program == &depth) {
      DrawMeshDepth();
    } else if (mesh->triangles > 0) {
      glBindVertexArray(mesh->casters.vao.Get());
      glDrawArrays(GL_TRIANGLES, 0, mesh->casters.count);
    } else if (points.count > 0) {
      program.Set("u_point_size", settings.point_size_px);
      glBindVertexArray(points.vao.Get());
      glDrawArrays(GL_POINTS, 0, points.count);
    }
  }
  // The mesh through the depth program (bound by the caller).
  void DrawMeshDepth() const {
    glBindVertexArray(mesh->positions.vao.Get());
    glDrawElements(GL_TRIANGLES, mesh->positions.count, GL_UNSIGNED_INT, nullptr);
  }
  // The frusta, but those of cameras within three frustum depths of the eye: the one looked
  // through, or one just in front of the eye, would cross the whole image.
  void DrawFrusta(const Eigen::Vector3d& eye_centre) {
    glBindVertexArray(frusta.vao.Get());
    GLint first = 0;
    for (size_t i = 0; i < source_centres.size(); ++i) {
      if ((source_centres[i] - eye_centre).norm() >= 3 * frustum_depth) continue;
      const GLint skipped = static_cast<GLint>(i) * kFrustumVertices;
      if (skipped > first) glDrawArrays(GL_LINES, first, skipped - first);
      first = skipped + kFrustumVertices;
    }
    if (frusta.count > first) glDrawArrays(GL_LINES, first, frusta.count - first);
  }
  void RenderDepthMap(DepthTarget& target, const Eigen::Matrix4f& clip_from_world,
                      const FrameSettings& settings, float slope_bias);
  GLuint Photo(int source);
  int SetUpProjectors(const ViewCamera& view, const FrameSettings& settings);
  const GlProgram& SurfaceProgram(int albedo_source, int shadow_mode, int pcf_radius);
  void UseSurfaceProgram(const GlProgram& program, const ViewCamera& view, const FrameSettings& settings,
                         const Eigen::Matrix4f& clip_from_world, int projectors);
  void DrawSurfaces(const ViewCamera& view, const FrameSettings& settings,
                    const Eigen::Matrix4f& clip_from_world, int shadow_mode, int projectors);
  void DrawPlanarShadows(const ViewCamera& view, const FrameSettings& settings,
                         const Eigen::Matrix4f& clip_from_world, int projectors);
  void DrawVolumeShadows(const ViewCamera& view, const FrameSettings& settings,
                         const Eigen::Matrix4f& clip_from_world, int projectors);
  // Multiplies each blob's texture into the frame on the ground (with a note, once, without a
  // ground).
  void DrawBlobShadows(const ViewCamera& view, const FrameSettings& settings, const Eigen::Matrix4f& clip_from_world);
  // Ground within this distance of the plane receives planar and blob shadows; triangles
  // reaching higher cast them.
  float GroundTolerance() const { return GroundBand(scene); }
  static Eigen::Vector4f GroundVector(const GroundPlane& ground) {
    return Eigen::Vector4d(ground.normal.x(), ground.normal.y(), ground.normal.z(), ground.offset).cast<float>();
  }
  // Re-renders the shadow map when the light, its size or the mesh changed; returns the
  // surface shader's shadow mode (0 none, 2 map, 3 PCF).
  int UpdateShadowMap(const FrameSettings& settings);
  // Binds the eye target at `width` x `height` and clears it to the background (depth cleared
  // for reverse_z_now).
  void BeginFrame(int width, int height, const FrameSettings& settings);
  // The float frame's log-average luminance (of a 64x36 shrunk copy).
  double LogAverageLuminance();
  // Exposes and tone-maps the float frame into the 8-bit frame.
  void ToneMapFrame(const FrameSettings& settings);
  Eigen::Matrix4f EyeProjection(const ViewCamera& view) const;
};

void SceneRenderer::Impl::RenderDepthMap(DepthTarget& target, const Eigen::Matrix4f& clip_from_world,
                                    const FrameSettings& settings, float slope_bias) {
  glBindFramebuffer(GL_FRAMEBUFFER, target.framebuffer.Get());
  glViewport(0, 0, target.width, target.height);
  glDisable(GL_STENCIL_TEST);
  glEnable(GL_DEPTH_TEST);
  glDepthMask(GL_TRUE);
  glDepthFunc(GL_LESS);
  glClearDepth(1.0);
  glClear(GL_DEPTH_BUFFER_BIT);
  // Slope-scaled bias against acne: each depth is pushed back by its slope across a texel.
  // No face culling: reconstructed meshes have no consistent winding.
  glEnable(GL_POLYGON_OFFSET_FILL);
  glPolygonOffset(slope_bias, 4.0f);
  depth.Use();
  depth.Set("u_clip_from_world", clip_from_world);
  DrawCasters(settings, depth);
  glDisable(GL_POLYGON_OFFSET_FILL);
}

GLuint SceneRenderer::Impl::Photo(int source) {
  auto found = photos.find(source);
  if (found == photos.end()) {
    found = photos.emplace(source, gpu::UploadSrgbTexture(ReadImage(scene.sources[source].image_path))).first;
  }
  return found->second.Get();
}

// Renders each chosen source camera's depth map and binds its photo; returns how many.
int SceneRenderer::Impl::SetUpProjectors(const ViewCamera& view, const FrameSettings& settings) {
  const std::vector<int> chosen =
      NearestSourceViews(scene, CameraCenter(view.cam_from_world), settings.projective_views);
  for (size_t k = 0; k < chosen.size(); ++k) {
    const ViewerSource& source = scene.sources[chosen[k]];
    const Eigen::Vector2d range = DepthBounds(scene.bounds, source.cam_from_world);
    const Eigen::Matrix4f clip_from_world =
        PerspectiveProjection(source.camera, range[0], range[1], Range()) * ViewMatrix(source.cam_from_world);
    projector_depth[k].Resize(static_cast<int>(std::min<uint64_t>(source.camera.width, 4096)),
                              static_cast<int>(std::min<uint64_t>(source.camera.height, 4096)));
    RenderDepthMap(projector_depth[k], clip_from_world, settings, 0.0f);
    const GLuint photo = Photo(chosen[k]);
    glActiveTexture(GL_TEXTURE0 + kPhotoUnit + k);
    glBindTexture(GL_TEXTURE_2D, photo);
    glActiveTexture(GL_TEXTURE0 + kProjectorDepthUnit + k);
    glBindTexture(GL_TEXTURE_2D, projector_depth[k].texture.Get());
    projector_from_world[k] = clip_from_world;
    projector_centre[k] = CameraCenter(source.cam_from_world).cast<float>();
    projector_gain[k] = Eigen::Vector3f(source.gain[0], source.gain[1], source.gain[2]);
  }
  glActiveTexture(GL_TEXTURE0);
  return static_cast<int>(chosen.size());
}

const GlProgram& SceneRenderer::Impl::SurfaceProgram(int albedo_source, int shadow_mode, int pcf_radius) {
  if (shadow_mode != 3) pcf_radius = 0;
  const std::tuple key{albedo_source, shadow_mode, pcf_radius, hdr_now};
  auto found = surface_programs.find(key);
  if (found != surface_programs.end()) return found->second;
  const std::string fragment = "#version 330 core\n#define ALBEDO_SOURCE " + std::to_string(albedo_source) +
                               "\n#define SHADOW_MODE " + std::to_string(shadow_mode) +
                               "\n#define PCF_RADIUS " + std::to_string(pcf_radius) +
                               "\n#define HDR_OUTPUT " + (hdr_now ? "1" : "0") + "\n" + shaders::kSurfaceFragment;
  GlProgram program("surface", shaders::kSurfaceVertex, fragment.c_str());
  program.Use();
  program.Set("u_atlas", kAtlasUnit);
  program.Set("u_shadow_map", kShadowUnit);
  program.Set("u_matcap", gpu::kMatcapUnit);
  for (int k = 0; k < kMaxProjectors; ++k) {
    program.Set(("u_photo" + std::to_string(k)).c_str(), kPhotoUnit + k);
    program.Set(("u_projector_depth" + std::to_string(k)).c_str(), kProjectorDepthUnit + k);
  }
  return surface_programs.emplace(key, std::move(program)).first->second;
}

void SceneRenderer::Impl::UseSurfaceProgram(const GlProgram& program, const ViewCamera& view,
                                       const FrameSettings& settings, const Eigen::Matrix4f& clip_from_world,
                                       int projectors) {
  program.Use();
  program.Set("u_clip_from_world", clip_from_world);
  program.Set("u_cam_from_world", ViewMatrix(view.cam_from_world));
  program.Set("u_eye", Eigen::Vector3f(CameraCenter(view.cam_from_world).cast<float>()));
  program.Set("u_light", Eigen::Vector4f(LightVector(settings.light).cast<float>()));
  program.Set("u_light_color", Eigen::Vector3f(settings.light.intensity * settings.light.color));
  program.Set("u_ambient", settings.ambient);
  program.Set("u_specular", settings.specular);
  program.Set("u_shininess", settings.shininess);
  program.Set("u_exposure", std::exp2(settings.exposure_stops));
  program.Set("u_ndc_to_depth", NdcToDepth());
  program.Set("u_shadow_from_world", shadow_from_world);
  program.Set("u_num_projectors", projectors);
  program.Set("u_projector_pull", 0.003f);
  for (int k = 0; k < projectors; ++k) {
    const std::string index = std::to_string(k);
    program.Set(("u_projector_from_world[" + index + "]").c_str(), projector_from_world[k]);
    program.Set(("u_projector_centre[" + index + "]").c_str(), projector_centre[k]);
    program.Set(("u_projector_gain[" + index + "]").c_str(), projector_gain[k]);
  }
  program.Set("u_has_atlas", mesh->atlas.Get() != 0 ? 1 : 0);
  program.Set("u_ground", ground_plane);
  program.Set("u_ground_tolerance", ground_tolerance);
  program.Set("u_point_size", settings.point_size_px);
}

void SceneRenderer::Impl::DrawSurfaces(const ViewCamera& view, const FrameSettings& settings,
                                  const Eigen::Matrix4f& clip_from_world, int shadow_mode,
                                  int projectors) {
  const int albedo = settings.texture == TextureMode::kProjective ? 1
                     : settings.texture == TextureMode::kShaded ? 2
                     : settings.texture == TextureMode::kMatcap ? 4
                                                               : 0;
  if (albedo == 4) UpdateMatcap(view, settings);
  if (settings.show_mesh && mesh->triangles > 0) {
    // Depth pre-pass: the mesh's depth alone first, then the shaded pass where it matches, so
    // each pixel is shaded once however much the walls and pillars overlap (fragment work
    // dominates on llvmpipe). Both vertex shaders compute an invariant gl_Position. The second
    // passes of planar shadows and shadow volumes already test against the finished depth.
    const bool prepass = shadow_mode != 1 && shadow_mode != 4;
    if (prepass) {
      glColorMask(GL_FALSE, GL_FALSE, GL_FALSE, GL_FALSE);
      depth.Use();
      depth.Set("u_clip_from_world", clip_from_world);
      DrawMeshDepth();
      glColorMask(GL_TRUE, GL_TRUE, GL_TRUE, GL_TRUE);
      glDepthMask(GL_FALSE);
      glDepthFunc(reverse_z_now ? GL_GEQUAL : GL_LEQUAL);
    }
    UseSurfaceProgram(SurfaceProgram(albedo == 0 && mesh->atlas.Get() == 0 ? 2 : albedo, shadow_mode, settings.pcf_radius), view, settings,
                      clip_from_world, projectors);
    glBindVertexArray(mesh->shaded.vao.Get());
    glDrawElements(GL_TRIANGLES, mesh->shaded.count, GL_UNSIGNED_INT, nullptr);
    if (prepass) {
      glDepthMask(GL_TRUE);
      glDepthFunc(reverse_z_now ? GL_GREATER : GL_LESS);
    }
  }
  if (settings.show_points && points.count > 0 &&
      (mesh->triangles == 0 || !settings.show_mesh || settings.points_with_mesh)) {
    UseSurfaceProgram(SurfaceProgram(albedo == 0 ? 3 : albedo, shadow_mode, settings.pcf_radius), view, settings, clip_from_world,
                      projectors);
    glBindVertexArray(points.vao.Get());
    glDrawArrays(GL_POINTS, 0, points.count);
  }
}

// Planar shadows: mark in the stencil the pixels covered by the geometry flattened onto the
// ground along the light (each pixel once, however many casters overlap: no double darkening),
// then redraw the ground there unlit.
void SceneRenderer::Impl::DrawPlanarShadows(const ViewCamera& view, const FrameSettings& settings,
                                       const Eigen::Matrix4f& clip_from_world, int projectors) {
  const GroundPlane& ground = *scene.ground;
  const Eigen::Vector4f plane = GroundVector(ground);
  const float tolerance = GroundTolerance();
  glEnable(GL_STENCIL_TEST);
  glStencilFunc(GL_ALWAYS, 1, 0xff);
  glStencilOp(GL_KEEP, GL_KEEP, GL_REPLACE);
  glColorMask(GL_FALSE, GL_FALSE, GL_FALSE, GL_FALSE);
  glDepthMask(GL_FALSE);
  glDisable(GL_DEPTH_TEST);  // The redraw below tests depth against the real ground.
  planar.Use();
  planar.Set("u_clip_from_world", clip_from_world);
  planar.Set("u_planar_shadow", PlanarShadowMatrix(ground, LightVector(settings.light)));
  planar.Set("u_ground", plane);
  planar.Set("u_ground_tolerance", tolerance);
  planar.Set("u_points", mesh->triangles == 0 ? 1 : 0);
  DrawCasters(settings, planar);

  glColorMask(GL_TRUE, GL_TRUE, GL_TRUE, GL_TRUE);
  glStencilFunc(GL_EQUAL, 1, 0xff);
  glStencilOp(GL_KEEP, GL_KEEP, GL_KEEP);
  glEnable(GL_DEPTH_TEST);
  glDepthFunc(reverse_z_now ? GL_GEQUAL : GL_LEQUAL);  // Same geometry, same depth: passes.
  ground_plane = plane;
  ground_tolerance = tolerance;
  DrawSurfaces(view, settings, clip_from_world, /*planar second pass*/ 1, projectors);
  glDepthMask(GL_TRUE);
  glDisable(GL_STENCIL_TEST);
}

// Shadow volumes, z-fail ("Carmack's reverse"): count in the stencil the volume's faces that
// lie behind the visible surface, back faces up and front faces down. The count is the number
// of casters between the surface and the light whether or not the eye is inside a volume,
// since it is taken behind the surface, where the volumes are closed (caps at infinity, depth
// unclipped). Then redraw unlit where the count is not zero.
void SceneRenderer::Impl::DrawVolumeShadows(const ViewCamera& view, const FrameSettings& settings,
                                       const Eigen::Matrix4f& clip_from_world, int projectors) {
  const ShadowVolumeKey key{LightVector(settings.light), cpu_mesh};
  if (shadow_volume_key != key) {
    // Casters move away from the light by a thousandth of the scene, so a lit face is not
    // inside its own volume (the volumes' shadow acne).
    const float offset = 1e-3f * scene.FocusRadius();
    shadow_volume.Replace(BuildShadowVolume(*cpu_mesh, key.light, offset).vertices);
    shadow_volume_key = key;
  }
  glEnable(GL_STENCIL_TEST);
  glStencilMask(0xff);
  glStencilFunc(GL_ALWAYS, 0, 0xff);
  glStencilOpSeparate(GL_BACK, GL_KEEP, GL_INCR_WRAP, GL_KEEP);
  glStencilOpSeparate(GL_FRONT, GL_KEEP, GL_DECR_WRAP, GL_KEEP);
  glColorMask(GL_FALSE, GL_FALSE, GL_FALSE, GL_FALSE);
  glDepthMask(GL_FALSE);
  glEnable(GL_DEPTH_CLAMP);  // Nothing of the volume is clipped by the near or far plane.
  volume.Use();
  volume.Set("u_clip_from_world", clip_from_world);
  glBindVertexArray(shadow_volume.vao.Get());
  glDrawArrays(GL_TRIANGLES, 0, shadow_volume.count);
  glDisable(GL_DEPTH_CLAMP);

  glColorMask(GL_TRUE, GL_TRUE, GL_TRUE, GL_TRUE);
  glStencilFunc(GL_NOTEQUAL, 0, 0xff);
  glStencilOp(GL_KEEP, GL_KEEP, GL_KEEP);
  glDepthFunc(reverse_z_now ? GL_GEQUAL : GL_LEQUAL);  // Same geometry, same depth: passes.
  DrawSurfaces(view, settings, clip_from_world, /*volume second pass*/ 4, projectors);
  glDepthMask(GL_TRUE);
  glDepthFunc(reverse_z_now ? GL_GREATER : GL_LESS);
  glDisable(GL_STENCIL_TEST);
}

// Blob shadows: the ground under each object darkened by a soft round texture (a quad on the
// ground per blob, multiplied into the color and the visibility), lifted towards the eye by the
// ground band so that the reconstructed ground's bumps do not hide it; objects nearer than that
// keep their color.
void SceneRenderer::Impl::DrawBlobShadows(const ViewCamera& view, const FrameSettings& settings,
                                     const Eigen::Matrix4f& clip_from_world) {
  if (!scene.ground) {
    NoteOnce("blob shadows skipped: no ground plane was found in the scene");
    return;
  }
  if (blob_texture.Get() == 0) {
    gpu::UploadFloatTexture(blob_texture, BlobTexture(kBlobTextureSize), kBlobTextureSize, gpu::kScratchUnit);
    // Objects are what rises five times the ground band above it (a reconstructed ground's
    // bumps do not join them into one); a footprint wider than a third of the scene is a wall
    // or a building around it.
    blob_casters = FindBlobCasters(scene.mesh, *scene.ground, 5 * GroundTolerance(), 0.35f * scene.Radius(),
                                   kMaxBlobs);
  }
  const Eigen::Vector4d light = LightVector(settings.light);
  if (blob_light != light) {
    std::vector<Vertex> corners;
    for (const Blob& b : PlaceBlobs(scene.mesh, blob_casters, *scene.ground, light, GroundTolerance())) {
      for (const auto& [s, t] : {std::pair{-1, -1}, {1, -1}, {1, 1}, {-1, -1}, {1, 1}, {-1, 1}}) {
        const Eigen::Vector3f p = b.centre + static_cast<float>(s) * b.axis_u + static_cast<float>(t) * b.axis_v;
        corners.push_back({{p.x(), p.y(), p.z()}, {}, {static_cast<float>(s), static_cast<float>(t)}, {}});
      }
    }
    blob_quads = Upload(corners);
    blob_light = light;
  }
  glActiveTexture(GL_TEXTURE0 + gpu::kScratchUnit);
  glBindTexture(GL_TEXTURE_2D, blob_texture.Get());
  glActiveTexture(GL_TEXTURE0);
  blob.Use();
  blob.Set("u_clip_from_world", clip_from_world);
  blob.Set("u_eye", Eigen::Vector3f(CameraCenter(view.cam_from_world).cast<float>()));
  blob.Set("u_lift", GroundTolerance());
  blob.Set("u_blob", gpu::kScratchUnit);
  glDepthMask(GL_FALSE);
  glEnable(GL_BLEND);
  glBlendFunc(GL_ZERO, GL_SRC_COLOR);
  glBindVertexArray(blob_quads.vao.Get());
  glDrawArrays(GL_TRIANGLES, 0, blob_quads.count);
  glDisable(GL_BLEND);
  glDepthMask(GL_TRUE);
}

double SceneRenderer::Impl::LogAverageLuminance() {
  constexpr int kMeterWidth = 64, kMeterHeight = 36;
  if (meter.Get() == 0) {
    meter = gpu::MakeTextureOnScratchUnit();
    glTexImage2D(GL_TEXTURE_2D, 0, GL_RGBA32F, kMeterWidth, kMeterHeight, 0, GL_RGBA, GL_FLOAT, nullptr);
    gpu::SetTextureParameters(GL_NEAREST, GL_CLAMP_TO_EDGE);
    meter_framebuffer = MakeGlFramebuffer();
    glBindFramebuffer(GL_FRAMEBUFFER, meter_framebuffer.Get());
    glFramebufferTexture2D(GL_FRAMEBUFFER, GL_COLOR_ATTACHMENT0, GL_TEXTURE_2D, meter.Get(), 0);
  }
  glBindFramebuffer(GL_READ_FRAMEBUFFER, eye.hdr_framebuffer.Get());
  glReadBuffer(GL_COLOR_ATTACHMENT0);
  glBindFramebuffer(GL_DRAW_FRAMEBUFFER, meter_framebuffer.Get());
  glBlitFramebuffer(0, 0, eye.width, eye.height, 0, 0, kMeterWidth, kMeterHeight, GL_COLOR_BUFFER_BIT, GL_LINEAR);
  std::vector<float> texels(static_cast<size_t>(kMeterWidth) * kMeterHeight * 4);
  glBindFramebuffer(GL_READ_FRAMEBUFFER, meter_framebuffer.Get());
  glReadPixels(0, 0, kMeterWidth, kMeterHeight, GL_RGBA, GL_FLOAT, texels.data());
  double sum_log = 0;
  for (size_t i = 0; i < texels.size(); i += 4) {
    const double luminance = 0.2126 * static_cast<double>(texels[i]) + 0.7152 * static_cast<double>(texels[i + 1]) +
                             0.0722 * static_cast<double>(texels[i + 2]);
    sum_log += std::log(std::max(luminance, 0.0) + 1e-4);  // The offset keeps black pixels finite.
  }
  return std::exp(sum_log / static_cast<double>(kMeterWidth * kMeterHeight));
}

// The frame's exposure (with auto exposure, the eye adapting towards the frame's brightness
// with the settings' time constant), then the named operator into the 8-bit frame.
void SceneRenderer::Impl::ToneMapFrame(const FrameSettings& settings) {
  double exposure = std::exp2(settings.exposure_stops);
  if (settings.auto_exposure) {
    const double luminance = LogAverageLuminance();
    const auto now = std::chrono::steady_clock::now();
    if (!adapted_luminance || settings.adaptation_seconds <= 0) {
      adapted_luminance = luminance;
    } else {
      const double dt = std::chrono::duration<double>(now - last_adaptation).count();
      *adapted_luminance += (luminance - *adapted_luminance) * (1 - std::exp(-dt / static_cast<double>(settings.adaptation_seconds)));
    }
    last_adaptation = now;
    constexpr double kMiddleGrey = 0.18;
    exposure *= kMiddleGrey / *adapted_luminance;
  }
  glBindFramebuffer(GL_FRAMEBUFFER, eye.framebuffer.Get());
  const GLenum color_only = GL_COLOR_ATTACHMENT0;
  glDrawBuffers(1, &color_only);
  glDisable(GL_DEPTH_TEST);
  glDisable(GL_STENCIL_TEST);
  glActiveTexture(GL_TEXTURE0 + gpu::kScratchUnit);
  glBindTexture(GL_TEXTURE_2D, eye.hdr.Get());
  glActiveTexture(GL_TEXTURE0);
  tone_map.Use();
  tone_map.Set("u_hdr", gpu::kScratchUnit);
  tone_map.Set("u_exposure", static_cast<float>(exposure));
  // Auto exposure alone, on an 8-bit frame that would clip, maps as Reinhard does.
  const ToneMap op = settings.tone_map == ToneMap::kClamp ? ToneMap::kReinhard : settings.tone_map;
  tone_map.Set("u_operator", op == ToneMap::kReinhard ? 1 : op == ToneMap::kAces ? 2 : 0);
  tone_map.Set("u_white", settings.white);
  glBindVertexArray(empty_vao.Get());
  glDrawArrays(GL_TRIANGLES, 0, 3);
  glBindVertexArray(0);
  glEnable(GL_DEPTH_TEST);
  const GLenum both[2] = {GL_COLOR_ATTACHMENT0, with_aux ? GLenum{GL_COLOR_ATTACHMENT1} : GLenum{GL_NONE}};
  glDrawBuffers(2, both);
}

// The sphere map for this frame's light as the camera sees it (a point light from the scene's
// centre), made again when the light turns relative to the camera.
void SceneRenderer::Impl::UpdateMatcap(const ViewCamera& view, const FrameSettings& settings) {
  const Eigen::Vector4d light = LightVector(settings.light);
  const Eigen::Vector3d towards =
      light.w() == 0 ? Eigen::Vector3d(light.head<3>()) : Eigen::Vector3d(light.head<3>() - scene.FocusCentre().cast<double>());
  const Eigen::Vector3d in_camera = (view.cam_from_world.rotation * towards).normalized();
  const std::tuple key{in_camera, settings.specular, settings.shininess};
  if (matcap_key == key) return;
  constexpr int kMatcapSize = 256;
  gpu::UploadFloatTexture(matcap, BlinnPhongMatcap(kMatcapSize, in_camera, settings.specular, settings.shininess),
                          kMatcapSize, gpu::kMatcapUnit);
  matcap_key = key;
}

SceneRenderer::SceneRenderer(const ViewerScene& scene) : impl_(std::make_unique<Impl>(scene)) {
  Impl& r = *impl_;
  r.reverse_z = HasExtension("GL_ARB_clip_control");
  if (r.reverse_z) glClipControl(GL_LOWER_LEFT, GL_ZERO_TO_ONE);
  r.depth = GlProgram("depth", shaders::kDepthVertex, shaders::kDepthFragment);
  r.planar = GlProgram("planar shadow", shaders::kPlanarVertex, shaders::kPlanarFragment);
  r.volume = GlProgram("shadow volume", shaders::kVolumeVertex, shaders::kDepthFragment);
  r.blob = GlProgram("blob shadow", shaders::kBlobVertex, shaders::kBlobFragment);
  r.tone_map = GlProgram("tone map", shaders::kToneMapVertex, shaders::kToneMapFragment);
  r.empty_vao = MakeGlVertexArray();
  r.lines = GlProgram("lines", shaders::kLineVertex, shaders::kLineFragment);
  r.full_mesh = gpu::UploadMesh(scene.mesh, scene.ground);
  r.display_mesh = gpu::UploadMesh(scene.display_mesh, scene.ground);
  if (!scene.points.empty()) r.points = Upload(PointVertices(scene.points));
  for (const ColoredPoint& point : scene.points) r.cloud_positions.push_back(point.position);
  r.frustum_depth = FrustumDepth(scene);
  for (const ViewerSource& source : scene.sources) r.source_centres.push_back(CameraCenter(source.cam_from_world));
  if (!scene.sources.empty()) r.frusta = Upload(FrustumLines(scene.sources, r.frustum_depth));
  r.grid = Upload(GridLines(scene));

  // Samplers must hold textures of their type even when unused: give the comparison samplers
  // a 1x1 depth map each.
  r.shadow.Resize(1, 1);
  for (DepthTarget& target : r.projector_depth) target.Resize(1, 1);
  glEnable(GL_PROGRAM_POINT_SIZE);
  CheckGlError("SceneRenderer setup");
}

SceneRenderer::~SceneRenderer() = default;

void SceneRenderer::Finish() const { glFinish(); }

bool SceneRenderer::UsesReverseZ() const { return impl_->reverse_z; }

size_t SceneRenderer::ShadowBytes(ShadowMode mode) const {
  const Impl& r = *impl_;
  switch (mode) {
    case ShadowMode::kMap:
    case ShadowMode::kPcf: return static_cast<size_t>(r.shadow.width) * static_cast<size_t>(r.shadow.height) * sizeof(float);
    case ShadowMode::kVolume: return static_cast<size_t>(r.shadow_volume.count) * sizeof(Eigen::Vector4f);
    case ShadowMode::kBlob:
      return r.blob_texture.Get() == 0 ? 0
                                       : kBlobTextureSize * kBlobTextureSize * sizeof(float) +
                                             static_cast<size_t>(r.blob_quads.count) * sizeof(Vertex);
    case ShadowMode::kNone:
    case ShadowMode::kPlanar: return 0;
  }
  return 0;
}

std::vector<std::string> SceneRenderer::TakeNotes() { return std::exchange(impl_->notes, {}); }

int SceneRenderer::Impl::UpdateShadowMap(const FrameSettings& settings) {
  int shadow_mode_uniform = 0;
  if (settings.shadows == ShadowMode::kMap || settings.shadows == ShadowMode::kPcf) {
    const Eigen::Matrix4f light_matrix = LightMatrix(settings.light);
    // PCF taps up to r texels away compare against the centre's depth: more slope bias.
    const float slope_bias = settings.shadows == ShadowMode::kPcf ? 1.5f + static_cast<float>(settings.pcf_radius) : 1.5f;
    const ShadowMapKey key{light_matrix, settings.shadow_map_size, slope_bias, mesh};
    if (shadow_key != key) {
      shadow.Resize(settings.shadow_map_size, settings.shadow_map_size);
      RenderDepthMap(shadow, light_matrix, settings, slope_bias);
      shadow_key = key;
    }
    shadow_from_world = light_matrix;
    shadow_mode_uniform = settings.shadows == ShadowMode::kMap ? 2 : 3;
  }
  return shadow_mode_uniform;
}

void SceneRenderer::Impl::BeginFrame(int width, int height, const FrameSettings& settings) {
  eye.Resize(width, height);
  glBindFramebuffer(GL_FRAMEBUFFER, hdr_now ? eye.hdr_framebuffer.Get() : eye.framebuffer.Get());
  glViewport(0, 0, width, height);
  const Eigen::Vector3f background =
      hdr_now ? settings.background
              : Eigen::Vector3f(LinearToSrgb(settings.background.x()), LinearToSrgb(settings.background.y()),
                                LinearToSrgb(settings.background.z()));
  const float clear_color[4] = {background.x(), background.y(), background.z(), 1};
  const float clear_aux[4] = {1, 0, 0, 0};
  glClearBufferfv(GL_COLOR, 0, clear_color);
  // The auxiliary target is read back by Render alone: a frame for the window (or a timing)
  // leaves it out, which saves llvmpipe 16 bytes a pixel written.
  const GLenum draw_buffers[2] = {GL_COLOR_ATTACHMENT0, with_aux ? GLenum{GL_COLOR_ATTACHMENT1} : GLenum{GL_NONE}};
  glDrawBuffers(2, draw_buffers);
  if (with_aux) glClearBufferfv(GL_COLOR, 1, clear_aux);
  glClearDepth(reverse_z_now ? 0.0 : 1.0);
  glClearStencil(0);
  glDepthMask(GL_TRUE);
  glStencilMask(0xff);
  glClear(GL_DEPTH_BUFFER_BIT | GL_STENCIL_BUFFER_BIT);
  glEnable(GL_DEPTH_TEST);
  glDepthFunc(reverse_z_now ? GL_GREATER : GL_LESS);
}

Eigen::Matrix4f SceneRenderer::Impl::EyeProjection(const ViewCamera& view) const {
  Eigen::Matrix4f projection;
  if (reverse_z_now) {
    const double near = view.near > 0 ? view.near : DepthBounds(scene.bounds, view.cam_from_world)[0];
    projection = ReverseZProjection(view.camera, near);
  } else {
    // Without reverse-Z the depth range is fitted to what can be seen: the scene's bounds.
    Eigen::Vector2d range = DepthBounds(scene.bounds, view.cam_from_world);
    if (view.near > 0) range[0] = view.near;
    projection = PerspectiveProjection(view.camera, range[0], std::max(range[1], 4 * range[0]), Range());
  }
  return projection;
}

void SceneRenderer::Draw(const ViewCamera& view, const FrameSettings& settings, int window_framebuffer,
                         int window_width, int window_height) {
  settings.Check();
  Impl& r = *impl_;
  const bool reverse_z = r.reverse_z && settings.reverse_z;
  r.reverse_z_now = reverse_z;
  r.hdr_now = settings.tone_map != ToneMap::kClamp || settings.auto_exposure;
  const int width = static_cast<int>(view.camera.width), height = static_cast<int>(view.camera.height);
  r.cpu_mesh = &DisplayedMesh(r.scene, width, height);
  r.mesh = r.cpu_mesh == &r.scene.display_mesh ? &r.display_mesh : &r.full_mesh;

  // 1. Shadow map from the light.
  const int shadow_mode_uniform = r.UpdateShadowMap(settings);
  glActiveTexture(GL_TEXTURE0 + kShadowUnit);
  glBindTexture(GL_TEXTURE_2D, r.shadow.texture.Get());
  glActiveTexture(GL_TEXTURE0 + kAtlasUnit);
  glBindTexture(GL_TEXTURE_2D, r.mesh->atlas.Get());

  // 2. Projectors' depth maps and photos.
  int projectors = 0;
  if (settings.texture == TextureMode::kProjective) projectors = r.SetUpProjectors(view, settings);

  // 3. The frame.
  r.BeginFrame(width, height, settings);
  const Eigen::Matrix4f projection = r.EyeProjection(view);
  const Eigen::Matrix4f clip_from_world = projection * ViewMatrix(view.cam_from_world);
  if (!reverse_z && r.reverse_z) {
    // glClipControl is global; this frame's projection uses [-1, 1].
    glClipControl(GL_LOWER_LEFT, GL_NEGATIVE_ONE_TO_ONE);
  }
  r.DrawSurfaces(view, settings, clip_from_world, shadow_mode_uniform, projectors);
  if (settings.shadows == ShadowMode::kPlanar) {
    if (r.scene.ground) {
      r.DrawPlanarShadows(view, settings, clip_from_world, projectors);
    } else {
      r.NoteOnce("planar shadows skipped: no ground plane was found in the scene");
    }
  } else if (settings.shadows == ShadowMode::kBlob) {
    r.DrawBlobShadows(view, settings, clip_from_world);
  } else if (settings.shadows == ShadowMode::kVolume) {
    if (r.mesh->triangles > 0) {
      r.DrawVolumeShadows(view, settings, clip_from_world, projectors);
    } else {
      r.NoteOnce("shadow volumes skipped: they need a mesh, and there is only a point cloud");
    }
  }
  r.lines.Use();
  r.lines.Set("u_clip_from_world", clip_from_world);
  r.lines.Set("u_linear_output", r.hdr_now ? 1 : 0);
  if (settings.show_grid) {
    glBindVertexArray(r.grid.vao.Get());
    glDrawArrays(GL_LINES, 0, r.grid.count);
  }
  if (settings.show_cameras && r.frusta.count > 0) r.DrawFrusta(CameraCenter(view.cam_from_world));
  glBindVertexArray(0);
  if (!reverse_z && r.reverse_z) glClipControl(GL_LOWER_LEFT, GL_ZERO_TO_ONE);
  if (r.hdr_now) r.ToneMapFrame(settings);

  if (window_framebuffer >= 0) {
    glBindFramebuffer(GL_READ_FRAMEBUFFER, r.eye.framebuffer.Get());
    glReadBuffer(GL_COLOR_ATTACHMENT0);
    glBindFramebuffer(GL_DRAW_FRAMEBUFFER, static_cast<GLuint>(window_framebuffer));
    const int shown_width = window_width > 0 ? window_width : width;
    const int shown_height = window_height > 0 ? window_height : height;
    glBlitFramebuffer(0, 0, width, height, 0, 0, shown_width, shown_height, GL_COLOR_BUFFER_BIT,
                      shown_width == width && shown_height == height ? GL_NEAREST : GL_LINEAR);
  }
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
  glBindFramebuffer(GL_READ_FRAMEBUFFER, impl_->eye.framebuffer.Get());
  glPixelStorei(GL_PACK_ALIGNMENT, 1);
  std::vector<uint8_t> bytes(static_cast<size_t>(width) * height * 4);
  std::vector<float> aux(static_cast<size_t>(width) * height * 4);
  glReadBuffer(GL_COLOR_ATTACHMENT0);
  glReadPixels(0, 0, width, height, GL_RGBA, GL_UNSIGNED_BYTE, bytes.data());
  glReadBuffer(GL_COLOR_ATTACHMENT1);
  glReadPixels(0, 0, width, height, GL_RGBA, GL_FLOAT, aux.data());
  CheckGlError("SceneRenderer::Render read back");
  FrameResult result{Image(width, height, 3), Image(width, height, 4)};
  for (int y = 0; y < height; ++y) {
    const size_t row = static_cast<size_t>(height - 1 - y) * width;  // GL rows go bottom-up.
    for (int x = 0; x < width; ++x) {
      for (int c = 0; c < 3; ++c) result.color.At(x, y, c) = bytes[(row + x) * 4 + c] / 255.0f;
      for (int c = 0; c < 4; ++c) result.aux.At(x, y, c) = aux[(row + x) * 4 + c];
    }
  }
  return result;
}

}  // namespace parallax
