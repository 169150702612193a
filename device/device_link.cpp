#include "device/device_link.hpp"

#include <atomic>
#include <lcm/lcm-cpp.hpp>
#include <mutex>
#include <thread>

#include "core/error.hpp"
#include "rt/monotonic_clock.hpp"
#include "hapticsim/device_input_t.hpp"
#include "hapticsim/force_feedback_t.hpp"
#include "ipc/lcm_start.hpp"
#include "ipc/shm_device_client.hpp"

namespace hapticsim::device {
namespace {

class LcmLink final : public DeviceLink {
 public:
  LcmLink(const std::string& url, std::string device_channel, const std::string& force_channel,
          const std::string& status_channel, bool listen_only)
      : lcm_(url), device_channel_(std::move(device_channel)), listen_only_(listen_only) {
    if (const std::string problem = LcmStartProblem(lcm_, url); !problem.empty()) {
      throw Error(problem);
    }
    lcm_.subscribe(force_channel, &LcmLink::OnForce, this);
    lcm_.subscribe(status_channel, &LcmLink::OnStatus, this);
    thread_ = std::thread([this] {
      while (!stop_) lcm_.handleTimeout(5);
    });
  }
  ~LcmLink() override {
    stop_ = true;
    thread_.join();
  }

  void Send(std::int64_t seq, std::int64_t utime_us,
            const std::array<double, 3>& position_m) override {
    if (listen_only_) return;
    device_input_t input{};
    input.utime = utime_us;
    input.seq = seq;
    for (int c = 0; c < 3; ++c) input.position[c] = position_m[c];
    lcm_.publish(device_channel_, &input);
  }
  bool SendGarbage() override {
    if (listen_only_) return false;
    static const char kGarbage[] = "not an LCM message of any type";
    lcm_.publish(device_channel_, kGarbage, sizeof kGarbage);
    const status_t wrong_type{};  // well-formed, but its fingerprint is not device_input_t's
    lcm_.publish(device_channel_, &wrong_type);
    return true;
  }
  void Collect(std::vector<Answer>* out) override {
    std::lock_guard lock(mutex_);
    out->insert(out->end(), pending_.begin(), pending_.end());
    pending_.clear();
  }
  bool needs_polling() const override { return false; }
  std::optional<status_t> LastStatus() const override {
    std::lock_guard lock(mutex_);
    return status_;
  }
  std::vector<RegionExecution> Execution() const override {
    std::lock_guard lock(mutex_);
    return execution_.Summary();
  }
  std::string name() const override { return "lcm"; }

 private:
  void OnForce(const lcm::ReceiveBuffer*, const std::string&, const force_feedback_t* f) {
    Answer a{f->period,
             f->seq,
             f->utime,
             MonotonicNowNs(),
             {f->force[0], f->force[1], f->force[2]},
             f->error_percent,
             f->flags,
             f->first_seq};
    std::lock_guard lock(mutex_);
    pending_.push_back(a);
  }
  void OnStatus(const lcm::ReceiveBuffer*, const std::string&, const status_t* s) {
    std::lock_guard lock(mutex_);
    status_ = *s;
    execution_.Add(*s);
  }

  lcm::LCM lcm_;
  std::string device_channel_;
  bool listen_only_;
  std::atomic<bool> stop_{false};
  std::thread thread_;
  mutable std::mutex mutex_;
  std::vector<Answer> pending_;
  std::optional<status_t> status_;
  ExecutionHistory execution_;
};

class ShmLink final : public DeviceLink {
 public:
  explicit ShmLink(const std::string& socket_path) : client_(socket_path) {}

  void Send(std::int64_t seq, std::int64_t utime_us,
            const std::array<double, 3>& position_m) override {
    client_.WriteInput(seq, utime_us, position_m);
  }
  void Collect(std::vector<Answer>* out) override {
    const std::int64_t now = MonotonicNowNs();
    last_period_ = client_.ReadForcesSince(last_period_, [&](const shm::ShmForceOutput& f) {
      if (f.seq < 0) return;  // before the first input: nothing answered
      out->push_back(Answer{f.period,
                            f.seq,
                            f.utime,
                            now,
                            {f.force_n[0], f.force_n[1], f.force_n[2]},
                            f.error_percent,
                            f.flags,
                            f.first_seq});
    });
  }
  bool needs_polling() const override { return true; }
  std::string name() const override { return "shm"; }

 private:
  shm::ShmDeviceClient client_;
  std::int64_t last_period_ = -1;
};

}  // namespace

std::unique_ptr<DeviceLink> MakeLcmLink(const std::string& url, const std::string& device_channel,
                                        const std::string& force_channel,
                                        const std::string& status_channel, bool listen_only) {
  return std::make_unique<LcmLink>(url, device_channel, force_channel, status_channel, listen_only);
}

std::unique_ptr<DeviceLink> MakeShmLink(const std::string& socket_path) {
  return std::make_unique<ShmLink>(socket_path);
}

}  // namespace hapticsim::device
