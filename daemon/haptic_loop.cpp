#include "daemon/haptic_loop.hpp"

#include <pthread.h>
#include <sched.h>
#include <time.h>

#include <cmath>
#include <cstring>

#include "core/error.hpp"

namespace hapticsim {
namespace {

void SleepUntilNs(std::int64_t wake_ns) noexcept {
  timespec ts{};
  ts.tv_sec = wake_ns / 1'000'000'000;
  ts.tv_nsec = wake_ns % 1'000'000'000;
  while (clock_nanosleep(CLOCK_MONOTONIC, TIMER_ABSTIME, &ts, nullptr) == EINTR) {
  }
}

}  // namespace

std::int64_t HapticLoop::NowNs() noexcept {
  timespec ts{};
  clock_gettime(CLOCK_MONOTONIC, &ts);
  return static_cast<std::int64_t>(ts.tv_sec) * 1'000'000'000 + ts.tv_nsec;
}

HapticLoop::HapticLoop(const Scene& scene, const Options& options)
    : scene_(scene), options_(options), regions_(std::make_unique<AsyncRegions>(scene)) {
  BuildSchedule();
  const LatticeIndex contact = ContactNode(scene);
  const double h = scene.mesh.edge_m / (scene.mesh.nodes - 1);
  for (int c = 0; c < 3; ++c) contact_rest_[c] = contact[c] * h;
}

void HapticLoop::BuildSchedule() {
  const int count = regions_->num_regions();
  monitors_.clear();
  tick_ns_ = 1e9 / static_cast<double>(regions_->ticks_per_second());
  lead_ns_.assign(static_cast<size_t>(count), 0);
  for (int a = 0; a < count; ++a) {
    const std::int64_t nominal = regions_->period_ticks(a) * regions_->schedule(a).substeps;
    monitors_.push_back(std::make_unique<DeadlineMonitor>(nominal * tick_ns_ * 1e-9));
    if (a > 0) {
      const std::int64_t inner = regions_->period_ticks(a - 1) * regions_->schedule(a - 1).substeps;
      lead_ns_[a] = lead_ns_[a - 1] + static_cast<std::int64_t>(1.25 * inner * tick_ns_);
    }
  }
}

void HapticLoop::Reconfigure(const Scene& scene) {
  auto regions = std::make_unique<AsyncRegions>(scene);  // the slow part, while the loop runs
  const bool was_running = running_.load();
  Stop();
  scene_ = scene;
  regions_ = std::move(regions);
  BuildSchedule();
  if (was_running) Start();
}

HapticLoop::~HapticLoop() { Stop(); }

void HapticLoop::SetErrorState(double error_percent, std::int32_t flags) noexcept {
  error_percent_.store(error_percent, std::memory_order_relaxed);
  error_flags_.store(flags, std::memory_order_relaxed);
}

void HapticLoop::PrimaryPeriod(std::int64_t now_ns) noexcept {
  DeviceSample sample;
  if (input_.Read(&sample)) last_input_ = sample;
  const bool have = last_input_.seq >= 0;
  const bool stale =
      !have || static_cast<double>(now_ns - last_input_.received_ns) > options_.stale_after_s * 1e9;
  std::int32_t flags = error_flags_.load(std::memory_order_relaxed);
  if (stale) {
    flags |= force_flags::kInputStale;
    if (have) stale_periods_.fetch_add(1, std::memory_order_relaxed);
  }
  if (last_input_.latest_rejected) flags |= force_flags::kInputRejected;

  // Stale input holds the contact where it was; fresh input moves it.
  if (have && !stale) {
    const auto& p = last_input_.position_m;
    const double depth = p[2] - contact_rest_[2];
    if (depth <= 0) await_lift_off_ = false;
    const bool touching = depth > 0 && !await_lift_off_;
    if (touching && !in_contact_) touch_down_ = p;
    in_contact_ = touching;
    displacement_ = touching
                        ? std::array<double, 3>{p[0] - touch_down_[0], p[1] - touch_down_[1], depth}
                        : std::array<double, 3>{0.0, 0.0, 0.0};
  }
  const int substeps = regions_->schedule(kPrimaryRegion).substeps;
  std::array<double, 3> reaction{};
  for (int q = 1; q <= substeps; ++q) {
    // The device gives one position per period: every substep holds it.
    const std::array<double, 3> r = regions_->StepPrimary(displacement_);
    if (q == 1) reaction = r;
  }
  ForceRecord out;
  BlackBoxRecord box;
  box.raw_force_n = {-reaction[0], -reaction[1], -reaction[2]};
  out.seq = last_input_.seq;
  out.utime_us = now_ns / 1000;
  out.error_percent = error_percent_.load(std::memory_order_relaxed);
  const bool render = in_contact_ && !(stale && options_.zero_force_when_stale);
  if (render) {
    for (int c = 0; c < 3; ++c) out.force_n[c] = -reaction[c];
    const double magnitude = std::hypot(out.force_n[0], out.force_n[1], out.force_n[2]);
    // Stability first: a force no tissue model should give is never sent to a device.
    if (!std::isfinite(magnitude) || magnitude > options_.max_force_n) {
      out.force_n = {0.0, 0.0, 0.0};
      force_faults_.fetch_add(1, std::memory_order_relaxed);
    }
  }
  if (in_contact_) {
    flags |= force_flags::kInContact;
    last_contact_ns_.store(now_ns, std::memory_order_relaxed);
  }
  out.flags = flags;
  forces_.Push(out);
  box.time_ns = now_ns;
  box.seq = out.seq;
  box.position_m = last_input_.position_m;
  box.force_n = out.force_n;
  box.error_percent = out.error_percent;
  box.flags = flags;
  black_box_.Push(box);
}

void HapticLoop::PrimaryThread(std::int64_t origin_ns) {
  DeadlineMonitor& monitor = *monitors_[kPrimaryRegion];
  while (!stop_.load(std::memory_order_acquire)) {
    const std::int64_t release =
        origin_ns + static_cast<std::int64_t>(regions_->state_ticks(kPrimaryRegion) * tick_ns_);
    SleepUntilNs(release);
    const std::int64_t woke = NowNs();
    PrimaryPeriod(woke);
    monitor.Record(release, woke, NowNs());
  }
}

void HapticLoop::SecondaryThread(RegionIndex region, std::int64_t origin_ns) {
  DeadlineMonitor& monitor = *monitors_[region];
  const int substeps = regions_->schedule(region).substeps;
  while (!stop_.load(std::memory_order_acquire)) {
    const std::int64_t release =
        origin_ns + static_cast<std::int64_t>(regions_->state_ticks(region) * tick_ns_) -
        lead_ns_[region];
    SleepUntilNs(release);
    const std::int64_t woke = NowNs();
    for (int q = 0; q < substeps; ++q) regions_->StepRegion(region);
    monitor.Record(release, woke, NowNs());
  }
}

std::string HapticLoop::Start() {
  if (running_) return "";
  regions_->Reset();
  in_contact_ = false;
  await_lift_off_ = true;
  displacement_ = {0.0, 0.0, 0.0};
  stop_ = false;
  const std::int64_t origin_ns = NowNs() + 5'000'000 + lead_ns_.back();
  threads_.emplace_back([this, origin_ns] { PrimaryThread(origin_ns); });
  for (int a = 1; a < regions_->num_regions(); ++a) {
    threads_.emplace_back([this, a, origin_ns] { SecondaryThread(a, origin_ns); });
  }
  running_ = true;
  return ApplyRealtimeSettings();
}

std::string HapticLoop::ApplyRealtimeSettings() {
  std::string refused;
  for (std::thread& thread : threads_) {
    const pthread_t handle = thread.native_handle();
    if (options_.fifo_priority > 0) {
      sched_param param{};
      param.sched_priority = options_.fifo_priority;
      const int error = pthread_setschedparam(handle, SCHED_FIFO, &param);
      if (error != 0 && refused.find("SCHED_FIFO") == std::string::npos) {
        refused += "SCHED_FIFO priority " + std::to_string(options_.fifo_priority) + " refused (" +
                   std::strerror(error) + "; needs CAP_SYS_NICE or LimitRTPRIO); ";
      }
    }
    if (!options_.cpus.empty()) {
      cpu_set_t set;
      CPU_ZERO(&set);
      for (int cpu : options_.cpus) CPU_SET(cpu, &set);
      const int error = pthread_setaffinity_np(handle, sizeof set, &set);
      if (error != 0 && refused.find("affinity") == std::string::npos) {
        refused += std::string("CPU affinity refused (") + std::strerror(error) + "); ";
      }
    }
  }
  return refused;
}

void HapticLoop::Stop() {
  stop_ = true;
  for (std::thread& thread : threads_) {
    if (thread.joinable()) thread.join();
  }
  threads_.clear();
  running_ = false;
}

}  // namespace hapticsim
