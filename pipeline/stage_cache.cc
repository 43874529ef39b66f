#include "pipeline/stage_cache.h"

#include <nlohmann/json.hpp>

#include "core/atomic_file.h"
#include "core/error.h"

namespace parallax {

StageCache::StageCache(std::filesystem::path file) : file_(std::move(file)) {
  if (!std::filesystem::exists(file_)) return;
  try {
    const nlohmann::json json = nlohmann::json::parse(ReadFileBytes(file_));
    keys_ = json.get<std::map<std::string, std::string>>();
  } catch (const std::exception& error) {
    keys_.clear();  // Recomputing everything is always safe.
    damage_ = file_.string() + " is damaged (" + error.what() +
              "): no stage counts as done, every stage runs again";
  }
}

bool StageCache::IsDone(const std::string& stage, const std::string& key) const {
  const auto found = keys_.find(stage);
  return found != keys_.end() && found->second == key;
}

std::optional<std::string> StageCache::KeyOf(const std::string& stage) const {
  const auto found = keys_.find(stage);
  if (found == keys_.end()) return std::nullopt;
  return found->second;
}

void StageCache::MarkDone(const std::string& stage, const std::string& key) {
  keys_[stage] = key;
  WriteFileAtomically(file_, nlohmann::json(keys_).dump(2) + "\n");
}

}  // namespace parallax
