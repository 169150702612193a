#include "daemon/shm_server.hpp"

namespace hapticsim {

ShmServer::ShmServer(const std::string& name, const std::string& group, const MeshSettings& mesh,
                     double workspace_margin_m, double max_speed_m_per_s, HapticLoop& loop,
                     InputCounters& counters, bool owns_input)
    : mapping_(shm::MappedSegment::Create(name, group)),
      intake_(mesh, workspace_margin_m, max_speed_m_per_s, loop, counters, owns_input) {}

void ShmServer::PollInput() {
  // Every input written since the last poll, in order. Nothing new (nothing written, or a writer
  // that died mid-write): the primary thread sees the last input age and flags it stale.
  inputs_.ReadNew(mapping_.segment(), [this](const shm::ShmDeviceInput& input) {
    intake_.Offer(input.seq, {input.position_m[0], input.position_m[1], input.position_m[2]});
  });
}

void ShmServer::Publish(const ForceRecord& record) {
  shm::ShmForceOutput out;
  out.period = record.period;
  out.seq = record.seq;
  out.first_seq = record.first_seq;
  out.utime = record.utime_us;
  for (int c = 0; c < 3; ++c) out.force_n[c] = record.force_n[c];
  out.error_percent = record.error_percent;
  out.flags = record.flags;
  shm::ShmSegment& segment = mapping_.segment();
  segment.outputs[record.period % shm::kOutputSlots].Write(out);
  segment.newest_output.store(record.period, std::memory_order_release);
  mapping_.segment().header.daemon_heartbeat_ns.store(record.utime_us * 1000,
                                                      std::memory_order_relaxed);
}

}  // namespace hapticsim
