// Transparent huge pages for the large arrays of a run (issue 27).
#pragma once

#include <string>

namespace mq::cli {

// What faulting fresh memory in costs on this machine: microseconds for 2 MiB, one write per
// 4 KiB, on one huge page and on small pages (the least of two rounds each; -1: not measured).
struct PageProbe {
  double small_us = -1, huge_us = -1;
  bool huge_pays() const;  // both measured, the huge page faster
};

// Measures it (about 2 x 2 MiB twice: 20 ms where a small-page fault costs 19 us, under 2 ms
// on most machines).
PageProbe first_touch_probe();

// The probe's figures for --stats: as this process measured them, or as passed on to the
// restarted one; -1 when it did not run.
PageProbe page_probe();

// Restarts this process (same pid, arguments and environment) with glibc's malloc asked to back
// its large blocks with transparent huge pages (GLIBC_TUNABLES glibc.malloc.hugetlb=1), when
// that helps and is safe: glibc 2.35 or later, the kernel's THP mode "madvise" (with "always"
// the pages are huge already, with "never" they cannot be), not built with a sanitizer (its
// malloc ignores the tunable), not under valgrind, the tunable not set already (so at most one
// restart), MESHQUILT_HUGE_PAGES not "0", and first_touch_probe finding the huge page faster
// (MESHQUILT_HUGE_PAGES=1 skips the probe). glibc reads tunables only when a process starts,
// hence the restart (about 10 ms). Why a probe: on one VM (Firecracker, its balloon reporting free
// pages to the host) huge pages made the armor job 1.3x slower, each huge page's zeroing faulting
// every 4 KiB of it in on the host; on another of the same kind (a paravirtual kernel) small-page
// faults cost 19 us and huge pages made it 1.15x faster. The reporting bit cannot tell them
// apart; the cost of a fault can. Returns only when no restart was made (or exec failed); call
// first in main, before any thread or file exists.
void restart_with_huge_pages(char** argv);

// Whether this process runs with the tunable above (for --stats).
bool huge_pages_on();

// Keeps the blocks the run frees for its next allocations when the run is not on huge pages
// (MESHQUILT_KEEP_FREED=1: always; =0: never) (issue 27): glibc's malloc maps every block over
// its threshold (at most 32 MiB) afresh and unmaps it when freed, so each large array of a stage
// (the intersection test's face boxes, 115 MB on the armor, made three times) faults its pages
// in and zeroes them again, and on a VM a 4 KiB fault cost 19 us (2.87M boxes: 0.54 s; 0.01 s
// reused). With mmap off and no trimming, large blocks come from the heap and go back to it.
// Paired runs on small pages (bench/results/paired_{new_keep_freed,old_freed_unmapped}.json,
// 2 cores): the armor 0.81x the time, the bunny 0.80x, the cup 0.76x, the ivy wall 0.87x; peak
// memory 1.03x, 1.02x, 0.99x and 1.10x (the heap's free blocks do not always fit the next
// request). On huge pages a fault costs 0.05 ms per 2 MiB and keeping gained nothing measurable
// (the armor 6.4-7.0 s either way) while the chair's peak rose 199 -> 225 MB: not kept there.
// Same bytes. Returns whether it did (glibc, no sanitizer: theirs replaces malloc). Call in
// main after restart_with_huge_pages.
bool keep_freed_memory();

// Whether keep_freed_memory did (for --stats).
bool freed_memory_kept();

}  // namespace mq::cli
