#include "core/color_gains.h"

#include <algorithm>
#include <cmath>

#include <nlohmann/json.hpp>

#include "core/atomic_file.h"
#include "core/error.h"
#include "core/workspace.h"

namespace parallax {
namespace {

bool ValidGain(const RgbGain& gain) {
  for (const float channel : gain) {
    if (!(channel > 0) || !std::isfinite(channel)) return false;
  }
  return true;
}

}  // namespace

RgbGain ColorGains::Of(const std::string& photo) const {
  const auto found = by_photo.find(photo);
  return found == by_photo.end() ? RgbGain{1, 1, 1} : found->second;
}

ColorGains ReadColorGains(const std::filesystem::path& path) {
  ColorGains gains;
  try {
    const nlohmann::json json = nlohmann::json::parse(ReadFileBytes(path));
    gains.by_photo = json.at("photos").get<std::map<std::string, RgbGain>>();
  } catch (const nlohmann::json::exception& e) {
    throw BadInputError(path.string() + ": not a color gains file (" + e.what() + ")");
  }
  for (const auto& [photo, gain] : gains.by_photo) {
    if (!ValidGain(gain)) throw BadInputError(path.string() + ": gain of " + photo + " is not a positive number");
  }
  return gains;
}

void WriteColorGains(const std::filesystem::path& path, const ColorGains& gains) {
  for (const auto& [photo, gain] : gains.by_photo) {
    if (!ValidGain(gain)) throw InternalError("WriteColorGains: gain of " + photo + " is not positive");
  }
  WriteFileAtomically(path, nlohmann::json{{"photos", gains.by_photo}}.dump(2) + "\n");
}

void ApplyGain(const RgbGain& gain, Image& linear) {
  if (gain == RgbGain{1, 1, 1}) return;
  const int channels = linear.Channels();
  std::vector<float>& pixels = linear.Pixels();
  for (size_t i = 0; i + static_cast<size_t>(channels) <= pixels.size(); i += static_cast<size_t>(channels)) {
    for (int c = 0; c < std::min(3, channels); ++c) pixels[i + static_cast<size_t>(c)] *= gain[static_cast<size_t>(c)];
  }
}

ColorGains ReadColorGainsIfPresent(const std::filesystem::path& file) {
  return !file.empty() && std::filesystem::exists(file) ? ReadColorGains(file) : ColorGains{};
}

ColorGains ReadWorkspaceColorGains(const std::filesystem::path& workspace) {
  return ReadColorGainsIfPresent(Workspace(workspace).ColorGainsFile());
}

}  // namespace parallax
