#pragma once

#include <cstdint>
#include <optional>
#include <string>

namespace hapticsim {

/**
 * When a primary that overruns again and again is worth the black box: kBurst late periods
 * within a window of at least kWindow_ns (however often the supervisor's tick counts them), at
 * most once a minute. The supervisor's thread.
 */
class OverrunBurst {
 public:
  static constexpr int kBurst = 10;
  static constexpr std::int64_t kWindow_ns = 20'000'000;
  static constexpr std::int64_t kAtMostEvery_ns = 60'000'000'000;

  explicit OverrunBurst(std::int64_t now_ns) : window_start_ns_(now_ns) {}

  /** Counts `misses` late primary periods seen at `now_ns`; the dump's reason when one is due. */
  std::optional<std::string> Count(int misses, std::int64_t now_ns) {
    late_ += misses;
    if (now_ns - window_start_ns_ < kWindow_ns) return std::nullopt;
    std::optional<std::string> due;
    if (late_ >= kBurst && (last_dump_ns_ < 0 || now_ns - last_dump_ns_ > kAtMostEvery_ns)) {
      due = std::to_string(late_) + " primary periods late within " +
            std::to_string((now_ns - window_start_ns_) / 1'000'000) + " ms";
      last_dump_ns_ = now_ns;
    }
    late_ = 0;
    window_start_ns_ = now_ns;
    return due;
  }

 private:
  int late_ = 0;  // since window_start_ns_
  std::int64_t window_start_ns_;
  std::int64_t last_dump_ns_ = -1;
};

}  // namespace hapticsim
