#include "tools/hapticsim/progress_line.hpp"

#include <unistd.h>

#include <cmath>
#include <cstdio>

namespace hapticsim::cli {

std::string ShortDuration(double seconds) {
  if (!std::isfinite(seconds) || seconds < 0) return "?";
  const long s = std::lround(seconds);
  char buffer[32];
  if (s >= 3600) {
    std::snprintf(buffer, sizeof buffer, "%ldh%02ldm", s / 3600, (s / 60) % 60);
  } else if (s >= 60) {
    std::snprintf(buffer, sizeof buffer, "%ldm%02lds", s / 60, s % 60);
  } else {
    std::snprintf(buffer, sizeof buffer, "%lds", s);
  }
  return buffer;
}

ProgressLine::ProgressLine(std::string what, double plain_interval_s, std::string unit)
    : what_(std::move(what)),
      unit_(std::move(unit)),
      terminal_(isatty(STDERR_FILENO)),
      plain_interval_s_(plain_interval_s) {}

void ProgressLine::Update(std::size_t done, std::size_t total, std::size_t fresh,
                          double elapsed_s) {
  const double fraction = total ? static_cast<double>(done) / total : 1.0;
  const double rate = elapsed_s > 0 ? fresh / elapsed_s : 0;
  const double eta = rate > 0 ? (total - done) / rate : NAN;
  if (terminal_) {
    constexpr int kWidth = 30;
    const int filled = static_cast<int>(fraction * kWidth);
    std::string bar(filled, '#');
    bar.resize(kWidth, '.');
    std::fprintf(stderr, "\r%s [%s] %zu/%zu %s  %.1f/s  ETA %s   ", what_.c_str(), bar.c_str(),
                 done, total, unit_.c_str(), rate, ShortDuration(eta).c_str());
    drawn_ = true;
  } else if (elapsed_s - last_plain_s_ >= plain_interval_s_ || done == total) {
    std::fprintf(stderr, "%s: %zu/%zu %s (%.0f %%), %.1f %s/s, %s elapsed, ETA %s\n", what_.c_str(),
                 done, total, unit_.c_str(), 100 * fraction, rate, unit_.c_str(),
                 ShortDuration(elapsed_s).c_str(), ShortDuration(eta).c_str());
    last_plain_s_ = elapsed_s;
  }
  std::fflush(stderr);
}

void ProgressLine::Finish() {
  if (terminal_ && drawn_) std::fprintf(stderr, "\n");
  drawn_ = false;
}

}  // namespace hapticsim::cli
