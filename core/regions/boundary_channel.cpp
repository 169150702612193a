#include "core/regions/boundary_channel.hpp"

#include <cassert>
#include <utility>

namespace hapticsim {

BoundaryChannel::BoundaryChannel(int width) : width_(width) {
  for (Slot& slot : slots_) {
    slot.values = std::make_unique<std::atomic<double>[]>(static_cast<size_t>(width));
    for (int i = 0; i < width; ++i) slot.values[i].store(0.0, std::memory_order_relaxed);
  }
}

void BoundaryChannel::Publish(double time_s, std::span<const double> values) noexcept {
  assert(static_cast<int>(values.size()) == width_);
  const std::uint64_t generation = published_.load(std::memory_order_relaxed) + 1;
  Slot& slot = slots_[generation % kSlots];
  const std::uint64_t sequence = slot.sequence.load(std::memory_order_relaxed);
  slot.sequence.store(sequence + 1, std::memory_order_relaxed);  // odd: writing
  std::atomic_thread_fence(std::memory_order_release);
  slot.generation.store(generation, std::memory_order_relaxed);
  slot.time_s.store(time_s, std::memory_order_relaxed);
  for (int i = 0; i < width_; ++i) slot.values[i].store(values[i], std::memory_order_relaxed);
  slot.sequence.store(sequence + 2, std::memory_order_release);  // even: consistent
  published_.store(generation, std::memory_order_release);
}

bool BoundaryChannel::TryReadSlot(std::uint64_t generation, Snapshot* out) const noexcept {
  const Slot& slot = slots_[generation % kSlots];
  for (int attempt = 0; attempt < 8; ++attempt) {
    const std::uint64_t before = slot.sequence.load(std::memory_order_acquire);
    if (before & 1u) continue;  // being written
    const std::uint64_t stored = slot.generation.load(std::memory_order_relaxed);
    const double time = slot.time_s.load(std::memory_order_relaxed);
    for (int i = 0; i < width_; ++i)
      out->values[i] = slot.values[i].load(std::memory_order_relaxed);
    std::atomic_thread_fence(std::memory_order_acquire);
    if (slot.sequence.load(std::memory_order_relaxed) != before) continue;  // torn: retry
    if (stored != generation) return false;  // overwritten by a newer publication
    out->generation = stored;
    out->time_s = time;
    return true;
  }
  return false;
}

BoundaryChannel::ReadPair::ReadPair(int width) {
  for (Snapshot* s : {&newer, &older, &next_newer_, &next_older_}) {
    s->values = Eigen::VectorXd::Zero(width);
  }
}

bool BoundaryChannel::TryReadLatestTwo(ReadPair* pair) const noexcept {
  Snapshot& newer = pair->next_newer_;
  Snapshot& older = pair->next_older_;
  assert(newer.values.size() == width_ && older.values.size() == width_);
  // Read into the pair's spare snapshots; only a whole, consistent pair replaces the one it has
  // (swapping vectors: no copy, no allocation).
  for (int attempt = 0; attempt < 8; ++attempt) {
    const std::uint64_t latest = published_.load(std::memory_order_acquire);
    if (latest == 0) return false;
    if (!TryReadSlot(latest, &newer)) continue;
    if (latest == 1) {
      older.time_s = newer.time_s;
      older.generation = newer.generation;
      older.values = newer.values;
    } else if (!TryReadSlot(latest - 1, &older)) {
      continue;
    }
    std::swap(pair->newer, newer);
    std::swap(pair->older, older);
    return true;
  }
  return false;
}

void BoundaryChannel::Clear() {
  published_.store(0, std::memory_order_relaxed);
  for (Slot& slot : slots_) {
    slot.generation.store(0, std::memory_order_relaxed);
    for (int i = 0; i < width_; ++i) slot.values[i].store(0.0, std::memory_order_relaxed);
  }
}

void BoundaryChannel::ScaleAll(double factor) {
  for (Slot& slot : slots_) {
    for (int i = 0; i < width_; ++i) {
      slot.values[i].store(slot.values[i].load(std::memory_order_relaxed) * factor,
                           std::memory_order_relaxed);
    }
  }
}

}  // namespace hapticsim
