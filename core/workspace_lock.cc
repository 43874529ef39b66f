#include "core/workspace_lock.h"

#include <fcntl.h>
#include <sys/file.h>
#include <unistd.h>

#include <cerrno>
#include <cstring>
#include <fstream>

#include "core/error.h"

namespace parallax {
namespace fs = std::filesystem;
namespace {

// What the lock file says about its last holder: "<command> (pid N)", or "another process".
std::string LastHolder(const fs::path& path) {
  std::ifstream file(path);
  std::string command, pid;
  if (file >> command >> pid) return command + " (pid " + pid + ")";
  return "another process";
}

}  // namespace

WorkspaceLock::WorkspaceLock(const fs::path& workspace, LockMode mode, const std::string& command)
    : path_(workspace / ".lock"), command_(command), mode_(LockMode::kShared) {
  if (!fs::is_directory(workspace)) throw BadInputError("workspace " + workspace.string() + " does not exist");
  fd_ = ::open(path_.c_str(), O_RDWR | O_CREAT | O_CLOEXEC, 0644);
  if (fd_ < 0 && mode == LockMode::kShared) fd_ = ::open(path_.c_str(), O_RDONLY | O_CLOEXEC);
  // A workspace nobody may write (read-only files or mount) has no writer to wait for.
  if (fd_ < 0 && mode == LockMode::kShared) return;
  if (fd_ < 0) {
    throw BadInputError("workspace " + workspace.string() + ": cannot open its lock file " + path_.string() + ": " +
                        std::strerror(errno));
  }
  if (const std::string refusal = TryLock(mode); !refusal.empty()) {
    ::close(fd_);
    throw BadInputError("workspace " + workspace.string() + refusal);
  }
  mode_ = mode;
  if (mode == LockMode::kExclusive) RecordHolder();
}

std::string WorkspaceLock::TryLock(LockMode mode) const {
  if (mode == LockMode::kExclusive && ::flock(fd_, LOCK_EX | LOCK_NB) == 0) return "";
  if (::flock(fd_, LOCK_SH | LOCK_NB) != 0) {
    return " is being written by " + LastHolder(path_) + "; run " + command_ + " when it has finished";
  }
  if (mode == LockMode::kShared) return "";
  ::flock(fd_, LOCK_UN);
  return " is being read by another parallax process (render, evaluate or view); " + command_ +
         " needs it alone to write: run it when that has finished";
}

void WorkspaceLock::RecordHolder() const {
  const std::string holder = command_ + " " + std::to_string(::getpid()) + "\n";
  if (::ftruncate(fd_, 0) == 0) {
    [[maybe_unused]] const ssize_t written = ::pwrite(fd_, holder.data(), holder.size(), 0);
  }
}

void WorkspaceLock::MakeExclusive() {
  if (mode_ == LockMode::kExclusive) return;
  const std::string workspace = path_.parent_path().string();
  if (fd_ < 0) throw BadInputError("workspace " + workspace + " is read-only; " + command_ + " needs to write into it");
  // Held shared, only other readers can be in the way.
  if (::flock(fd_, LOCK_EX | LOCK_NB) != 0) {
    throw BadInputError("workspace " + workspace + " is being read by another parallax process (render, evaluate or " +
                        "view); " + command_ + " needs it alone to write: run it when that has finished");
  }
  mode_ = LockMode::kExclusive;
  RecordHolder();
}

WorkspaceLock::~WorkspaceLock() {
  if (fd_ >= 0) ::close(fd_);
}

}  // namespace parallax
