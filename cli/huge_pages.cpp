#include "cli/huge_pages.h"

#include <algorithm>
#include <chrono>
#include <climits>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <fstream>
#include <iterator>
#include <limits>
#include <string>

#if defined(__linux__)
#include <sys/mman.h>
#include <unistd.h>
#endif
#if defined(__GLIBC__)
#include <malloc.h>
#endif

namespace mq::cli {

namespace {

constexpr const char* kTunable = "glibc.malloc.hugetlb";
// The probe's figures, passed on to the restarted process for --stats.
constexpr const char* kProbeVariable = "MESHQUILT_PAGE_PROBE";

// Built with AddressSanitizer, ThreadSanitizer or MemorySanitizer (GCC's macro or clang's
// feature test): their allocator replaces glibc's.
constexpr bool sanitized() {
#if defined(__SANITIZE_ADDRESS__) || defined(__SANITIZE_THREAD__)
  return true;
#elif defined(__has_feature)
#if __has_feature(address_sanitizer) || __has_feature(thread_sanitizer) || \
    __has_feature(memory_sanitizer)
  return true;
#else
  return false;
#endif
#else
  return false;
#endif
}

// glibc reads the tunable from 2.35 on (older ones ignore it: no restart for nothing).
constexpr bool glibc_with_tunable() {
#if defined(__linux__) && defined(__GLIBC__) && \
    (__GLIBC__ > 2 || (__GLIBC__ == 2 && __GLIBC_MINOR__ >= 35))
  return true;
#else
  return false;
#endif
}

bool contains(const char* text, const char* part) {
  return text != nullptr && std::strstr(text, part) != nullptr;
}

// Whether environment variable `name` is set to exactly `value`.
bool env_is(const char* name, const char* value) {
  const char* set = std::getenv(name);
  return set != nullptr && std::strcmp(set, value) == 0;
}

// The kernel's THP mode is "madvise" (the selected one is in brackets).
bool thp_on_request() {
  std::ifstream in("/sys/kernel/mm/transparent_hugepage/enabled");
  const std::string modes((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  return modes.find("[madvise]") != std::string::npos;
}

// The figures of first_touch_probe, as measured in this process or passed on by the restart.
PageProbe probe_figures;
// Whether keep_freed_memory did.
bool kept = false;

// Microseconds to fault in 2 MiB of fresh anonymous memory, one write per 4 KiB: on one huge
// page (MADV_HUGEPAGE over an aligned block) or on small pages (MADV_NOHUGEPAGE); -1 when the
// memory cannot be mapped.
double first_touch_us(bool huge) {
#if defined(__linux__)
  constexpr size_t kHuge = size_t{2} << 20;
  void* const raw =
      ::mmap(nullptr, 2 * kHuge, PROT_READ | PROT_WRITE, MAP_PRIVATE | MAP_ANONYMOUS, -1, 0);
  if (raw == MAP_FAILED) return -1;
  const auto address = reinterpret_cast<std::uintptr_t>(raw);
  char* const block = static_cast<char*>(raw) + (kHuge - address % kHuge) % kHuge;
  ::madvise(block, kHuge, huge ? MADV_HUGEPAGE : MADV_NOHUGEPAGE);
  const auto start = std::chrono::steady_clock::now();
  volatile char* const touched = block;
  for (size_t i = 0; i < kHuge; i += 4096) touched[i] = 1;
  const double us =
      std::chrono::duration<double, std::micro>(std::chrono::steady_clock::now() - start).count();
  ::munmap(raw, 2 * kHuge);
  return us;
#else
  (void)huge;
  return -1;
#endif
}

}  // namespace

bool PageProbe::huge_pays() const { return huge_us >= 0 && small_us >= 0 && huge_us < small_us; }

PageProbe first_touch_probe() {
  // Two rounds, alternating, the least of each: one slow fault (a timer tick, a migration)
  // does not decide.
  PageProbe probe{std::numeric_limits<double>::infinity(), std::numeric_limits<double>::infinity()};
  for (int round = 0; round < 2; ++round) {
    const double huge = first_touch_us(true), small = first_touch_us(false);
    if (huge < 0 || small < 0) return {};
    probe.huge_us = std::min(probe.huge_us, huge);
    probe.small_us = std::min(probe.small_us, small);
  }
  return probe;
}

PageProbe page_probe() { return probe_figures; }

void restart_with_huge_pages(char** argv) {
  if (!glibc_with_tunable() || sanitized()) return;
  if (env_is("MESHQUILT_HUGE_PAGES", "0")) return;
  const bool asked = env_is("MESHQUILT_HUGE_PAGES", "1");
  const char* tunables = std::getenv("GLIBC_TUNABLES");
  if (contains(tunables, kTunable)) {  // set already, by us or the user
    const char* passed = std::getenv(kProbeVariable);
    if (passed != nullptr &&
        std::sscanf(passed, "%lf,%lf", &probe_figures.small_us, &probe_figures.huge_us) != 2)
      probe_figures = {};
    return;
  }
  if (contains(std::getenv("LD_PRELOAD"), "vgpreload")) return;  // valgrind follows no exec
  if (!thp_on_request()) return;
  if (!asked) {
    probe_figures = first_touch_probe();
    if (!probe_figures.huge_pays()) return;
  }
#if defined(__linux__)
  std::string value = tunables != nullptr && *tunables != '\0' ? std::string(tunables) + ":" : "";
  value += std::string(kTunable) + "=1";
  if (::setenv("GLIBC_TUNABLES", value.c_str(), 1) != 0) return;
  char figures[64];
  std::snprintf(figures, sizeof figures, "%.1f,%.1f", probe_figures.small_us,
                probe_figures.huge_us);
  ::setenv(kProbeVariable, figures, 1);
  ::execv("/proc/self/exe", argv);
  // Only on failure (no /proc): run on as started, without the tunable.
  if (tunables != nullptr)
    ::setenv("GLIBC_TUNABLES", tunables, 1);
  else
    ::unsetenv("GLIBC_TUNABLES");
#else
  (void)argv;
#endif
}

bool huge_pages_on() {
  const char* tunables = std::getenv("GLIBC_TUNABLES");
  const std::string set = std::string(kTunable) + "=", off = set + "0";
  return glibc_with_tunable() && !sanitized() && contains(tunables, set.c_str()) &&
         !contains(tunables, off.c_str());
}

bool keep_freed_memory() {
#if defined(__GLIBC__)
  if (sanitized()) return false;
  if (env_is("MESHQUILT_KEEP_FREED", "0")) return false;
  // On huge pages a fresh block's faults cost little (zeroing at memory speed), and keeping
  // blocks would only raise the peak.
  if (!env_is("MESHQUILT_KEEP_FREED", "1") && huge_pages_on()) return false;
  // Both succeed or the defaults stay (mallopt returns 0 on an invalid value only).
  kept = ::mallopt(M_MMAP_MAX, 0) == 1 && ::mallopt(M_TRIM_THRESHOLD, INT_MAX) == 1;
#endif
  return kept;
}

bool freed_memory_kept() { return kept; }

}  // namespace mq::cli
