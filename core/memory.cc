#include "core/memory.h"

#include <malloc.h>
#include <sys/resource.h>

#include <atomic>
#include <fstream>
#include <string>

namespace parallax {

namespace {

std::atomic<long> children_peak_kb{0};

}  // namespace

void ReturnFreedMemory() { malloc_trim(0); }

void NoteChildPeakMemory(long peak_kb) {
  long seen = children_peak_kb.load();
  while (peak_kb > seen && !children_peak_kb.compare_exchange_weak(seen, peak_kb)) {
  }
}

double PeakChildResidentMemoryMb() { return static_cast<double>(children_peak_kb.load()) / 1024.0; }

bool ResetPeakResidentMemory() {
  children_peak_kb = 0;
  std::ofstream clear_refs("/proc/self/clear_refs");
  clear_refs << "5";
  return static_cast<bool>(clear_refs.flush());
}

double PeakResidentMemoryMb() {
  std::ifstream status("/proc/self/status");
  for (std::string line; std::getline(status, line);) {
    if (line.rfind("VmHWM:", 0) == 0) return std::stod(line.substr(6)) / 1024.0;  // kB.
  }
  return 0;
}

double CpuSeconds() {
  double seconds = 0;
  for (const int who : {RUSAGE_SELF, RUSAGE_CHILDREN}) {
    rusage usage{};
    if (getrusage(who, &usage) != 0) continue;
    for (const timeval& time : {usage.ru_utime, usage.ru_stime}) {
      seconds += static_cast<double>(time.tv_sec) + static_cast<double>(time.tv_usec) * 1e-6;
    }
  }
  return seconds;
}

}  // namespace parallax
