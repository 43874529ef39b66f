#pragma once
#include <chrono>
#include <cstdio>
#include <string>

#include "core/progress.h"

namespace parallax {

// Renders progress on one stderr line: stage, n/total, elapsed and a rough ETA.
class TerminalProgress final : public Progress {
 public:
  explicit TerminalProgress(std::FILE* stream = stderr) : stream_(stream) {}
  ~TerminalProgress() override;
  void Update(std::string_view stage, int64_t done, int64_t total) override;

 private:
  std::FILE* stream_;
  std::string stage_;
  std::chrono::steady_clock::time_point stage_start_;
  bool line_open_ = false;
};

}  // namespace parallax
