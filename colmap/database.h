#pragma once
// Reads what parallax needs from a COLMAP database (SQLite): which id COLMAP gave each image.
// COLMAP's multi-threaded feature extractor assigns ids in the order images finish, not in
// name order, so a model that must match the database (point_triangulator) takes its ids
// from here.
#include <cstdint>
#include <filesystem>
#include <map>
#include <string>

namespace parallax {

struct DatabaseImage {
  uint32_t image_id = 0;
  uint32_t camera_id = 0;
};

// Image name -> ids. Throws BadInputError naming the file if it cannot be read.
std::map<std::string, DatabaseImage> ReadDatabaseImages(const std::filesystem::path& database);

}  // namespace parallax
