#pragma once
// Which stages of a workspace are complete, and for which inputs: each stage records the key
// (a hash of its inputs and options) it last completed with, in <ws>/stages.json. A stage
// whose key is unchanged and whose outputs exist is skipped; an interrupted stage never
// recorded its key, so it runs again.
#include <filesystem>
#include <map>
#include <optional>
#include <string>

namespace parallax {

class StageCache {
 public:
  // Loads `file` if it exists; an unreadable or damaged file counts as "nothing done", and
  // Damage() says so.
  explicit StageCache(std::filesystem::path file);

  // What was wrong with the file and what that costs ("... every stage runs again"); empty
  // when it was whole or absent.
  const std::string& Damage() const { return damage_; }

  bool IsDone(const std::string& stage, const std::string& key) const;
  // The key `stage` last completed with, if any.
  std::optional<std::string> KeyOf(const std::string& stage) const;
  // Records the stage as complete and writes the file atomically.
  void MarkDone(const std::string& stage, const std::string& key);

 private:
  std::filesystem::path file_;
  std::map<std::string, std::string> keys_;
  std::string damage_;
};

}  // namespace parallax
