// The heap tuned for commands that work on whole-record columns (`mpm
// diagnose`): each hypothesis fit allocates and frees a few columns of N
// doubles (8 MB at 10^6 samples). With glibc's defaults each such block is
// an mmap of fresh pages or, once the dynamic threshold has risen, heap
// memory trimmed back to the system as soon as it is freed: either way every
// fit pays page faults and zeroing for every page it touches (measured on a
// 10^6-sample diagnosis: a third of the CPU time in the kernel). Kept in the
// heap instead, freed columns are reused warm. One arena for every thread:
// with one per thread (glibc's default), the hypothesis threads' columns
// live in 64 MB heaps of their own that are mapped and unmapped as they fill
// and empty (measured on 10^6 samples: 5.2 s of system time and 603 MB peak
// RSS, against 1.2 s and 495 MB with one arena; the fits allocate a few
// columns each, so the shared lock costs nothing measurable). This moves no
// peak: the process holds at most what it held at its peak, which is
// bounded by what the fits keep (core/diagnosis.hpp).
#pragma once

#include <malloc.h>

namespace mpm {

inline void keep_freed_columns_in_heap() {
  // 32 MB is glibc's largest mmap threshold on 64-bit: blocks below it come
  // from the heap; a freed top of the heap is kept up to 1 GB.
  mallopt(M_MMAP_THRESHOLD, 32 * 1024 * 1024);
  mallopt(M_TRIM_THRESHOLD, 1024 * 1024 * 1024);
  mallopt(M_ARENA_MAX, 1);
}

}  // namespace mpm
