#include "core/interrupt.h"

#include <signal.h>
#include <sys/wait.h>
#include <unistd.h>

#include <chrono>
#include <cstdio>
#include <mutex>
#include <set>
#include <system_error>
#include <thread>

namespace parallax {
namespace fs = std::filesystem;
namespace {

// What an interruption undoes, each set under its mutex.
std::mutex mutex;
std::set<fs::path>& Temporaries() {
  static std::set<fs::path> temporaries;
  return temporaries;
}
std::set<pid_t>& Children() {
  static std::set<pid_t> children;
  return children;
}

// Whether `child` has ended (left for its waiter to reap).
bool Ended(pid_t child) {
  siginfo_t info{};
  return ::waitid(P_PID, static_cast<id_t>(child), &info, WEXITED | WNOHANG | WNOWAIT) != 0 || info.si_pid == child;
}

// SIGTERM to each child, and SIGKILL to those still there after 2 s.
void StopChildren() {
  for (const pid_t child : Children()) ::kill(child, SIGTERM);
  const auto deadline = std::chrono::steady_clock::now() + std::chrono::seconds(2);
  for (const pid_t child : Children()) {
    while (!Ended(child) && std::chrono::steady_clock::now() < deadline) {
      std::this_thread::sleep_for(std::chrono::milliseconds(20));
    }
    ::kill(child, SIGKILL);
  }
}

[[noreturn]] void Interrupted(int signal) {
  std::fprintf(stderr, "\ninterrupted (%s): stopping, removing temporary files; the next run resumes from the last "
               "finished stage\n", signal == SIGINT ? "SIGINT" : "SIGTERM");
  const std::lock_guard<std::mutex> lock(mutex);
  StopChildren();
  std::error_code error;
  for (const fs::path& path : Temporaries()) fs::remove_all(path, error);
  std::fflush(stdout);
  ::_exit(128 + signal);
}

}  // namespace

void InstallInterruptHandler() {
  sigset_t signals;
  sigemptyset(&signals);
  sigaddset(&signals, SIGINT);
  sigaddset(&signals, SIGTERM);
  pthread_sigmask(SIG_BLOCK, &signals, nullptr);
  std::thread([signals] {
    int signal = 0;
    while (sigwait(&signals, &signal) != 0) {
    }
    Interrupted(signal);
  }).detach();
}

RunningChild::RunningChild(pid_t pid) : pid_(pid) {
  const std::lock_guard<std::mutex> lock(mutex);
  Children().insert(pid_);
}

RunningChild::~RunningChild() {
  const std::lock_guard<std::mutex> lock(mutex);
  Children().erase(pid_);
}

TemporaryOutput::TemporaryOutput(fs::path path) : path_(std::move(path)) {
  const std::lock_guard<std::mutex> lock(mutex);
  Temporaries().insert(path_);
}

TemporaryOutput::~TemporaryOutput() {
  const std::lock_guard<std::mutex> lock(mutex);
  Temporaries().erase(path_);
}

}  // namespace parallax
