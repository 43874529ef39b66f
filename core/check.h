#pragma once
// The one way an Options::Check() refuses a value: UsageError (options come from the command
// line) naming the field, its value and what was expected, e.g.
// "ForwardWarpOptions.max_slant_deg = 95: expected (0, 90)".
#include <string_view>

namespace parallax {

// Throws UsageError unless `ok`.
void RequireOption(bool ok, std::string_view field, double value, std::string_view expected);

}  // namespace parallax
