#include "sfm/feature_matching.h"

#include <algorithm>
#include <cmath>

#if defined(__AVX2__)
#include <immintrin.h>
#endif

namespace parallax {
namespace {

// The descriptors' bytes are multiplied as 16-bit integers, two dimensions at a time, and summed
// in 32 bits: exact, as a dot product is at most 128 * 255^2 < 2^31.
constexpr int kPairs = kSiftDimensions / 2;
constexpr int kLanes = 8;  // 32-bit lanes of an AVX2 register.
// A tile: 3 x 3 registers of sums, which with 3 of columns and 1 of a row fit the 16 registers
// (4 x 3 spill them to memory).
constexpr int kTileRows = 3;     // Descriptors of the first photo in a tile.
constexpr int kTileVectors = 3;  // Of the second photo, in groups of kLanes.
constexpr int kTileColumns = kTileVectors * kLanes;
// The loops go over bands of the first photo's descriptors (12 KB, within a core's L1 cache)
// against chunks of the second photo's (240 KB, within its L2 cache).
constexpr int kBandRows = 16 * kTileRows;
constexpr int kChunkTiles = 40;

// Two dimensions of a descriptor, 16 bits each, in one word (the first in the low half).
uint32_t DimensionPair(const uint8_t* descriptor, int pair) {
  return descriptor[2 * pair] | uint32_t{descriptor[2 * pair + 1]} << 16;
}

// The first photo's descriptors, a row of kPairs words each, with zero rows after them up to
// `padded_rows` (a zero descriptor matches nothing).
std::vector<uint32_t> PackRows(const SiftDescriptors& descriptors, int padded_rows) {
  std::vector<uint32_t> packed(static_cast<size_t>(padded_rows) * kPairs, 0);
  for (int i = 0; i < descriptors.rows; ++i) {
    const uint8_t* descriptor = descriptors.data + static_cast<size_t>(i) * kSiftDimensions;
    for (int p = 0; p < kPairs; ++p) packed[static_cast<size_t>(i) * kPairs + p] = DimensionPair(descriptor, p);
  }
  return packed;
}

// The second photo's descriptors in groups of kLanes, zero ones after them up to
// `padded_columns`: in group g, pair p holds at lane l the pair of descriptor g * kLanes + l,
// so that one load gives the kernel one pair of dimensions of kLanes descriptors.
std::vector<uint32_t> PackColumns(const SiftDescriptors& descriptors, int padded_columns) {
  std::vector<uint32_t> packed(static_cast<size_t>(padded_columns) * kPairs, 0);
  for (int j = 0; j < descriptors.rows; ++j) {
    const uint8_t* descriptor = descriptors.data + static_cast<size_t>(j) * kSiftDimensions;
    for (int p = 0; p < kPairs; ++p) {
      packed[(static_cast<size_t>(j / kLanes) * kPairs + p) * kLanes + j % kLanes] = DimensionPair(descriptor, p);
    }
  }
  return packed;
}

using Tile = int32_t[kTileRows][kTileColumns];

// The dot products of kTileRows packed rows with kTileVectors packed groups of columns.
void DotTile(const uint32_t* rows, const uint32_t* groups, Tile& tile) {
#if defined(__AVX2__)
  __m256i sums[kTileRows][kTileVectors];
  for (auto& row : sums) {
    for (__m256i& sum : row) sum = _mm256_setzero_si256();
  }
  for (int p = 0; p < kPairs; ++p) {
    __m256i columns[kTileVectors];
    for (int v = 0; v < kTileVectors; ++v) {
      columns[v] = _mm256_loadu_si256(reinterpret_cast<const __m256i*>(groups + (v * kPairs + p) * kLanes));
    }
    for (int r = 0; r < kTileRows; ++r) {
      const __m256i row = _mm256_set1_epi32(static_cast<int32_t>(rows[r * kPairs + p]));
      for (int v = 0; v < kTileVectors; ++v) {
        sums[r][v] = _mm256_add_epi32(sums[r][v], _mm256_madd_epi16(row, columns[v]));
      }
    }
  }
  for (int r = 0; r < kTileRows; ++r) {
    for (int v = 0; v < kTileVectors; ++v) {
      _mm256_storeu_si256(reinterpret_cast<__m256i*>(&tile[r][v * kLanes]), sums[r][v]);
    }
  }
#else
  for (int r = 0; r < kTileRows; ++r) {
    for (int c = 0; c < kTileColumns; ++c) {
      const uint32_t* column = groups + (c / kLanes * kPairs) * kLanes + c % kLanes;
      int32_t sum = 0;
      for (int p = 0; p < kPairs; ++p) {
        const uint32_t a = rows[r * kPairs + p], b = column[p * kLanes];
        sum += static_cast<int32_t>((a & 0xffff) * (b & 0xffff) + (a >> 16) * (b >> 16));
      }
      tile[r][c] = sum;
    }
  }
#endif
}

// A descriptor's nearest and second-nearest descriptor of the other photo, as dot products (the
// largest is the nearest), and the nearest's index; -1 where nothing scored above 0.
struct Nearest {
  int32_t best = 0;
  int32_t second = 0;
  int index = -1;
};

// Nearest descriptors found so far, one per lane: branch-free updates the compiler vectorises.
// Ties at the best need no order: they fail the ratio test.
template <int kCount>
struct NearestLanes {
  NearestLanes() { std::fill(index, index + kCount, -1); }

  // Offers scores[l], descriptor first_index + l * step, to lane l.
  void Offer(const int32_t* scores, int first_index, int step) {
    for (int l = 0; l < kCount; ++l) {
      const int32_t score = scores[l];
      second[l] = std::max(second[l], std::min(best[l], score));
      index[l] = score > best[l] ? first_index + l * step : index[l];
      best[l] = std::max(best[l], score);
    }
  }

  // The nearest over all lanes.
  Nearest Merged() const {
    const int top = static_cast<int>(std::max_element(best, best + kCount) - best);
    Nearest nearest{best[top], 0, index[top]};
    for (int l = 0; l < kCount; ++l) {
      nearest.second = std::max({nearest.second, second[l], l == top ? 0 : best[l]});
    }
    return nearest;
  }

  int32_t best[kCount] = {};
  int32_t second[kCount] = {};
  int index[kCount];
};

// Whether `nearest` is a match by colmap's rules: the angle to the best within `max_angle`, and
// below `max_ratio` times the angle to the second best (equal angles fail).
bool Passes(const Nearest& nearest, const SiftMatchingThresholds& thresholds) {
  if (nearest.index < 0) return false;
  constexpr float kUnit = 1.0f / (512.0f * 512.0f);  // Descriptors have length 512.
  const float best_angle = std::acos(std::min(kUnit * static_cast<float>(nearest.best), 1.0f));
  if (best_angle > thresholds.max_angle) return false;
  const float second_angle = std::acos(std::min(kUnit * static_cast<float>(nearest.second), 1.0f));
  return best_angle < thresholds.max_ratio * second_angle;
}

int RoundUp(int value, int multiple) { return (value + multiple - 1) / multiple * multiple; }

}  // namespace

std::vector<FeatureMatch> MatchSiftFeatures(const SiftDescriptors& first, const SiftDescriptors& second,
                                            const SiftMatchingThresholds& thresholds) {
  if (first.rows == 0 || second.rows == 0) return {};
  const int padded_rows = RoundUp(first.rows, kTileRows);
  const int tiles_across = RoundUp(second.rows, kTileColumns) / kTileColumns;
  const std::vector<uint32_t> rows = PackRows(first, padded_rows);
  const std::vector<uint32_t> columns = PackColumns(second, tiles_across * kTileColumns);

  std::vector<Nearest> row_nearest(static_cast<size_t>(first.rows));
  // Each column's nearest row, its lanes the tiles' columns (kTileColumns apart).
  std::vector<NearestLanes<kTileColumns>> column_nearest(static_cast<size_t>(tiles_across));
  Tile tile;
  for (int band = 0; band < padded_rows; band += kBandRows) {
    const int band_end = std::min(padded_rows, band + kBandRows);
    std::vector<NearestLanes<kLanes>> band_nearest(static_cast<size_t>(band_end - band));
    for (int chunk = 0; chunk < tiles_across; chunk += kChunkTiles) {
      const int chunk_end = std::min(tiles_across, chunk + kChunkTiles);
      for (int i = band; i < band_end; i += kTileRows) {
        for (int t = chunk; t < chunk_end; ++t) {
          DotTile(&rows[static_cast<size_t>(i) * kPairs], &columns[static_cast<size_t>(t) * kTileColumns * kPairs],
                  tile);
          for (int r = 0; r < kTileRows; ++r) {
            for (int v = 0; v < kTileVectors; ++v) {
              band_nearest[static_cast<size_t>(i - band + r)].Offer(&tile[r][v * kLanes],
                                                                     t * kTileColumns + v * kLanes, 1);
            }
            column_nearest[static_cast<size_t>(t)].Offer(tile[r], i + r, 0);
          }
        }
      }
    }
    for (int i = band; i < std::min(band_end, first.rows); ++i) {
      row_nearest[static_cast<size_t>(i)] = band_nearest[static_cast<size_t>(i - band)].Merged();
    }
  }

  std::vector<FeatureMatch> matches;
  for (int i = 0; i < first.rows; ++i) {
    const Nearest& forward = row_nearest[static_cast<size_t>(i)];
    if (!Passes(forward, thresholds)) continue;
    const NearestLanes<kTileColumns>& lanes = column_nearest[static_cast<size_t>(forward.index / kTileColumns)];
    const int lane = forward.index % kTileColumns;
    const Nearest backward{lanes.best[lane], lanes.second[lane], lanes.index[lane]};
    if (backward.index != i || !Passes(backward, thresholds)) continue;
    matches.push_back({static_cast<uint32_t>(i), static_cast<uint32_t>(forward.index)});
  }
  return matches;
}

}  // namespace parallax
