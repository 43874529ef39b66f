#include "reproject/warp_rows.h"

#include <algorithm>
#include <cmath>
#include <numbers>

#include "reproject/rasterizer.h"
#include "reproject/simd.h"

namespace parallax::warp_internal {
namespace {


// The per-row constants of ProjectSpan.
struct RowProjection {
  float base0, base1, base2;  // Rotated source ray (x, y, 1) = ray_x * r_0 + base.
  float r00, r10, r20;
  float t0, t1, t2;
  float fx, fy, cx, cy;
  float min_view_cos;
};

// n pixels of a row. Written without branches (every pixel computed, then kept or marked
// invalid) and with __restrict arrays (no run-time alias checks) so that it vectorises; masks
// are int32 (a loop mixing float and byte lanes does not vectorise on SSE2).
void ProjectSpan(int n, const RowProjection& c, const float* __restrict ray_x,
                 const float* __restrict depth_in, const int32_t* __restrict sky_in,
                 float* __restrict out_u, float* __restrict out_v, float* __restrict out_inv_z,
                 float* __restrict out_angle,
                 int32_t* __restrict out_kind) {
  for (int k = 0; k < n; ++k) {
    const float dir0 = ray_x[k] * c.r00 + c.base0;
    const float dir1 = ray_x[k] * c.r10 + c.base1;
    const float dir2 = ray_x[k] * c.r20 + c.base2;
    const float depth = depth_in[k];
    const int surface = static_cast<int>(depth > 0) & static_cast<int>(depth <= kFloatMax);
    const int sky = static_cast<int>(depth == 0) & static_cast<int>(sky_in[k] != 0);
    // Background: the direction itself (scale 1, no translation).
    const float scale = surface != 0 ? depth : 1.0f;
    const float shift = surface != 0 ? 1.0f : 0.0f;
    const float p0 = scale * dir0 + shift * c.t0;
    const float p1 = scale * dir1 + shift * c.t1;
    const float p2 = scale * dir2 + shift * c.t2;
    const float norm_p = std::sqrt(p0 * p0 + p1 * p1 + p2 * p2);
    const float norm_dir = std::sqrt(dir0 * dir0 + dir1 * dir1 + dir2 * dir2);
    // Chord between the unit rays from the target centre (p) and the source centre (dir).
    const float inv_norm_p = 1.0f / norm_p, inv_norm_dir = 1.0f / norm_dir;
    const float e0 = p0 * inv_norm_p - dir0 * inv_norm_dir;
    const float e1 = p1 * inv_norm_p - dir1 * inv_norm_dir;
    const float e2 = p2 * inv_norm_p - dir2 * inv_norm_dir;
    const float angle = std::sqrt(e0 * e0 + e1 * e1 + e2 * e2);
    const float inv_z = 1.0f / p2;
    const float u = c.fx * p0 * inv_z + c.cx;
    const float v = c.fy * p1 * inv_z + c.cy;
    // Comparisons with NaN are false, so these also reject NaN.
    const int finite = static_cast<int>(std::abs(u) <= kFloatMax) &
                       static_cast<int>(std::abs(v) <= kFloatMax) &
                       static_cast<int>(std::abs(inv_z) <= kFloatMax) &
                       static_cast<int>(norm_p <= kFloatMax);
    const int ok = (surface | sky) & static_cast<int>(p2 > c.min_view_cos * norm_p) & finite;
    out_u[k] = u;
    out_v[k] = v;
    out_inv_z[k] = surface != 0 ? inv_z : 0.0f;
    out_angle[k] = (surface & ok) != 0 ? angle : 0.0f;
    out_kind[k] = ok * (kSky - surface);
  }
}

}  // namespace

WarpSetup MakeSetup(const SourceView& source, const PosedCamera& target,
                    const ForwardWarpOptions& options) {
  WarpSetup setup;
  setup.src = Pinhole::From(source.camera);
  setup.dst = Pinhole::From(target.camera);
  const Rigid3d target_from_source = RelativePose(source.cam_from_world, target.cam_from_world);
  const Eigen::Matrix3d rotation = target_from_source.rotation.toRotationMatrix();
  for (int i = 0; i < 3; ++i) {
    for (int j = 0; j < 3; ++j) setup.r[i][j] = static_cast<float>(rotation(i, j));
    setup.t[i] = static_cast<float>(target_from_source.translation(i));
  }
  setup.min_view_cos = static_cast<float>(options.min_view_cos);
  const double slope = std::tan(options.max_slant_deg * std::numbers::pi / 180.0);
  setup.max_depth_ratio = static_cast<float>(
      1.0 + slope * std::sqrt(2.0) / std::min(setup.src.fx, setup.src.fy));
  return setup;
}

void ProjectRow(const WarpSetup& s, const SourceView& source, const uint8_t* background,
                const float* ray_x, int y, Vertices* out) {
  const int width = s.src.width;
  const float ray_y = static_cast<float>((y + 0.5 - s.src.cy) / s.src.fy);
  RowProjection c;
  c.base0 = ray_y * s.r[0][1] + s.r[0][2];
  c.base1 = ray_y * s.r[1][1] + s.r[1][2];
  c.base2 = ray_y * s.r[2][1] + s.r[2][2];
  c.r00 = s.r[0][0];
  c.r10 = s.r[1][0];
  c.r20 = s.r[2][0];
  c.t0 = s.t[0];
  c.t1 = s.t[1];
  c.t2 = s.t[2];
  c.fx = static_cast<float>(s.dst.fx);
  c.fy = static_cast<float>(s.dst.fy);
  c.cx = static_cast<float>(s.dst.cx);
  c.cy = static_cast<float>(s.dst.cy);
  c.min_view_cos = s.min_view_cos;
  const size_t row = static_cast<size_t>(y) * static_cast<size_t>(width);
  // The background bytes and the kinds go through int32 chunks.
  constexpr int kChunk = 64;
  int32_t kinds[kChunk], sky_in[kChunk];
  for (int chunk = 0; chunk < width; chunk += kChunk) {
    const int n = std::min(width - chunk, kChunk);
    const size_t i = row + static_cast<size_t>(chunk);
    const size_t o = out->At(i);
    for (int k = 0; k < n; ++k) sky_in[k] = background != nullptr ? background[i + static_cast<size_t>(k)] : 0;
    ProjectSpan(n, c, ray_x + chunk, source.depth.Values().data() + i, sky_in, out->u.get() + o,
                out->v.get() + o, out->inv_z.get() + o, out->angle.get() + o,
                kinds);
    for (int k = 0; k < n; ++k) {
      out->kind[o + static_cast<size_t>(k)] = static_cast<uint8_t>(kinds[k]);
    }
  }
}

void ContinuousRow(const SourceView& source, const WarpSetup& s, int y, Vertices* vtx) {
  const int width = s.src.width;
  const size_t row = static_cast<size_t>(y) * static_cast<size_t>(width);
  uint8_t* __restrict quad = vtx->quads.get() + vtx->At(row);
  if (y + 1 >= s.src.height) {
    std::fill(quad, quad + width, uint8_t{0});
    return;
  }
  // In three passes that each vectorise (a loop mixing float and byte lanes does not, on
  // SSE2): the depth test per quad as int32, then as bytes, then with the kinds. The kinds
  // AND to kSurface or kSky when all four agree (1 & 2 == 0), else to kInvalid; a surface quad
  // failing the depth test becomes kInvalid by clearing bit 0 (kSky keeps its bit 1).
  const float* __restrict depth = source.depth.Values().data() + row;
  const float* __restrict depth_below = depth + width;
  const uint8_t* __restrict kind = vtx->kind.get() + vtx->At(row);
  const uint8_t* __restrict kind_below = kind + width;
  const float max_ratio = s.max_depth_ratio;
  constexpr int kChunk = 64;
  int32_t one_surface[kChunk];
  uint8_t keep[kChunk];
  for (int chunk = 0; chunk + 1 < width; chunk += kChunk) {
    const int n = std::min(width - 1 - chunk, kChunk);
    const float* d = depth + chunk;
    const float* e = depth_below + chunk;
    for (int k = 0; k < n; ++k) {
      const float lo = std::min(std::min(d[k], d[k + 1]), std::min(e[k], e[k + 1]));
      const float hi = std::max(std::max(d[k], d[k + 1]), std::max(e[k], e[k + 1]));
      one_surface[k] = hi <= max_ratio * lo ? 0xFF : 0xFE;
    }
    for (int k = 0; k < n; ++k) keep[k] = static_cast<uint8_t>(one_surface[k]);
    const uint8_t* p = kind + chunk;
    const uint8_t* q = kind_below + chunk;
    for (int k = 0; k < n; ++k) quad[chunk + k] = p[k] & p[k + 1] & q[k] & q[k + 1] & keep[k];
  }
  quad[width - 1] = 0;
}

void PenaliseSilhouetteRow(const WarpSetup& s, float penalty, int y, uint8_t* marks_row,
                           Vertices* vtx) {
  const int width = s.src.width, height = s.src.height;
  if (width < 2 || height < 2) return;  // No quads.
  const size_t row = static_cast<size_t>(y) * static_cast<size_t>(width);
  // Quad rows y - 1 and y; the first and the last vertex row have one of them, read twice
  // (AND is idempotent). Quad column width - 1 does not exist (ContinuousRow marks it 0).
  const uint8_t* quads = vtx->quads.get() + vtx->At(row);
  const uint8_t* __restrict above = y > 0 ? quads - width : quads;
  const uint8_t* __restrict below = y + 1 < height ? quads : above;
  const uint8_t* __restrict kind = vtx->kind.get() + vtx->At(row);
  uint8_t* __restrict marks = marks_row;
  const auto mark = [&](int x, uint8_t quads_joined) {
    marks[x] = static_cast<uint8_t>((quads_joined != kSurface) & (kind[x] == kSurface));
  };
  const int last = width - 1;
  mark(0, above[0] & below[0]);
  for (int x = 1; x < last; ++x) mark(x, above[x - 1] & above[x] & below[x - 1] & below[x]);
  mark(last, above[last - 1] & below[last - 1]);
  float* angle = vtx->angle.get() + vtx->At(row);
  simd::ForEachMarked(marks, width, [&](int x) { angle[x] += penalty; });
}

}  // namespace parallax::warp_internal
