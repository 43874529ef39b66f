#include "reproject/background.h"

#include <cstddef>

namespace parallax {

std::vector<uint8_t> MarkBackground(const DepthMap& depth) {
  std::vector<uint8_t> background;
  std::vector<size_t> stack;
  MarkBackground(depth, &background, &stack);
  return background;
}

void MarkBackground(const DepthMap& depth, std::vector<uint8_t>* background_out,
                    std::vector<size_t>* stack_out) {
  const int width = depth.Width();
  const int height = depth.Height();
  const size_t count = static_cast<size_t>(width) * static_cast<size_t>(height);
  std::vector<uint8_t>& background = *background_out;
  background.assign(count, 0);
  // Flood fill from the border; the stack holds each pixel at most once (marked on push), so
  // one allocation of the image size bounds it.
  std::vector<size_t>& stack = *stack_out;
  stack.clear();
  stack.reserve(count);
  const auto push = [&](int x, int y) {
    const size_t i = static_cast<size_t>(y) * static_cast<size_t>(width) + static_cast<size_t>(x);
    if (background[i] == 0 && depth.At(x, y) == 0) {
      background[i] = 1;
      stack.push_back(i);
    }
  };
  for (int x = 0; x < width; ++x) {
    push(x, 0);
    push(x, height - 1);
  }
  for (int y = 0; y < height; ++y) {
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

}  // namespace parallax
