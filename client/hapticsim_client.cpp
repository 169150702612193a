// The C API of the shared-memory client (hapticsim_client.h): a thin shell over
// hapticsim::shm::ShmDeviceClient. No exception crosses it: the one call that can fail for a
// reason (connect) says why in the caller's buffer.
#include "client/hapticsim_client.h"

#include <algorithm>
#include <atomic>
#include <cstring>
#include <exception>
#include <hapticsim/force_feedback_t.hpp>
#include <string>
#include <string_view>

#include "ipc/shm_device_client.hpp"

// The flags a C caller tests are the daemon's own.
static_assert(HAPTICSIM_FLAG_IN_CONTACT == hapticsim::force_feedback_t::FLAG_IN_CONTACT);
static_assert(HAPTICSIM_FLAG_ERROR_TARGET_EXCEEDED ==
              hapticsim::force_feedback_t::FLAG_ERROR_TARGET_EXCEEDED);
static_assert(HAPTICSIM_FLAG_LOOKUP_CLAMPED == hapticsim::force_feedback_t::FLAG_LOOKUP_CLAMPED);
static_assert(HAPTICSIM_FLAG_INPUT_STALE == hapticsim::force_feedback_t::FLAG_INPUT_STALE);
static_assert(HAPTICSIM_FLAG_RECONFIGURING == hapticsim::force_feedback_t::FLAG_RECONFIGURING);
static_assert(HAPTICSIM_FLAG_NO_ERROR_MAP == hapticsim::force_feedback_t::FLAG_NO_ERROR_MAP);
static_assert(HAPTICSIM_FLAG_INPUT_REJECTED == hapticsim::force_feedback_t::FLAG_INPUT_REJECTED);
static_assert(HAPTICSIM_FLAG_BOUNDARY_STALE == hapticsim::force_feedback_t::FLAG_BOUNDARY_STALE);
static_assert(HAPTICSIM_FLAG_FORCE_LIMITED == hapticsim::force_feedback_t::FLAG_FORCE_LIMITED);
static_assert(HAPTICSIM_FLAG_PORT_DISSIPATING ==
              hapticsim::force_feedback_t::FLAG_PORT_DISSIPATING);
static_assert(HAPTICSIM_FLAG_FAULT_LATCHED == hapticsim::force_feedback_t::FLAG_FAULT_LATCHED);
static_assert(std::string_view(HAPTICSIM_DEFAULT_SOCKET) == hapticsim::shm::kDefaultSocket);

struct hapticsim_client {
  explicit hapticsim_client(const std::string& socket) : shm(socket) {}
  hapticsim::shm::ShmDeviceClient shm;
  std::atomic<std::int64_t> poses_sent{0};  // written by the pose writer, read by status
};

namespace {

void SayWhy(char* error, size_t error_size, const char* why) {
  if (error == nullptr || error_size == 0) return;
  const size_t n = std::min(std::strlen(why), error_size - 1);
  std::memcpy(error, why, n);
  error[n] = '\0';
}

}  // namespace

extern "C" {

hapticsim_client* hapticsim_connect(const char* socket_path, char* error, size_t error_size) {
  SayWhy(error, error_size, "");
  try {
    return new hapticsim_client(socket_path ? socket_path : HAPTICSIM_DEFAULT_SOCKET);
  } catch (const std::exception& e) {
    SayWhy(error, error_size, e.what());
  } catch (...) {
    SayWhy(error, error_size, "connecting to hapticsimd failed for an unknown reason");
  }
  return nullptr;
}

void hapticsim_disconnect(hapticsim_client* client) { delete client; }

int hapticsim_send_pose(hapticsim_client* client, int64_t seq, int64_t utime_us,
                        const double position_m[3]) {
  if (client == nullptr || position_m == nullptr) return -1;
  client->shm.WriteInput(seq, utime_us, {position_m[0], position_m[1], position_m[2]});
  client->poses_sent.fetch_add(1, std::memory_order_relaxed);
  return 0;
}

int hapticsim_read_force(const hapticsim_client* client, hapticsim_force* out) {
  if (client == nullptr || out == nullptr) return -1;
  hapticsim::shm::ShmForceOutput force;
  if (!client->shm.ReadForce(&force)) return 0;
  out->period = force.period;
  out->seq = force.seq;
  out->first_seq = force.first_seq;
  out->utime_us = force.utime;
  for (int c = 0; c < 3; ++c) out->force_n[c] = force.force_n[c];
  out->error_percent = force.error_percent;
  out->flags = force.flags;
  return 1;
}

int hapticsim_is_live(const hapticsim_client* client, int64_t now_ns) {
  return client != nullptr && client->shm.Source(now_ns) == hapticsim::shm::ForceSource::kLive;
}

int hapticsim_read_status(const hapticsim_client* client, hapticsim_status* out) {
  if (client == nullptr || out == nullptr) return -1;
  const hapticsim::shm::ShmSegment& segment = client->shm.segment();
  const std::int64_t pid = segment.header.daemon_pid.load(std::memory_order_relaxed);
  out->daemon_pid = pid;
  out->daemon_running = pid != 0;
  out->heartbeat_ns = segment.header.daemon_heartbeat_ns.load(std::memory_order_acquire);
  out->newest_period = segment.newest_output.load(std::memory_order_acquire);
  out->poses_sent = client->poses_sent.load(std::memory_order_relaxed);
  return 0;
}

int32_t hapticsim_deformation_nodes(const hapticsim_client* client) {
  return client == nullptr ? 0 : static_cast<int32_t>(client->shm.deformation_nodes());
}

int hapticsim_read_deformation(const hapticsim_client* client, hapticsim_deformation* out,
                               int32_t* node_ids, double* displacement_m, int32_t capacity_nodes) {
  using Read = hapticsim::shm::ShmDeviceClient::DeformationRead;
  if (client == nullptr || out == nullptr || capacity_nodes < 0) return -1;
  hapticsim::shm::ShmDeformationFrame frame;
  switch (client->shm.ReadDeformation(&frame, node_ids, displacement_m,
                                      static_cast<std::uint32_t>(capacity_nodes))) {
    case Read::kArraysTooSmall:
      return -1;
    case Read::kNoneYet:
      return 0;
    case Read::kRead:
      break;
  }
  out->frame = frame.frame;
  out->utime_us = frame.utime;
  out->configuration_id = frame.configuration_id;
  out->in_contact = frame.in_contact ? 1 : 0;
  out->complete = frame.complete ? 1 : 0;
  out->nodes_per_axis = frame.nodes_per_axis;
  for (int c = 0; c < 3; ++c) out->contact_node[c] = frame.contact_node[c];
  out->spacing_m = frame.spacing_m;
  out->num_nodes = static_cast<int32_t>(frame.num_nodes);
  return 1;
}

int hapticsim_reconnect(hapticsim_client* client) {
  if (client == nullptr) return 0;
  try {
    return client->shm.Reconnect() ? 1 : 0;
  } catch (...) {  // Reconnect throws nothing it knows of; an allocation failure is a "no"
    return 0;
  }
}

const char* hapticsim_client_version(void) { return HAPTICSIM_VERSION; }

}  // extern "C"
