#pragma once
// The progress of a long run on stderr (docs/cli.md, "Progress"): nothing for the first second,
// then the model, step, depth, force so far and elapsed time — redrawn in place on a terminal,
// one line per step when stderr is a file or a pipe. `--quiet` turns it off.

#include <chrono>
#include <functional>
#include <ostream>
#include <string>

namespace mneedle::cli {

struct ProgressState {
  std::string model;  ///< "fe_3d", "fe_axisymmetric"
  int step = 0;
  int steps = 0;
  double depth_m = 0.0;
  double force_N = 0.0;
};

class ProgressLine {
 public:
  using Clock = std::function<double()>;  ///< seconds, monotonic

  /// `terminal`: redraw in place; `quiet`: print nothing. `clock` defaults to steady_clock.
  ProgressLine(std::ostream& out, std::string command, bool terminal, bool quiet, Clock clock = {});
  /// After the first second: one line (terminal: the line redrawn).
  void update(const ProgressState& state);
  /// Ends a redrawn line with a newline so that what follows starts on its own line.
  void finish();
  /// finish(): an error that ends the run starts on its own line too.
  ~ProgressLine() { finish(); }
  ProgressLine(const ProgressLine&) = delete;
  ProgressLine& operator=(const ProgressLine&) = delete;

  /// The text of one update, without line control: "simulate: fe_3d step 7/20, depth 35 um,
  /// force 1.23 mN, 2.1 s" (seconds since the progress line was made, one decimal).
  std::string text(const ProgressState& state, double elapsed_s) const;

 private:
  std::ostream& out_;
  std::string command_;
  bool terminal_ = false;
  bool quiet_ = false;
  Clock clock_;
  double start_s_ = 0.0;
  bool drawn_ = false;  ///< a redrawn line is open on the terminal
};

/// True when file descriptor 2 is a terminal.
bool stderr_is_terminal();

}  // namespace mneedle::cli
