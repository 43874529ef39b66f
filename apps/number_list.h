#pragma once
// Comma-separated numbers on the command line ("--intrinsics 500,500,320,240").
#include <sstream>
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

}  // namespace parallax
