#pragma once
// One writer per workspace: an advisory lock (flock) on <ws>/.lock. `reconstruct` holds it
// exclusively, `render`, `evaluate` and `view` shared, for as long as the WorkspaceLock lives.
// The kernel drops it when the process ends, however it ends (SIGKILL included), so a lock is
// never stale; the file itself stays and only says who held it last.
#include <filesystem>
#include <string>

namespace parallax {

enum class LockMode { kShared, kExclusive };

class WorkspaceLock {
 public:
  // Takes the lock without waiting. Throws BadInputError naming the workspace and the
  // command and process that hold it in a conflicting mode, or why the lock file cannot be
  // opened. `command` (e.g. "reconstruct") is recorded for the message others get.
  WorkspaceLock(const std::filesystem::path& workspace, LockMode mode, const std::string& command);
  ~WorkspaceLock();
  WorkspaceLock(const WorkspaceLock&) = delete;
  WorkspaceLock& operator=(const WorkspaceLock&) = delete;

  // From shared to exclusive, for a reader about to write a stage (render computing missing
  // depth maps); throws BadInputError as above when another process holds it too.
  void MakeExclusive();

 private:
  // Takes the lock in `mode` and returns ""; else returns what stands in the way, as the end
  // of a sentence that starts with the workspace.
  std::string TryLock(LockMode mode) const;
  // Writes "<command> <pid>" into the lock file, for the messages of those it keeps out.
  void RecordHolder() const;

  std::filesystem::path path_;
  std::string command_;
  int fd_ = -1;
  LockMode mode_;
};

}  // namespace parallax
