#pragma once
// How right are the rasterised shadows? A ray-traced reference (Embree) of what each pixel of a
// view sees and whether the light reaches it, and the intersection over union of the renderer's
// shadow mask with it. Used by the viewer tests, `parallax view --shadow-iou` and the bench.
#include <functional>
#include <optional>
#include <vector>

#include <Eigen/Core>

#include "core/image.h"
#include "geometry/ground_plane.h"
#include "geometry/obj.h"
#include "viewer/frame.h"

namespace parallax {

struct ReferencePixel {
  bool hit = false;
  bool facing_away = false;  // The surface turns its back to the light (face normal).
  bool shadowed = false;     // Facing away from the light, or the way to the light is blocked.
  int triangle = -1;
  double depth = 0;
  Eigen::Vector3d point = Eigen::Vector3d::Zero();
};

// Per pixel of `view` (row-major): the surface of `mesh` its centre ray hits and whether a
// directional light travelling along `direction` reaches it. Faces are lit on the side the eye
// sees (reconstructed meshes have no consistent winding).
std::vector<ReferencePixel> ReferenceShadows(const TriangleMesh& mesh, const ViewCamera& view,
                                             const Eigen::Vector3d& direction);

// The renderer's masks, from FrameResult::aux: a surface facing away from the light or not lit
// by it; a pixel showing the scene.
inline bool RenderedShadowed(const Image& aux, int x, int y) {
  return aux.At(x, y, 0) < 0.5f || aux.At(x, y, 1) <= 0;
}
inline bool RenderedCovered(const Image& aux, int x, int y) { return aux.At(x, y, 3) > 0.5f; }

struct MaskComparison {
  double iou = 0;
  int reference_shadowed = 0, rendered_shadowed = 0, compared = 0;
};

// IoU of the shadowed pixels over the pixels both the renderer and the ray tracer cover (and
// that `only` accepts, when given). 1 when neither shadows anything.
MaskComparison CompareShadowMasks(const std::vector<ReferencePixel>& reference, const Image& aux,
                                  const std::function<bool(const ReferencePixel&)>& only = {});

// The same for cast shadows alone: over the pixels whose surface faces the light, whether the
// shadow map and the ray tracer find the way to the light blocked. On a reconstructed mesh the
// many small faces that turn from the light make the full mask measure the mesh's noise and
// its shading normals more than the shadow map.
MaskComparison CompareCastShadows(const std::vector<ReferencePixel>& reference, const Image& aux,
                                  const std::function<bool(const ReferencePixel&)>& only = {});

struct ShadowAccuracy {
  MaskComparison all;   // Every shadowed pixel.
  MaskComparison cast;  // Cast shadows alone (CompareCastShadows).
  // With a ground plane, the cast shadows split: those falling on the ground (shadows on other
  // objects, in the lecture's words) and on what stands on it (objects shadowing themselves).
  std::optional<MaskComparison> on_ground, on_objects;
};

// A rendered frame's shadow mask against Embree's exact one for the mesh it drew; the ground is
// what lies within `ground_band` of `ground`. Throws BadInputError without a directional light
// or a mesh.
ShadowAccuracy MeasureShadowAccuracy(const TriangleMesh& drawn, const ViewCamera& view,
                                     const FrameSettings& settings, const FrameResult& frame,
                                     const std::optional<GroundPlane>& ground = std::nullopt,
                                     double ground_band = 0);

}  // namespace parallax
