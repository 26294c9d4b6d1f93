// Transparent huge pages for the large arrays of a run (issue 27).
#pragma once

#include <string>

namespace mq::cli {

// Restarts this process (same pid, arguments and environment) with glibc's malloc asked to back
// its large blocks with transparent huge pages (GLIBC_TUNABLES glibc.malloc.hugetlb=1), when
// that helps and is safe: glibc 2.35 or later, the kernel's THP mode "madvise" (with "always"
// the pages are huge already, with "never" they cannot be), not built with a sanitizer (its
// malloc ignores the tunable), not under valgrind, the tunable not set already (so at most one
// restart), and MESHQUILT_HUGE_PAGES not "0". glibc reads tunables only when a process starts,
// hence the restart (about 10 ms). Measured (farm-bench, 4 pairs, 2 cores): the armor job 0.78x
// wall time, the ivy wall 0.91x, Spot 0.88x; most of the page faults of the output's large
// arrays go, peak memory 1-5% higher. Returns only when no restart was made (or exec failed);
// call first in main, before any thread or file exists. Not on a virtual machine whose balloon
// reports free pages to the host (reports_free_pages): there the huge pages are the memory the
// host took back, and faulting them in made the armor job 1.35x slower; MESHQUILT_HUGE_PAGES=1
// asks for them all the same.
void restart_with_huge_pages(char** argv);

// Whether a virtio balloon's features string (one '0' or '1' per feature bit, bit 0 first, as in
// /sys/bus/virtio/devices/*/features) offers free page reporting (bit 5).
bool reports_free_pages(const std::string& features);

// Whether a virtio balloon of this machine reports free pages (reads sysfs; false off Linux).
bool host_reclaims_free_pages();

// Whether this process runs with the tunable above (for --stats).
bool huge_pages_on();

// Keeps the blocks the run frees for its next allocations, unless MESHQUILT_KEEP_FREED is "0"
// (issue 27): glibc's malloc maps every block over its threshold (at most 32 MiB) afresh and
// unmaps it when freed, so each large array of a stage (the intersection test's face boxes,
// 115 MB on the armor, made three times) faults its pages in and zeroes them again, and on a VM
// a 4 KiB fault cost 19 us (2.87M boxes: 0.54 s; 0.01 s reused). With mmap off and no trimming,
// large blocks come from the heap and go back to it. Paired runs (bench/results/paired_{new_keep_
// freed,old_freed_unmapped}.json, 2 cores, no huge pages): the armor 0.81x the time, the bunny
// 0.80x, the cup 0.76x, the ivy wall 0.87x; peak memory 1.03x, 1.02x, 0.99x and 1.10x (the
// heap's free blocks do not always fit the next request). Same bytes. Returns whether it did
// (glibc, no sanitizer: theirs replaces malloc). Call first in main.
bool keep_freed_memory();

// Whether keep_freed_memory did (for --stats).
bool freed_memory_kept();

}  // namespace mq::cli
