#include "colmap/database.h"

#include <algorithm>
#include <cstring>
#include <functional>
#include <memory>
#include <set>
#include <string>

#include <sqlite3.h>

#include "core/error.h"

namespace parallax {

namespace {

using Connection = std::unique_ptr<sqlite3, decltype(&sqlite3_close)>;
using Statement = std::unique_ptr<sqlite3_stmt, decltype(&sqlite3_finalize)>;

// COLMAP's pair id: image_id1 * 2147483647 + image_id2, with image_id1 < image_id2.
constexpr int64_t kMaxImageId = 2147483647;

// Throws BadInputError naming the database, the action ("read", "write"), the step that failed and
// SQLite's message.
[[noreturn]] void Fail(const std::filesystem::path& database, sqlite3* connection, const char* what,
                       const char* action = "read") {
  throw BadInputError(std::string("cannot ") + action + " the COLMAP database " + database.string() +
                      " (" + what + "): " + (connection ? sqlite3_errmsg(connection) : "out of memory"));
}

Connection Open(const std::filesystem::path& database, int flags, const char* action) {
  sqlite3* raw = nullptr;
  const int opened = sqlite3_open_v2(database.c_str(), &raw, flags, nullptr);
  Connection connection(raw, &sqlite3_close);
  if (opened != SQLITE_OK) Fail(database, raw, "open", action);
  return connection;
}

Statement Prepare(const std::filesystem::path& database, sqlite3* connection, const char* query,
                  const char* action) {
  sqlite3_stmt* raw = nullptr;
  if (sqlite3_prepare_v2(connection, query, -1, &raw, nullptr) != SQLITE_OK) {
    Fail(database, connection, "query", action);
  }
  return Statement(raw, &sqlite3_finalize);
}

// Runs `query` on an open connection, calling `row` for each result row. Throws BadInputError
// naming the file if it cannot be queried or read.
void ForEachRow(const std::filesystem::path& database, sqlite3* connection, const char* query,
                const std::function<void(sqlite3_stmt*)>& row) {
  const Statement statement = Prepare(database, connection, query, "read");
  int step;
  while ((step = sqlite3_step(statement.get())) == SQLITE_ROW) row(statement.get());
  if (step != SQLITE_DONE) Fail(database, connection, "read");
}

// Runs `query` on the database read-only, calling `row` for each result row. Throws
// BadInputError naming the file if it cannot be opened, queried or read.
void ForEachRow(const std::filesystem::path& database, const char* query,
                const std::function<void(sqlite3_stmt*)>& row) {
  const Connection connection = Open(database, SQLITE_OPEN_READONLY, "read");
  ForEachRow(database, connection.get(), query, row);
}

// Runs the statement `sql`, which returns no rows. Throws BadInputError naming the file if it fails.
void Execute(const std::filesystem::path& database, sqlite3* connection, const std::string& sql) {
  if (sqlite3_exec(connection, sql.c_str(), nullptr, nullptr, nullptr) != SQLITE_OK) {
    Fail(database, connection, sql.c_str(), "write");
  }
}

// Steps a prepared statement that returns no rows, then resets it for the next bindings.
void StepOnce(const std::filesystem::path& database, sqlite3* connection, sqlite3_stmt* statement,
              const char* what) {
  if (sqlite3_step(statement) != SQLITE_DONE) Fail(database, connection, what, "write");
  sqlite3_reset(statement);
}

int64_t PairId(uint32_t first, uint32_t second) {
  return int64_t{std::min(first, second)} * kMaxImageId + std::max(first, second);
}

std::string TextColumn(sqlite3_stmt* statement, int column) {
  const auto* text = reinterpret_cast<const char*>(sqlite3_column_text(statement, column));
  return text ? text : "";
}

}  // namespace

void NumberImagesByName(const std::filesystem::path& database, uint32_t after) {
  const Connection connection = Open(database, SQLITE_OPEN_READWRITE, "write");
  const std::string above = std::to_string(after);
  int64_t matched = 0;
  // A pair's second id is its larger.
  const std::string pairs_above = "pair_id % " + std::to_string(kMaxImageId) + " > " + above;
  ForEachRow(database, connection.get(),
             ("SELECT (SELECT COUNT(*) FROM matches WHERE " + pairs_above +
              ") + (SELECT COUNT(*) FROM two_view_geometries WHERE " + pairs_above + ")").c_str(),
             [&](sqlite3_stmt* row) { matched = sqlite3_column_int64(row, 0); });
  if (matched > 0) {
    throw BadInputError("cannot number the images of the COLMAP database " + database.string() +
                        " by name: they have matches already");
  }
  std::vector<int64_t> ids;  // In name order (SQLite compares text bytewise, as std::string does).
  const std::string by_name = "SELECT image_id FROM images WHERE image_id > " + above + " ORDER BY name";
  ForEachRow(database, connection.get(), by_name.c_str(),
             [&](sqlite3_stmt* row) { ids.push_back(sqlite3_column_int64(row, 0)); });
  const auto number = [&](size_t i) { return int64_t{after} + static_cast<int64_t>(i) + 1; };
  bool numbered = true;
  for (size_t i = 0; i < ids.size(); ++i) numbered = numbered && ids[i] == number(i);
  if (numbered) return;
  // Every id is first moved past the largest, so that no new number meets an old one.
  const int64_t offset = *std::max_element(ids.begin(), ids.end());
  Execute(database, connection.get(), "BEGIN");
  for (const char* table : {"images", "keypoints", "descriptors"}) {
    Execute(database, connection.get(), std::string("UPDATE ") + table + " SET image_id = image_id + " +
                                            std::to_string(offset) + " WHERE image_id > " + above);
    const std::string sql = std::string("UPDATE ") + table + " SET image_id = ? WHERE image_id = ?";
    const Statement renumber = Prepare(database, connection.get(), sql.c_str(), "write");
    for (size_t i = 0; i < ids.size(); ++i) {
      sqlite3_bind_int64(renumber.get(), 1, number(i));
      sqlite3_bind_int64(renumber.get(), 2, ids[i] + offset);
      StepOnce(database, connection.get(), renumber.get(), "number the images");
    }
  }
  Execute(database, connection.get(), "COMMIT");
}

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

std::vector<DatabaseDescriptors> ReadDescriptors(const std::filesystem::path& database) {
  std::vector<DatabaseDescriptors> images;
  ForEachRow(database, "SELECT image_id, rows, cols, data FROM descriptors ORDER BY image_id",
             [&](sqlite3_stmt* row) {
               DatabaseDescriptors image;
               image.image_id = static_cast<uint32_t>(sqlite3_column_int64(row, 0));
               image.rows = sqlite3_column_int(row, 1);
               const int columns = sqlite3_column_int(row, 2);
               const auto* bytes = static_cast<const uint8_t*>(sqlite3_column_blob(row, 3));
               const int64_t size = sqlite3_column_bytes(row, 3);
               if (image.rows < 0 || (image.rows > 0 && columns != 128) ||
                   size != int64_t{image.rows} * columns || (size > 0 && !bytes)) {
                 throw BadInputError("the COLMAP database " + database.string() + " holds descriptors of image " +
                                     std::to_string(image.image_id) + " that are not rows of 128 bytes (" +
                                     std::to_string(image.rows) + " x " + std::to_string(columns) + ", " +
                                     std::to_string(size) + " bytes)");
               }
               image.data.assign(bytes, bytes + size);
               images.push_back(std::move(image));
             });
  return images;
}

std::vector<RawMatches> ReadRawMatches(const std::filesystem::path& database) {
  std::vector<RawMatches> pairs;
  ForEachRow(database, "SELECT pair_id, rows, cols, data FROM matches", [&](sqlite3_stmt* row) {
    const int64_t pair_id = sqlite3_column_int64(row, 0);
    const int64_t rows = sqlite3_column_int64(row, 1);
    const void* blob = sqlite3_column_blob(row, 3);
    if ((rows > 0 && sqlite3_column_int(row, 2) != 2) ||
        sqlite3_column_bytes(row, 3) != rows * 2 * static_cast<int64_t>(sizeof(uint32_t))) {
      throw BadInputError("the COLMAP database " + database.string() + " holds matches of pair " +
                          std::to_string(pair_id) + " that are not rows of two indices");
    }
    RawMatches pair{static_cast<uint32_t>(pair_id / kMaxImageId), static_cast<uint32_t>(pair_id % kMaxImageId), {}};
    pair.matches.resize(static_cast<size_t>(rows));
    if (rows > 0) std::memcpy(pair.matches.data(), blob, pair.matches.size() * sizeof(pair.matches[0]));
    pairs.push_back(std::move(pair));
  });
  return pairs;
}

void WriteRawMatches(const std::filesystem::path& database, const std::vector<RawMatches>& pairs) {
  const Connection connection = Open(database, SQLITE_OPEN_READWRITE, "write");
  Execute(database, connection.get(), "BEGIN");
  {
    const Statement insert =
        Prepare(database, connection.get(),
                "INSERT OR REPLACE INTO matches (pair_id, rows, cols, data) VALUES (?, ?, ?, ?)", "write");
    for (const RawMatches& pair : pairs) {
      const bool swap = pair.first_image_id > pair.second_image_id;
      std::vector<uint32_t> columns;  // colmap's layout: rows of (low's feature, high's feature).
      columns.reserve(2 * pair.matches.size());
      for (const auto& match : pair.matches) {
        columns.push_back(match[swap ? 1 : 0]);
        columns.push_back(match[swap ? 0 : 1]);
      }
      sqlite3_stmt* statement = insert.get();
      sqlite3_bind_int64(statement, 1, PairId(pair.first_image_id, pair.second_image_id));
      sqlite3_bind_int64(statement, 2, static_cast<int64_t>(pair.matches.size()));
      sqlite3_bind_int64(statement, 3, 2);
      sqlite3_bind_blob64(statement, 4, columns.data(), columns.size() * sizeof(uint32_t), SQLITE_TRANSIENT);
      StepOnce(database, connection.get(), statement, "insert matches");
    }
  }
  Execute(database, connection.get(), "COMMIT");
}

void MarkOtherPairsVerified(const std::filesystem::path& database,
                            const std::vector<std::array<uint32_t, 2>>& pairs) {
  std::set<int64_t> kept;
  for (const auto& [first, second] : pairs) kept.insert(PairId(first, second));
  const Connection connection = Open(database, SQLITE_OPEN_READWRITE, "write");
  std::vector<uint32_t> ids;
  ForEachRow(database, connection.get(), "SELECT image_id FROM images",
             [&](sqlite3_stmt* row) { ids.push_back(static_cast<uint32_t>(sqlite3_column_int64(row, 0))); });
  Execute(database, connection.get(), "BEGIN");
  {
    // colmap matches again a pair with a geometry and no matches: both are marked.
    const Statement matched =
        Prepare(database, connection.get(),
                "INSERT OR IGNORE INTO matches (pair_id, rows, cols, data) VALUES (?, 0, 2, NULL)", "write");
    const Statement verified = Prepare(database, connection.get(),
                                       "INSERT OR IGNORE INTO two_view_geometries (pair_id, rows, cols, data, config) "
                                       "VALUES (?, 0, 2, NULL, 0)",
                                       "write");
    for (size_t i = 0; i < ids.size(); ++i) {
      for (size_t j = i + 1; j < ids.size(); ++j) {
        const int64_t pair_id = PairId(ids[i], ids[j]);
        if (kept.count(pair_id)) continue;
        for (sqlite3_stmt* mark : {matched.get(), verified.get()}) {
          sqlite3_bind_int64(mark, 1, pair_id);
          StepOnce(database, connection.get(), mark, "mark pairs verified");
        }
      }
    }
  }
  Execute(database, connection.get(), "COMMIT");
}

void GatherVerifiedPairs(const std::filesystem::path& database, const std::filesystem::path& part,
                         const std::vector<std::array<uint32_t, 2>>& pairs) {
  const Connection connection = Open(database, SQLITE_OPEN_READWRITE, "write");
  {
    const Statement attach = Prepare(database, connection.get(), "ATTACH DATABASE ? AS part", "write");
    sqlite3_bind_text(attach.get(), 1, part.c_str(), -1, SQLITE_TRANSIENT);
    StepOnce(part, connection.get(), attach.get(), "attach");
  }
  Execute(database, connection.get(), "BEGIN");
  {
    const Statement copy = Prepare(database, connection.get(),
                                   "INSERT OR REPLACE INTO main.two_view_geometries "
                                   "SELECT * FROM part.two_view_geometries WHERE pair_id = ?",
                                   "write");
    for (const auto& [first, second] : pairs) {
      sqlite3_bind_int64(copy.get(), 1, PairId(first, second));
      StepOnce(database, connection.get(), copy.get(), "gather verified pairs");
    }
  }
  Execute(database, connection.get(), "COMMIT");
}

}  // namespace parallax
