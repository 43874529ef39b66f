#include "colmap/database.h"

#include <functional>
#include <memory>

#include <sqlite3.h>

#include "core/error.h"

namespace parallax {

namespace {

// Runs `query` on the database read-only, calling `row` for each result row. Throws
// BadInputError naming the file if it cannot be opened, queried or read.
void ForEachRow(const std::filesystem::path& database, const char* query,
                const std::function<void(sqlite3_stmt*)>& row) {
  sqlite3* raw = nullptr;
  const int opened = sqlite3_open_v2(database.c_str(), &raw, SQLITE_OPEN_READONLY, nullptr);
  const std::unique_ptr<sqlite3, decltype(&sqlite3_close)> connection(raw, &sqlite3_close);
  auto fail = [&](const char* what) {
    throw BadInputError("cannot read the COLMAP database " + database.string() + " (" + what +
                        "): " + (raw ? sqlite3_errmsg(raw) : "out of memory"));
  };
  if (opened != SQLITE_OK) fail("open");
  sqlite3_stmt* raw_statement = nullptr;
  if (sqlite3_prepare_v2(raw, query, -1, &raw_statement, nullptr) != SQLITE_OK) fail("query");
  const std::unique_ptr<sqlite3_stmt, decltype(&sqlite3_finalize)> statement(raw_statement,
                                                                             &sqlite3_finalize);
  int step;
  while ((step = sqlite3_step(raw_statement)) == SQLITE_ROW) row(raw_statement);
  if (step != SQLITE_DONE) fail("read");
}

std::string TextColumn(sqlite3_stmt* statement, int column) {
  const auto* text = reinterpret_cast<const char*>(sqlite3_column_text(statement, column));
  return text ? text : "";
}

}  // namespace

std::map<std::string, DatabaseImage> ReadDatabaseImages(const std::filesystem::path& database) {
  std::map<std::string, DatabaseImage> images;
  ForEachRow(database, "SELECT image_id, name, camera_id FROM images", [&](sqlite3_stmt* row) {
    images[TextColumn(row, 1)] = {static_cast<uint32_t>(sqlite3_column_int64(row, 0)),
                                  static_cast<uint32_t>(sqlite3_column_int64(row, 2))};
  });
  return images;
}

int64_t CountDescriptors(const std::filesystem::path& database) {
  int64_t count = 0;
  ForEachRow(database, "SELECT SUM(rows) FROM descriptors",
             [&](sqlite3_stmt* row) { count = sqlite3_column_int64(row, 0); });
  return count;
}

std::map<std::string, int> ReadFeatureCounts(const std::filesystem::path& database) {
  std::map<std::string, int> counts;
  ForEachRow(database, "SELECT images.name, keypoints.rows FROM images JOIN keypoints USING (image_id)",
             [&](sqlite3_stmt* row) { counts[TextColumn(row, 0)] = sqlite3_column_int(row, 1); });
  return counts;
}

std::vector<VerifiedPair> ReadVerifiedPairs(const std::filesystem::path& database) {
  std::map<int64_t, std::string> names;
  ForEachRow(database, "SELECT image_id, name FROM images", [&](sqlite3_stmt* row) {
    names[sqlite3_column_int64(row, 0)] = TextColumn(row, 1);
  });
  // COLMAP's pair id: image_id1 * 2147483647 + image_id2, with image_id1 < image_id2.
  constexpr int64_t kMaxImageId = 2147483647;
  std::vector<VerifiedPair> pairs;
  ForEachRow(database, "SELECT pair_id, rows, config FROM two_view_geometries WHERE rows > 0",
             [&](sqlite3_stmt* row) {
               const int64_t pair_id = sqlite3_column_int64(row, 0);
               const int config = sqlite3_column_int(row, 2);
               pairs.push_back({names[pair_id / kMaxImageId], names[pair_id % kMaxImageId],
                                sqlite3_column_int(row, 1),
                                config >= 0 && config <= 8 ? static_cast<PairGeometry>(config)
                                                           : PairGeometry::kUndefined});
             });
  return pairs;
}

}  // namespace parallax
