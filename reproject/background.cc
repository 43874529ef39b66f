#include "reproject/background.h"

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <string>

#include "core/error.h"

namespace parallax {
namespace {

// Absolute allowance of the color test, for dark pixels (linear light).
constexpr float kDarkNoise = 0.002f;

bool SimilarColor(const float* a, const float* b, float max_step) {
  for (int c = 0; c < 3; ++c) {
    if (!(std::abs(a[c] - b[c]) <= max_step * std::max(a[c], b[c]) + kDarkNoise)) return false;
  }
  return true;
}

// Two depth values of one surface: the larger within max_step of the smaller, relatively.
bool SameSurface(float a, float b, float max_step) {
  return std::max(a, b) <= std::min(a, b) * (1 + max_step);
}

}  // namespace

std::vector<uint8_t> MarkBackground(const DepthMap& depth, const Image& color, float max_step) {
  std::vector<uint8_t> background;
  std::vector<size_t> stack;
  MarkBackground(depth, color, max_step, &background, &stack);
  return background;
}

void MarkBackground(const DepthMap& depth, const Image& color, float max_step,
                    std::vector<uint8_t>* background_out, std::vector<size_t>* stack_out) {
  const int width = depth.Width();
  const int height = depth.Height();
  if (color.Width() != width || color.Height() != height || color.Channels() != 3) {
    throw InternalError("MarkBackground: color " + std::to_string(color.Width()) + "x" +
                        std::to_string(color.Height()) + "x" +
                        std::to_string(color.Channels()) + " does not match depth " +
                        std::to_string(width) + "x" + std::to_string(height) + "x3");
  }
  const size_t count = static_cast<size_t>(width) * static_cast<size_t>(height);
  const float* rgb = color.Pixels().data();
  // A pixel next to one with depth lies on a silhouette, where the photo mixes the sky with
  // the surface: it passes. Elsewhere, every neighbour must be of similar color.
  const auto smooth = [&](int x, int y) {
    if (max_step >= 1) return true;
    const int xs[4] = {x - 1, x + 1, x, x};
    const int ys[4] = {y, y, y - 1, y + 1};
    for (int k = 0; k < 4; ++k) {
      if (xs[k] >= 0 && ys[k] >= 0 && xs[k] < width && ys[k] < height && depth.At(xs[k], ys[k]) != 0) {
        return true;
      }
    }
    const float* p = rgb + 3 * (static_cast<size_t>(y) * static_cast<size_t>(width) + static_cast<size_t>(x));
    for (int k = 0; k < 4; ++k) {
      if (xs[k] < 0 || ys[k] < 0 || xs[k] >= width || ys[k] >= height) continue;
      const float* q = rgb + 3 * (static_cast<size_t>(ys[k]) * static_cast<size_t>(width) + static_cast<size_t>(xs[k]));
      if (!SimilarColor(p, q, max_step)) return false;
    }
    return true;
  };
  std::vector<uint8_t>& background = *background_out;
  background.assign(count, 0);
  // Flood fill from the border; the stack holds each pixel at most once (marked on push), so
  // one allocation of the image size bounds it.
  std::vector<size_t>& stack = *stack_out;
  stack.clear();
  stack.reserve(count);
  const auto push = [&](int x, int y) {
    const size_t i = static_cast<size_t>(y) * static_cast<size_t>(width) + static_cast<size_t>(x);
    if (background[i] == 0 && depth.At(x, y) == 0 && smooth(x, y)) {
      background[i] = 1;
      stack.push_back(i);
    }
  };
  // From the top row and the upper half of the sides: the sky is above the scene, and smooth
  // ground without depth reaching the bottom or the lower sides (a lawn, a square) is not
  // at infinity.
  for (int x = 0; x < width; ++x) push(x, 0);
  for (int y = 0; y < height / 2; ++y) {
    push(0, y);
    push(width - 1, y);
  }
  while (!stack.empty()) {
    const size_t i = stack.back();
    stack.pop_back();
    const int x = static_cast<int>(i % static_cast<size_t>(width));
    const int y = static_cast<int>(i / static_cast<size_t>(width));
    if (x > 0) push(x - 1, y);
    if (x + 1 < width) push(x + 1, y);
    if (y > 0) push(x, y - 1);
    if (y + 1 < height) push(x, y + 1);
  }
}

int RemoveDepthSpeckles(DepthMap* depth, int max_pixels, float max_step) {
  if (!(max_step > 0)) {
    throw InternalError("RemoveDepthSpeckles: max_step " + std::to_string(max_step) +
                        ": expected > 0");
  }
  const int width = depth->Width(), height = depth->Height();
  float* values = depth->Values().data();
  const size_t count = static_cast<size_t>(width) * static_cast<size_t>(height);
  std::vector<uint8_t> visited(count, 0);
  std::vector<size_t> patch;  // The current patch, also the stack of its flood fill.
  int cleared = 0;
  for (size_t seed = 0; seed < count; ++seed) {
    if (visited[seed] != 0 || values[seed] == 0) continue;
    patch.assign(1, seed);
    visited[seed] = 1;
    for (size_t next = 0; next < patch.size(); ++next) {
      const size_t i = patch[next];
      const int x = static_cast<int>(i % static_cast<size_t>(width));
      const int y = static_cast<int>(i / static_cast<size_t>(width));
      const auto visit = [&](size_t j) {
        if (visited[j] != 0 || values[j] == 0 || !SameSurface(values[i], values[j], max_step)) return;
        visited[j] = 1;
        patch.push_back(j);
      };
      if (x > 0) visit(i - 1);
      if (x + 1 < width) visit(i + 1);
      if (y > 0) visit(i - static_cast<size_t>(width));
      if (y + 1 < height) visit(i + static_cast<size_t>(width));
    }
    if (patch.size() > static_cast<size_t>(std::max(max_pixels, 0))) continue;
    for (size_t i : patch) values[i] = 0;
    cleared += static_cast<int>(patch.size());
  }
  return cleared;
}

int ErodeDepthEdges(DepthMap* depth, float max_step, int pixels) {
  if (!(max_step > 0) || pixels < 0) {
    throw InternalError("ErodeDepthEdges: max_step " + std::to_string(max_step) +
                        ", pixels " + std::to_string(pixels) + ": expected > 0 and >= 0");
  }
  const int width = depth->Width(), height = depth->Height();
  std::vector<float>& values = depth->Values();
  const size_t count = values.size();
  const auto index = [&](int x, int y) {
    return static_cast<size_t>(y) * static_cast<size_t>(width) + static_cast<size_t>(x);
  };
  // Ring by ring: first the near-side edge pixels, then their neighbours on the same surface.
  std::vector<size_t> ring, next;
  std::vector<uint8_t> cleared(count, 0);
  for (int y = 0; y < height; ++y) {
    for (int x = 0; x < width; ++x) {
      const float d = values[index(x, y)];
      if (d == 0) continue;
      const auto farther = [&](int nx, int ny) {
        if (nx < 0 || ny < 0 || nx >= width || ny >= height) return false;
        const float n = values[index(nx, ny)];
        return n != 0 && n > d * (1 + max_step);
      };
      if (farther(x - 1, y) || farther(x + 1, y) || farther(x, y - 1) || farther(x, y + 1)) {
        ring.push_back(index(x, y));
        cleared[index(x, y)] = 1;
      }
    }
  }
  int total = 0;
  for (int step = 0; step < pixels && !ring.empty(); ++step) {
    next.clear();
    for (size_t i : ring) {
      const int x = static_cast<int>(i % static_cast<size_t>(width));
      const int y = static_cast<int>(i / static_cast<size_t>(width));
      const auto spread = [&](int nx, int ny) {
        if (nx < 0 || ny < 0 || nx >= width || ny >= height) return;
        const size_t j = index(nx, ny);
        if (cleared[j] != 0 || values[j] == 0 || !SameSurface(values[i], values[j], max_step)) return;
        cleared[j] = 1;
        next.push_back(j);
      };
      if (step + 1 < pixels) {
        spread(x - 1, y);
        spread(x + 1, y);
        spread(x, y - 1);
        spread(x, y + 1);
      }
    }
    for (size_t i : ring) values[i] = 0;
    total += static_cast<int>(ring.size());
    ring.swap(next);
  }
  return total;
}

}  // namespace parallax
