#pragma once

#include <cstddef>
#include <string>

namespace hapticsim::cli {

/**
 * Progress of long work on stderr: a redrawn bar with rate and ETA on a terminal, a plain line
 * every `plain_interval_s` otherwise (logs and CI stay readable).
 */
class ProgressLine {
 public:
  /** `what` names the work, `unit` what it counts ("samples", "cases"). */
  ProgressLine(std::string what, double plain_interval_s = 10.0, std::string unit = "samples");
  /** done of total units, `fresh` of them made in this run (the rate counts only those). */
  void Update(std::size_t done, std::size_t total, std::size_t fresh, double elapsed_s);
  /** Ends the bar's line on a terminal. */
  void Finish();

 private:
  std::string what_, unit_;
  bool terminal_;
  double plain_interval_s_;
  double last_plain_s_ = -1e9;
  bool drawn_ = false;
};

/** "1h02m", "3m05s", "12s". */
std::string ShortDuration(double seconds);

}  // namespace hapticsim::cli
