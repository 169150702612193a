#include "daemon/status_report.hpp"

namespace hapticsim {

status_t MakeStatus(const HapticLoop& loop, const std::vector<DeadlineSnapshot>& snapshots,
                    const SupervisorDecision& decision, double target, bool pinned,
                    const std::string& map_path, const InputCounters* counters) {
  status_t s{};
  s.utime = HapticLoop::NowNs() / 1000;
  s.primary_size = decision.configuration.primary_size;
  s.secondary_lod = decision.configuration.secondary_lod;
  s.secondary_rate_hz = decision.configuration.secondary_rate_hz;
  s.spectral_radius = -1;  // not estimated: the runaway watch guards the coupling (`runaways`)
  s.error_target_percent = target;
  s.error_percent = decision.error_percent;
  s.target_met = decision.target_met;
  s.pinned = pinned;
  s.error_map = decision.have_map ? map_path : "";
  if (counters) {
    s.inputs_received = counters->inputs_received.load();
    s.inputs_rejected = counters->inputs_rejected.load();
    s.decode_errors = counters->decode_errors.load();
    s.forces_published = counters->forces_published.load();
    s.inputs_wrong_transport = counters->inputs_wrong_transport.load();
    s.shm_sessions = counters->shm_sessions.load();
    s.shm_refused = counters->shm_refused.load();
    s.commands_refused = counters->commands_refused.load();
  }
  s.max_force_n = loop.port_settings().max_force_n;
  s.force_limited_periods = loop.limited_periods();
  s.port_dissipating_periods = loop.dissipating_periods();
  s.port_energy_dissipated_j = loop.port_energy_dissipated_j();
  s.fault_latched = loop.fault_latched();
  s.latched_faults = loop.force_faults();
  s.fault_rearms = loop.rearms();
  s.port_guard_off = loop.port_guard_off();
  s.interface_backlog_j = loop.interface_backlog_j();
  s.interface_backlog_max_j = loop.interface_backlog_max_j();
  s.energy_balance_violations = loop.energy_balance_violations();
  s.runaways = loop.runaways();
  s.stale_periods = loop.stale_periods();
  for (int c = 0; c < 3; ++c) s.contact_node[c] = loop.centre_node()[c];
  s.reconfigurations = loop.reconfigurations();
  s.paused_periods = loop.paused_periods();
  s.asleep = loop.asleep();
  s.sleeps = loop.sleeps();
  const AsyncRegions& regions = loop.regions();
  s.num_regions = regions.num_regions();
  for (int r = 0; r < regions.num_regions(); ++r) {
    const DeadlineSnapshot& d = snapshots[r];
    region_status_t region{};
    region.name = regions.partition().RegionName(r);
    region.nodes = regions.partition().num_nodes(r);
    region.rate_hz = regions.schedule(r).rate_hz;
    region.substeps = regions.schedule(r).substeps;
    region.critical_dt_s = regions.schedule(r).alone.critical_dt_s;
    region.cycles = d.cycles;
    region.deadline_misses = d.misses;
    region.worst_lateness_us = d.worst_lateness_s * 1e6;
    region.recent_lateness_us = d.recent_worst_lateness_s * 1e6;
    region.execution_p50_us = d.recent_execution_p50_s * 1e6;
    region.execution_p99_us = d.recent_execution_p99_s * 1e6;
    region.execution_max_us = d.recent_execution_max_s * 1e6;
    s.regions.push_back(region);
  }
  return s;
}

}  // namespace hapticsim
