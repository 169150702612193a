#pragma once

#include <cstdint>
#include <optional>
#include <string>
#include <vector>

namespace hapticsim {

/**
 * A thread the force depends on, as the supervisor's health check sees it: its newest sign of
 * life and how long it may go without one.
 */
struct ThreadBeat {
  std::string name;            ///< as the log and status name it: "primary", "I/O", …
  std::int64_t last_ns = 0;    ///< its newest sign of life, CLOCK_MONOTONIC ns
  double max_silence_s = 0.5;  ///< longer without one is a stall
  bool expected = true;        ///< false while it is meant to be idle (asleep, no job)
  bool force_path = true;      ///< without it no force is computed or reaches the device
};

/** A beat found silent for too long. */
struct Stall {
  std::string name;
  double silent_s = 0;
  bool force_path = true;
};

class HapticLoop;

/**
 * The daemon's threads as beats: the primary (0.1 s or 50 periods), the I/O thread (0.5 s,
 * `io_alive_ns`), each secondary while the regions are awake (0.5 s, counted from
 * `regions_since_ns` at the latest: new or just-woken threads get that long to run; the caller
 * reads `regions_asleep` once, with the same read that decides regions_since_ns), and the
 * two background workers while a job runs (300 s: a stability estimate takes up to a minute).
 */
std::vector<ThreadBeat> HealthBeats(HapticLoop& loop, double primary_period_s,
                                    std::int64_t io_alive_ns, std::int64_t regions_since_ns,
                                    bool regions_asleep, std::int64_t choice_since_ns,
                                    std::int64_t verify_since_ns);

/** The expected beats silent for longer than they may be at `now_ns`, in the order given. */
std::vector<Stall> StalledThreads(const std::vector<ThreadBeat>& beats, std::int64_t now_ns);

/** "I/O (0.8 s), secondary (1.2 s)": the stalls in words; "" when none. */
std::string DescribeStalls(const std::vector<Stall>& stalls);

/** Whether any stall is on the force path: then the systemd watchdog is not pinged. */
bool AnyOnForcePath(const std::vector<Stall>& stalls);

/**
 * When the stalled threads are said (the log and systemd's status line): when the set of stalled
 * threads changes, and every 10 s while some stay stalled.
 */
class StallReport {
 public:
  /** What to say at `now_ns`: nullopt nothing, "" every thread runs again, else DescribeStalls. */
  std::optional<std::string> Due(const std::vector<Stall>& stalls, std::int64_t now_ns);
  static constexpr std::int64_t kRepeat_ns = 10'000'000'000;

 private:
  std::string said_names_;  // the stalled threads' names as last said
  std::int64_t said_ns_ = 0;
};

}  // namespace hapticsim
