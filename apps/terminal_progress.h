#pragma once
#include <chrono>
#include <cstdio>
#include <string>

#include "core/progress.h"

namespace parallax {

// Renders progress on one stderr line: stage, n/total, elapsed and a rough ETA.
class TerminalProgress final : public Progress {
 public:
  // Redraws one line in place on a terminal; prints a line per finished stage otherwise.
  explicit TerminalProgress(std::FILE* stream = stderr);
  ~TerminalProgress() override;
  void Update(std::string_view stage, int64_t done, int64_t total) override;
  // "WARNING: message" on a line of its own.
  void Warn(std::string_view message) override;

 private:
  // Ends a redrawn line with its newline, if one is open.
  void CloseLine();

  std::FILE* stream_;
  std::string stage_;
  std::chrono::steady_clock::time_point stage_start_;
  bool interactive_;
  bool line_open_ = false;       // A redrawn line awaits its newline.
  bool stage_reported_ = false;  // Non-interactive: the stage's final line is printed.
};

}  // namespace parallax
