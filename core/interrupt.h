#pragma once
// SIGINT and SIGTERM stop a run promptly and leave the workspace as a SIGKILL would not: a
// thread of its own takes the signal (it is blocked in every other thread), stops the external
// program running (colmap), removes the temporary files being written, says what it did and
// exits with 128 + the signal. Final files are renamed into place whole or not at all, and the
// workspace lock goes with the process, so the next run resumes from the last finished stage.
#include <sys/types.h>

#include <filesystem>

namespace parallax {

// Call first in main, before any other thread starts (threads inherit the blocked signals).
void InstallInterruptHandler();

// An external program for as long as it runs: an interrupted run stops it.
class RunningChild {
 public:
  explicit RunningChild(pid_t pid);
  ~RunningChild();
  RunningChild(const RunningChild&) = delete;
  RunningChild& operator=(const RunningChild&) = delete;

 private:
  pid_t pid_;
};

// A temporary file or folder for as long as it lives: an interrupted run removes it.
class TemporaryOutput {
 public:
  explicit TemporaryOutput(std::filesystem::path path);
  ~TemporaryOutput();
  TemporaryOutput(const TemporaryOutput&) = delete;
  TemporaryOutput& operator=(const TemporaryOutput&) = delete;

 private:
  std::filesystem::path path_;
};

}  // namespace parallax
