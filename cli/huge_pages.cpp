#include "cli/huge_pages.h"

#include <climits>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <string>

#if defined(__linux__)
#include <unistd.h>
#endif
#if defined(__GLIBC__)
#include <malloc.h>
#endif

namespace mq::cli {

namespace {

constexpr const char* kTunable = "glibc.malloc.hugetlb";

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

// The kernel's THP mode is "madvise" (the selected one is in brackets).
bool thp_on_request() {
  std::ifstream in("/sys/kernel/mm/transparent_hugepage/enabled");
  const std::string modes((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  return modes.find("[madvise]") != std::string::npos;
}

}  // namespace

bool reports_free_pages(const std::string& features) {
  constexpr size_t kReportingBit = 5;
  return features.size() > kReportingBit && features[kReportingBit] == '1';
}

// Such a guest hands its free blocks of 2 MiB and more back to the host, and a huge page is
// taken from exactly those, so zeroing it faults every 4 KiB of it in on the host. Measured on such
// a VM (Firecracker, 2 cores): the armor job 16.0-17.1 s on huge pages against 12.1-12.4 s without,
// the kernel's clear_page 34% of samples against under 1%.
bool host_reclaims_free_pages() {
#if defined(__linux__)
  std::error_code error;
  for (const auto& device :
       std::filesystem::directory_iterator("/sys/bus/virtio/drivers/virtio_balloon", error)) {
    if (device.path().filename().string().rfind("virtio", 0) != 0) continue;
    std::ifstream in(device.path() / "features");
    std::string bits;
    if (in >> bits && reports_free_pages(bits)) return true;
  }
#endif
  return false;
}

void restart_with_huge_pages(char** argv) {
  if (!glibc_with_tunable() || sanitized()) return;
  const char* choice = std::getenv("MESHQUILT_HUGE_PAGES");
  if (choice != nullptr && std::strcmp(choice, "0") == 0) return;
  const bool asked = choice != nullptr && std::strcmp(choice, "1") == 0;
  if (!asked && host_reclaims_free_pages()) return;
  const char* tunables = std::getenv("GLIBC_TUNABLES");
  if (contains(tunables, kTunable)) return;                      // set already, by us or the user
  if (contains(std::getenv("LD_PRELOAD"), "vgpreload")) return;  // valgrind follows no exec
  if (!thp_on_request()) return;
#if defined(__linux__)
  std::string value = tunables != nullptr && *tunables != '\0' ? std::string(tunables) + ":" : "";
  value += std::string(kTunable) + "=1";
  if (::setenv("GLIBC_TUNABLES", value.c_str(), 1) != 0) return;
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

namespace {
bool kept = false;
}  // namespace

bool keep_freed_memory() {
#if defined(__GLIBC__)
  if (sanitized()) return false;
  const char* choice = std::getenv("MESHQUILT_KEEP_FREED");
  if (choice != nullptr && std::strcmp(choice, "0") == 0) return false;
  // Both succeed or the defaults stay (mallopt returns 0 on an invalid value only).
  kept = ::mallopt(M_MMAP_MAX, 0) == 1 && ::mallopt(M_TRIM_THRESHOLD, INT_MAX) == 1;
#endif
  return kept;
}

bool freed_memory_kept() { return kept; }

}  // namespace mq::cli
