#pragma once
// A textured block's projective map and the vertices it maps, for the rasteriser
// (rasterizer.h; internal to reproject/).
#include <cmath>

#include "reproject/simd.h"

namespace parallax::warp_internal {

using simd::kFloatMax;
inline bool Finite(float value) { return std::abs(value) <= kFloatMax; }

// A vertex as the rasteriser reads it.
struct Corner {
  float u, v, inv_z, angle;
  const float* rgb;
  float sx, sy;  // Source pixel (column, row) whose centre this is.
};

// Pixels of a row side by side in a textured block: eight with AVX2, one group instead of two
// or three across a block about nine pixels wide.
using simd::FV;
using simd::IV;
using simd::kLanes;
using simd::LaneBits;
using simd::LaneIndices;

// A textured block's map from target pixels to its source square: the projective map
// (homography) that takes the target positions of its corners a, b, c, d to source (0, 0),
// (side, 0), (0, side), (side, side) relative to a. Exact on a plane (two pinhole images of a
// plane are related by a homography); on a curved block exact at the corners, and an edge
// shared with the next block is the same target line mapped to the same source line in both,
// so their inside tests agree. Attributes are bilinear in the source position, inverse depth
// as w times a bilinear factor, exact on a plane (there w is target over source depth up to
// scale, and inverse source depth is affine in the source position). Target positions are
// relative to a's (small numbers, so float keeps the map exact to ~1e-6 of the block).
struct BlockMap {
  // (s, t, w) = row k . (du, dv, 1); the source position relative to a is (s / w, t / w).
  float s_du, s_dv, t_du, t_dv, w_du, w_dv, w_a;
  // Bilinear coefficients, value = c[0] + c[1] fx + c[2] fy + c[3] fx fy: inverse depth / w
  // (surfaces) and ray angle.
  float inv_z[4], angle[4];
  float stretch;  // Target pixels per source pixel (area ratio).

  // False unless the target quad a, b, d, c is strictly convex (a plane in front of the
  // camera always is; a block seen edge-on or folded is not, and is drawn in smaller parts).
  template <bool kBackground>
  bool Init(const Corner& a, const Corner& b, const Corner& c, const Corner& d, float side) {
    const float x1 = b.u - a.u, y1 = b.v - a.v;  // Square corner (1, 0).
    const float x2 = d.u - a.u, y2 = d.v - a.v;  // (1, 1).
    const float x3 = c.u - a.u, y3 = c.v - a.v;  // (0, 1).
    // Turns at a, b, d, c: all of one sign for a convex quad.
    const float turn_a = x1 * y3 - y1 * x3, turn_b = x1 * (y2 - y1) - y1 * (x2 - x1);
    const float turn_d = (x2 - x1) * (y3 - y2) - (y2 - y1) * (x3 - x2);
    const float turn_c = (x3 - x2) * (-y3) - (y3 - y2) * (-x3);
    const bool positive = turn_a > 0 && turn_b > 0 && turn_d > 0 && turn_c > 0;
    const bool negative = turn_a < 0 && turn_b < 0 && turn_d < 0 && turn_c < 0;
    if (!positive && !negative) return false;
    // The unit square to the quad (Heckbert's square-to-quad): (u, v, w) = A (sigma, tau, 1).
    const float sum_x = x2 - x1 - x3, sum_y = y2 - y1 - y3;
    const float dx1 = x1 - x2, dx2 = x3 - x2, dy1 = y1 - y2, dy2 = y3 - y2;
    const float den = dx1 * dy2 - dx2 * dy1;
    const float g = (sum_x * dy2 - dx2 * sum_y) / den, h = (dx1 * sum_y - sum_x * dy1) / den;
    const float a00 = x1 + g * x1, a01 = x3 + h * x3, a10 = y1 + g * y1, a11 = y3 + h * y3;
    // Its inverse up to scale (the adjugate), signed so that w > 0 inside, the source
    // position scaled from the unit square to side.
    const float det = a00 * a11 - a01 * a10;
    const float sign = det > 0 ? 1.0f : -1.0f;
    w_a = sign * det;
    w_du = sign * (a10 * h - a11 * g);
    w_dv = sign * (a01 * g - a00 * h);
    const float scale = sign * side;
    s_du = scale * a11;
    s_dv = -scale * a01;
    t_du = -scale * a10;
    t_dv = scale * a00;
    if (!(w_a > 0) || !Finite(w_a) || !Finite(w_du) || !Finite(w_dv) || !Finite(s_du) ||
        !Finite(s_dv) || !Finite(t_du) || !Finite(t_dv)) {
      return false;
    }
    stretch = 0.5f * std::abs(x2 * (y3 - y1) - y2 * (x3 - x1)) / (side * side);
    const float inv_side = 1.0f / side;
    const auto bilinear = [&](float va, float vb, float vc, float vd, float out[4]) {
      out[0] = va;
      out[1] = (vb - va) * inv_side;
      out[2] = (vc - va) * inv_side;
      out[3] = (va - vb - vc + vd) * inv_side * inv_side;
    };
    if constexpr (!kBackground) {
      const auto w_at = [&](float du, float dv) { return w_a + w_du * du + w_dv * dv; };
      bilinear(a.inv_z / w_a, b.inv_z / w_at(x1, y1), c.inv_z / w_at(x3, y3),
               d.inv_z / w_at(x2, y2), inv_z);
      bilinear(a.angle, b.angle, c.angle, d.angle, angle);
    }
    return true;
  }

  static FV Interpolate(const float c[4], FV fx, FV fy) {
    return c[0] + fx * c[1] + fy * (c[2] + fx * c[3]);
  }
};

}  // namespace parallax::warp_internal
