#include "tools/hapticsim/device_report.hpp"

#include <cstdio>
#include <sstream>

#include "hapticsim/force_feedback_t.hpp"

namespace hapticsim::cli {
namespace {

constexpr std::pair<std::int32_t, const char*> kFlagNames[] = {
    {force_feedback_t::FLAG_IN_CONTACT, "in contact"},
    {force_feedback_t::FLAG_ERROR_TARGET_EXCEEDED, "error target exceeded"},
    {force_feedback_t::FLAG_LOOKUP_CLAMPED, "lookup clamped"},
    {force_feedback_t::FLAG_INPUT_STALE, "input stale"},
    {force_feedback_t::FLAG_RECONFIGURING, "reconfiguring"},
    {force_feedback_t::FLAG_NO_ERROR_MAP, "no error map"},
    {force_feedback_t::FLAG_INPUT_REJECTED, "input rejected"},
    {force_feedback_t::FLAG_BOUNDARY_STALE, "boundary stale"},
    {force_feedback_t::FLAG_FORCE_LIMITED, "force limited"},
    {force_feedback_t::FLAG_PORT_DISSIPATING, "port dissipating"},
    {force_feedback_t::FLAG_FAULT_LATCHED, "fault latched"},
};

nlohmann::json LatencyJson(const device::LatencySummary& l) {
  return {{"count", l.count},
          {"median", l.median_us},
          {"p99", l.p99_us},
          {"p999", l.p999_us},
          {"max", l.max_us}};
}

nlohmann::json StreamJson(const device::StreamSummary& s) {
  return {{"answers", s.answers},
          {"lost_answers", s.lost_answers},
          {"duplicated_answers", s.duplicated_answers}};
}

}  // namespace

std::string FlagNames(std::int32_t flags) {
  std::string names;
  for (const auto& [bit, name] : kFlagNames) {
    if (flags & bit) names += (names.empty() ? "" : ", ") + std::string(name);
  }
  return names.empty() ? "none" : names;
}

std::vector<std::string> ExceededLimits(const device::SessionReport& r, const DeviceLimits& l) {
  std::vector<std::string> exceeded;
  auto check = [&](double limit, double value, const char* name) {
    if (limit >= 0 && value > limit) exceeded.push_back(name);
  };
  check(l.p99_us, r.latency.p99_us, "--max-p99-us");
  check(l.max_latency_us, r.latency.max_us, "--max-latency-us");
  check(l.unanswered, static_cast<double>(r.unanswered_inputs), "--max-unanswered");
  check(l.late_percent,
        r.inputs_sent > 0 ? 100.0 * static_cast<double>(r.late_answers) / r.inputs_sent : 0.0,
        "--max-late-percent");
  check(l.lost, static_cast<double>(r.stream.lost_answers), "--max-lost");
  check(l.force_step_n, r.largest_force_step_n, "--max-force-step");
  if (r.nonfinite_forces > 0) exceeded.push_back("non-finite forces (never allowed)");
  return exceeded;
}

nlohmann::json ReportJson(const device::SessionReport& r) {
  nlohmann::json out = {{"duration_s", r.duration_s},
                        {"inputs_sent", r.inputs_sent},
                        {"bad_inputs_sent", r.bad_inputs_sent},
                        {"silent_periods", r.silent_periods},
                        {"unanswered_inputs", r.unanswered_inputs},
                        {"late_answers", r.late_answers},
                        {"answers", r.stream.answers},
                        {"lost_answers", r.stream.lost_answers},
                        {"duplicated_answers", r.stream.duplicated_answers},
                        {"latency_us", LatencyJson(r.latency)},
                        {"nonfinite_forces", r.nonfinite_forces},
                        {"force_out_of_contact", r.force_out_of_contact},
                        {"largest_force_step_N", r.largest_force_step_n},
                        {"max_force_step_in_contact_n", r.largest_force_step_n},
                        {"max_force_step_any_n", r.largest_force_step_any_n},
                        {"max_force_step_one_period_n", r.largest_force_step_one_period_n},
                        {"max_force_n", r.largest_force_n},
                        {"contact_answers", r.contact_answers},
                        {"error_percent_in_contact",
                         {{"lowest", r.error_percent_lowest},
                          {"highest", r.error_percent_highest},
                          {"answers_without", r.contact_answers_error_unknown}}},
                        {"flags_seen", FlagNames(r.flags_seen)},
                        {"answers_after_last_bad_input", r.answers_after_last_burst}};
  if (!r.press_peaks_n.empty()) out["press_peaks_n"] = r.press_peaks_n;
  out["max_lateral_force_n"] = r.largest_lateral_n;
  out["max_lateral_to_normal"] = r.largest_lateral_ratio;
  if (r.monitor) out["lcm_monitor"] = StreamJson(*r.monitor);
  if (r.status) {
    nlohmann::json regions = nlohmann::json::array();
    for (const region_status_t& region : r.status->regions) {
      regions.push_back({{"name", region.name},
                         {"rate_hz", region.rate_hz},
                         {"cycles", region.cycles},
                         {"deadline_misses", region.deadline_misses},
                         {"worst_lateness_us", region.worst_lateness_us},
                         {"execution_p99_us", region.execution_p99_us}});
    }
    out["daemon"] = {
        {"primary_size", r.status->primary_size},
        {"secondary_lod", r.status->secondary_lod},
        {"secondary_rate_hz", r.status->secondary_rate_hz},
        {"error_percent", r.status->error_percent},
        {"error_target_percent", r.status->error_target_percent},
        {"target_met", r.status->target_met},
        {"inputs_received", r.status->inputs_received},
        {"inputs_rejected", r.status->inputs_rejected},
        {"decode_errors", r.status->decode_errors},
        {"reconfigurations", r.status->reconfigurations},
        {"input_owner", r.status->input_owner},
        {"inputs_wrong_transport", r.status->inputs_wrong_transport},
        {"shm_sessions", r.status->shm_sessions},
        {"shm_refused", r.status->shm_refused},
        {"commands_refused", r.status->commands_refused},
        {"max_force_n", r.status->max_force_n},
        {"force_limited_periods", r.status->force_limited_periods},
        {"port_dissipating_periods", r.status->port_dissipating_periods},
        {"port_energy_dissipated_j", r.status->port_energy_dissipated_j},
        {"fault_latched", r.status->fault_latched},
        {"latched_faults", r.status->latched_faults},
        {"fault_rearms", r.status->fault_rearms},
        {"contact_node",
         {r.status->contact_node[0], r.status->contact_node[1], r.status->contact_node[2]}},
        {"regions", regions}};
    nlohmann::json execution = nlohmann::json::array();
    for (const device::RegionExecution& e : r.execution) {
      execution.push_back({{"region", e.region},
                           {"rate_hz", e.rate_hz},
                           {"status_intervals", e.intervals},
                           {"p50_median_us", e.p50_median_us},
                           {"p50_period_share", e.p50_period_share},
                           {"p99_interval_median_us", e.p99_interval_median_us},
                           {"p99_interval_worst_us", e.p99_interval_worst_us},
                           {"max_us", e.max_us}});
    }
    out["daemon"]["execution"] = execution;
  }
  nlohmann::json seconds = nlohmann::json::array();
  for (const device::SecondSummary& s : r.seconds) {
    seconds.push_back({{"t_s", s.t_s},
                       {"answers", s.answers},
                       {"latency_median_us", s.latency.median_us},
                       {"latency_p99_us", s.latency.p99_us},
                       {"latency_max_us", s.latency.max_us}});
  }
  out["seconds"] = seconds;
  return out;
}

std::string ReportText(const device::SessionReport& r) {
  std::ostringstream text;
  char line[256];
  auto add = [&](const char* format, auto... values) {
    std::snprintf(line, sizeof line, format, values...);
    text << line << "\n";
  };
  add("  inputs sent                %lld (+ %lld bad and %lld periods of silence, injected)",
      static_cast<long long>(r.inputs_sent), static_cast<long long>(r.bad_inputs_sent),
      static_cast<long long>(r.silent_periods));
  add("  unanswered inputs          %lld", static_cast<long long>(r.unanswered_inputs));
  add("  late answers (> 1 period)  %lld", static_cast<long long>(r.late_answers));
  add("  answers                    %lld (lost %lld, duplicated %lld)",
      static_cast<long long>(r.stream.answers), static_cast<long long>(r.stream.lost_answers),
      static_cast<long long>(r.stream.duplicated_answers));
  if (r.monitor) {
    add("  answers on LCM (monitor)   %lld (lost %lld, duplicated %lld)",
        static_cast<long long>(r.monitor->answers), static_cast<long long>(r.monitor->lost_answers),
        static_cast<long long>(r.monitor->duplicated_answers));
  }
  add("  round trip                 median %.0f µs, p99 %.0f µs, p99.9 %.0f µs, max %.0f µs",
      r.latency.median_us, r.latency.p99_us, r.latency.p999_us, r.latency.max_us);
  add("  forces                     %lld non-finite, %lld non-zero out of contact, largest step "
      "%.4f N between periods in contact (%.4f N between answers of one input each)",
      static_cast<long long>(r.nonfinite_forces), static_cast<long long>(r.force_out_of_contact),
      r.largest_force_step_n, r.largest_force_step_one_period_n);
  add("  in contact                 %lld answers; largest force %.3f N; largest lateral %.3f N, "
      "%.3f × the normal",
      static_cast<long long>(r.contact_answers), r.largest_force_n, r.largest_lateral_n,
      r.largest_lateral_ratio);
  if (!r.press_peaks_n.empty()) {
    std::string peaks;
    for (double p : r.press_peaks_n) {
      char value[32];
      std::snprintf(value, sizeof value, "%s%.3f", peaks.empty() ? "" : ", ", p);
      peaks += value;
    }
    text << "  press peaks                " << peaks << " N\n";
  }
  if (r.error_percent_highest >= 0) {
    add("  error reported in contact  %.3f–%.3f %% of the peak (%lld answers said none)",
        r.error_percent_lowest, r.error_percent_highest,
        static_cast<long long>(r.contact_answers_error_unknown));
  } else if (r.contact_answers > 0) {
    text
        << "  error reported in contact  none (no error map, or none for where the regions were)\n";
  }
  text << "  flags seen                 " << FlagNames(r.flags_seen) << "\n";
  if (r.status) {
    add("  daemon                     primary_size %d, secondary_lod %d, %.0f Hz; error %.2f %% "
        "(target %.1f %%)",
        r.status->primary_size, r.status->secondary_lod, r.status->secondary_rate_hz,
        r.status->error_percent, r.status->error_target_percent);
    add("  daemon port guard          input from %s (%lld refused on the other transport); "
        "%lld periods limited, %lld dissipating (%.3g J); %lld fault(s) latched, %lld re-armed",
        r.status->input_owner.c_str(), static_cast<long long>(r.status->inputs_wrong_transport),
        static_cast<long long>(r.status->force_limited_periods),
        static_cast<long long>(r.status->port_dissipating_periods),
        r.status->port_energy_dissipated_j, static_cast<long long>(r.status->latched_faults),
        static_cast<long long>(r.status->fault_rearms));
    for (const region_status_t& region : r.status->regions) {
      add("  daemon %-19s %lld deadline misses in %lld periods, worst lateness %.0f µs",
          (region.name + " thread").c_str(), static_cast<long long>(region.deadline_misses),
          static_cast<long long>(region.cycles), region.worst_lateness_us);
    }
    for (const device::RegionExecution& e : r.execution) {
      add("  daemon %-19s median %.0f µs (%.1f %% of its %.2f ms period), interval p99 median "
          "%.0f µs, worst %.0f µs; longest %.0f µs; %lld status intervals",
          (e.region + " step").c_str(), e.p50_median_us, 100 * e.p50_period_share, 1e3 / e.rate_hz,
          e.p99_interval_median_us, e.p99_interval_worst_us, e.max_us,
          static_cast<long long>(e.intervals));
    }
  }
  return text.str();
}

}  // namespace hapticsim::cli
