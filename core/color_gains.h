#pragma once
// Per-photo color correction: the linear-RGB gains that bring each photo of a set to the
// exposure and white balance common to the set, so that photos combined into one picture (a
// novel view's blend, a texture atlas, the viewer's projected photos, fused point colors)
// show no steps between them. Estimated by sfm/color_gains.h into <ws>/color_gains.json.
#include <array>
#include <filesystem>
#include <map>
#include <string>

#include "core/image.h"

namespace parallax {

using RgbGain = std::array<float, 3>;

struct ColorGains {
  std::map<std::string, RgbGain> by_photo;  // Photo name -> gain; absent photos keep 1.

  RgbGain Of(const std::string& photo) const;
};

// The file is {"photos": {"<name>": [r, g, b], ...}}. Reading throws BadInputError naming the
// file for malformed JSON or a gain that is not a positive finite number.
ColorGains ReadColorGains(const std::filesystem::path& path);
// Written atomically; throws InternalError for a gain that is not positive and finite.
void WriteColorGains(const std::filesystem::path& path, const ColorGains& gains);

// Multiplies each pixel's first three channels (linear light) by `gain`.
void ApplyGain(const RgbGain& gain, Image& linear);

// The gains in `file`; none when `file` is empty or names no file (a workspace made before
// gains were estimated, a scene folder).
ColorGains ReadColorGainsIfPresent(const std::filesystem::path& file);

// The gains of a workspace's photos (<ws>/color_gains.json), as ReadColorGainsIfPresent.
ColorGains ReadWorkspaceColorGains(const std::filesystem::path& workspace);

}  // namespace parallax
