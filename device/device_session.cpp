#include "device/device_session.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <optional>
#include <vector>

#include "device/force_steps.hpp"
#include "hapticsim/force_feedback_t.hpp"
#include "rt/monotonic_clock.hpp"

namespace hapticsim::device {
namespace {

double Percentile(const std::vector<double>& sorted, double q) {
  if (sorted.empty()) return 0;
  const auto index = static_cast<std::size_t>(std::ceil(q * sorted.size())) - 1;
  return sorted[std::min(index, sorted.size() - 1)];
}

// Counts the daemon periods of one answer stream: each answer carries its period's number.
class StreamCounter {
 public:
  void Add(const Answer& a) {
    if (last_period_ >= 0) {
      const std::int64_t gap = a.period - last_period_;
      if (gap <= 0) {
        ++summary_.duplicated_answers;
        return;
      }
      summary_.lost_answers += gap - 1;
    }
    last_period_ = a.period;
    ++summary_.answers;
  }
  const StreamSummary& summary() const { return summary_; }

 private:
  std::int64_t last_period_ = -1;
  StreamSummary summary_;
};

// The link the daemon's status comes in on: the device's own where it carries status (LCM),
// else the listening LCM monitor, if any.
const DeviceLink* StatusLink(const DeviceLink& link, const DeviceLink* monitor) {
  return link.LastStatus() ? &link : monitor;
}

}  // namespace

LatencySummary Summarise(std::vector<double>& values_us) {
  std::sort(values_us.begin(), values_us.end());
  LatencySummary s;
  s.count = static_cast<std::int64_t>(values_us.size());
  if (values_us.empty()) return s;
  s.median_us = Percentile(values_us, 0.5);
  s.p99_us = Percentile(values_us, 0.99);
  s.p999_us = Percentile(values_us, 0.999);
  s.max_us = values_us.back();
  return s;
}

namespace {

// Which input each period sends: the motion's, a burst of bad input after each burst start, or
// nothing in the silence after a burst (longer than the daemon's stale_after, 0.05 s by default:
// stale input).
class InputPlan {
 public:
  static constexpr int kBurstPeriods = 8;
  static constexpr int kSilentPeriods = 100;

  explicit InputPlan(const SessionSettings& settings) {
    for (double t : settings.bad_input_bursts_s) starts_.push_back(std::llround(t * settings.rate_hz));
  }
  /** The start of the burst period n is in, if it is in one. */
  std::optional<std::int64_t> BurstOf(std::int64_t n) const {
    for (std::int64_t b : starts_) {
      if (n >= b && n < b + kBurstPeriods) return b;
    }
    return std::nullopt;
  }
  bool Silent(std::int64_t n) const {
    return std::any_of(starts_.begin(), starts_.end(), [&](std::int64_t b) {
      return n >= b + kBurstPeriods && n < b + kBurstPeriods + kSilentPeriods;
    });
  }

 private:
  std::vector<std::int64_t> starts_;
};

// The k-th bad input of a burst, one kind after the other: the daemon must refuse each and keep
// the last good one. Returns the seq to send it with.
std::int64_t BadInput(std::int64_t k, std::int64_t seq, const std::array<double, 3>& last_good,
                      std::array<double, 3>* tip) {
  switch (k % 4) {
    case 0:
      (*tip)[0] = std::numeric_limits<double>::quiet_NaN();
      return seq;
    case 1:
      *tip = {last_good[0], last_good[1], 5.0};  // far outside
      return seq;
    case 2:
      *tip = {last_good[0] + 0.2, last_good[1], last_good[2]};  // 200 m/s
      return seq;
    default:
      *tip = last_good;
      return std::max<std::int64_t>(1, seq - 100);  // an old seq again
  }
}

// What the answers tell, into the report: the stream, forces, steps, press peaks, round trips.
class AnswerTally {
 public:
  AnswerTally(const SessionSettings& settings, std::int64_t periods, SessionReport* report)
      : settings_(settings),
        period_us_(1e6 / settings.rate_hz),
        report_(*report),
        sent_ns_(static_cast<std::size_t>(periods) + 2, 0),
        bad_(sent_ns_.size(), 0),
        answered_(sent_ns_.size(), 0) {
    latencies_us_.reserve(static_cast<std::size_t>(periods));
    if (settings.press_period_inputs > 0) {  // whole presses only: a partial last one is left out
      report_.press_peaks_n.assign(static_cast<std::size_t>(periods / settings.press_period_inputs),
                                   0.0);
    }
  }

  /** Input `seq` went out at `sent_ns` with the tip at `tip_m`; a bad one (or none) expects no
   *  answer of its own. */
  void Sent(std::int64_t seq, std::int64_t sent_ns, bool bad, const std::array<double, 3>& tip_m) {
    sent_ns_[seq] = sent_ns;
    bad_[seq] = bad ? 1 : 0;
    if (settings_.keep_trace) {
      if (first_sent_ns_ < 0) first_sent_ns_ = sent_ns;
      tips_.resize(sent_ns_.size());
      tips_[static_cast<std::size_t>(seq)] = tip_m;
    }
  }
  void BurstEnded(std::int64_t seq) { last_burst_end_ = seq; }

  void Take(const Answer& a) {
    stream_.Add(a);
    ++second_answers_;
    report_.flags_seen |= a.flags;
    const bool finite = std::isfinite(a.force_n[0] + a.force_n[1] + a.force_n[2]);
    const bool contact = a.flags & force_feedback_t::FLAG_IN_CONTACT;
    if (!finite) ++report_.nonfinite_forces;
    if (contact) ++report_.contact_answers;
    if (contact) TakeError(a.error_percent);  // finite or not: every answer in contact counts
    if (finite) TakeForce(a, contact);
    steps_.Take(a);  // every answer: which inputs it took counts, finite or not
    report_.largest_force_step_any_n = steps_.any_n();
    report_.largest_force_step_n = steps_.in_contact_n();
    report_.largest_force_step_one_period_n = steps_.one_period_n();
    if (settings_.keep_trace && a.seq >= 1 && a.seq < static_cast<std::int64_t>(tips_.size())) {
      const auto seq = static_cast<std::size_t>(a.seq);
      report_.trace.push_back({(sent_ns_[seq] - first_sent_ns_) * 1e-9, tips_[seq], a.force_n,
                               a.flags, a.error_percent});
    }
    if (last_burst_end_ >= 0 && a.seq > last_burst_end_) ++report_.answers_after_last_burst;
    TakeRoundTrips(a);
  }

  /** Closes second `t_s` of the session in the report. */
  void CloseSecond(double t_s) {
    SecondSummary s;
    s.t_s = t_s;
    s.latency = Summarise(second_latencies_us_);
    s.answers = second_answers_;
    report_.seconds.push_back(s);
    second_latencies_us_.clear();
    second_answers_ = 0;
    report_.stream = stream_.summary();
    report_.latency.count = static_cast<std::int64_t>(latencies_us_.size());
  }

  /** The session's end: the unanswered good inputs, the stream and the round trips. */
  void Finish(std::int64_t periods) {
    for (std::int64_t seq = 1; seq <= periods; ++seq) {
      if (!bad_[seq] && !answered_[seq]) ++report_.unanswered_inputs;
    }
    report_.stream = stream_.summary();
    report_.latency = Summarise(latencies_us_);
  }

 private:
  void TakeForce(const Answer& a, bool contact) {
    const bool limited = a.flags & force_feedback_t::FLAG_FORCE_LIMITED;
    const bool stale = a.flags & force_feedback_t::FLAG_INPUT_STALE;
    if (!contact && !limited && (a.force_n[0] != 0 || a.force_n[1] != 0 || a.force_n[2] != 0)) {
      ++report_.force_out_of_contact;
    }
    const double magnitude = std::hypot(a.force_n[0], a.force_n[1], a.force_n[2]);
    report_.largest_force_n = std::max(report_.largest_force_n, magnitude);
    if (settings_.press_period_inputs > 0 && a.seq >= 1) {
      const auto press = static_cast<std::size_t>((a.seq - 1) / settings_.press_period_inputs);
      if (press < report_.press_peaks_n.size()) {
        report_.press_peaks_n[press] = std::max(report_.press_peaks_n[press], magnitude);
      }
    }
    const double normal = -a.force_n[2], lateral = std::hypot(a.force_n[0], a.force_n[1]);
    if (contact && !stale && normal > 0.05) {
      report_.largest_lateral_n = std::max(report_.largest_lateral_n, lateral);
      report_.largest_lateral_ratio = std::max(report_.largest_lateral_ratio, lateral / normal);
    }
  }

  void TakeError(double error_percent) {
    if (!(error_percent >= 0)) {
      ++report_.contact_answers_error_unknown;
      return;
    }
    if (report_.error_percent_lowest < 0 || error_percent < report_.error_percent_lowest) {
      report_.error_percent_lowest = error_percent;
    }
    report_.error_percent_highest = std::max(report_.error_percent_highest, error_percent);
  }

  // Every input the answer names (first_seq … seq: those the daemon's period took), each with
  // its own round trip.
  void TakeRoundTrips(const Answer& a) {
    const std::int64_t first = a.first_seq >= 1 && a.first_seq <= a.seq ? a.first_seq : a.seq;
    for (std::int64_t seq = std::max<std::int64_t>(first, 1);
         seq <= a.seq && seq < static_cast<std::int64_t>(sent_ns_.size()); ++seq) {
      if (bad_[seq] || sent_ns_[seq] <= 0 || answered_[seq]) continue;
      answered_[seq] = 1;
      const double latency_us = (a.received_ns - sent_ns_[seq]) * 1e-3;
      latencies_us_.push_back(latency_us);
      second_latencies_us_.push_back(latency_us);
      if (latency_us > period_us_) ++report_.late_answers;
    }
  }

  const SessionSettings& settings_;
  double period_us_;
  SessionReport& report_;
  std::vector<std::int64_t> sent_ns_;
  std::vector<char> bad_, answered_;
  std::vector<double> latencies_us_, second_latencies_us_;
  StreamCounter stream_;
  std::int64_t last_burst_end_ = -1;
  std::int64_t second_answers_ = 0;
  std::vector<std::array<double, 3>> tips_;  // by seq, with keep_trace
  std::int64_t first_sent_ns_ = -1;
  ForceSteps steps_;
};

// The answers that arrived on the device's link (tallied) and the monitor's (counted).
void Collect(DeviceLink& link, DeviceLink* monitor, AnswerTally* tally, StreamCounter* watched,
             std::vector<Answer>* scratch) {
  scratch->clear();
  link.Collect(scratch);
  for (const Answer& a : *scratch) tally->Take(a);
  if (monitor) {
    scratch->clear();
    monitor->Collect(scratch);
    for (const Answer& a : *scratch) watched->Add(a);
  }
}

}  // namespace

SessionReport RunSession(DeviceMotion& motion, DeviceLink& link, DeviceLink* monitor,
                         const SessionSettings& settings,
                         const std::function<void(const SessionReport&)>& each_second) {
  const double period_ns = 1e9 / settings.rate_hz;
  const std::int64_t periods = std::llround(settings.duration_s * settings.rate_hz);
  const InputPlan plan(settings);
  SessionReport report;
  AnswerTally tally(settings, periods, &report);
  StreamCounter watched;
  std::array<double, 3> last_good{};
  std::vector<Answer> scratch;
  auto collect = [&] { Collect(link, monitor, &tally, &watched, &scratch); };

  const std::int64_t start = MonotonicNowNs() + 2'000'000;
  std::int64_t next_second = 1;
  for (std::int64_t n = 0; n < periods; ++n) {
    const std::int64_t release = start + std::llround(n * period_ns);
    SleepUntilMonotonicNs(release);
    const std::int64_t seq = n + 1;
    const std::optional<std::array<double, 3>> next = motion.Next();  // none: a replayed silence
    std::array<double, 3> tip = next.value_or(last_good);
    const std::optional<std::int64_t> burst = plan.BurstOf(n);
    const bool silent = !next || plan.Silent(n);
    if (silent) {
      ++report.silent_periods;  // nothing sent: nothing to answer
    } else if (burst) {
      ++report.bad_inputs_sent;
      link.Send(BadInput(n - *burst, seq, last_good, &tip), release / 1000, tip);
      if (link.SendGarbage()) report.bad_inputs_sent += 2;
      if (monitor && monitor->SendGarbage()) report.bad_inputs_sent += 2;
      tally.BurstEnded(seq);
    } else {
      last_good = tip;
      link.Send(seq, release / 1000, tip);
      ++report.inputs_sent;
    }
    tally.Sent(seq, MonotonicNowNs(), silent || burst, tip);
    const std::int64_t next_release = start + std::llround((n + 1) * period_ns);
    if (link.needs_polling()) {
      // Shared memory: look for the answer every 50 µs until just before the next period.
      while (MonotonicNowNs() < next_release - 60'000) {
        collect();
        SleepUntilMonotonicNs(MonotonicNowNs() + 50'000);
      }
    }
    collect();
    if (seq >= next_second * static_cast<std::int64_t>(settings.rate_hz)) {
      tally.CloseSecond(static_cast<double>(next_second++));
      const DeviceLink* status_link = StatusLink(link, monitor);
      report.status = status_link ? status_link->LastStatus() : std::nullopt;
      if (each_second) each_second(report);
    }
  }
  // The last answers: a few periods to arrive.
  const std::int64_t end = MonotonicNowNs() + 50'000'000;
  while (MonotonicNowNs() < end) {
    collect();
    SleepUntilMonotonicNs(MonotonicNowNs() + 200'000);
  }
  tally.Finish(periods);
  if (monitor) report.monitor = watched.summary();
  if (const DeviceLink* status_link = StatusLink(link, monitor)) {
    report.status = status_link->LastStatus();
    report.execution = status_link->Execution();
  }
  report.duration_s = settings.duration_s;
  return report;
}

}  // namespace hapticsim::device
