#pragma once

#include <spdlog/spdlog.h>

#include <algorithm>
#include <string>
#include <vector>

#include "daemon/haptic_loop.hpp"

namespace hapticsim {

// The last cycles of the primary loop, kept by the supervisor and logged when a fault happens.
class BlackBox {
 public:
  explicit BlackBox(size_t cycles) : records_(cycles) {}
  void Drain(HapticLoop& loop) {
    BlackBoxRecord record;
    while (loop.black_box().Pop(&record)) {
      records_[next_ % records_.size()] = record;
      ++next_;
    }
  }
  void Dump(const std::string& why) const {
    const size_t count = std::min(next_, records_.size());
    spdlog::error("black box ({}): the last {} primary periods, oldest first", why, count);
    if (count == 0) return;
    const std::int64_t end = records_[(next_ - 1) % records_.size()].time_ns;
    for (size_t i = next_ - count; i < next_; ++i) {
      const BlackBoxRecord& r = records_[i % records_.size()];
      spdlog::error(
          "black box: t {:+.1f} ms seq {} tip ({:.4f}, {:.4f}, {:.4f}) m force sent "
          "({:.3f}, {:.3f}, {:.3f}) N simulated ({:.3g}, {:.3g}, {:.3g}) N error {:.2f} % "
          "flags 0x{:x}",
          (r.time_ns - end) * 1e-6, r.seq, r.position_m[0], r.position_m[1], r.position_m[2],
          r.force_n[0], r.force_n[1], r.force_n[2], r.raw_force_n[0], r.raw_force_n[1],
          r.raw_force_n[2], r.error_percent, r.flags);
    }
  }

 private:
  std::vector<BlackBoxRecord> records_;
  size_t next_ = 0;
};

}  // namespace hapticsim
