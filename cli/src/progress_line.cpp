#include "progress_line.h"

#include <unistd.h>

#include <cstdio>
#include <iomanip>
#include <sstream>

#include "mneedle/base/units.h"

namespace mneedle::cli {
namespace {

// Runs shorter than this print nothing: most runs end before anyone would read a progress line.
constexpr double kQuietSeconds = 1.0;

double steady_seconds() {
  return std::chrono::duration<double>(std::chrono::steady_clock::now().time_since_epoch()).count();
}

}  // namespace

ProgressLine::ProgressLine(std::ostream& out, std::string command, bool terminal, bool quiet,
                           Clock clock)
    : out_(out),
      command_(std::move(command)),
      terminal_(terminal),
      quiet_(quiet),
      clock_(clock ? std::move(clock) : Clock(steady_seconds)),
      start_s_(clock_()) {}

std::string ProgressLine::text(const ProgressState& s, double elapsed_s) const {
  std::ostringstream line;
  line << command_ << ": " << s.model << " step " << s.step;
  if (s.steps > 0) line << "/" << s.steps;
  line << ", depth " << format_quantity(s.depth_m, Dimension::Length) << ", force "
       << format_quantity(s.force_N, Dimension::Force) << ", " << std::fixed << std::setprecision(1)
       << elapsed_s << " s";
  return line.str();
}

void ProgressLine::update(const ProgressState& state) {
  if (quiet_) return;
  const double elapsed = clock_() - start_s_;
  if (elapsed < kQuietSeconds) return;
  if (terminal_) {
    out_ << "\r\033[K" << text(state, elapsed) << std::flush;  // carriage return, erase line
    drawn_ = true;
  } else {
    out_ << text(state, elapsed) << "\n" << std::flush;
  }
}

void ProgressLine::finish() {
  if (drawn_) out_ << "\n" << std::flush;
  drawn_ = false;
}

bool stderr_is_terminal() {
  return ::isatty(STDERR_FILENO) == 1;
}

}  // namespace mneedle::cli
