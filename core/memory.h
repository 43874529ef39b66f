#pragma once
// The peak resident memory of this process (Linux), for reporting what a piece of work
// needed: reset the high-water mark, do the work, read it.
namespace parallax {

// Resets the process's resident-set high-water mark to its current size (/proc/self/clear_refs);
// false where the kernel does not allow it.
bool ResetPeakResidentMemory();

// The high-water mark of the resident set since start or the last reset, in MiB (VmHWM of
// /proc/self/status); 0 when unavailable.
double PeakResidentMemoryMb();

}  // namespace parallax
