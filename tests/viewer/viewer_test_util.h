#pragma once
// Shared by the viewer tests: one headless GL context per process, synthetic scenes built from
// synth's shapes, and the ray-traced reference shadow mask.
#include <cmath>
#include <memory>
#include <optional>
#include <vector>

#include <Eigen/Geometry>

#include "pipeline/raycaster.h"
#include "synth/ray_tracer.h"
#include "synth/scene.h"
#include "viewer/egl_context.h"
#include "viewer/renderer.h"
#include "viewer/viewer_scene.h"

namespace parallax::viewer_test {

// llvmpipe (LIBGL_ALWAYS_SOFTWARE=1, set by the context) for the whole test binary.
inline void EnsureGlContext() {
  static const auto context = std::make_unique<HeadlessGlContext>(true);
}

inline ObjectDesc Plane(double size, double z = 0) {
  ObjectDesc plane;
  plane.type = ShapeType::kPlane;
  plane.material = "m";
  plane.center = {0, 0, z};
  plane.size = {size, size, 0};
  return plane;
}

inline ObjectDesc Box(const Eigen::Vector3d& center, const Eigen::Vector3d& size, double yaw_deg = 0) {
  ObjectDesc box;
  box.type = ShapeType::kBox;
  box.material = "m";
  box.center = center;
  box.size = size;
  box.yaw_deg = yaw_deg;
  return box;
}

// The objects as one mesh with a grey 2x2 atlas, bounds and ground plane computed.
inline ViewerScene SceneFromObjects(const std::vector<ObjectDesc>& objects) {
  ViewerScene scene;
  for (const ObjectDesc& object : objects) {
    const TriangleMesh part = TessellateObject(object);
    const int base = static_cast<int>(scene.mesh.vertices.size());
    scene.mesh.vertices.insert(scene.mesh.vertices.end(), part.vertices.begin(), part.vertices.end());
    for (const Eigen::Vector3i& t : part.triangles) {
      scene.mesh.triangles.push_back(t + Eigen::Vector3i::Constant(base));
      for (int c = 0; c < 3; ++c) scene.mesh.corner_uvs.emplace_back(0.5f, 0.5f);
    }
  }
  scene.mesh.atlas = Image(2, 2, 3);
  for (float& v : scene.mesh.atlas.Pixels()) v = 0.7f;
  FinishViewerScene(scene);
  return scene;
}

// Möller-Trumbore: whether the ray origin + t dir hits the triangle for t in (t_min, inf).
inline bool RayHitsTriangle(const Eigen::Vector3d& origin, const Eigen::Vector3d& dir,
                            const Eigen::Vector3d& a, const Eigen::Vector3d& b, const Eigen::Vector3d& c,
                            double t_min) {
  const Eigen::Vector3d e1 = b - a, e2 = c - a, p = dir.cross(e2);
  const double det = e1.dot(p);
  if (std::abs(det) < 1e-15) return false;
  const Eigen::Vector3d s = origin - a;
  const double u = s.dot(p) / det;
  if (u < 0 || u > 1) return false;
  const Eigen::Vector3d q = s.cross(e1);
  const double v = dir.dot(q) / det;
  if (v < 0 || u + v > 1) return false;
  return e2.dot(q) / det > t_min;
}

struct ReferencePixel {
  bool hit = false;
  bool shadowed = false;  // Facing away from the light, or the way to the light is blocked.
  int triangle = -1;
  double depth = 0;
  Eigen::Vector3d point = Eigen::Vector3d::Zero();
};

// Ray-traced reference for a directional light travelling along `direction`: primary rays by
// Embree (MeshRaycaster), exact shadow rays against every triangle.
inline std::vector<ReferencePixel> ReferenceShadows(const ViewerScene& scene, const ViewCamera& view,
                                                    const Eigen::Vector3d& direction) {
  const MeshRaycaster raycaster(scene.mesh.vertices, scene.mesh.triangles);
  const std::vector<RayHit> hits = raycaster.CastPixels(view.camera, view.cam_from_world);
  const Rigid3d world_from_cam = view.cam_from_world.Inverse();
  const Eigen::Vector3d eye = CameraCenter(view.cam_from_world);
  const Eigen::Vector3d to_light = -direction.normalized();
  const int width = static_cast<int>(view.camera.width);
  std::vector<ReferencePixel> pixels(hits.size());
  for (size_t i = 0; i < hits.size(); ++i) {
    if (hits[i].triangle < 0) continue;
    ReferencePixel& pixel = pixels[i];
    pixel.hit = true;
    pixel.triangle = hits[i].triangle;
    pixel.depth = hits[i].depth;
    const Eigen::Vector2d xy(static_cast<double>(i % width) + 0.5, static_cast<double>(i / width) + 0.5);
    pixel.point = world_from_cam * *view.camera.Unproject(xy, hits[i].depth);
    const Eigen::Vector3i& t = scene.mesh.triangles[hits[i].triangle];
    const Eigen::Vector3d a = scene.mesh.vertices[t[0]].cast<double>();
    const Eigen::Vector3d b = scene.mesh.vertices[t[1]].cast<double>();
    const Eigen::Vector3d c = scene.mesh.vertices[t[2]].cast<double>();
    Eigen::Vector3d normal = (b - a).cross(c - a).normalized();
    if (normal.dot(eye - pixel.point) < 0) normal = -normal;
    if (normal.dot(to_light) <= 0) {
      pixel.shadowed = true;
      continue;
    }
    const Eigen::Vector3d origin = pixel.point + 1e-5 * normal;
    for (const Eigen::Vector3i& other : scene.mesh.triangles) {
      if (RayHitsTriangle(origin, to_light, scene.mesh.vertices[other[0]].cast<double>(),
                          scene.mesh.vertices[other[1]].cast<double>(),
                          scene.mesh.vertices[other[2]].cast<double>(), 1e-6)) {
        pixel.shadowed = true;
        break;
      }
    }
  }
  return pixels;
}

// The renderer's shadow mask: a surface facing away from the light or not lit by it.
inline bool RenderedShadowed(const Image& aux, int x, int y) {
  return aux.At(x, y, 0) < 0.5f || aux.At(x, y, 1) <= 0;
}
inline bool RenderedCovered(const Image& aux, int x, int y) { return aux.At(x, y, 3) > 0.5f; }

struct MaskComparison {
  double iou = 0;
  int reference_shadowed = 0, rendered_shadowed = 0, compared = 0;
};

// IoU of the shadowed pixels over pixels both the renderer and the ray tracer cover; with
// `only` given, just those pixels of the reference.
template <typename Predicate>
MaskComparison CompareMasks(const std::vector<ReferencePixel>& reference, const Image& aux, Predicate only) {
  MaskComparison result;
  int intersection = 0, union_count = 0;
  for (int y = 0; y < aux.Height(); ++y) {
    for (int x = 0; x < aux.Width(); ++x) {
      const ReferencePixel& ref = reference[static_cast<size_t>(y) * aux.Width() + x];
      if (!ref.hit || !RenderedCovered(aux, x, y) || !only(ref)) continue;
      ++result.compared;
      const bool rendered = RenderedShadowed(aux, x, y);
      result.reference_shadowed += ref.shadowed;
      result.rendered_shadowed += rendered;
      intersection += rendered && ref.shadowed;
      union_count += rendered || ref.shadowed;
    }
  }
  result.iou = union_count == 0 ? 1.0 : static_cast<double>(intersection) / union_count;
  return result;
}

// SceneRenderer settings for shadow measurements: grey albedo, nothing but the mesh.
inline FrameSettings ShadowSettings(ShadowMode mode, const Eigen::Vector3d& light_direction) {
  FrameSettings settings;
  settings.shadows = mode;
  settings.texture = TextureMode::kShaded;
  settings.light.direction = light_direction;
  settings.show_cameras = false;
  settings.show_grid = false;
  return settings;
}

}  // namespace parallax::viewer_test
