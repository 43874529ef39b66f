#include "reproject/blend.h"

#include <algorithm>
#include <cmath>
#include <string>

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include "core/error.h"
#include "reproject/simd.h"
#include "core/check.h"

namespace parallax {
namespace {

using simd::F4;
using simd::I4;
using simd::kFloatMax;
using simd::LaneBits;
using simd::Load4;
using simd::Store4;

// The running sums of one row of the blend, and what decides which samples join them.
struct RowSums {
  const float* front;  // Front-most surface depth; +inf: none.
  const float* limit;  // Samples up to this depth join.
  float* rgbw;         // Weighted color (RGB) and weight (W) per pixel, interleaved.
  float* depth;
};

// A pixel's color and weight (RGBW) added to its sums (color times weight, and weight)
// where `take` (all lanes alike).
void AddPixel(F4 rgbw, I4 take, float* sums) {
  const F4 w = __builtin_shufflevector(rgbw, rgbw, 3, 3, 3, 3);
  const F4 added = I4{0, 0, 0, -1} ? w : rgbw * w;
  Store4(sums, Load4(sums) + (take ? added : F4{}));
}

// Adds the samples of one buffer's row that lie within the limit (0 < depth <= limit) to the
// sums, four pixels at a time (the row's last width % 4 pixels one at a time); a surface's
// depth only where the front holds a surface. `color_weight`: WarpBuffer::ColorWeights.
void AddSamples(const float* depth, const uint16_t* color_weight, size_t width,
                const RowSums& sums) {
  // Color and weight are read here first, a stream per buffer next to the others' and the
  // sums: the hardware prefetcher fell behind. Asked for kAhead pixels ahead, a cache line
  // (8 pixels) at a time.
  constexpr size_t kAhead = 128;
  size_t x = 0;
  for (; x + 4 <= width; x += 4) {
    if (x % 8 == 0) __builtin_prefetch(color_weight + 4 * (x + kAhead));
    const F4 d = Load4(depth + x);
    const I4 take = (d > 0) & (d <= Load4(sums.limit + x));
    if (LaneBits(take) == 0) continue;
    // Color and weight are written only where a sample landed: lanes not taken may hold
    // anything, and are selected away, never added.
    const uint16_t* samples = color_weight + 4 * x;
    const F4 rgbw[4] = {simd::LoadHalf4(samples), simd::LoadHalf4(samples + 4),
                        simd::LoadHalf4(samples + 8), simd::LoadHalf4(samples + 12)};
    float* sum = sums.rgbw + 4 * x;
    AddPixel(rgbw[0], __builtin_shufflevector(take, take, 0, 0, 0, 0), sum);
    AddPixel(rgbw[1], __builtin_shufflevector(take, take, 1, 1, 1, 1), sum + 4);
    AddPixel(rgbw[2], __builtin_shufflevector(take, take, 2, 2, 2, 2), sum + 8);
    AddPixel(rgbw[3], __builtin_shufflevector(take, take, 3, 3, 3, 3), sum + 12);
    const F4 w = {rgbw[0][3], rgbw[1][3], rgbw[2][3], rgbw[3][3]};
    const I4 surface = Load4(sums.front + x) != WarpBuffer::kBackground;
    Store4(sums.depth + x, Load4(sums.depth + x) + ((take & surface) ? w * d : F4{}));
  }
  for (; x < width; ++x) {
    const float d = depth[x];
    if (!(d > 0 && d <= sums.limit[x])) continue;
    const F4 rgbw = simd::LoadHalf4(color_weight + 4 * x);
    const float w = rgbw[3];
    AddPixel(rgbw, I4{} - 1, sums.rgbw + 4 * x);
    if (sums.front[x] != WarpBuffer::kBackground) sums.depth[x] += w * d;
  }
}

// One row of the blend, buffer after buffer (each buffer's row is read as a stream).
// `scratch` is resized to 8 floats per pixel of the row.
void BlendRow(std::span<const WarpBuffer> buffers, int y, float tolerance, int min_support,
              std::vector<float>* scratch, BlendResult* out) {
  const size_t width = static_cast<size_t>(out->color.Width());
  const size_t row = static_cast<size_t>(y) * width;
  scratch->resize(8 * width);
  float* front = scratch->data();             // Front-most surface depth; +inf: none.
  float* rgbw_sum = front + width;            // Interleaved: weighted RGB, weight.
  float* depth_sum = rgbw_sum + 4 * width;
  float* any_background = depth_sum + width;  // 1 where a background sample landed.
  std::fill(front, front + width, WarpBuffer::kBackground);
  std::fill(rgbw_sum, any_background + width, 0.0f);
  float* back = depth_sum;  // Farthest surface depth; 0: none (depth_sum is zeroed below).
  // Without branches (depth 0 maps to +inf for the front, background to 0 for the back), so
  // that it vectorises.
  for (const WarpBuffer& buffer : buffers) {
    const float* __restrict depth = buffer.Depths() + row;
    for (size_t x = 0; x < width; ++x) {
      const float d = depth[x];
      const bool background = d == WarpBuffer::kBackground;
      any_background[x] = background ? 1.0f : any_background[x];
      front[x] = std::min(front[x], d > 0 ? d : WarpBuffer::kBackground);
      back[x] = std::max(back[x], background ? 0.0f : d);
    }
  }
  if (min_support > 1 && buffers.size() > 1) {
    // The front-most surface that min_support sources agree on (where as many have a
    // surface sample here): a sample in front of what the others agree on, seen by it alone,
    // is more likely a depth error than an occluder the others all miss. Only where the
    // samples disagree (most pixels hold one surface).
    for (size_t x = 0; x < width; ++x) {
      if (front[x] == WarpBuffer::kBackground || back[x] <= front[x] * (1.0f + tolerance)) continue;
      float surfaces[16];
      size_t n = 0;
      for (const WarpBuffer& buffer : buffers) {
        const float d = buffer.Depths()[row + x];
        if (d > 0 && d != WarpBuffer::kBackground && n < 16) surfaces[n++] = d;
      }
      const size_t need = std::min(n, static_cast<size_t>(min_support));
      float best = WarpBuffer::kBackground;
      for (size_t a = 0; a < n; ++a) {
        size_t support = 0;
        for (size_t b = 0; b < n; ++b) {
          support += std::abs(surfaces[b] - surfaces[a]) <= tolerance * surfaces[a] ? 1 : 0;
        }
        if (support >= need && surfaces[a] < best) best = surfaces[a];
      }
      // No two agree: the front-most, as without support.
      if (best != WarpBuffer::kBackground) front[x] = best;
    }
  }
  std::fill(depth_sum, depth_sum + width, 0.0f);
  // Where a surface landed, the samples up to this depth; elsewhere +inf takes the
  // background samples (nothing else landed there).
  float* limit = any_background + width;
  for (size_t x = 0; x < width; ++x) limit[x] = front[x] * (1.0f + tolerance);
  const RowSums sums{front, limit, rgbw_sum, depth_sum};
  for (const WarpBuffer& buffer : buffers) {
    AddSamples(buffer.Depths() + row, buffer.ColorWeights() + 4 * row, width, sums);
  }
  float* rgb_out = out->color.Pixels().data() + 3 * row;
  float* depth_out = out->depth.Values().data() + row;
  SampleKind* kind_out = out->kind.data() + row;
  // Every pixel: where something landed the weighted means, elsewhere 0 and kNone. Weights
  // are positive and finite (clamped by the warp); guarded anyway so a degenerate sample can
  // never write NaN.
  for (size_t x = 0; x < width; ++x) {
    const F4 sum = Load4(rgbw_sum + 4 * x);
    const float weight = sum[3];
    const bool surface = front[x] != WarpBuffer::kBackground;
    if ((!surface && any_background[x] == 0.0f) || !(weight > 0) || !(weight <= kFloatMax)) {
      for (size_t k = 0; k < 3; ++k) rgb_out[3 * x + k] = 0.0f;
      depth_out[x] = 0.0f;
      kind_out[x] = SampleKind::kNone;
      continue;
    }
    const float inv = 1.0f / weight;
    for (size_t k = 0; k < 3; ++k) rgb_out[3 * x + k] = sum[k] * inv;
    depth_out[x] = surface ? depth_sum[x] * inv : 0.0f;
    kind_out[x] = surface ? SampleKind::kSurface : SampleKind::kBackground;
  }
}

}  // namespace

void BlendOptions::Check() const {
  RequireOption(depth_tolerance > 0 && depth_tolerance < 1, "BlendOptions.depth_tolerance", depth_tolerance,
                "(0, 1)");
  RequireOption(min_support >= 1 && min_support <= 16, "BlendOptions.min_support", min_support, "[1, 16]");
}

void Blend(std::span<const WarpBuffer> buffers, const BlendOptions& options, BlendResult* out) {
  options.Check();
  if (buffers.empty()) throw InternalError("Blend: no warped sources");
  const int width = buffers.front().Width(), height = buffers.front().Height();
  for (const WarpBuffer& buffer : buffers) {
    if (buffer.Width() != width || buffer.Height() != height) {
      throw InternalError("Blend: warp buffers of different sizes " +
                          std::to_string(width) + "x" + std::to_string(height) +
                          " and " + std::to_string(buffer.Width()) + "x" +
                          std::to_string(buffer.Height()));
    }
  }
  // BlendRow writes every pixel: a frame loop's result of the same size is reused as it is,
  // without clearing ~5 MB first at 640x480.
  if (out->color.Width() != width || out->color.Height() != height || out->color.Channels() != 3) {
    out->color.Reset(width, height, 3);
  }
  if (out->depth.Width() != width || out->depth.Height() != height) out->depth.Reset(width, height);
  out->kind.resize(static_cast<size_t>(width) * static_cast<size_t>(height));
  const float tolerance = static_cast<float>(options.depth_tolerance);
  const int min_support = options.min_support;
  tbb::parallel_for(tbb::blocked_range<int>(0, height, 8), [&](const tbb::blocked_range<int>& rows) {
    std::vector<float> scratch;
    for (int y = rows.begin(); y < rows.end(); ++y) {
      BlendRow(buffers, y, tolerance, min_support, &scratch, out);
    }
  });
}

}  // namespace parallax
