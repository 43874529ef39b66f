#pragma once
// Reads what parallax needs from a COLMAP database (SQLite): which id COLMAP gave each image
// (a model that must match the database (point_triangulator) takes its ids from here), and how
// each matched pair was verified (to say why mapping could not start); numbers its images by
// name, and writes matches and gathers verified pairs for parallax's matching.
#include <array>
#include <cstdint>
#include <filesystem>
#include <map>
#include <string>
#include <vector>

namespace parallax {

struct DatabaseImage {
  uint32_t image_id = 0;
  uint32_t camera_id = 0;
};

// Numbers the images numbered above `after` as after + 1, after + 2, ... in name order, their
// keypoints and descriptors with them, in one transaction. COLMAP's multi-threaded feature
// extractor numbers images in the order they finish, and the numbers steer the order of
// matching and the mapper's choices between equals: numbered by name, the same photos give the
// same database on every run. For images without matches yet (just extracted); throws
// BadInputError naming the file if they have some or it cannot be written.
void NumberImagesByName(const std::filesystem::path& database, uint32_t after = 0);

// Image name -> ids. Throws BadInputError naming the file if it cannot be read.
std::map<std::string, DatabaseImage> ReadDatabaseImages(const std::filesystem::path& database);

// COLMAP's TwoViewGeometry::ConfigurationType: which model explained a pair's matches best.
enum class PairGeometry {
  kUndefined = 0, kDegenerate = 1, kCalibrated = 2, kUncalibrated = 3, kPlanar = 4,
  kPanoramic = 5, kPlanarOrPanoramic = 6, kWatermark = 7, kMultiple = 8,
};

// A pair of photos that passed geometric verification, as the matcher stored it.
struct VerifiedPair {
  std::string first;
  std::string second;
  int inliers = 0;
  PairGeometry geometry = PairGeometry::kUndefined;
};

// The number of feature descriptors stored for all images together. Throws BadInputError
// naming the file if it cannot be read.
int64_t CountDescriptors(const std::filesystem::path& database);

// Each image's number of features (keypoints), by name. Throws BadInputError naming the file if
// it cannot be read.
std::map<std::string, int> ReadFeatureCounts(const std::filesystem::path& database);

// Every verified pair, in the database's order. Throws BadInputError naming the file if it
// cannot be read.
std::vector<VerifiedPair> ReadVerifiedPairs(const std::filesystem::path& database);

// One image's SIFT descriptors: `rows` rows of 128 bytes, row-major.
struct DatabaseDescriptors {
  uint32_t image_id = 0;
  int rows = 0;
  std::vector<uint8_t> data;
};

// Every image's descriptors, by image id. Throws BadInputError naming the file if it cannot be
// read or a descriptor is not 128 bytes.
std::vector<DatabaseDescriptors> ReadDescriptors(const std::filesystem::path& database);

// The feature matches of one pair of images, before any verification: (feature of the first,
// feature of the second).
struct RawMatches {
  uint32_t first_image_id = 0;
  uint32_t second_image_id = 0;
  std::vector<std::array<uint32_t, 2>> matches;
};

// Every pair's matches before verification, as colmap's matchers stored them (first image id
// below the second). Throws BadInputError naming the file if it cannot be read.
std::vector<RawMatches> ReadRawMatches(const std::filesystem::path& database);

// Stores `pairs` in the database's matches table, replacing what it held for them, in one
// transaction: colmap's matchers then verify these pairs without matching them again. Throws
// BadInputError naming the file if it cannot be written.
void WriteRawMatches(const std::filesystem::path& database, const std::vector<RawMatches>& pairs);

// Marks every pair of images of `database` except `pairs` (image ids) as matched and verified
// with nothing, where it is not yet, in one transaction: colmap's matchers then pass them by and
// handle `pairs` only. Throws BadInputError naming the file if it cannot be written.
void MarkOtherPairsVerified(const std::filesystem::path& database,
                            const std::vector<std::array<uint32_t, 2>>& pairs);

// Copies into `database` the two-view geometries of `pairs` (image ids) that `part` holds (a copy
// of `database` in which they were verified), in one transaction. Throws BadInputError naming
// the file that cannot be read or written.
void GatherVerifiedPairs(const std::filesystem::path& database, const std::filesystem::path& part,
                         const std::vector<std::array<uint32_t, 2>>& pairs);

}  // namespace parallax
