#include "eval/shadow_reference.h"

#include <cmath>

#include <Eigen/Geometry>

#include "core/error.h"
#include "geometry/raycaster.h"

namespace parallax {

std::vector<ReferencePixel> ReferenceShadows(const TriangleMesh& mesh, const ViewCamera& view,
                                             const Eigen::Vector3d& direction) {
  if (!(direction.norm() > 0) || !direction.allFinite()) {
    throw InternalError("ReferenceShadows: the light direction must be finite and non-zero");
  }
  const MeshRaycaster raycaster(mesh.vertices, mesh.triangles);
  const std::vector<RayHit> hits = raycaster.CastPixels(view.camera, view.cam_from_world);
  const Rigid3d world_from_cam = view.cam_from_world.Inverse();
  const Eigen::Vector3d eye = CameraCenter(view.cam_from_world);
  const Eigen::Vector3d to_light = -direction.normalized();
  const int width = static_cast<int>(view.camera.width);
  Eigen::AlignedBox3f bounds;
  for (const Eigen::Vector3f& v : mesh.vertices) bounds.extend(v);
  const double size = static_cast<double>(bounds.isEmpty() ? 1.0f : bounds.diagonal().norm());

  std::vector<ReferencePixel> pixels(hits.size());
  std::vector<Eigen::Vector3f> shadow_origins;
  std::vector<size_t> shadow_pixels;
  for (size_t i = 0; i < hits.size(); ++i) {
    if (hits[i].triangle < 0) continue;
    ReferencePixel& pixel = pixels[i];
    pixel.hit = true;
    pixel.triangle = hits[i].triangle;
    pixel.depth = hits[i].depth;
    const Eigen::Vector2d xy(static_cast<double>(i % width) + 0.5, static_cast<double>(i / width) + 0.5);
    pixel.point = world_from_cam * *view.camera.Unproject(xy, hits[i].depth);
    const Eigen::Vector3i& t = mesh.triangles[static_cast<size_t>(hits[i].triangle)];
    const Eigen::Vector3d a = mesh.vertices[t[0]].cast<double>();
    Eigen::Vector3d normal = (mesh.vertices[t[1]].cast<double>() - a).cross(mesh.vertices[t[2]].cast<double>() - a).normalized();
    if (normal.dot(eye - pixel.point) < 0) normal = -normal;
    if (normal.dot(to_light) <= 0) {
      pixel.facing_away = true;
      pixel.shadowed = true;
      continue;
    }
    // Off the surface by 1e-4 of the scene, so the float ray does not hit its own triangle.
    shadow_origins.push_back((pixel.point + 1e-4 * size * normal).cast<float>());
    shadow_pixels.push_back(i);
  }
  const std::vector<uint8_t> lit = raycaster.Unoccluded(shadow_origins, to_light.cast<float>(),
                                                        static_cast<float>(4 * size));
  for (size_t k = 0; k < shadow_pixels.size(); ++k) pixels[shadow_pixels[k]].shadowed = !lit[k];
  return pixels;
}

namespace {

// IoU of `rendered_shadowed(x, y)` against ReferencePixel::shadowed over the pixels both cover
// and `only` accepts.
template <typename RenderedShadowedFn, typename OnlyFn>
MaskComparison CompareMasks(const std::vector<ReferencePixel>& reference, const Image& aux,
                            const RenderedShadowedFn& rendered_shadowed, const OnlyFn& only) {
  if (reference.size() != static_cast<size_t>(aux.Width()) * static_cast<size_t>(aux.Height())) {
    throw InternalError("shadow mask comparison: the reference and the frame differ in size");
  }
  MaskComparison result;
  int intersection = 0, union_count = 0;
  for (int y = 0; y < aux.Height(); ++y) {
    for (int x = 0; x < aux.Width(); ++x) {
      const ReferencePixel& ref = reference[static_cast<size_t>(y) * static_cast<size_t>(aux.Width()) + static_cast<size_t>(x)];
      if (!ref.hit || !RenderedCovered(aux, x, y) || !only(ref)) continue;
      ++result.compared;
      const bool rendered = rendered_shadowed(x, y);
      result.reference_shadowed += ref.shadowed;
      result.rendered_shadowed += rendered;
      intersection += rendered && ref.shadowed;
      union_count += rendered || ref.shadowed;
    }
  }
  result.iou = union_count == 0 ? 1.0 : static_cast<double>(intersection) / union_count;
  return result;
}

}  // namespace

MaskComparison CompareShadowMasks(const std::vector<ReferencePixel>& reference, const Image& aux,
                                  const std::function<bool(const ReferencePixel&)>& only) {
  return CompareMasks(
      reference, aux, [&](int x, int y) { return RenderedShadowed(aux, x, y); },
      [&](const ReferencePixel& pixel) { return !only || only(pixel); });
}

MaskComparison CompareCastShadows(const std::vector<ReferencePixel>& reference, const Image& aux,
                                  const std::function<bool(const ReferencePixel&)>& only) {
  return CompareMasks(
      reference, aux, [&](int x, int y) { return aux.At(x, y, 0) < 0.5f; },
      [&](const ReferencePixel& pixel) { return !pixel.facing_away && (!only || only(pixel)); });
}

ShadowAccuracy MeasureShadowAccuracy(const TriangleMesh& drawn, const ViewCamera& view,
                                     const FrameSettings& settings, const FrameResult& frame,
                                     const std::optional<GroundPlane>& ground, double ground_band) {
  if (settings.light.type != LightKind::kDirectional || drawn.triangles.empty()) {
    throw BadInputError("--shadow-iou needs a directional light and a mesh");
  }
  const std::vector<ReferencePixel> reference = ReferenceShadows(drawn, view, settings.light.direction);
  ShadowAccuracy accuracy{CompareShadowMasks(reference, frame.aux), CompareCastShadows(reference, frame.aux), {}, {}};
  if (ground) {
    const auto on_ground = [&](const ReferencePixel& p) {
      return std::abs(ground->SignedDistance(p.point)) <= ground_band;
    };
    accuracy.on_ground = CompareCastShadows(reference, frame.aux, on_ground);
    accuracy.on_objects = CompareCastShadows(reference, frame.aux, [&](const ReferencePixel& p) { return !on_ground(p); });
  }
  return accuracy;
}

}  // namespace parallax
