#pragma once
// Numbers on the command line: comma-separated lists ("--intrinsics 500,500,320,240") and
// image sizes ("--size 1280x720").
#include <cstdio>
#include <sstream>
#include <utility>
#include <stdexcept>
#include <string>
#include <vector>

namespace parallax {

// Throws std::invalid_argument (a usage error) naming `option` and the item that is not a
// number.
inline std::vector<double> ParseNumberList(const std::string& text, const std::string& option) {
  std::vector<double> values;
  std::stringstream stream(text);
  for (std::string item; std::getline(stream, item, ',');) {
    try {
      size_t used = 0;
      values.push_back(std::stod(item, &used));
      if (used != item.size()) throw std::invalid_argument(item);
    } catch (const std::exception&) {
      throw std::invalid_argument(option + " '" + text + "': '" + item + "' is not a number");
    }
  }
  return values;
}

// Exactly `count` numbers; throws std::invalid_argument otherwise.
inline std::vector<double> ParseNumbers(const std::string& text, size_t count, const std::string& option) {
  std::vector<double> values = ParseNumberList(text, option);
  if (values.size() != count) {
    throw std::invalid_argument(option + " " + text + ": expected " + std::to_string(count) +
                                " comma-separated numbers");
  }
  return values;
}

// WxH with 16..16384 pixels a side; throws std::invalid_argument otherwise.
inline std::pair<int, int> ParseSize(const std::string& text) {
  int width = 0, height = 0;
  char x = 0, extra = 0;
  if (std::sscanf(text.c_str(), "%d%c%d%c", &width, &x, &height, &extra) != 3 || x != 'x' || width < 16 ||
      height < 16 || width > 16384 || height > 16384) {
    throw std::invalid_argument("--size " + text + ": expected WxH with 16..16384 pixels per side, e.g. 1280x720");
  }
  return {width, height};
}

}  // namespace parallax
