#include "device/device_session.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

#include "rt/monotonic_clock.hpp"
#include "hapticsim/force_feedback_t.hpp"

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

SessionReport RunSession(DeviceMotion& motion, DeviceLink& link, DeviceLink* monitor,
                         const SessionSettings& settings,
                         const std::function<void(const SessionReport&)>& each_second) {
  const double period_ns = 1e9 / settings.rate_hz;
  const std::int64_t periods = std::llround(settings.duration_s * settings.rate_hz);
  constexpr int kBurstPeriods = 8;
  // Then silence longer than the daemon's stale_after (0.05 s by default): stale input.
  constexpr int kSilentPeriods = 100;
  std::vector<std::int64_t> burst_starts;
  for (double t : settings.bad_input_bursts_s)
    burst_starts.push_back(std::llround(t * settings.rate_hz));

  SessionReport report;
  if (settings.press_period_inputs > 0) {  // whole presses only: a partial last one is left out
    report.press_peaks_n.assign(static_cast<std::size_t>(periods / settings.press_period_inputs),
                                0.0);
  }
  std::vector<std::int64_t> sent_ns(static_cast<std::size_t>(periods) + 2, 0);
  std::vector<char> bad(sent_ns.size(), 0), answered(sent_ns.size(), 0);
  std::vector<double> latencies_us, second_latencies_us;
  latencies_us.reserve(static_cast<std::size_t>(periods));
  StreamCounter stream, watched;
  std::vector<Answer> answers, watched_answers;
  std::int64_t last_burst_end = -1;
  std::int64_t second_answers = 0;
  std::optional<Answer> previous;
  std::array<double, 3> last_good{};

  auto take = [&](const Answer& a) {
    stream.Add(a);
    ++second_answers;
    report.flags_seen |= a.flags;
    const bool finite = std::isfinite(a.force_n[0] + a.force_n[1] + a.force_n[2]);
    if (!finite) ++report.nonfinite_forces;
    const bool contact = a.flags & force_feedback_t::FLAG_IN_CONTACT;
    const bool stale = a.flags & force_feedback_t::FLAG_INPUT_STALE;
    if (contact) ++report.contact_answers;
    const bool limited = a.flags & force_feedback_t::FLAG_FORCE_LIMITED;
    if (!contact && !limited && finite &&
        (a.force_n[0] != 0 || a.force_n[1] != 0 || a.force_n[2] != 0)) {
      ++report.force_out_of_contact;
    }
    if (finite) {
      const double magnitude = std::hypot(a.force_n[0], a.force_n[1], a.force_n[2]);
      report.largest_force_n = std::max(report.largest_force_n, magnitude);
      if (settings.press_period_inputs > 0 && a.seq >= 1) {
        const auto press = static_cast<std::size_t>((a.seq - 1) / settings.press_period_inputs);
        if (press < report.press_peaks_n.size()) {
          report.press_peaks_n[press] = std::max(report.press_peaks_n[press], magnitude);
        }
      }
    }
    if (previous && finite) {
      report.largest_force_step_any_n = std::max(
          report.largest_force_step_any_n,
          std::hypot(a.force_n[0] - previous->force_n[0], a.force_n[1] - previous->force_n[1],
                     a.force_n[2] - previous->force_n[2]));
    }
    if (previous && contact && !stale && (previous->flags & force_feedback_t::FLAG_IN_CONTACT) &&
        finite) {
      const double step =
          std::hypot(a.force_n[0] - previous->force_n[0], a.force_n[1] - previous->force_n[1],
                     a.force_n[2] - previous->force_n[2]);
      report.largest_force_step_n = std::max(report.largest_force_step_n, step);
    }
    previous = a;
    if (last_burst_end >= 0 && a.seq > last_burst_end) ++report.answers_after_last_burst;
    // Every input the answer names (first_seq … seq: those the daemon's period took), each with
    // its own round trip.
    const std::int64_t first = a.first_seq >= 1 && a.first_seq <= a.seq ? a.first_seq : a.seq;
    for (std::int64_t seq = std::max<std::int64_t>(first, 1);
         seq <= a.seq && seq < static_cast<std::int64_t>(sent_ns.size()); ++seq) {
      if (bad[seq] || sent_ns[seq] <= 0 || answered[seq]) continue;
      answered[seq] = 1;
      const double latency_us = (a.received_ns - sent_ns[seq]) * 1e-3;
      latencies_us.push_back(latency_us);
      second_latencies_us.push_back(latency_us);
      if (latency_us > period_ns * 1e-3) ++report.late_answers;
    }
  };
  auto collect = [&] {
    answers.clear();
    link.Collect(&answers);
    for (const Answer& a : answers) take(a);
    if (monitor) {
      watched_answers.clear();
      monitor->Collect(&watched_answers);
      for (const Answer& a : watched_answers) watched.Add(a);
    }
  };

  const std::int64_t start = MonotonicNowNs() + 2'000'000;
  std::int64_t next_second = 1;
  for (std::int64_t n = 0; n < periods; ++n) {
    const std::int64_t release = start + std::llround(n * period_ns);
    SleepUntilMonotonicNs(release);
    const std::int64_t seq = n + 1;
    const std::optional<std::array<double, 3>> next = motion.Next();  // none: a replayed silence
    std::array<double, 3> tip = next.value_or(last_good);
    const auto burst = std::find_if(burst_starts.begin(), burst_starts.end(), [&](std::int64_t b) {
      return n >= b && n < b + kBurstPeriods;
    });
    const bool silent =
        !next || std::any_of(burst_starts.begin(), burst_starts.end(), [&](std::int64_t b) {
          return n >= b + kBurstPeriods && n < b + kBurstPeriods + kSilentPeriods;
        });
    if (silent) {
      bad[seq] = 1;  // nothing sent: nothing to answer
      ++report.silent_periods;
    } else if (burst != burst_starts.end()) {
      // Bad input, one kind after the other; the daemon must refuse it and keep the last good.
      bad[seq] = 1;
      ++report.bad_inputs_sent;
      std::int64_t sent_seq = seq;
      switch ((n - *burst) % 4) {
        case 0:
          tip[0] = std::numeric_limits<double>::quiet_NaN();
          break;
        case 1:
          tip = {last_good[0], last_good[1], 5.0};
          break;  // far outside
        case 2:
          tip = {last_good[0] + 0.2, last_good[1], last_good[2]};
          break;  // 200 m/s
        default:
          sent_seq = std::max<std::int64_t>(1, seq - 100);
          tip = last_good;
          break;
      }
      link.Send(sent_seq, release / 1000, tip);
      if (link.SendGarbage()) report.bad_inputs_sent += 2;
      if (monitor && monitor->SendGarbage()) report.bad_inputs_sent += 2;
      last_burst_end = seq;
    } else {
      last_good = tip;
      link.Send(seq, release / 1000, tip);
      ++report.inputs_sent;
    }
    sent_ns[seq] = MonotonicNowNs();
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
      SecondSummary s;
      s.t_s = static_cast<double>(next_second);
      s.latency = Summarise(second_latencies_us);
      s.answers = second_answers;
      report.seconds.push_back(s);
      second_latencies_us.clear();
      second_answers = 0;
      ++next_second;
      report.stream = stream.summary();
      report.latency.count = static_cast<std::int64_t>(latencies_us.size());
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
  for (std::int64_t seq = 1; seq <= periods; ++seq) {
    if (!bad[seq] && !answered[seq]) ++report.unanswered_inputs;
  }
  report.stream = stream.summary();
  if (monitor) report.monitor = watched.summary();
  report.latency = Summarise(latencies_us);
  if (const DeviceLink* status_link = StatusLink(link, monitor)) {
    report.status = status_link->LastStatus();
    report.execution = status_link->Execution();
  }
  report.duration_s = settings.duration_s;
  return report;
}

}  // namespace hapticsim::device
