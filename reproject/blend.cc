#include "reproject/blend.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <string>

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

namespace parallax {
namespace {

float SampleWeight(const WarpWeight& weight, float angle_epsilon) {
  return 1.0f / ((weight.ray_angle_rad + angle_epsilon) * std::max(1.0f, weight.stretch));
}

struct Accumulator {
  float rgb[3] = {0, 0, 0};
  float depth = 0;
  float weight = 0;

  void Add(const WarpBuffer& buffer, size_t i, float depth_value, float angle_epsilon) {
    const float w = SampleWeight(buffer.Weight(i), angle_epsilon);
    const float* color = buffer.Color(i);
    for (int k = 0; k < 3; ++k) rgb[k] += w * color[k];
    depth += w * depth_value;
    weight += w;
  }
};

void BlendPixel(const std::vector<WarpBuffer>& buffers, size_t i, float tolerance,
                float angle_epsilon, BlendResult* out) {
  float front = WarpBuffer::kBackground;
  bool any_background = false;
  for (const WarpBuffer& buffer : buffers) {
    const float depth = buffer.Depth(i);
    if (depth == WarpBuffer::kBackground) {
      any_background = true;
    } else if (depth > 0) {
      front = std::min(front, depth);
    }
  }
  const bool surface = front != WarpBuffer::kBackground;
  if (!surface && !any_background) return;
  Accumulator sum;
  const float limit = front * (1.0f + tolerance);
  for (const WarpBuffer& buffer : buffers) {
    const float depth = buffer.Depth(i);
    const bool take = surface ? (depth > 0 && depth <= limit) : depth == WarpBuffer::kBackground;
    if (take) sum.Add(buffer, i, surface ? depth : 0.0f, angle_epsilon);
  }
  // Weights are positive and finite (angles >= 0, epsilon > 0); guard anyway so a degenerate
  // sample can never write NaN.
  if (!(sum.weight > 0) || !std::isfinite(sum.weight)) return;
  float* rgb = out->color.Pixels().data() + 3 * i;
  for (int k = 0; k < 3; ++k) rgb[k] = sum.rgb[k] / sum.weight;
  out->depth.Values()[i] = surface ? sum.depth / sum.weight : 0.0f;
  out->kind[i] = surface ? SampleKind::kSurface : SampleKind::kBackground;
}

}  // namespace

void BlendOptions::Check() const {
  if (!(depth_tolerance > 0 && depth_tolerance < 1)) {
    throw std::invalid_argument("BlendOptions.depth_tolerance = " +
                                std::to_string(depth_tolerance) + ": expected (0, 1)");
  }
  if (!(angle_epsilon_rad > 0 && std::isfinite(angle_epsilon_rad))) {
    throw std::invalid_argument("BlendOptions.angle_epsilon_rad = " +
                                std::to_string(angle_epsilon_rad) + ": expected > 0");
  }
}

BlendResult Blend(const std::vector<WarpBuffer>& buffers, const BlendOptions& options) {
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
  BlendResult out;
  out.color = Image(width, height, 3);
  out.depth = DepthMap(width, height);
  out.kind.assign(static_cast<size_t>(width) * static_cast<size_t>(height), SampleKind::kNone);
  const float tolerance = static_cast<float>(options.depth_tolerance);
  const float angle_epsilon = static_cast<float>(options.angle_epsilon_rad);
  tbb::parallel_for(tbb::blocked_range<int>(0, height, 8), [&](const tbb::blocked_range<int>& rows) {
    for (int y = rows.begin(); y < rows.end(); ++y) {
      const size_t row = static_cast<size_t>(y) * static_cast<size_t>(width);
      for (int x = 0; x < width; ++x) {
        BlendPixel(buffers, row + static_cast<size_t>(x), tolerance, angle_epsilon, &out);
      }
    }
  });
  return out;
}

}  // namespace parallax
