#pragma once

#include <array>
#include <cstdint>

namespace hapticsim {

/**
 * The tool tip at the primary's release time, from device inputs that arrive with jitter.
 *
 * A device samples its tip on its own regular clock, one seq per device period; its messages
 * reach us after a latency that varies (a late driver thread, a busy bus, our own late wake).
 * Taking "the newest input" every period turns that variation into uneven steps of the contact
 * node — two device periods' motion in one of our periods, none in the next — and the driven
 * node's inertia turns uneven steps into force spikes (0.34 N measured on a 0.36 N press when a
 * driver thread and the primary were both woken a period late).
 *
 * So the tip is placed on the device's own timeline instead. Input seq s was sampled at device
 * time s · T (T: the nominal device period); the smallest latency, received − s · T, of the last
 * kLatencyWindow inputs maps our release time onto that timeline. A late input does not move a
 * minimum. A window rather than the minimum of all time, and the minimum carried forward along
 * the window's trend (how much later each seq arrives than the one before, from the quickest
 * input of each half), follow a device whose clock is not quite ours: a crystal's 100 ppm, or a
 * driver that sleeps 1 ms between inputs and so runs 5 % slow (then the tip runs at the
 * device's pace, still one period behind the newest input). The tip
 * is taken one device period behind the mapped time: there the two inputs around it have
 * normally both arrived and the tip is interpolated between them — a constant delay of one device
 * period instead of the newest input's 0 to 1 period sawtooth, and no overshoot where the motion
 * turns. An input later than that is made up for by continuing the last two inputs' velocity,
 * for at most `max_ahead_s` past the newest; then the tip is held.
 *
 * The seq is the device's clock, not the message's utime: drivers in the field fill utime from
 * clocks of every kind (and some not at all), while "seq increases by one per device period" is
 * what the input contract says. A seq that goes back (a restarted driver) starts afresh, and so
 * does a latency more than kRelock_ns above the window's minimum (a driver that paused without
 * counting the periods).
 *
 * Plain logic for the primary thread: no allocation, no locks, no exceptions.
 */
class InputResampler {
 public:
  InputResampler(double device_period_s, double max_ahead_s) noexcept;

  /** A new device input (a seq other than the last one added). */
  void Add(std::int64_t seq, std::int64_t received_ns,
           const std::array<double, 3>& position_m) noexcept;

  /** Whether an input has been added since construction or the last Reset. */
  bool has_input() const noexcept { return count_ > 0; }

  /** The tip at our CLOCK_MONOTONIC time `at_ns` (the newest input's position with only one). */
  std::array<double, 3> TipAt(std::int64_t at_ns) const noexcept;

  /** Forgets every input. */
  void Reset() noexcept { count_ = 0, latencies_ = 0, next_latency_ = 0; }

  /**
   * Inputs held. A device and a primary held up together (a loaded machine) send their missed
   * inputs and run their missed periods back to back: every late period's tip must still lie
   * between two inputs held, or it is clamped to the oldest one and the contact node jumps.
   * With three held, a 4-period burst put the tip 34 µm ahead in one period (a 0.11 N spike on
   * a 1.4 N press) and held it there for three. 256 device periods at 1 kHz cover a stall up to
   * the port guard's default watchdog (device.watchdog_s, 0.2 s), beyond which the force is
   * released anyway; a period further back than the history is clamped to its oldest input.
   */
  static constexpr int kHistory = 256;
  /** The longest timeline, ns from its first seq: 2⁵³, every whole ns exact in a double (104
   *  days). (Counting periods instead let seq 1 then 2⁵³ give device times ~1 ms apart.) */
  static constexpr double kExactNs = 9007199254740992.0;

  /** How many of the newest inputs' latencies the timeline's mapping takes the minimum of. */
  static constexpr int kLatencyWindow = 16;
  /** A latency this much above the window's minimum is a new timeline, not a late input. */
  static constexpr double kRelock_ns = 20e6;

 private:
  struct Input {
    double device_ns = 0;  // seq · T
    std::array<double, 3> position_m{};
  };

  double period_ns_;
  double max_ahead_ns_;
  std::array<Input, kHistory> history_{};  // a ring, in seq order
  int count_ = 0;                          // inputs it holds
  int newest_ = -1;                        // where the newest is
  std::int64_t newest_seq_ = 0;
  std::int64_t newest_periods_ = 0;  // device periods from the timeline's first input to the newest
  std::array<double, kLatencyWindow> latencies_ns_{};  // received − device time, a ring
  int latencies_ = 0;                                  // how many the ring holds
  int next_latency_ = 0;                               // where the next one goes
  double latency_floor_ns_ = 0;                        // LatencyFloor() after the last Add

  double LatencyFloor() const noexcept;
  /** The i-th newest input held (0: the newest), i < count_. */
  const Input& Newest(int i) const noexcept {
    return history_[(newest_ - i + kHistory) % kHistory];
  }
};

}  // namespace hapticsim
