#include "device/execution_history.hpp"

#include <algorithm>

namespace hapticsim::device {
namespace {

// The lower median — the value of rank ceil(n/2), as the daemon ranks its own percentiles.
double Median(std::vector<double> values) {
  if (values.empty()) return 0;
  const auto middle = values.begin() + static_cast<std::ptrdiff_t>((values.size() - 1) / 2);
  std::nth_element(values.begin(), middle, values.end());
  return *middle;
}

}  // namespace

void ExecutionHistory::Add(const status_t& status) {
  // Asleep, the primary still answers every input but steps nothing: its periods then say
  // nothing about what a step costs.
  if (status.asleep) return;
  for (const region_status_t& region : status.regions) {
    // A thread that did not run in the interval (parked, not started): median 0.
    if (!(region.execution_p50_us > 0)) continue;
    auto at = std::find_if(regions_.begin(), regions_.end(),
                           [&](const Samples& s) { return s.region == region.name; });
    if (at == regions_.end()) at = regions_.insert(at, Samples{region.name});
    Samples& s = *at;
    s.rate_hz = region.rate_hz;
    s.p50_us.push_back(region.execution_p50_us);
    s.p50_share.push_back(region.execution_p50_us * 1e-6 * region.rate_hz);
    s.p99_us.push_back(region.execution_p99_us);
    s.max_us = std::max(s.max_us, region.execution_max_us);
  }
}

std::vector<RegionExecution> ExecutionHistory::Summary() const {
  std::vector<RegionExecution> out;
  for (const Samples& s : regions_) {
    RegionExecution r;
    r.region = s.region;
    r.rate_hz = s.rate_hz;
    r.intervals = static_cast<std::int64_t>(s.p50_us.size());
    r.p50_median_us = Median(s.p50_us);
    r.p50_period_share = Median(s.p50_share);
    r.p99_interval_median_us = Median(s.p99_us);
    r.p99_interval_worst_us = *std::max_element(s.p99_us.begin(), s.p99_us.end());
    r.max_us = s.max_us;
    out.push_back(r);
  }
  return out;
}

}  // namespace hapticsim::device
