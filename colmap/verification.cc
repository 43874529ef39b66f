#include "colmap/verification.h"

#include <algorithm>
#include <exception>
#include <fstream>
#include <memory>
#include <thread>

#include "colmap/database.h"
#include "core/error.h"
#include "core/interrupt.h"

namespace parallax {
namespace fs = std::filesystem;
namespace {

// One part's copy of the database, and the files SQLite keeps beside it: removed when the part
// is gathered, failed or interrupted (core/interrupt.h).
class PartDatabase {
 public:
  explicit PartDatabase(fs::path path)
      : path_(std::move(path)), files_{Suffixed(""), Suffixed("-wal"), Suffixed("-shm"), Suffixed("-journal")},
        temporaries_{TemporaryOutput(files_[0]), TemporaryOutput(files_[1]), TemporaryOutput(files_[2]),
                     TemporaryOutput(files_[3])} {}
  ~PartDatabase() {
    std::error_code ignored;
    for (const fs::path& file : files_) fs::remove(file, ignored);
  }
  PartDatabase(const PartDatabase&) = delete;
  PartDatabase& operator=(const PartDatabase&) = delete;

  const fs::path& Path() const { return path_; }

 private:
  fs::path Suffixed(const char* suffix) const { return path_.string() + suffix; }

  fs::path path_;
  std::array<fs::path, 4> files_;
  std::array<TemporaryOutput, 4> temporaries_;
};

// Appends the file `part` to `log` and removes it.
void AppendLog(const fs::path& log, const fs::path& part) {
  {
    std::ifstream in(part, std::ios::binary);
    std::ofstream out(log, std::ios::binary | std::ios::app);
    out << in.rdbuf();
  }
  std::error_code ignored;
  fs::remove(part, ignored);
}

}  // namespace

void VerifyMatches(const Colmap& colmap, const fs::path& database,
                   const std::vector<std::array<uint32_t, 2>>& pairs, int parts,
                   const std::vector<std::string>& options, const fs::path& log,
                   std::string_view stage, Progress& progress) {
  if (pairs.empty()) return;
  const size_t count = std::min(static_cast<size_t>(std::max(parts, 1)), pairs.size());
  std::vector<std::vector<std::array<uint32_t, 2>>> part_pairs(count);
  for (size_t i = 0; i < pairs.size(); ++i) part_pairs[i % count].push_back(pairs[i]);

  std::vector<std::unique_ptr<PartDatabase>> copies;
  std::vector<fs::path> logs;
  for (size_t k = 0; k < count; ++k) {
    const std::string suffix = ".part" + std::to_string(k + 1);
    copies.push_back(std::make_unique<PartDatabase>(database.string() + suffix));
    logs.push_back(log.string() + suffix);
    fs::copy_file(database, copies[k]->Path(), fs::copy_options::overwrite_existing);
    // colmap's exhaustive matcher verifies what has matches and no geometry: this part's pairs.
    MarkOtherPairsVerified(copies[k]->Path(), part_pairs[k]);
  }

  std::vector<std::exception_ptr> failures(count);
  std::vector<std::thread> threads;
  for (size_t k = 0; k < count; ++k) {
    threads.emplace_back([&, k] {
      try {
        std::vector<std::string> arguments = {"--database_path", copies[k]->Path().string(),
                                              "--SiftMatching.num_threads", "1"};
        arguments.insert(arguments.end(), options.begin(), options.end());
        SilentProgress silent;  // The calling thread reports progress, a part at a time.
        colmap.Run("exhaustive_matcher", arguments, logs[k], stage, 0, silent);
      } catch (...) {
        failures[k] = std::current_exception();
      }
    });
  }
  progress.Update(stage, 0, static_cast<int64_t>(count));
  for (size_t k = 0; k < count; ++k) {
    threads[k].join();
    progress.Update(stage, static_cast<int64_t>(k + 1), static_cast<int64_t>(count));
  }
  for (const std::exception_ptr& failure : failures) {
    if (failure) std::rethrow_exception(failure);
  }
  for (size_t k = 0; k < count; ++k) {
    AppendLog(log, logs[k]);
    GatherVerifiedPairs(database, copies[k]->Path(), part_pairs[k]);
  }
}

}  // namespace parallax
