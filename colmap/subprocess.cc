#include "colmap/subprocess.h"

#include <cerrno>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <stdexcept>

#include <fcntl.h>
#include <signal.h>
#include <spawn.h>
#include <sys/resource.h>
#include <sys/wait.h>
#include <unistd.h>

#include "core/error.h"
#include "core/interrupt.h"

extern char** environ;

namespace parallax {
namespace {

// Closes a pipe end once, whatever path leaves the function.
class FileDescriptor {
 public:
  explicit FileDescriptor(int fd = -1) : fd_(fd) {}
  ~FileDescriptor() { Close(); }
  FileDescriptor(const FileDescriptor&) = delete;
  FileDescriptor& operator=(const FileDescriptor&) = delete;
  int Get() const { return fd_; }
  void Close() {
    if (fd_ >= 0) ::close(fd_);
    fd_ = -1;
  }

 private:
  int fd_;
};

std::vector<char*> PointersTo(std::vector<std::string>& strings) {
  std::vector<char*> pointers;
  for (std::string& s : strings) pointers.push_back(s.data());
  pointers.push_back(nullptr);
  return pointers;
}

}  // namespace

std::string FindExecutable(const std::string& name) {
  namespace fs = std::filesystem;
  if (name.find('/') != std::string::npos) {
    return ::access(name.c_str(), X_OK) == 0 && !fs::is_directory(name) ? name : "";
  }
  const char* path = std::getenv("PATH");
  std::string_view remaining = path ? path : "/usr/local/bin:/usr/bin:/bin";
  while (!remaining.empty()) {
    const size_t colon = remaining.find(':');
    const std::string dir(remaining.substr(0, colon));
    remaining = colon == std::string_view::npos ? "" : remaining.substr(colon + 1);
    const fs::path candidate = fs::path(dir.empty() ? "." : dir) / name;
    if (::access(candidate.c_str(), X_OK) == 0 && !fs::is_directory(candidate)) {
      return candidate.string();
    }
  }
  return "";
}

ProcessResult RunProcess(const std::vector<std::string>& argv,
                         const std::vector<std::string>& extra_environment,
                         const std::function<void(std::string_view line)>& on_line) {
  if (argv.empty()) throw InternalError("RunProcess: empty command line");
  // Closed on exec: a child started by another thread at the same time must not hold this
  // pipe's write end, or its reader would wait for that child too.
  int fds[2];
  if (::pipe2(fds, O_CLOEXEC) != 0) {
    throw std::runtime_error("cannot create a pipe: " + std::string(std::strerror(errno)));
  }
  FileDescriptor read_end(fds[0]), write_end(fds[1]);

  posix_spawn_file_actions_t actions;
  posix_spawn_file_actions_init(&actions);
  posix_spawn_file_actions_addclose(&actions, read_end.Get());
  posix_spawn_file_actions_adddup2(&actions, write_end.Get(), STDOUT_FILENO);
  posix_spawn_file_actions_adddup2(&actions, write_end.Get(), STDERR_FILENO);
  posix_spawn_file_actions_addclose(&actions, write_end.Get());
  posix_spawn_file_actions_addopen(&actions, STDIN_FILENO, "/dev/null", O_RDONLY, 0);

  std::vector<std::string> arguments = argv;
  std::vector<std::string> environment;
  for (char** entry = environ; *entry; ++entry) environment.emplace_back(*entry);
  environment.insert(environment.end(), extra_environment.begin(), extra_environment.end());
  std::vector<char*> argument_pointers = PointersTo(arguments);
  std::vector<char*> environment_pointers = PointersTo(environment);

  // The child takes SIGINT and SIGTERM as programs do, not blocked as in parallax's threads
  // (core/interrupt.h).
  posix_spawnattr_t attributes;
  posix_spawnattr_init(&attributes);
  sigset_t no_signals, interrupts;
  sigemptyset(&no_signals);
  sigemptyset(&interrupts);
  sigaddset(&interrupts, SIGINT);
  sigaddset(&interrupts, SIGTERM);
  posix_spawnattr_setsigmask(&attributes, &no_signals);
  posix_spawnattr_setsigdefault(&attributes, &interrupts);
  posix_spawnattr_setflags(&attributes, POSIX_SPAWN_SETSIGMASK | POSIX_SPAWN_SETSIGDEF);
  pid_t pid = 0;
  const int spawn_error = ::posix_spawnp(&pid, arguments[0].c_str(), &actions, &attributes,
                                         argument_pointers.data(), environment_pointers.data());
  posix_spawn_file_actions_destroy(&actions);
  posix_spawnattr_destroy(&attributes);
  if (spawn_error != 0) {
    throw std::runtime_error("cannot start " + argv[0] + ": " + std::strerror(spawn_error));
  }
  const RunningChild running(pid);
  write_end.Close();  // Only the child writes now; EOF arrives when it exits.

  std::string pending;
  char buffer[4096];
  for (;;) {
    const ssize_t count = ::read(read_end.Get(), buffer, sizeof(buffer));
    if (count < 0 && errno == EINTR) continue;
    if (count <= 0) break;
    pending.append(buffer, static_cast<size_t>(count));
    size_t start = 0;
    for (size_t newline; (newline = pending.find_first_of("\n\r", start)) != std::string::npos;
         start = newline + 1) {
      if (newline > start) on_line(std::string_view(pending).substr(start, newline - start));
    }
    pending.erase(0, start);
  }
  if (!pending.empty()) on_line(pending);

  int status = 0;
  struct rusage usage {};
  while (::wait4(pid, &status, 0, &usage) < 0 && errno == EINTR) {
  }
  ProcessResult result;
  result.exit_code = WIFEXITED(status) ? WEXITSTATUS(status) : 128 + WTERMSIG(status);
  result.peak_memory_kb = usage.ru_maxrss;  // Linux reports kilobytes.
  return result;
}

}  // namespace parallax
