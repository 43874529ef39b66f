#pragma once
// What a piece of work needed (Linux): the peak resident memory of this process (reset the
// high-water mark, do the work, read it) and the CPU time (read before and after).
namespace parallax {

// Returns the heap memory freed so far to the system (glibc keeps it for reuse otherwise), so
// that what one piece of work left behind does not count in the next one's peak.
void ReturnFreedMemory();

// Resets the process's resident-set high-water mark to its current size (/proc/self/clear_refs),
// and the children's recorded peak to 0; false where the kernel does not allow the former.
bool ResetPeakResidentMemory();

// Records the peak resident set of a child process this process waited for (colmap).
void NoteChildPeakMemory(long peak_kb);

// The largest peak of the children recorded since start or the last reset, in MiB.
double PeakChildResidentMemoryMb();

// The high-water mark of the resident set since start or the last reset, in MiB (VmHWM of
// /proc/self/status); 0 when unavailable.
double PeakResidentMemoryMb();

// CPU time, user and system, of this process and of the child processes it has waited for
// (colmap), in seconds: unlike wall time, it does not grow when other work shares the cores.
double CpuSeconds();

}  // namespace parallax
