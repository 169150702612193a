#include "tools/view/view_feed.hpp"

#include <cmath>
#include <lcm/lcm-cpp.hpp>
#include <nlohmann/json.hpp>

#include "core/error.hpp"
#include "hapticsim/deformation_t.hpp"
#include "hapticsim/device_input_t.hpp"
#include "hapticsim/force_feedback_t.hpp"
#include "hapticsim/status_t.hpp"
#include "ipc/lcm_start.hpp"

namespace hapticsim::view {
namespace {

using nlohmann::json;

// Metres to 0.1 µm, far below what a screen shows, so the JSON stays short.
double Rounded(double metres) { return std::round(metres * 1e7) / 1e7; }

template <typename Message>
bool Decode(const lcm::ReceiveBuffer* buffer, Message& message) {
  return buffer->data_size <= static_cast<uint32_t>(INT32_MAX) &&
         message.decode(buffer->data, 0, static_cast<int>(buffer->data_size)) ==
             static_cast<int>(buffer->data_size);
}

json RegionsJson(const hapticsim::status_t& s) {
  json regions = json::array();
  for (const auto& r : s.regions) {
    regions.push_back({{"name", r.name},
                       {"nodes", r.nodes},
                       {"rate_hz", r.rate_hz},
                       {"deadline_misses", r.deadline_misses},
                       {"cycles", r.cycles}});
  }
  return regions;
}

}  // namespace

// The LCM callbacks: each decodes, turns the message into the page's JSON and hands it over.
class ViewFeed::Handlers {
 public:
  explicit Handlers(ViewFeed& feed) : feed_(feed) {}

  void OnDevice(const lcm::ReceiveBuffer* buffer, const std::string&) {
    hapticsim::device_input_t m;
    if (!Decode(buffer, m)) return feed_.decode_errors_++, void();
    feed_.Publish(
        &FeedSnapshot::tool, &FeedSnapshot::tool_version,
        json{{"type", "tool"}, {"position_m", {m.position[0], m.position[1], m.position[2]}}});
  }

  void OnForce(const lcm::ReceiveBuffer* buffer, const std::string&) {
    hapticsim::force_feedback_t m;
    if (!Decode(buffer, m)) return feed_.decode_errors_++, void();
    feed_.Publish(
        &FeedSnapshot::force, &FeedSnapshot::force_version,
        json{{"type", "force"},
             {"force_n", {m.force[0], m.force[1], m.force[2]}},
             {"error_percent", m.error_percent},
             {"in_contact", (m.flags & hapticsim::force_feedback_t::FLAG_IN_CONTACT) != 0},
             {"flags", m.flags}});
  }

  void OnStatus(const lcm::ReceiveBuffer* buffer, const std::string&) {
    hapticsim::status_t m;
    if (!Decode(buffer, m)) return feed_.decode_errors_++, void();
    feed_.Publish(&FeedSnapshot::status, &FeedSnapshot::status_version,
                  json{{"type", "status"},
                       {"error_percent", m.error_percent},
                       {"error_target_percent", m.error_target_percent},
                       {"target_met", m.target_met},
                       {"error_map", m.error_map},
                       {"primary_size", m.primary_size},
                       {"secondary_lod", m.secondary_lod},
                       {"secondary_rate_hz", m.secondary_rate_hz},
                       {"max_force_n", m.max_force_n},
                       {"fault_latched", m.fault_latched},
                       {"asleep", m.asleep},
                       {"regions", RegionsJson(m)}});
  }

  // node_ids come in the first frame of each configuration and once a second; every frame the
  // page gets carries them, so a page opened at any moment can draw the next frame.
  void OnDeformation(const lcm::ReceiveBuffer* buffer, const std::string&) {
    hapticsim::deformation_t m;
    if (!Decode(buffer, m)) return feed_.decode_errors_++, void();
    if (m.num_ids > 0) {
      ids_ = m.node_ids;
      ids_configuration_ = m.configuration_id;
    }
    if (ids_configuration_ != m.configuration_id ||
        ids_.size() != static_cast<size_t>(m.num_nodes)) {
      return;  // this configuration's ids have not come yet
    }
    std::vector<double> displacement;
    displacement.reserve(3 * ids_.size());
    for (const auto& row : m.displacement_m) {
      for (float v : row) displacement.push_back(Rounded(v));
    }
    feed_.Publish(&FeedSnapshot::deformation, &FeedSnapshot::deformation_version,
                  json{{"type", "deformation"},
                       {"frame", m.frame},
                       {"latency_ms", m.latency_ms},
                       {"complete", m.complete},
                       {"configuration_id", m.configuration_id},
                       {"primary_size", m.primary_size},
                       {"secondary_lod", m.secondary_lod},
                       {"secondary_rate_hz", m.secondary_rate_hz},
                       {"contact_node", {m.contact_node[0], m.contact_node[1], m.contact_node[2]}},
                       {"in_contact", m.in_contact},
                       {"nodes_per_axis", m.nodes_per_axis},
                       {"spacing_m", m.spacing_m},
                       {"node_ids", ids_},
                       {"displacement_m", displacement}});
  }

 private:
  ViewFeed& feed_;
  std::vector<int32_t> ids_;
  int32_t ids_configuration_ = -1;
};

ViewFeed::ViewFeed(const std::string& lcm_url, FeedChannels channels)
    : lcm_(std::make_unique<lcm::LCM>(lcm_url)), handlers_(std::make_unique<Handlers>(*this)) {
  const std::string problem = LcmStartProblem(*lcm_, lcm_url);
  HAPTICSIM_THROW_UNLESS(problem.empty(), problem + " (--lcm-url)");
  lcm_->subscribe(channels.device, &Handlers::OnDevice, handlers_.get());
  lcm_->subscribe(channels.force, &Handlers::OnForce, handlers_.get());
  lcm_->subscribe(channels.status, &Handlers::OnStatus, handlers_.get());
  lcm_->subscribe(channels.deformation, &Handlers::OnDeformation, handlers_.get());
  thread_ = std::thread([this] { Run(); });
}

ViewFeed::~ViewFeed() {
  stop_ = true;
  thread_.join();
}

void ViewFeed::Run() {
  while (!stop_) {
    // No descriptor: a tcpq:// server gone. liblcm's handleTimeout would select() on -1; wait,
    // then handle(), which is what reconnects.
    if (lcm_->getFileno() < 0) {
      std::this_thread::sleep_for(std::chrono::milliseconds(200));
      if (lcm_->getFileno() >= 0) lcm_->handleTimeout(0);
      continue;
    }
    if (lcm_->handleTimeout(100) < 0) std::this_thread::sleep_for(std::chrono::milliseconds(100));
  }
}

void ViewFeed::Publish(FeedSnapshot::Text FeedSnapshot::*text, uint64_t FeedSnapshot::*version,
                       const nlohmann::json& message) {
  messages_++;
  // Text from the bus (a map's path, a region's name) may be any bytes: invalid UTF-8 is
  // replaced, not thrown about.
  auto shared = std::make_shared<const std::string>(
      message.dump(-1, ' ', false, nlohmann::json::error_handler_t::replace));
  {
    std::lock_guard lock(mutex_);
    snapshot_.*text = std::move(shared);
    snapshot_.*version = ++snapshot_.version;
  }
  changed_.notify_all();
}

FeedSnapshot ViewFeed::WaitNewer(uint64_t seen, std::chrono::milliseconds timeout) const {
  std::unique_lock lock(mutex_);
  changed_.wait_for(lock, timeout, [&] { return snapshot_.version > seen; });
  return snapshot_;
}

}  // namespace hapticsim::view
