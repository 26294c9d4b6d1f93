// meshquilt: geometric texture synthesis by mesh quilting (Zhou et al. 2006).
#include <cstdio>
#include <cstring>
#include <exception>
#include <new>
#include <string>

#include "cli/command_line.h"
#include "cli/commands.h"
#include "cli/huge_pages.h"
#include "core/common/errors.h"
#include "core/mesh/atomic_file.h"

namespace {

constexpr const char* kUsage =
    "usage: meshquilt COMMAND [options]\n"
    "\n"
    "Covers surfaces with 3D geometric texture by mesh quilting (Zhou et al. 2006).\n"
    "\n"
    "commands:\n"
    "  plane    grow a swatch into a seamless L x W layer\n"
    "  surface  cover a base mesh with the swatch's geometry in a thin shell\n"
    "  embed    place a saved quilt again on its base, moved (posed, animated)\n"
    "  edit     remove elements of a saved quilt or give them materials\n"
    "  swatch   generate a sample swatch (chainmail, chainmail-square, weave, apples, ivy)\n"
    "  info     print counts, bounding box and topology of a mesh file\n"
    "  render   render a mesh to a PNG preview\n"
    "\n"
    "Run 'meshquilt COMMAND --help' for the options of a command.\n"
    "\n"
    "environment: MESHQUILT_HUGE_PAGES=0 keeps the engine off transparent huge pages (on\n"
    "  where the kernel gives them on request and a probe at start finds a huge page faster to\n"
    "  fault in than small ones: 10-20% faster on large jobs, peak memory a few percent\n"
    "  higher; =1 asks for them without the probe; --stats says which in memory.huge_pages,\n"
    "  and the probe's figures). Off huge pages, large freed blocks are kept for the run's next\n"
    "  arrays (fewer page faults: 0.8x the time, peak memory 1.0-1.1x);\n"
    "  MESHQUILT_KEEP_FREED=0 never keeps them, =1 also on huge pages\n"
    "  (memory.freed_memory_kept).\n"
    "\n";

struct Command {
  const char* name;
  int (*run)(int, char**, int);
};

constexpr Command kCommands[] = {
    {"info", mq::cli::run_info},       {"swatch", mq::cli::run_swatch},
    {"render", mq::cli::run_render},   {"plane", mq::cli::run_plane},
    {"surface", mq::cli::run_surface}, {"embed", mq::cli::run_embed},
    {"edit", mq::cli::run_edit},
};

}  // namespace

int main(int argc, char** argv) {
  if (argc < 2 || !std::strcmp(argv[1], "--help") || !std::strcmp(argv[1], "-h") ||
      !std::strcmp(argv[1], "help")) {
    std::fputs(kUsage, argc < 2 ? stderr : stdout);
    std::fputs(mq::cli::kExitStatus, argc < 2 ? stderr : stdout);
    return argc < 2 ? 2 : 0;
  }
  if (!std::strcmp(argv[1], "--version")) {
    std::puts("meshquilt 0.1.0");
    return 0;
  }
  mq::cli::restart_with_huge_pages(argv);  // returns when it does not restart
  mq::cli::keep_freed_memory();
  mq::install_temporary_file_cleanup();  // no .NAME.tmp-* left behind on SIGINT or SIGTERM
  for (const Command& c : kCommands) {
    if (std::strcmp(argv[1], c.name) != 0) continue;
    try {
      return c.run(argc, argv, 2);
    } catch (const mq::cli::UsageError& e) {
      std::fprintf(stderr, "meshquilt %s: %s (see 'meshquilt %s --help')\n", c.name,
                   mq::detail::printable(e.what()).c_str(), c.name);
      return 2;
    } catch (const mq::InternalError& e) {
      // A violated invariant is meshquilt's fault, not the input's: 3, as for other bugs.
      std::fprintf(stderr, "meshquilt %s: internal error: %s\n", c.name,
                   mq::detail::printable(e.what()).c_str());
      return 3;
    } catch (const mq::DeviceError& e) {
      std::fprintf(stderr, "meshquilt %s: OpenCL device error: %s\n", c.name,
                   mq::detail::printable(e.what()).c_str());
      return 3;
    } catch (const mq::Error& e) {
      std::fprintf(stderr, "meshquilt %s: error: %s\n", c.name,
                   mq::detail::printable(e.what()).c_str());
      return 1;
    } catch (const std::bad_alloc&) {
      std::fprintf(stderr, "meshquilt %s: error: out of memory\n", c.name);
      return 1;
    } catch (const std::exception& e) {
      std::fprintf(stderr, "meshquilt %s: internal error: %s\n", c.name,
                   mq::detail::printable(e.what()).c_str());
      return 3;
    }
  }
  std::fprintf(stderr, "meshquilt: unknown command '%s' (see 'meshquilt --help')\n", argv[1]);
  return 2;
}
