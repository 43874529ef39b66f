#pragma once
// Numbers on the command line: comma-separated lists ("--intrinsics 500,500,320,240") and
// image sizes ("--size 1280x720").
#include <cstdio>
#include <sstream>
#include <string>
#include <utility>
#include <vector>

#include "core/error.h"

namespace parallax {

// Throws UsageError naming `option` and the item that is not a number.
inline std::vector<double> ParseNumberList(const std::string& text, const std::string& option) {
  std::vector<double> values;
  std::stringstream stream(text);
  for (std::string item; std::getline(stream, item, ',');) {
    size_t used = 0;
    double value = 0;
    try {
      value = std::stod(item, &used);
    } catch (const std::exception&) {  // std::stod's own: not a number, or out of range.
      used = 0;
    }
    if (used == 0 || used != item.size()) {
      throw UsageError(option + " '" + text + "': '" + item + "' is not a number");
    }
    values.push_back(value);
  }
  return values;
}

// Exactly `count` numbers; throws UsageError otherwise.
inline std::vector<double> ParseNumbers(const std::string& text, size_t count, const std::string& option) {
  std::vector<double> values = ParseNumberList(text, option);
  if (values.size() != count) {
    throw UsageError(option + " " + text + ": expected " + std::to_string(count) +
                                " comma-separated numbers");
  }
  return values;
}

// WxH with 16..16384 pixels a side; throws UsageError otherwise.
inline std::pair<int, int> ParseSize(const std::string& text) {
  int width = 0, height = 0;
  char x = 0, extra = 0;
  if (std::sscanf(text.c_str(), "%d%c%d%c", &width, &x, &height, &extra) != 3 || x != 'x' || width < 16 ||
      height < 16 || width > 16384 || height > 16384) {
    throw UsageError("--size " + text + ": expected WxH with 16..16384 pixels per side, e.g. 1280x720");
  }
  return {width, height};
}

}  // namespace parallax
