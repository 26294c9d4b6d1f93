#include "cli/huge_pages.h"

#include <cstdlib>
#include <cstring>
#include <fstream>
#include <iterator>
#include <string>

#if defined(__linux__)
#include <unistd.h>
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

void restart_with_huge_pages(char** argv) {
  if (!glibc_with_tunable() || sanitized()) return;
  const char* choice = std::getenv("MESHQUILT_HUGE_PAGES");
  if (choice != nullptr && std::strcmp(choice, "0") == 0) return;
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

}  // namespace mq::cli
