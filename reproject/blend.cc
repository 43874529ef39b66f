#include "reproject/blend.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <string>

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

namespace parallax {
namespace {

// One row of the blend, buffer after buffer (each buffer's row is read as a stream).
// `scratch` is resized to 8 floats per pixel of the row.
void BlendRow(const std::vector<WarpBuffer>& buffers, int y, float tolerance, int min_support,
              std::vector<float>* scratch, BlendResult* out) {
  const size_t width = static_cast<size_t>(out->color.Width());
  const size_t row = static_cast<size_t>(y) * width;
  scratch->resize(8 * width);
  float* front = scratch->data();             // Front-most surface depth; +inf: none.
  float* rgb_sum = front + width;             // Interleaved.
  float* depth_sum = rgb_sum + 3 * width;
  float* weight = depth_sum + width;
  float* any_background = weight + width;     // 1 where a background sample landed.
  std::fill(front, front + width, WarpBuffer::kBackground);
  std::fill(rgb_sum, any_background + width, 0.0f);
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
  for (const WarpBuffer& buffer : buffers) {
    const float* depth = buffer.Depths() + row;
    for (size_t x = 0; x < width; ++x) {
      const float d = depth[x];
      if (!(d > 0 && d <= limit[x])) continue;
      const bool surface = front[x] != WarpBuffer::kBackground;
      const float w = buffer.Weight(row + x);
      const float* color = buffer.Color(row + x);
      for (int k = 0; k < 3; ++k) rgb_sum[3 * x + static_cast<size_t>(k)] += w * color[k];
      if (surface) depth_sum[x] += w * d;
      weight[x] += w;
    }
  }
  float* rgb_out = out->color.Pixels().data() + 3 * row;
  float* depth_out = out->depth.Values().data() + row;
  SampleKind* kind_out = out->kind.data() + row;
  for (size_t x = 0; x < width; ++x) {
    const bool surface = front[x] != WarpBuffer::kBackground;
    // Weights are positive and finite (angles >= 0, epsilon > 0); guard anyway so a
    // degenerate sample can never write NaN.
    if ((!surface && any_background[x] == 0.0f) || !(weight[x] > 0) || !std::isfinite(weight[x])) {
      continue;
    }
    const float inv = 1.0f / weight[x];
    for (int k = 0; k < 3; ++k) rgb_out[3 * x + static_cast<size_t>(k)] = rgb_sum[3 * x + static_cast<size_t>(k)] * inv;
    depth_out[x] = surface ? depth_sum[x] * inv : 0.0f;
    kind_out[x] = surface ? SampleKind::kSurface : SampleKind::kBackground;
  }
}

}  // namespace

void BlendOptions::Check() const {
  if (!(depth_tolerance > 0 && depth_tolerance < 1)) {
    throw std::invalid_argument("BlendOptions.depth_tolerance = " +
                                std::to_string(depth_tolerance) + ": expected (0, 1)");
  }
  if (min_support < 1 || min_support > 16) {
    throw std::invalid_argument("BlendOptions.min_support = " + std::to_string(min_support) +
                                ": expected [1, 16]");
  }
}

void Blend(const std::vector<WarpBuffer>& buffers, const BlendOptions& options, BlendResult* out) {
  options.Check();
  if (buffers.empty()) throw std::invalid_argument("Blend: no warped sources");
  const int width = buffers.front().Width(), height = buffers.front().Height();
  for (const WarpBuffer& buffer : buffers) {
    if (buffer.Width() != width || buffer.Height() != height) {
      throw std::invalid_argument("Blend: warp buffers of different sizes " +
                                  std::to_string(width) + "x" + std::to_string(height) +
                                  " and " + std::to_string(buffer.Width()) + "x" +
                                  std::to_string(buffer.Height()));
    }
  }
  out->color.Reset(width, height, 3);
  out->depth.Reset(width, height);
  out->kind.assign(static_cast<size_t>(width) * static_cast<size_t>(height), SampleKind::kNone);
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
