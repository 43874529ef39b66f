#include "viewer/surface_pass.h"

#include <cmath>
#include <string>
#include <utility>

#include "viewer/matcap.h"
#include "viewer/shaders.h"
#include "viewer/view_math.h"

namespace parallax {

const GlProgram& SurfacePass::Program(Albedo albedo, SurfaceShadow shadow, int pcf_radius, bool hdr) {
  if (shadow != SurfaceShadow::kPcf) pcf_radius = 0;
  const std::tuple key{static_cast<int>(albedo), static_cast<int>(shadow), pcf_radius, hdr};
  auto found = programs_.find(key);
  if (found != programs_.end()) return found->second;
  const std::string fragment = "#version 330 core\n#define ALBEDO_SOURCE " + std::to_string(std::get<0>(key)) +
                               "\n#define SHADOW_MODE " + std::to_string(std::get<1>(key)) +
                               "\n#define PCF_RADIUS " + std::to_string(pcf_radius) +
                               "\n#define HDR_OUTPUT " + (hdr ? "1" : "0") + "\n" + shaders::kSurfaceFragment;
  GlProgram program("surface", shaders::kSurfaceVertex, fragment.c_str());
  program.Use();
  program.Set("u_atlas", gpu::kAtlasUnit);
  program.Set("u_shadow_map", gpu::kShadowUnit);
  program.Set("u_matcap", gpu::kMatcapUnit);
  for (int k = 0; k < kMaxProjectors; ++k) {
    program.Set(("u_photo" + std::to_string(k)).c_str(), gpu::kPhotoUnit + k);
    program.Set(("u_projector_depth" + std::to_string(k)).c_str(), gpu::kProjectorDepthUnit + k);
  }
  return programs_.emplace(key, std::move(program)).first->second;
}

void SurfacePass::Use(const GlProgram& program, const FrameContext& frame, const SurfaceInputs& inputs) const {
  const FrameSettings& settings = frame.settings;
  program.Use();
  program.Set("u_clip_from_world", frame.clip_from_world);
  program.Set("u_cam_from_world", ViewMatrix(frame.view.cam_from_world));
  program.Set("u_eye", Eigen::Vector3f(CameraCenter(frame.view.cam_from_world).cast<float>()));
  program.Set("u_light", Eigen::Vector4f(frame.light.cast<float>()));
  program.Set("u_light_color", Eigen::Vector3f(settings.light.intensity * settings.light.color));
  program.Set("u_ambient", settings.ambient);
  program.Set("u_specular", settings.specular);
  program.Set("u_shininess", settings.shininess);
  program.Set("u_exposure", std::exp2(settings.exposure_stops));
  program.Set("u_ndc_to_depth", frame.NdcToDepth());
  program.Set("u_shadow_from_world", inputs.shadow_from_world);
  program.Set("u_num_projectors", static_cast<int>(inputs.projectors.size()));
  program.Set("u_projector_pull", 0.003f);
  for (size_t k = 0; k < inputs.projectors.size(); ++k) {
    const std::string index = std::to_string(k);
    program.Set(("u_projector_from_world[" + index + "]").c_str(), inputs.projectors[k].clip_from_world);
    program.Set(("u_projector_centre[" + index + "]").c_str(), inputs.projectors[k].centre);
    program.Set(("u_projector_gain[" + index + "]").c_str(), inputs.projectors[k].gain);
  }
  program.Set("u_has_atlas", frame.mesh.atlas.Get() != 0 ? 1 : 0);
  program.Set("u_ground", inputs.ground);
  program.Set("u_ground_tolerance", inputs.ground_tolerance);
  program.Set("u_point_size", settings.point_size_px);
}

void SurfacePass::Draw(const FrameContext& frame, SurfaceShadow shadow, const SurfaceInputs& inputs,
                       const DepthPass& depth) {
  const FrameSettings& settings = frame.settings;
  const Albedo albedo = settings.texture == TextureMode::kProjective ? Albedo::kProjective
                        : settings.texture == TextureMode::kShaded   ? Albedo::kShaded
                        : settings.texture == TextureMode::kMatcap   ? Albedo::kMatcap
                                                                     : Albedo::kAtlas;
  if (albedo == Albedo::kMatcap) UpdateMatcap(frame);
  if (settings.show_mesh && frame.HasMesh()) DrawMesh(frame, albedo, shadow, inputs, depth);
  if (settings.show_points && frame.points.count > 0 &&
      (!frame.HasMesh() || !settings.show_mesh || settings.points_with_mesh)) {
    DrawPoints(frame, albedo, shadow, inputs);
  }
}

void SurfacePass::DrawMesh(const FrameContext& frame, Albedo albedo, SurfaceShadow shadow,
                           const SurfaceInputs& inputs, const DepthPass& depth) {
  // Depth pre-pass: the mesh's depth alone first, then the shaded pass where it matches, so
  // each pixel is shaded once however much the walls and pillars overlap (fragment work
  // dominates on llvmpipe). Both vertex shaders compute an invariant gl_Position. The second
  // passes of planar shadows and shadow volumes already test against the finished depth.
  const bool prepass = shadow != SurfaceShadow::kPlanarRedraw && shadow != SurfaceShadow::kVolumeRedraw;
  if (prepass) {
    glColorMask(GL_FALSE, GL_FALSE, GL_FALSE, GL_FALSE);
    depth.DrawEyeDepth(frame);
    glColorMask(GL_TRUE, GL_TRUE, GL_TRUE, GL_TRUE);
    glDepthMask(GL_FALSE);
    glDepthFunc(frame.DepthLessOrEqual());
  }
  // Without an atlas, the atlas mode shows the grey albedo.
  const Albedo mesh_albedo = albedo == Albedo::kAtlas && frame.mesh.atlas.Get() == 0 ? Albedo::kShaded : albedo;
  Use(Program(mesh_albedo, shadow, frame.settings.pcf_radius, frame.hdr), frame, inputs);
  glBindVertexArray(frame.mesh.shaded.vao.Get());
  glDrawElements(GL_TRIANGLES, frame.mesh.shaded.count, GL_UNSIGNED_INT, nullptr);
  if (prepass) {
    glDepthMask(GL_TRUE);
    glDepthFunc(frame.DepthLess());
  }
}

void SurfacePass::DrawPoints(const FrameContext& frame, Albedo albedo, SurfaceShadow shadow,
                             const SurfaceInputs& inputs) {
  // The atlas mode shows each point's own color.
  const Albedo point_albedo = albedo == Albedo::kAtlas ? Albedo::kPointColors : albedo;
  Use(Program(point_albedo, shadow, frame.settings.pcf_radius, frame.hdr), frame, inputs);
  glBindVertexArray(frame.points.vao.Get());
  glDrawArrays(GL_POINTS, 0, frame.points.count);
}

// The sphere map holds the highlight of a light at the scene's centre for a point light.
void SurfacePass::UpdateMatcap(const FrameContext& frame) {
  const FrameSettings& settings = frame.settings;
  const Eigen::Vector4d& light = frame.light;
  const Eigen::Vector3d towards = light.w() == 0 ? Eigen::Vector3d(light.head<3>())
                                                 : Eigen::Vector3d(light.head<3>() -
                                                                   frame.scene.FocusCentre().cast<double>());
  const Eigen::Vector3d in_camera = (frame.view.cam_from_world.rotation * towards).normalized();
  const std::tuple key{in_camera, settings.specular, settings.shininess};
  if (matcap_key_ == key) return;
  constexpr int kMatcapSize = 256;
  gpu::UploadFloatTexture(matcap_, BlinnPhongMatcap(kMatcapSize, in_camera, settings.specular, settings.shininess),
                          kMatcapSize, gpu::kMatcapUnit);
  matcap_key_ = key;
}

}  // namespace parallax
