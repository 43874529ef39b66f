#pragma once
// The rasteriser behind ForwardWarp (internal to reproject/: included by forward_warp.cc and
// warp_rows.cc only): triangles, textured blocks and splats of one source written into its
// WarpBuffer with a z-test.
#include <algorithm>
#include <cmath>
#include <cstddef>
#include <cstdint>

#include "core/image.h"
#include "reproject/block_map.h"
#include "reproject/forward_warp.h"
#include "reproject/simd.h"

namespace parallax::warp_internal {

// floor and ceil for values >= -1 by truncation: std::floor is a library call without SSE4.1,
// and these run several times per triangle.
inline int FloorClamped(float value) { return static_cast<int>(value + 1.0f) - 1; }
inline int CeilClamped(float value) {
  const int floor = FloorClamped(value);
  return static_cast<float>(floor) < value ? floor + 1 : floor;
}

// Color channels (RGB and one more) side by side.
using simd::F4;
using simd::LoadHalf4;

// `value` as four halves at p, each lane clamped to [low, WarpBuffer::kMaxHalf] first (a
// larger float would round to infinity; NaN becomes low).
inline void StoreHalf4Clamped(uint16_t* p, F4 value, F4 low) {
  constexpr float kMax = WarpBuffer::kMaxHalf;
  value = value > low ? value : low;
  value = value < kMax ? value : F4{} + kMax;
  simd::StoreHalf4(p, value);
}

// Writes samples of one source into the target buffer (z-test: nearest surface wins;
// background only where nothing is).
class Rasterizer {
 public:
  // Draws only target rows [row_begin, row_end): rasterisers of disjoint row bands may share
  // one buffer from different threads.
  // `texture`: the source's color as SourceView::texture holds it (half floats, RGBA),
  // texture_width x texture_height pixels.
  Rasterizer(WarpBuffer* buffer, const uint16_t* texture, int texture_width, int texture_height,
             const ForwardWarpOptions& options, int row_begin, int row_end)
      : row_begin_(row_begin),
        row_end_(row_end),
        bicubic_min_stretch_(options.texture_filter == TextureFilter::kBicubic ? 0.0f
                                                                               : kMagnifiedStretch),
        angle_epsilon_(static_cast<float>(options.angle_epsilon_rad)),
        width_(buffer->Width()),
        height_(buffer->Height()),
        depth_(buffer->MutableDepth()),
        color_weight_(buffer->MutableColorWeights()),
        texture_(texture),
        texture_width_(texture_width),
        texture_height_(texture_height) {}

  // Perspective-correct: inverse depth is affine in the image, attributes / z too.
  void SurfaceTriangle(const Corner& a, const Corner& b, const Corner& c) {
    Box box;
    float inv_area;
    if (!Setup(a, b, c, &box, &inv_area)) return;
    const float stretch = Stretch(inv_area);
    for (int y = box.y0; y <= box.y1; ++y) {
      for (int x = box.x0; x <= box.x1; ++x) ShadeSurface(a, b, c, x, y, inv_area, stretch);
    }
  }

  // A square block of `side` x `side` source pixels of one continuous surface (or of
  // background, kBackground), corners a (top left), b, c, d (bottom right), its color sampled
  // from the source at the position BlockMap gives (so a block larger than one pixel keeps
  // the texture's detail). Returns false, drawing nothing, where the map is not defined
  // (BlockMap::Init): the caller draws the block another way.
  //
  // Drawn by inverse mapping: every pixel of the block's bounding box is mapped to a source
  // position relative to a's, (fx, fy), and the block covers the pixel when that lies in the
  // source square. That needs no edge setup and runs kLanes pixels at a time. The slack is far
  // above float rounding, so a centre on an edge shared with the next block is drawn by both,
  // never by neither.
  template <bool kBackground>
  bool TexturedBlock(const Corner& a, const Corner& b, const Corner& c, const Corner& d,
                     float side) {
    Box box;
    if (!ClipQuad(a, b, c, d, &box)) return true;
    BlockMap map;
    if (!map.Init<kBackground>(a, b, c, d, side)) return false;
    PrefetchTexture(a, side);
    const float slack = 1e-5f * side;
    const FV lane = __builtin_convertvector(LaneIndices(), FV) + 0.5f;
    const IV lane_index = LaneIndices();
    for (int y = box.y0; y <= box.y1; ++y) {
      PrefetchTarget(box.x1, y);
      const float dv = static_cast<float>(y) + 0.5f - a.v;
      const float s_row = map.s_dv * dv, t_row = map.t_dv * dv, w_row = map.w_a + map.w_dv * dv;
      for (int x = box.x0; x <= box.x1; x += kLanes) {
        const FV du = (static_cast<float>(x) - a.u) + lane;
        const FV w = w_row + du * map.w_du;
        // Lanes where w <= 0 (beyond the quad's horizon) divide to garbage and are dropped.
        const FV inv_w = 1.0f / w;
        const FV fx = (s_row + du * map.s_du) * inv_w, fy = (t_row + du * map.t_du) * inv_w;
        const IV in = (w > 0) & (fx >= -slack) & (fy >= -slack) & (fx <= side + slack) &
                      (fy <= side + slack) & (lane_index < box.x1 - x + 1);
        if (LaneBits(in) == 0) continue;
        WriteGroup<kBackground>(Index(x, y), width_ - x, in, fx, fy, w, map, a);
      }
    }
    return true;
  }

  // Directions: screen-affine interpolation (no depth); never covers a surface.
  void BackgroundTriangle(const Corner& a, const Corner& b, const Corner& c) {
    Box box;
    float inv_area;
    if (!Setup(a, b, c, &box, &inv_area)) return;
    const float stretch = Stretch(inv_area);
    for (int y = box.y0; y <= box.y1; ++y) {
      const float pv = static_cast<float>(y) + 0.5f;
      for (int x = box.x0; x <= box.x1; ++x) {
        const float pu = static_cast<float>(x) + 0.5f;
        float w[3];
        if (!Barycentric(a, b, c, pu, pv, inv_area, w)) continue;
        const size_t i = Index(x, y);
        if (depth_[i] != 0) continue;
        Write(i, WarpBuffer::kBackground, w, a, b, c, stretch);
      }
    }
  }

  // A square footprint of half-size (half_u, half_v) pixels around the corner.
  void Splat(const Corner& a, float half_u, float half_v, float stretch, bool background) {
    Box box;
    if (!Clip(a.u - half_u, a.u + half_u, a.v - half_v, a.v + half_v, &box)) return;
    const float z = background ? WarpBuffer::kBackground : 1.0f / a.inv_z;
    if (!background && !Finite(z)) return;
    const float q[3] = {1, 0, 0};
    for (int y = box.y0; y <= box.y1; ++y) {
      for (int x = box.x0; x <= box.x1; ++x) {
        const size_t i = Index(x, y);
        if (background ? depth_[i] != 0 : !Nearer(i, z)) continue;
        Write(i, z, q, a, a, a, stretch);
      }
    }
  }

 private:
  struct Box {
    int x0, x1, y0, y1;
  };

  // The block walk moves right along a row of source blocks, so the next blocks read the
  // texture and write the target a few dozen pixels further right on the same rows: some
  // twenty streams, more than the hardware prefetcher follows. They are asked for kAhead
  // pixels ahead: the texture rows once per block, each target row as the block reaches it.
  static constexpr int kAhead = 32;

  void PrefetchTexture(const Corner& a, float side) const {
    const int sx = std::min(static_cast<int>(a.sx) + kAhead, texture_width_ - 1);
    for (int r = 0; r <= static_cast<int>(side) + 1; ++r) {
      const int sy = std::min(static_cast<int>(a.sy) + r, texture_height_ - 1);
      const size_t pixel = static_cast<size_t>(sy) * static_cast<size_t>(texture_width_) +
                           static_cast<size_t>(sx);
      __builtin_prefetch(texture_ + 4 * pixel);
    }
  }

  // Target row y, kAhead pixels right of x.
  void PrefetchTarget(int x, int y) const {
    const size_t i = Index(std::min(x + kAhead, width_ - 1), y);
    __builtin_prefetch(depth_ + i, 1);
    __builtin_prefetch(color_weight_ + 4 * i, 1);
  }

  // Twice the signed area of a triangle below which it is degenerate (pixels squared).
  static constexpr float kMinArea2 = 1e-12f;

  size_t Index(int x, int y) const {
    return static_cast<size_t>(y) * static_cast<size_t>(width_) + static_cast<size_t>(x);
  }

  // The z-test: target pixel i is empty or holds something farther than z.
  bool Nearer(size_t i, float z) const { return depth_[i] == 0 || z < depth_[i]; }

  // Source triangles have area 1/2, so the area ratio is twice the target area: |area2|.
  static float Stretch(float inv_area) { return std::abs(1.0f / inv_area); }

  static float Area2(const Corner& a, const Corner& b, const Corner& c) {
    return (b.u - a.u) * (c.v - a.v) - (b.v - a.v) * (c.u - a.u);
  }

  // Writes pixel (x, y) from the triangle when its centre lies inside and passes the z-test;
  // returns whether the centre lies inside.
  // `stretch` is the triangle's, as in WarpBuffer::Weight.
  bool ShadeSurface(const Corner& a, const Corner& b, const Corner& c, int x, int y,
                    float inv_area, float stretch) {
    float w[3];
    if (!Barycentric(a, b, c, static_cast<float>(x) + 0.5f, static_cast<float>(y) + 0.5f,
                     inv_area, w)) {
      return false;
    }
    const float inv_z = w[0] * a.inv_z + w[1] * b.inv_z + w[2] * c.inv_z;
    if (!(inv_z > 0)) return true;
    const float z = 1.0f / inv_z;
    const size_t i = Index(x, y);
    if (!Nearer(i, z) || !Finite(z)) return true;
    const float q[3] = {w[0] * a.inv_z * z, w[1] * b.inv_z * z, w[2] * c.inv_z * z};
    Write(i, z, q, a, b, c, stretch);
    return true;
  }

  // The pixel box of a quad's bounding rectangle, clipped to the target; false when empty.
  bool ClipQuad(const Corner& a, const Corner& b, const Corner& c, const Corner& d, Box* box) const {
    return Clip(std::min(std::min(a.u, b.u), std::min(c.u, d.u)),
                std::max(std::max(a.u, b.u), std::max(c.u, d.u)),
                std::min(std::min(a.v, b.v), std::min(c.v, d.v)),
                std::max(std::max(a.v, b.v), std::max(c.v, d.v)), box);
  }

  // Pixels whose centres lie in [u0, u1] x [v0, v1], clipped to the image and the rows drawn.
  // Coordinates are clamped as floats before the integer conversion so far-off vertices
  // cannot overflow it.
  bool Clip(float u0, float u1, float v0, float v1, Box* box) const {
    const float w = static_cast<float>(width_), h = static_cast<float>(height_);
    box->x0 = std::max(0, CeilClamped(std::clamp(u0 - 0.5f, -1.0f, w)));
    box->x1 = std::min(width_ - 1, FloorClamped(std::clamp(u1 - 0.5f, -1.0f, w)));
    box->y0 = std::max(row_begin_, CeilClamped(std::clamp(v0 - 0.5f, -1.0f, h)));
    box->y1 = std::min(row_end_ - 1, FloorClamped(std::clamp(v1 - 0.5f, -1.0f, h)));
    return box->x0 <= box->x1 && box->y0 <= box->y1;
  }

  bool Setup(const Corner& a, const Corner& b, const Corner& c, Box* box,
             float* inv_area) const {
    const float area2 = Area2(a, b, c);
    if (!(std::abs(area2) > kMinArea2) || !Finite(area2)) return false;
    if (!Clip(std::min({a.u, b.u, c.u}), std::max({a.u, b.u, c.u}),
              std::min({a.v, b.v, c.v}), std::max({a.v, b.v, c.v}), box)) {
      return false;
    }
    *inv_area = 1.0f / area2;
    return true;
  }

  // Barycentric weights of the pixel centre; false outside the triangle. Edges are inclusive
  // (with a hair of slack) so that no centre on a shared edge falls between two triangles.
  static bool Barycentric(const Corner& a, const Corner& b, const Corner& c, float pu, float pv,
                          float inv_area, float w[3]) {
    constexpr float kSlack = -1e-5f;
    w[0] = ((b.u - pu) * (c.v - pv) - (b.v - pv) * (c.u - pu)) * inv_area;
    w[1] = ((c.u - pu) * (a.v - pv) - (c.v - pv) * (a.u - pu)) * inv_area;
    w[2] = 1.0f - w[0] - w[1];
    return w[0] >= kSlack && w[1] >= kSlack && w[2] >= kSlack;
  }

  void Write(size_t i, float depth, const float q[3], const Corner& a, const Corner& b,
             const Corner& c, float stretch) {
    depth_[i] = depth;
    F4 rgbw;
    for (int k = 0; k < 3; ++k) rgbw[k] = q[0] * a.rgb[k] + q[1] * b.rgb[k] + q[2] * c.rgb[k];
    rgbw[3] = Weight(q[0] * a.angle + q[1] * b.angle + q[2] * c.angle, stretch);
    StoreColorWeight(i, rgbw);
  }

  // Color (RGB) and weight of target pixel i, in WarpBuffer::ColorWeights' halves.
  void StoreColorWeight(size_t i, F4 rgbw) {
    constexpr float kMax = WarpBuffer::kMaxHalf;
    StoreHalf4Clamped(color_weight_ + 4 * i, rgbw, F4{-kMax, -kMax, -kMax, WarpBuffer::kMinWeight});
  }

  // WarpBuffer::Weight of samples at ray angle `angle` (a float, or lanes) and area
  // ratio `stretch`.
  template <typename T>
  T Weight(T angle, float stretch) const {
    return 1.0f / ((angle + angle_epsilon_) * std::max(1.0f, stretch));
  }

  // Writes the lanes of a group of kLanes pixels (target pixels i to i + kLanes - 1 of one
  // row, `left` of them before the row ends) that a block covers (`in`, at source positions
  // fx, fy relative to corner a's, `w` of its map) and that pass the z-test: depth and weight
  // for all lanes at once, then the color of each written lane, sampled from the source.
  template <bool kBackground>
  void WriteGroup(size_t i, int left, IV in, FV fx, FV fy, FV w, const BlockMap& map,
                  const Corner& a) {
    // All lanes' depths at once inside the row, lanes not written stored back unchanged. A
    // group that runs past the row's end goes lane by lane: the next row may be another
    // thread's.
    const bool whole = left >= kLanes;
    FV depth{};
    if (whole) {
      depth = simd::Load<FV>(depth_ + i);
    } else {
      for (int k = 0; k < left; ++k) depth[k] = depth_[i + static_cast<size_t>(k)];
    }
    FV z, angle;
    IV write;
    if constexpr (kBackground) {
      z = FV{} + WarpBuffer::kBackground;
      angle = FV{};
      write = in & (depth == 0);
    } else {
      const FV inv_z = w * BlockMap::Interpolate(map.inv_z, fx, fy);
      z = 1.0f / inv_z;
      angle = BlockMap::Interpolate(map.angle, fx, fy);
      // In front of the camera and finite; NaN fails every test.
      write = in & (inv_z > 0) & ((depth == 0) | (z < depth)) & (z <= kFloatMax);
    }
    const int bits = LaneBits(write);
    if (bits == 0) return;
    if (whole) {
      simd::Store(depth_ + i, write ? z : depth);
    } else {
      for (int k = 0; k < left; ++k) {
        if (bits >> k & 1) depth_[i + static_cast<size_t>(k)] = z[k];
      }
    }
    const FV weight = Weight(angle, map.stretch);
    const FV sx = a.sx + fx;
    const FV sy = a.sy + fy;
    const Taps taps = TapsAt(sx, sy, map.stretch);
    for (int k = 0; k < kLanes; ++k) {
      if ((bits >> k & 1) == 0) continue;
      F4 rgbw = taps.bicubic[k] != 0 ? Bicubic(sx[k], sy[k]) : Bilinear(taps, k);
      rgbw[3] = weight[k];
      StoreColorWeight(i + static_cast<size_t>(k), rgbw);
    }
  }

  // Where the lanes' samples at source pixels (sx, sy) read the source: bicubic where
  // magnified (or always, TextureFilter::kBicubic) and inside by a pixel, else bilinear from
  // the pixel (x0, y0) at or before the position, its right and lower neighbours (the pixel
  // itself on the last column / row) and weights.
  struct Taps {
    IV bicubic, x0, y0, step_x, step_y;  // Steps in halves.
    FV w00, w10, w01, w11;
  };

  Taps TapsAt(FV sx, FV sy, float stretch) const {
    const float last_x = static_cast<float>(texture_width_ - 1);
    const float last_y = static_cast<float>(texture_height_ - 1);
    Taps t;
    const IV magnified = IV{} - (stretch > bicubic_min_stretch_ ? 1 : 0);
    t.bicubic = magnified & (sx >= 1.0f) & (sy >= 1.0f) & (sx < last_x - 1.0f) &
                (sy < last_y - 1.0f);
    // Clamped to the image (the interpolation can overshoot a corner by a hair; NaN to 0);
    // then non-negative, so truncation is floor.
    sx = sx > 0.0f ? sx : FV{};
    sy = sy > 0.0f ? sy : FV{};
    sx = sx < last_x ? sx : FV{} + last_x;
    sy = sy < last_y ? sy : FV{} + last_y;
    t.x0 = __builtin_convertvector(sx, IV);
    t.y0 = __builtin_convertvector(sy, IV);
    const FV fx = sx - __builtin_convertvector(t.x0, FV);
    const FV fy = sy - __builtin_convertvector(t.y0, FV);
    t.step_x = (t.x0 < texture_width_ - 1) & 4;
    t.step_y = (t.y0 < texture_height_ - 1) & (4 * texture_width_);
    t.w00 = (1 - fx) * (1 - fy);
    t.w10 = fx * (1 - fy);
    t.w01 = (1 - fx) * fy;
    t.w11 = fx * fy;
    return t;
  }

  // The color at lane k of `taps` (lane 3 is 0).
  F4 Bilinear(const Taps& taps, int k) const {
    const size_t row = static_cast<size_t>(taps.y0[k]) * static_cast<size_t>(texture_width_);
    const uint16_t* t00 = texture_ + 4 * (row + static_cast<size_t>(taps.x0[k]));
    const uint16_t* t10 = t00 + taps.step_x[k];
    const uint16_t* t01 = t00 + taps.step_y[k];
    const uint16_t* t11 = t01 + taps.step_x[k];
    return taps.w00[k] * LoadHalf4(t00) + taps.w10[k] * LoadHalf4(t10) +
           taps.w01[k] * LoadHalf4(t01) + taps.w11[k] * LoadHalf4(t11);
  }

  // Where the target samples the source more densely than its pixels (magnified), and
  // between pixels generally, bilinear interpolation blurs the texture: Catmull-Rom over
  // 4 x 4 source pixels keeps it sharper. Inside the image by at least one pixel (the caller
  // checks). Lane 3 is 0 (the texture's fourth channel).
  F4 Bicubic(float sx, float sy) const {
    const int x0 = static_cast<int>(sx), y0 = static_cast<int>(sy);
    float wx[4], wy[4];
    CatmullRom(sx - static_cast<float>(x0), wx);
    CatmullRom(sy - static_cast<float>(y0), wy);
    F4 rgb{};
    for (int r = 0; r < 4; ++r) {
      const uint16_t* row = texture_ + 4 * (static_cast<size_t>(y0 - 1 + r) * static_cast<size_t>(texture_width_) +
                                            static_cast<size_t>(x0 - 1));
      const F4 across = wx[0] * LoadHalf4(row) + wx[1] * LoadHalf4(row + 4) +
                        wx[2] * LoadHalf4(row + 8) + wx[3] * LoadHalf4(row + 12);
      rgb += wy[r] * across;
    }
    // The kernel's negative lobes can undershoot below black.
    return rgb > 0.0f ? rgb : F4{};
  }

  static void CatmullRom(float t, float w[4]) {
    const float t2 = t * t, t3 = t2 * t;
    w[0] = 0.5f * (-t3 + 2 * t2 - t);
    w[1] = 0.5f * (3 * t3 - 5 * t2 + 2);
    w[2] = 0.5f * (-3 * t3 + 4 * t2 + t);
    w[3] = 0.5f * (t3 - t2);
  }

  // Target pixels per source pixel above which TextureFilter::kAuto draws a sample bicubic.
  static constexpr float kMagnifiedStretch = 1.5f;

  int row_begin_;  // Target rows drawn.
  int row_end_;
  float bicubic_min_stretch_;  // Bicubic above this stretch (where inside by a pixel).
  float angle_epsilon_;
  int width_;
  int height_;
  float* depth_;
  uint16_t* color_weight_;
  const uint16_t* texture_;
  int texture_width_;
  int texture_height_;
};


}  // namespace parallax::warp_internal
