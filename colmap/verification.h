#pragma once
// colmap's geometric verification of the matches parallax stored, the same on every run.
// colmap's verifier threads each draw their RANSAC samples from a random stream of their own,
// seeded alike, so the pairs a thread happens to take change its results from run to run
// (castle-p19: other inliers on every run, and other cameras after them). Here the pairs are cut
// into fixed parts, each verified by a colmap on one thread in a copy of the database, the parts
// at once, and their geometries are gathered into the database: as fast as colmap's threads,
// and the same parts give the same result.
#include <array>
#include <cstdint>
#include <filesystem>
#include <string>
#include <string_view>
#include <vector>

#include "colmap/runner.h"
#include "core/progress.h"

namespace parallax {

// Verifies the matches `database` holds for `pairs` (image ids) in `parts` parts at once (pair i
// in part i mod `parts`), with colmap's matching `options` beside the database's path. Pairs
// verified already stay as they are. Each of `pairs` must have its matches stored: colmap would
// match the others itself, and its matcher did not repeat itself on one thread (the same
// keypoints gave other matches; its verifier thread seeds rand() while the matcher thread's
// randomised k-d trees may be drawing from it). colmap's output is appended to `log`, progress
// reported under `stage` as the parts finish. Throws ToolError if a colmap fails (its part's log
// kept beside `log`), BadInputError if a database cannot be read or written.
void VerifyMatches(const Colmap& colmap, const std::filesystem::path& database,
                   const std::vector<std::array<uint32_t, 2>>& pairs, int parts,
                   const std::vector<std::string>& options, const std::filesystem::path& log,
                   std::string_view stage, Progress& progress);

}  // namespace parallax
