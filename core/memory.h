#pragma once
// What a piece of work needed (Linux): the peak resident memory of this process (reset the
// high-water mark, do the work, read it) and the CPU time (read before and after).
namespace parallax {

// Resets the process's resident-set high-water mark to its current size (/proc/self/clear_refs);
// false where the kernel does not allow it.
bool ResetPeakResidentMemory();

// The high-water mark of the resident set since start or the last reset, in MiB (VmHWM of
// /proc/self/status); 0 when unavailable.
double PeakResidentMemoryMb();

// CPU time, user and system, of this process and of the child processes it has waited for
// (colmap), in seconds: unlike wall time, it does not grow when other work shares the cores.
double CpuSeconds();

}  // namespace parallax
