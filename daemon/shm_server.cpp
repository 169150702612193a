#include "daemon/shm_server.hpp"

#include <poll.h>
#include <spdlog/spdlog.h>
#include <sys/socket.h>
#include <unistd.h>

#include <cerrno>

#include "core/error.hpp"

namespace hapticsim {
namespace {

/** Connections answered per poll: a flood of them waits in the backlog, not in the I/O thread. */
constexpr int kAcceptsPerPoll = 4;

}  // namespace

ShmServer::ShmServer(const std::string& socket_path, const std::string& group,
                     double workspace_margin_m, double max_speed_m_per_s,
                     double max_log_lines_per_s, HapticLoop& loop, InputCounters& counters,
                     bool owns_input)
    : listener_(socket_path, group),
      intake_(workspace_margin_m, max_speed_m_per_s, loop, counters, owns_input),
      surface_nodes_(static_cast<std::uint32_t>(loop.regions().surface_ids().size())),
      counters_(counters),
      min_log_gap_ns_(1e9 / max_log_lines_per_s) {}

template <typename... Args>
void ShmServer::Log(spdlog::level::level_enum level, const char* format, const Args&... args) {
  const std::int64_t now = HapticLoop::NowNs();
  if (last_log_ns_ != 0 && now - last_log_ns_ < min_log_gap_ns_) {
    ++unlogged_;
    return;
  }
  if (unlogged_ > 0) {
    spdlog::info("shared memory: {} session lines not logged (log.max_lines_per_s)", unlogged_);
    unlogged_ = 0;
  }
  spdlog::log(level, fmt::runtime(format), args...);
  last_log_ns_ = now;
}

void ShmServer::EndSessionIfGone() {
  if (!session_) return;
  pollfd state{session_.get(), POLLIN, 0};
  if (poll(&state, 1, 0) != 1) return;
  // A driver says nothing after the greeting: anything it sends is read and dropped (a few
  // messages per poll); end of file or an error ends the session.
  char ignored[64];
  for (int k = 0; k < 4; ++k) {
    const ssize_t n = recv(session_.get(), ignored, sizeof ignored, MSG_DONTWAIT);
    if (n > 0) continue;
    if (n < 0 && (errno == EAGAIN || errno == EINTR)) return;
    Log(spdlog::level::info, "shared memory: the session of pid {} ended", session_peer_.pid);
    session_.reset();
    mapping_.reset();  // its inputs are no longer read; its client sees the daemon gone
    return;
  }
}

void ShmServer::Admit(shm::Connection connection) {
  const shm::PeerIdentity& peer = connection.peer;
  std::string refusal = listener_.Refusal(peer);
  if (refusal.empty() && session_) {
    refusal = "a driver (pid " + std::to_string(session_peer_.pid) +
              ") holds the session; one driver at a time";
  }
  if (!refusal.empty()) {
    const std::int64_t refused = counters_.shm_refused.fetch_add(1) + 1;
    shm::SendMessage(connection.socket.get(), shm::Refusal(refusal));
    Log(spdlog::level::warn, "shared memory: refused a driver: {} ({} refused so far)", refusal,
        refused);
    return;
  }
  try {
    // A new segment per session: the previous driver's mapping is left to it alone.
    shm::MappedSegment fresh = shm::MappedSegment::CreateSealed("hapticsim", surface_nodes_);
    if (!shm::SendMessage(connection.socket.get(), shm::SessionGreeting(), fresh.fd())) return;
    mapping_.reset();  // says the previous session's daemon is gone (daemon_pid = 0)
    mapping_.emplace(std::move(fresh));
    inputs_ = shm::ShmInputReader();
    intake_.Reset();  // a new driver's first seq and tip are not "old" or "a jump"
    session_ = std::move(connection.socket);
    session_peer_ = peer;
    deformation_writes_ = 0;
    deformation_for_new_session_ = true;  // the newest frame, at the next poll
    counters_.shm_sessions.fetch_add(1);
    Log(spdlog::level::info, "shared memory: a session for pid {} (uid {}) started", peer.pid,
        peer.uid);
  } catch (const Error& e) {
    Log(spdlog::level::err, "shared memory: no session for pid {}: {}", peer.pid, e.what());
  }
}

void ShmServer::PollInput() {
  EndSessionIfGone();
  for (int k = 0; k < kAcceptsPerPoll; ++k) {
    std::optional<shm::Connection> connection = listener_.Accept();
    if (!connection) break;
    Admit(std::move(*connection));
  }
  if (!mapping_) return;
  // Every input written since the last poll, in order. Nothing new (nothing written, or a writer
  // that died mid-write): the primary thread sees the last input age and flags it stale.
  inputs_.ReadNew(mapping_->segment(), [this](const shm::ShmDeviceInput& input) {
    intake_.Offer(input.seq, {input.position_m[0], input.position_m[1], input.position_m[2]});
  });
  PublishPendingDeformation();
}

void ShmServer::Publish(const ForceRecord& record) {
  if (!mapping_) return;
  shm::ShmForceOutput out;
  out.period = record.period;
  out.seq = record.seq;
  out.first_seq = record.first_seq;
  out.utime = record.utime_us;
  for (int c = 0; c < 3; ++c) out.force_n[c] = record.force_n[c];
  out.error_percent = record.error_percent;
  out.flags = record.flags;
  shm::ShmSegment& segment = mapping_->segment();
  segment.outputs[record.period % shm::kOutputSlots].Write(out);
  segment.newest_output.store(record.period, std::memory_order_release);
  segment.header.daemon_heartbeat_ns.store(record.utime_us * 1000, std::memory_order_relaxed);
}

void ShmServer::OfferDeformation(const HapticLoop::SurfaceFrame& frame, std::int64_t utime_us,
                                 std::int64_t number) {
  const std::lock_guard<std::mutex> lock(deformation_mutex_);
  if (frame.ids.size() != surface_nodes_) return;  // not this object's surface: nothing to write
  deformation_meta_.frame = number;
  deformation_meta_.utime = utime_us;
  deformation_meta_.configuration_id = frame.configuration_id;
  deformation_meta_.in_contact = frame.in_contact;
  deformation_meta_.complete = frame.complete;
  deformation_meta_.nodes_per_axis = frame.nodes_per_axis;
  deformation_meta_.spacing_m = frame.spacing_m;
  for (int c = 0; c < 3; ++c) deformation_meta_.contact_node[c] = frame.centre[c];
  deformation_ids_ = frame.ids;
  deformation_u_ = frame.displacement_m;
  deformation_fresh_ = true;
}

void ShmServer::PublishPendingDeformation() {
  if (!mapping_) return;
  std::unique_lock<std::mutex> lock(deformation_mutex_, std::try_to_lock);
  if (!lock.owns_lock()) return;  // the deformation thread is storing one: at the next poll
  if (!deformation_fresh_ && !deformation_for_new_session_) return;
  if (deformation_meta_.frame < 0) return;  // none offered yet
  mapping_->deformation().Write(deformation_writes_++, deformation_meta_, deformation_ids_.data(),
                                deformation_u_.data());
  deformation_fresh_ = false;
  deformation_for_new_session_ = false;
}

}  // namespace hapticsim
