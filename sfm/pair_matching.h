#pragma once
// Pairs of a colmap database's photos matched by sfm/feature_matching.h, on all cores, and stored
// for colmap to verify.
#include <array>
#include <cstddef>
#include <cstdint>
#include <filesystem>
#include <functional>
#include <vector>

namespace parallax {

// Matches each of `pairs` (image ids of `database`) by MatchSiftFeatures, the pairs on all cores,
// 16 at a time (`done(n)` told from the calling thread after each 16), and stores the matches
// in the database's matches table (WriteRawMatches). Throws BadInputError naming the database if
// it cannot be read or written.
void MatchAndStorePairs(const std::filesystem::path& database, const std::vector<std::array<uint32_t, 2>>& pairs,
                        const std::function<void(size_t done)>& done = {});

}  // namespace parallax
