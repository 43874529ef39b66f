#include "apps/terminal_progress.h"

#include <unistd.h>

namespace parallax {

TerminalProgress::TerminalProgress(std::FILE* stream)
    : stream_(stream), interactive_(::isatty(::fileno(stream)) != 0) {}

TerminalProgress::~TerminalProgress() { CloseLine(); }

void TerminalProgress::CloseLine() {
  if (line_open_) std::fputc('\n', stream_);
  line_open_ = false;
}

void TerminalProgress::Update(std::string_view stage, int64_t done, int64_t total) {
  const auto now = std::chrono::steady_clock::now();
  if (stage != stage_) {
    CloseLine();
    stage_reported_ = false;
    stage_ = stage;
    stage_start_ = now;
  }
  const double elapsed = std::chrono::duration<double>(now - stage_start_).count();
  if (!interactive_) {
    // A log file gets one line per finished stage, not a line redrawn in place.
    if (done == total && !stage_reported_) {
      std::fprintf(stream_, "%-12s %lld/%lld  %6.1f s\n", stage_.c_str(),
                   static_cast<long long>(done), static_cast<long long>(total), elapsed);
      stage_reported_ = true;
    }
    return;
  }
  std::fprintf(stream_, "\r%-12s %lld/%lld  %6.1f s", stage_.c_str(),
               static_cast<long long>(done), static_cast<long long>(total), elapsed);
  if (done > 0 && done < total) {
    std::fprintf(stream_, "  eta %5.1f s", elapsed / static_cast<double>(done) *
                                               static_cast<double>(total - done));
  } else {
    std::fputs("            ", stream_);
  }
  std::fflush(stream_);
  line_open_ = true;
}

void TerminalProgress::Warn(std::string_view message) {
  CloseLine();
  std::fprintf(stream_, "WARNING: %.*s\n", static_cast<int>(message.size()), message.data());
  std::fflush(stream_);
}

}  // namespace parallax
