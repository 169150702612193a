#pragma once

#include <Eigen/Core>
#include <algorithm>
#include <atomic>
#include <cstdint>
#include <memory>
#include <span>

namespace hapticsim {

/**
 * Time-stamped interface state passed from one region to another: one writer, any number of
 * readers, lock-free. The writer publishes (simulation time, values) snapshots into a ring of
 * seqlock slots; a reader copies the newest two consistent snapshots (the two bracketing the
 * time it needs, for interpolation or extrapolation).
 *
 * Every value is a relaxed std::atomic<double> and every slot has a sequence counter (odd while
 * being written), so a reader never sees a torn snapshot and the exchange is free of data races
 * under the C++ memory model (and ThreadSanitizer). The ring holds kSlots snapshots; a reader
 * that falls more than kSlots − 2 publications behind simply reads the newest ones (uORB style).
 *
 * Threads: Publish() from one thread only; TryReadLatestTwo() from any thread. Neither blocks,
 * allocates or throws.
 */
class BoundaryChannel {
 public:
  static constexpr int kSlots = 4;

  /** A snapshot as the reader sees it. values must be sized to width() before reading. */
  struct Snapshot {
    double time_s = 0;
    std::uint64_t generation = 0;  ///< 1 for the first publication, counting up
    Eigen::VectorXd values;
  };

  /**
   * What one reader keeps: the newest two snapshots it has read, and room to read the next two
   * into, so that a read that fails part-way leaves `newer` and `older` as they were — a pair
   * the reader can go on interpolating between.
   */
  class ReadPair {
   public:
    explicit ReadPair(int width = 0);
    Snapshot newer, older;

   private:
    friend class BoundaryChannel;
    Snapshot next_newer_, next_older_;
  };

  explicit BoundaryChannel(int width);

  int width() const { return width_; }

  /** Writer thread only. @pre values.size() == width(). */
  void Publish(double time_s, std::span<const double> values) noexcept;

  /**
   * Copies the newest snapshot into pair->newer and the one published before it into
   * pair->older (both equal to the newest when only one has been published).
   * @return false when nothing has been published yet, or no consistent copy could be taken
   *         within a few attempts because the writer kept overwriting the slots; the pair is then
   *         exactly as it was. @pre the pair was made for this channel's width.
   */
  [[nodiscard]] bool TryReadLatestTwo(ReadPair* pair) const noexcept;

  /** Forgets every snapshot (not thread-safe: only while no thread uses the channel). */
  void Clear();
  /** Multiplies every stored value (not thread-safe; for the spectral-radius estimate). */
  void ScaleAll(double factor);

 private:
  struct Slot {
    std::atomic<std::uint64_t> sequence{0};
    std::atomic<std::uint64_t> generation{0};
    std::atomic<double> time_s{0};
    std::unique_ptr<std::atomic<double>[]> values;
  };
  bool TryReadSlot(std::uint64_t generation, Snapshot* out) const noexcept;

  int width_;
  Slot slots_[kSlots];
  std::atomic<std::uint64_t> published_{0};
};

// Value `i` at time t on the line through two snapshots (the newer one alone if they coincide).
// Callers clamp t from above: a late writer must never be extrapolated far. A reader that has
// fallen behind both snapshots (its thread was late by more than the ring holds) gets the older
// one: extrapolating backwards multiplies the difference between the snapshots by the lag, and
// fed back through the coupling that diverges within a few late periods.
inline double OnLine(const BoundaryChannel::Snapshot& older, const BoundaryChannel::Snapshot& newer,
                     int i, double t) noexcept {
  const double span = newer.time_s - older.time_s;
  if (!(span > 0)) return newer.values[i];
  t = std::max(t, older.time_s);
  return newer.values[i] + (t - newer.time_s) / span * (newer.values[i] - older.values[i]);
}

}  // namespace hapticsim
