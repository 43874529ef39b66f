#include "colmap/database.h"

#include <memory>

#include <sqlite3.h>

#include "core/error.h"

namespace parallax {

std::map<std::string, DatabaseImage> ReadDatabaseImages(const std::filesystem::path& database) {
  sqlite3* raw = nullptr;
  const int opened = sqlite3_open_v2(database.c_str(), &raw, SQLITE_OPEN_READONLY, nullptr);
  const std::unique_ptr<sqlite3, decltype(&sqlite3_close)> connection(raw, &sqlite3_close);
  auto fail = [&](const char* what) {
    throw BadInputError("cannot read the COLMAP database " + database.string() + " (" + what +
                        "): " + (raw ? sqlite3_errmsg(raw) : "out of memory"));
  };
  if (opened != SQLITE_OK) fail("open");
  sqlite3_stmt* raw_statement = nullptr;
  if (sqlite3_prepare_v2(raw, "SELECT image_id, name, camera_id FROM images", -1, &raw_statement,
                         nullptr) != SQLITE_OK) {
    fail("query");
  }
  const std::unique_ptr<sqlite3_stmt, decltype(&sqlite3_finalize)> statement(raw_statement,
                                                                             &sqlite3_finalize);
  std::map<std::string, DatabaseImage> images;
  int step;
  while ((step = sqlite3_step(raw_statement)) == SQLITE_ROW) {
    const auto* name = reinterpret_cast<const char*>(sqlite3_column_text(raw_statement, 1));
    images[name ? name : ""] = {static_cast<uint32_t>(sqlite3_column_int64(raw_statement, 0)),
                                static_cast<uint32_t>(sqlite3_column_int64(raw_statement, 2))};
  }
  if (step != SQLITE_DONE) fail("read");
  return images;
}

}  // namespace parallax
