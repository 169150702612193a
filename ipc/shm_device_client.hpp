#pragma once

// The client library for device-driver writers: talk to hapticsimd through shared memory.
//
//   hapticsim::shm::ShmDeviceClient client;   // connects to /run/hapticsim/hapticsimd.sock,
//                                              // checks the daemon and maps its segment
//   client.WriteInput(seq, utime_us, {x, y, z});          // every device period (1 kHz)
//   hapticsim::shm::ShmForceOutput force;
//   if (client.ReadForce(&force) && force.seq == seq) { /* render force.force_n */ }
//   client.ReadForcesSince(last_period, [&](const ShmForceOutput& f) { /* log every answer */ });
//   if (client.Source(now_ns) == ForceSource::kNone) { /* render zero; client.Reconnect() off
//                                                           the device thread, now and then */ }
//   std::vector<int32_t> ids(client.deformation_nodes());   // the deformed surface, for drawing
//   std::vector<double> u(3 * ids.size());
//   ShmDeformationFrame frame;
//   if (client.ReadDeformation(&frame, ids.data(), u.data(), ids.size()) ==
//       ShmDeviceClient::DeformationRead::kRead) { /* draw rest + u for frame.num_nodes */ }
//
// All but Reconnect are wait-free: no locks, no allocation, no system calls (the clock is read
// by the caller). Link hapticsim_ipc.

#include <algorithm>
#include <array>
#include <atomic>
#include <climits>
#include <cstdint>
#include <deque>
#include <optional>
#include <string>

#include "ipc/service_socket.hpp"

namespace hapticsim::shm {

/** Whether a daemon is answering (ShmDeviceClient::Source). */
enum class ForceSource { kLive, kNone };

class ShmDeviceClient {
 public:
  /** A daemon whose newest answer is older than this is no force source. */
  static constexpr std::int64_t kLiveWithin_ns = 10'000'000;

  /** How long the constructor waits for the daemon's answer. */
  static constexpr int kConnectTimeout_ms = 2000;

  /**
   * Connects to hapticsimd's service socket and maps the segment it hands over (ipc/
   * service_socket.hpp). @throws Error naming the problem: no daemon there, a socket another user
   * could have put there, a refusal (not in its group; another driver holds the session), or a
   * segment that is not the daemon's.
   */
  explicit ShmDeviceClient(const std::string& socket_path = kDefaultSocket)
      : socket_path_(socket_path) {
    sessions_.push_back(ConnectToService(socket_path, kConnectTimeout_ms));
    Publish(sessions_.back());
  }

  /**
   * kLive while the daemon that made the segment runs and its newest answer is at most
   * kLiveWithin_ns old at `now_ns` (CLOCK_MONOTONIC); else kNone: the force read is not being
   * computed by anyone (a daemon killed or hung leaves its last answer in the segment, in
   * contact, for ever) — render zero. The daemon answers every input, so a driver writing at
   * its device rate sees kLive within a period of each write.
   */
  ForceSource Source(std::int64_t now_ns) const {
    const ShmHeader& h = segment().header;
    if (h.daemon_pid.load(std::memory_order_relaxed) == 0) return ForceSource::kNone;
    const std::int64_t heartbeat = h.daemon_heartbeat_ns.load(std::memory_order_acquire);
    return heartbeat > 0 && now_ns - heartbeat <= kLiveWithin_ns ? ForceSource::kLive
                                                                 : ForceSource::kNone;
  }

  /**
   * Not wait-free (it connects: system calls, allocation, up to 400 ms): call it from one
   * thread off the device's real-time thread, now and then, while Source says kNone; the
   * real-time thread may go on calling the others meanwhile. Starts a new session with the daemon
   * at the same socket (a restarted service) and maps its segment; true when it did. Writes go on
   * into the new segment; the old one stays mapped (a real-time call may still be reading it)
   * until kKeptSessions newer ones have come. @throws nothing: no daemon, a refusal or a
   * foreign socket just leaves the old session.
   */
  bool Reconnect() {
    try {
      sessions_.push_back(ConnectToService(socket_path_, 200));
    } catch (const std::exception&) {
      return false;
    }
    Publish(sessions_.back());
    sessions_[sessions_.size() - 2].connection.reset();  // that session is over
    if (sessions_.size() > kKeptSessions) sessions_.pop_front();
    return true;
  }

  /**
   * The tool tip (object frame, m), once per device period. Only one process may write: this is a
   * single-writer ring. Two writes in quick succession (a driver catching up) both reach the
   * daemon, up to the ring's kInputSlots.
   */
  void WriteInput(std::int64_t seq, std::int64_t utime_us,
                  const std::array<double, 3>& position_m) {
    ShmDeviceInput input;
    input.seq = seq;
    input.utime = utime_us;
    for (int c = 0; c < 3; ++c) input.position_m[c] = position_m[c];
    WriteDeviceInput(segment(), input);
  }
  /** The newest force; false when none is available consistently yet. */
  bool ReadForce(ShmForceOutput* out) const {
    const ShmSegment& s = segment();
    const std::int64_t newest = s.newest_output.load(std::memory_order_acquire);
    return newest >= 0 && s.outputs[newest % kOutputSlots].Read(out) && out->period >= 0;
  }
  /**
   * Every answer after period `after` that the ring still holds, oldest first, to `each`; returns
   * the newest period seen (`after` when there is nothing new). Answers older than the ring
   * (the caller was away longer than kOutputSlots periods) are skipped: their periods are
   * missing from what `each` sees.
   */
  template <class Each>
  std::int64_t ReadForcesSince(std::int64_t after, Each&& each) const {
    const ShmSegment& s = segment();
    const std::int64_t newest = s.newest_output.load(std::memory_order_acquire);
    for (std::int64_t p = std::max(after + 1, newest - kOutputSlots + 1); p <= newest; ++p) {
      ShmForceOutput out;
      // The slot may have been overwritten by a newer period meanwhile: then p is gone.
      if (s.outputs[p % kOutputSlots].Read(&out) && out.period == p) each(out);
    }
    return std::max(after, newest);
  }
  /** What ReadDeformation did. */
  enum class DeformationRead { kRead, kNoneYet, kArraysTooSmall };
  /**
   * The newest frame of the deformed surface the daemon wrote (docs/simulator.md, "The deformed
   * shape"): its facts into `frame` (frame->num_nodes: the surface's nodes), that many ids into
   * `ids` and 3 × as many displacements (x, y, z per node, m) into `displacement_m`, each with
   * room for `capacity_nodes` nodes; either array may be null. kNoneYet when the daemon has
   * written none (deformation.rate_hz = 0, or just started) or its writes raced every try (the
   * arrays may then hold parts of several frames); kArraysTooSmall, nothing written, when the
   * surface has more nodes than `capacity_nodes` (a Reconnect on another thread may have reached a
   * daemon of another object: the count is the one read here, from one session). Wait-free.
   */
  DeformationRead ReadDeformation(ShmDeformationFrame* frame, std::int32_t* ids,
                                  double* displacement_m, std::uint32_t capacity_nodes) const {
    const ShmDeformationArea area = mapping_.load(std::memory_order_acquire)->deformation();
    if ((ids != nullptr || displacement_m != nullptr) && area.nodes() > capacity_nodes) {
      return DeformationRead::kArraysTooSmall;
    }
    return area.Read(frame, ids, displacement_m) ? DeformationRead::kRead
                                                 : DeformationRead::kNoneYet;
  }
  /** Surface nodes in every frame of the newest session's segment: the room ReadDeformation's
   *  arrays need. A Reconnect to a daemon of another object changes it. */
  std::uint32_t deformation_nodes() const {
    return mapping_.load(std::memory_order_acquire)->deformation().nodes();
  }

  /** True while the daemon that created the segment runs and serves this session. */
  bool DaemonRunning() const { return segment().header.daemon_pid.load() != 0; }

  /** The daemon this session is with, as the kernel reported it when connecting. */
  const PeerIdentity& daemon() const { return sessions_.back().daemon; }
  /** The mapped segment itself: for tools and tests that look inside; drivers need not. */
  ShmSegment& segment() { return *segment_.load(std::memory_order_acquire); }
  const ShmSegment& segment() const { return *segment_.load(std::memory_order_acquire); }

  /** Sessions kept mapped after newer ones replaced them (Reconnect). */
  static constexpr std::size_t kKeptSessions = 8;

 private:
  std::string socket_path_;
  std::deque<ServiceSession> sessions_;        // newest last (a deque: the others never move)
  std::atomic<ShmSegment*> segment_{nullptr};  // the newest session's, for the wait-free calls
  std::atomic<const MappedSegment*> mapping_{nullptr};  // and its mapping (the deformation area)

  void Publish(ServiceSession& session) {
    mapping_.store(&session.segment, std::memory_order_release);
    segment_.store(&session.segment.segment(), std::memory_order_release);
  }
};

}  // namespace hapticsim::shm
