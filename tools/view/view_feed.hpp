#pragma once
// hapticsim view's side of the bus: it listens to a running hapticsimd over LCM and keeps the
// newest of each message as JSON for the page. The daemon's messages come at up to 1 kHz; the page
// draws at its screen's rate, so only the newest of each kind is kept and a page that reads late
// skips what it missed rather than falling behind.
#include <atomic>
#include <chrono>
#include <condition_variable>
#include <cstdint>
#include <memory>
#include <mutex>
#include <nlohmann/json_fwd.hpp>
#include <string>
#include <thread>
#include <vector>

namespace lcm {
class LCM;
}

namespace hapticsim::view {

struct FeedChannels {
  std::string device = "HAPTIC_DEVICE", force = "HAPTIC_FORCE", status = "HAPTIC_STATUS",
              deformation = "HAPTIC_DEFORMATION";
};

/** What the page is sent: one JSON text per kind of message, the newest, with a version each.
 *  The texts are shared, not copied: a snapshot costs a few reference counts. */
struct FeedSnapshot {
  using Text = std::shared_ptr<const std::string>;
  uint64_t version = 0;  ///< grows with every message taken in; 0: nothing yet
  Text deformation, force, tool, status;
  uint64_t deformation_version = 0, force_version = 0, tool_version = 0, status_version = 0;
};

class ViewFeed {
 public:
  /** Subscribes on lcm_url; throws hapticsim::Error with the URL when LCM cannot start. */
  ViewFeed(const std::string& lcm_url, FeedChannels channels);
  ~ViewFeed();
  ViewFeed(const ViewFeed&) = delete;
  ViewFeed& operator=(const ViewFeed&) = delete;

  /** Waits up to `timeout` for a snapshot newer than `seen`; returns the newest either way. */
  FeedSnapshot WaitNewer(uint64_t seen, std::chrono::milliseconds timeout) const;

  /** Messages taken in and messages that could not be decoded, since the start. */
  uint64_t messages() const { return messages_.load(); }
  uint64_t decode_errors() const { return decode_errors_.load(); }

 private:
  class Handlers;
  void Run();
  void Publish(FeedSnapshot::Text FeedSnapshot::*text, uint64_t FeedSnapshot::*version,
               const nlohmann::json& message);

  std::unique_ptr<lcm::LCM> lcm_;
  std::unique_ptr<Handlers> handlers_;
  mutable std::mutex mutex_;
  mutable std::condition_variable changed_;
  FeedSnapshot snapshot_;
  std::atomic<uint64_t> messages_{0}, decode_errors_{0};
  std::atomic<bool> stop_{false};
  std::thread thread_;
};

}  // namespace hapticsim::view
