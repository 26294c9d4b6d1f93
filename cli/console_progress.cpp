#include "cli/console_progress.h"

#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <cstdio>

namespace mq::cli {

std::string format_duration(double seconds) {
  const long s = std::lround(std::max(0.0, seconds));
  char buf[32];
  if (s >= 3600)
    std::snprintf(buf, sizeof buf, "%ld:%02ld:%02ld", s / 3600, (s / 60) % 60, s % 60);
  else
    std::snprintf(buf, sizeof buf, "%ld:%02ld", s / 60, s % 60);
  return buf;
}

ConsoleProgress::ConsoleProgress(bool quiet, bool machine)
    : quiet_(quiet && !machine),
      terminal_(::isatty(STDERR_FILENO) == 1 && !machine),
      machine_(machine),
      start_(Clock::now()) {
  last_print_ = start_;
}

ConsoleProgress::~ConsoleProgress() { finish(); }

void ConsoleProgress::update(const std::string& stage, double done, double total) {
  if (quiet_ || total <= 0) return;
  const auto now = Clock::now();
  if (stage != stage_) {
    stage_ = stage;
    stage_start_ = now;
    last_fraction_ = -1;
  }
  const double fraction = std::clamp(done / total, 0.0, 1.0);
  const double stage_elapsed = std::chrono::duration<double>(now - stage_start_).count();
  // Remaining time of the current stage extrapolated from its own rate so far.
  const bool can_estimate = fraction > 0.02 && stage_elapsed > 0.5;
  const double remaining = can_estimate ? stage_elapsed * (1 - fraction) / fraction : 0;
  if (machine_) {
    // Every stage's start and end are printed; in between at most one line per 0.25 s.
    const bool new_stage = last_fraction_ < 0;
    if (!new_stage && now - last_print_ < std::chrono::milliseconds(250) && fraction < 1) return;
    if (fraction >= 1 && last_fraction_ >= 1) return;
    std::fprintf(stderr, "progress %s %.4f %.2f %.2f\n", stage.c_str(), fraction,
                 std::chrono::duration<double>(now - start_).count(),
                 can_estimate ? remaining : -1.0);
    std::fflush(stderr);
  } else if (terminal_) {
    if (now - last_print_ < std::chrono::milliseconds(100) && fraction < 1) return;
    const int width = 30;
    const int filled = static_cast<int>(std::lround(fraction * width));
    std::string bar(filled, '#');
    bar.resize(width, '-');
    std::fprintf(
        stderr, "\r%-22.22s [%s] %3d%%  %s", stage.c_str(), bar.c_str(),
        static_cast<int>(fraction * 100),
        can_estimate ? ("ETA " + format_duration(remaining) + "   ").c_str() : "            ");
    std::fflush(stderr);
    line_open_ = true;
  } else {
    // Plain lines: at most one every 2 s, always at stage completion.
    if (now - last_print_ < std::chrono::seconds(2) && fraction < 1) return;
    if (fraction >= 1 && last_fraction_ >= 1) return;
    std::fprintf(stderr, "[%s] %s %d%%%s\n",
                 format_duration(std::chrono::duration<double>(now - start_).count()).c_str(),
                 stage.c_str(), static_cast<int>(fraction * 100),
                 can_estimate && fraction < 1
                     ? (", about " + format_duration(remaining) + " left").c_str()
                     : "");
  }
  last_fraction_ = fraction;
  last_print_ = now;
}

void ConsoleProgress::finish() {
  if (line_open_) {
    std::fprintf(stderr, "\r%*s\r", 72, "");
    std::fflush(stderr);
    line_open_ = false;
  }
}

}  // namespace mq::cli
