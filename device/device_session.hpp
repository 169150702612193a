#pragma once

#include <array>
#include <cstdint>
#include <functional>
#include <optional>
#include <vector>

#include "device/device_link.hpp"
#include "device/device_motion.hpp"

namespace hapticsim::device {

struct SessionSettings {
  double duration_s = 10;
  double rate_hz = 1000;
  /// Bursts of bad input (NaN, far outside, a jump no hand makes, an old seq, and on LCM a
  /// message that is no device input and one of another type) starting at these times, s; each
  /// lasts 8 periods and is followed by 0.1 s of silence (stale input).
  std::vector<double> bad_input_bursts_s;
  /// A repeating press: inputs per press (seq 1 … n the first); 0: none. Each press's peak force
  /// is reported (press_peaks_n).
  std::int64_t press_period_inputs = 0;
  /// Keep every answer with the tip it answers (SessionReport::trace), for a plot of force
  /// against position.
  bool keep_trace = false;
};

/** One answer as the trace keeps it: the force and the tip position of the input it answers. */
struct TracePoint {
  double t_s = 0;                      ///< when the input it answers was sent, from the start
  std::array<double, 3> position_m{};  ///< that input's tip, object frame
  std::array<double, 3> force_n{};     ///< on the user
  std::int32_t flags = 0;
  double error_percent = -1;  ///< the error the daemon reported with it, % (−1: unknown)
};

/** Round-trip latency percentiles, µs (input sent → the first force answering it received). */
struct LatencySummary {
  std::int64_t count = 0;
  double median_us = 0, p99_us = 0, p999_us = 0, max_us = 0;
};

/** One second of the run, for plots. */
struct SecondSummary {
  double t_s = 0;
  LatencySummary latency;
  std::int64_t answers = 0;
};

/** What a stream of answers (one link) looked like. */
struct StreamSummary {
  std::int64_t answers = 0;             ///< distinct daemon periods seen
  std::int64_t lost_answers = 0;        ///< daemon periods between seen ones that never arrived
  std::int64_t duplicated_answers = 0;  ///< a daemon period seen again, or out of order
};

struct SessionReport {
  std::int64_t inputs_sent = 0;  ///< good inputs (bad ones are counted apart)
  std::int64_t bad_inputs_sent = 0;
  std::int64_t silent_periods = 0;       ///< periods nothing was sent (stale input on purpose)
  std::int64_t unanswered_inputs = 0;    ///< good inputs no force ever answered
  std::int64_t late_answers = 0;         ///< first answer more than one period after sending
  StreamSummary stream;                  ///< on the device's own link
  std::optional<StreamSummary> monitor;  ///< on the listening LCM link, when there is one
  LatencySummary latency;
  std::int64_t nonfinite_forces = 0;
  /// A non-zero force flagged neither in contact nor limited (the port guard's ramp to zero).
  std::int64_t force_out_of_contact = 0;
  double largest_force_step_n = 0;        ///< between consecutive answers in contact, fresh input
  double largest_force_step_any_n = 0;    ///< between any consecutive answers
  /// … in contact, fresh input, between answers that each took one new input, the next one: the
  /// step of one period, without a catch-up through several inputs after a late daemon period or
  /// a late device (ForceSteps).
  double largest_force_step_one_period_n = 0;
  double largest_force_n = 0;             ///< the largest force magnitude received
  std::vector<double> press_peaks_n;      ///< each whole press's largest force (a press input)
  /// In contact with fresh input and a normal force (−z, the front face's) above 0.05 N: the
  /// largest tangential force and its largest ratio to the normal (a sliding tool keeps it at
  /// most μ_s, μ_k once sliding).
  double largest_lateral_n = 0;
  double largest_lateral_ratio = 0;
  std::vector<TracePoint> trace;  ///< every answer, with keep_trace
  std::int64_t contact_answers = 0;
  /// In contact: the lowest and highest error the daemon reported with its answers, % (its map's
  /// where the regions were; −1 while none said one), and the answers that said none (no map).
  double error_percent_lowest = -1, error_percent_highest = -1;
  std::int64_t contact_answers_error_unknown = 0;
  std::int32_t flags_seen = 0;  ///< every FLAG_* bit any answer carried
  std::int64_t answers_after_last_burst = 0;
  std::optional<status_t> status;          ///< the daemon's last status (LCM)
  std::vector<RegionExecution> execution;  ///< its threads' compute per period, session (LCM)
  std::vector<SecondSummary> seconds;
  double duration_s = 0;
};

/** Percentiles of `values_us` (sorted in place). */
LatencySummary Summarise(std::vector<double>& values_us);

/**
 * The simulated device's loop: one input per period on absolute CLOCK_MONOTONIC releases,
 * answers collected from `link` (and, when given, counted on `monitor`, a listening LCM link),
 * everything measured. `each_second` is called once a second with the report so far (progress).
 */
SessionReport RunSession(DeviceMotion& motion, DeviceLink& link, DeviceLink* monitor,
                         const SessionSettings& settings,
                         const std::function<void(const SessionReport&)>& each_second = {});

}  // namespace hapticsim::device
