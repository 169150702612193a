#include "core/errormap/error_lookup.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

#include "core/error.hpp"

namespace hapticsim {

LookupQuery LookupQuery::At(const MapPoint& point) {
  LookupQuery query;
  query.lo = point;
  query.hi = point;
  return query;
}

namespace {

std::vector<double> FieldValues(const ErrorMap& map, ErrorField field) {
  HAPTICSIM_THROW_UNLESS(map.grid,
                         "a scattered (Monte Carlo) map cannot be looked up: make a grid map");
  std::vector<double> values;
  values.reserve(map.samples.size());
  for (const MapSample& sample : map.samples) values.push_back(FieldOf(sample, field));
  return values;
}

std::vector<std::uint8_t> Statuses(const ErrorMap& map) {
  std::vector<std::uint8_t> statuses;
  statuses.reserve(map.samples.size());
  for (const MapSample& sample : map.samples) {
    statuses.push_back(static_cast<std::uint8_t>(sample.status));
  }
  return statuses;
}

}  // namespace

ErrorLookup::ErrorLookup(const ErrorMap& map, ErrorField field)
    : ErrorLookup(map.axes, FieldValues(map, field), Statuses(map), field) {}

ErrorLookup::ErrorLookup(const std::array<std::vector<double>, kNumMapAxes>& axes,
                         std::vector<double> values, std::vector<std::uint8_t> statuses,
                         ErrorField field)
    : field_(field), axes_(axes), value_(std::move(values)), status_(std::move(statuses)) {
  for (int a = 0; a < kNumMapAxes; ++a) {
    HAPTICSIM_THROW_UNLESS(
        !axes_[a].empty() && axes_[a].size() <= kMaxAxisValues,
        std::string(AxisInfo(a).scene_key) + ": a lookup axis needs 1 to 64 values");
    for (size_t i = 1; i < axes_[a].size(); ++i) {
      HAPTICSIM_THROW_UNLESS(axes_[a][i] > axes_[a][i - 1],
                             std::string(AxisInfo(a).scene_key) + ": axis values must increase");
    }
  }
  std::size_t stride = 1;
  for (int a = kNumMapAxes - 1; a >= 0; --a) {
    stride_[a] = stride;
    stride *= axes_[a].size();
  }
  HAPTICSIM_THROW_UNLESS(stride == value_.size() && stride == status_.size(),
                         "map samples do not match its axes");
}

double ErrorLookup::Interpolate(const MapPoint& point, LookupResult* result) const noexcept {
  // Per axis: the lower grid index and the weight of the upper one (0 on an exact hit).
  std::array<std::size_t, kNumMapAxes> base{};
  std::array<double, kNumMapAxes> weight{};
  std::array<int, kNumMapAxes> varying{};
  int num_varying = 0;
  std::size_t base_index = 0;
  for (int a = 0; a < kNumMapAxes; ++a) {
    const std::vector<double>& v = axes_[a];
    const double x = point[a];
    std::size_t i = 0;
    if (v.size() > 1) {
      i = static_cast<std::size_t>(std::upper_bound(v.begin(), v.end(), x) - v.begin());
      i = std::min(std::max<std::size_t>(i, 1), v.size() - 1) - 1;  // v[i] ≤ x ≤ v[i+1]
      const double w = (x - v[i]) / (v[i + 1] - v[i]);
      if (w >= 1.0) {
        ++i;
      } else if (w > 0.0) {
        weight[a] = w;
        varying[num_varying++] = a;
      }
    }
    base[a] = i;
    base_index += i * stride_[a];
  }
  double sum = 0;
  for (unsigned corner = 0; corner < (1u << num_varying); ++corner) {
    double w = 1;
    std::size_t index = base_index;
    for (int k = 0; k < num_varying; ++k) {
      const int a = varying[k];
      if (corner & (1u << k)) {
        w *= weight[a];
        index += stride_[a];
      } else {
        w *= 1 - weight[a];
      }
    }
    const auto status = static_cast<SampleStatus>(status_[index]);
    if (status == SampleStatus::kNotComputed) {
      result->incomplete = true;
    } else if (status != SampleStatus::kOk) {
      result->unstable = true;
    } else {
      sum += w * value_[index];
    }
  }
  return sum;
}

LookupResult ErrorLookup::Lookup(const LookupQuery& query) const noexcept {
  LookupResult result;
  // Candidate coordinates per axis: the box's ends and every grid value strictly inside. The
  // interpolant is multilinear in each grid cell, so its maximum over the box is at one of them.
  std::array<std::array<double, kMaxAxisValues + 2>, kNumMapAxes> candidates;
  std::array<int, kNumMapAxes> count{};
  for (int a = 0; a < kNumMapAxes; ++a) {
    const std::vector<double>& v = axes_[a];
    double lo = std::min(query.lo[a], query.hi[a]);
    double hi = std::max(query.lo[a], query.hi[a]);
    const bool unknown_frequency =
        a == static_cast<int>(MapAxis::kFrequency) && !query.frequency_known;
    if (unknown_frequency) {
      lo = v.front();
      hi = v.back();
    } else if (!(lo >= v.front() && hi <= v.back())) {  // NaN counts as outside
      if (!result.clamped) result.clamped_axis = a;
      result.clamped = true;
      lo = std::isnan(lo) ? v.front() : std::clamp(lo, v.front(), v.back());
      hi = std::isnan(hi) ? v.back() : std::clamp(hi, v.front(), v.back());
    }
    auto& c = candidates[a];
    if (query.neighbourhood == LookupQuery::Neighbourhood::kAverage && !unknown_frequency) {
      c[count[a]++] = 0.5 * (lo + hi);
      continue;
    }
    c[count[a]++] = lo;
    for (double value : v) {
      if (value > lo && value < hi) c[count[a]++] = value;
    }
    if (hi > lo) c[count[a]++] = hi;
  }
  std::array<int, kNumMapAxes> pick{};
  MapPoint point;
  double worst = -std::numeric_limits<double>::infinity();
  for (;;) {
    for (int a = 0; a < kNumMapAxes; ++a) point[a] = candidates[a][pick[a]];
    worst = std::max(worst, Interpolate(point, &result));
    int a = kNumMapAxes - 1;
    for (; a >= 0; --a) {
      if (++pick[a] < count[a]) break;
      pick[a] = 0;
    }
    if (a < 0) break;
  }
  result.error = result.usable() ? worst : std::numeric_limits<double>::infinity();
  return result;
}

}  // namespace hapticsim
