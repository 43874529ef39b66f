#pragma once
// The per-row steps of a forward warp (forward_warp.cc): a source row's pixel centres mapped
// into the target, the quads of one surface between them, and the silhouette penalty. Internal
// to the warp; each call covers one whole row.
#include <cstddef>
#include <cstdint>

#include "reproject/forward_warp.h"
#include "reproject/view.h"

namespace parallax::warp_internal {

enum VertexKind : uint8_t { kInvalid = 0, kSurface = 1, kSky = 2 };

// Source pixel centres mapped into the target, each once; triangles and splats share them.
// A window of consecutive source rows (RowWindow's): source pixel i (row-major index) is at
// At(i) while its row is in the window.
struct Vertices {
  PixelArray<float> u;       // Target pixel coordinates.
  PixelArray<float> v;
  PixelArray<float> inv_z;   // 1 / target z; 0 for background.
  PixelArray<float> angle;   // Ray angle, as in WarpBuffer::Weight.
  PixelArray<uint8_t> kind;  // VertexKind.
  // Mesh: per quad (pixel centres (x, y) to (x + 1, y + 1)), ContinuousRow's.
  PixelArray<uint8_t> quads;
  // Mesh: 1 where the vertex is to be splatted (the image border, and beside dropped
  // triangles).
  PixelArray<uint8_t> edges;
  size_t capacity = 0;
  size_t offset = 0;  // Source index of the window's first pixel.

  size_t At(size_t i) const { return i - offset; }
};

// Everything the per-pixel loops need, in the float form they use.
struct WarpSetup {
  Pinhole src;
  Pinhole dst;
  float r[3][3];  // target_from_source rotation.
  float t[3];     // target_from_source translation: the source centre in the target frame.
  float min_view_cos;
  float max_depth_ratio;  // Between samples of one surface (mesh and splat footprints).
};

// The warp's constants for one source and target.
WarpSetup MakeSetup(const SourceView& source, const PosedCamera& target,
                    const ForwardWarpOptions& options);

// Maps one source row into the target. Surfaces are lifted at their depth; background pixels
// are rotated only (a direction has no position, so the baseline does not move it).
void ProjectRow(const WarpSetup& s, const SourceView& source, const uint8_t* background,
                const float* ray_x, int y, Vertices* out);

// Per quad of source row y (pixel centres (x, y) to (x + 1, y + 1)): kSurface when its four
// samples are surface within max_depth_ratio of each other (one surface), kSky when all four
// are background, else kInvalid.
void ContinuousRow(const SourceView& source, const WarpSetup& s, int y, Vertices* vtx);

// Adds `penalty` to the ray angle (so to the blend weight's denominator) of the surface
// vertices of source row y beside a dropped quad (quads: ContinuousRow's, complete): those
// pixels lie on a silhouette, or next to sky or unknown depth, and their photo color mixes
// the two sides, where another source that sees the point away from its silhouettes has it
// pure. Quads outside the image do not count (the image border is no silhouette).
void PenaliseSilhouetteRow(const WarpSetup& s, float penalty, int y, uint8_t* marks_row,
                           Vertices* vtx);

}  // namespace parallax::warp_internal
