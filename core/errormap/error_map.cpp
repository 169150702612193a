#include "core/errormap/error_map.hpp"

#include <cstring>

#include "core/error.hpp"
#include "core/fnv1a.hpp"

namespace hapticsim {

std::string_view SampleStatusName(SampleStatus status) {
  switch (status) {
    case SampleStatus::kOk:
      return "ok";
    case SampleStatus::kPredictedUnstable:
      return "predicted unstable";
    case SampleStatus::kDiverged:
      return "diverged";
    case SampleStatus::kNotComputed:
      return "not computed";
  }
  return "unknown";
}

std::string_view ErrorFieldName(ErrorField field) {
  switch (field) {
    case ErrorField::kL2:
      return "l2_percent";
    case ErrorField::kMagnitude:
      return "max_magnitude_percent";
    case ErrorField::kDirection:
      return "max_direction_deg";
  }
  return "unknown";
}

ErrorField ParseErrorField(std::string_view name) {
  if (name == "l2" || name == "l2_percent") return ErrorField::kL2;
  if (name == "magnitude" || name == "max_magnitude_percent") return ErrorField::kMagnitude;
  if (name == "direction" || name == "max_direction_deg") return ErrorField::kDirection;
  throw Error("error field '" + std::string(name) +
              "' is unknown: choose l2 (relative L2 %), magnitude (worst magnitude error, % of "
              "peak) or direction (worst direction error, degrees)");
}

double FieldOf(const MapSample& sample, ErrorField field) {
  switch (field) {
    case ErrorField::kL2:
      return sample.l2_percent;
    case ErrorField::kMagnitude:
      return sample.max_magnitude_percent;
    case ErrorField::kDirection:
      return sample.max_direction_deg;
  }
  return 0;
}

double MapSample::total_cost_us_per_ms() const {
  double total = 0;
  for (double cost : cost_us_per_ms) total += cost;
  return total;
}

std::size_t ErrorMap::GridSize() const {
  std::size_t size = 1;
  for (const auto& values : axes) size *= values.size();
  return size;
}

std::size_t ErrorMap::GridIndex(const std::array<int, kNumMapAxes>& index) const {
  std::size_t flat = 0;
  for (int a = 0; a < kNumMapAxes; ++a) flat = flat * axes[a].size() + index[a];
  return flat;
}

ErrorMap ErrorMap::MakeGrid(const std::array<std::vector<double>, kNumMapAxes>& axes) {
  ErrorMap map;
  map.grid = true;
  map.axes = axes;
  for (int a = 0; a < kNumMapAxes; ++a) {
    const auto& values = axes[a];
    HAPTICSIM_THROW_UNLESS(!values.empty(), std::string(AxisInfo(a).scene_key) +
                                                ": a grid axis needs at least one value");
    for (size_t i = 1; i < values.size(); ++i) {
      HAPTICSIM_THROW_UNLESS(
          values[i] > values[i - 1],
          std::string(AxisInfo(a).scene_key) + ": grid values must be strictly increasing");
    }
  }
  map.samples.resize(map.GridSize());
  std::array<int, kNumMapAxes> index{};
  for (MapSample& sample : map.samples) {
    for (int a = 0; a < kNumMapAxes; ++a) sample.point[a] = axes[a][index[a]];
    for (int a = kNumMapAxes - 1; a >= 0; --a) {  // odometer, last axis fastest
      if (++index[a] < static_cast<int>(axes[a].size())) break;
      index[a] = 0;
    }
  }
  return map;
}

std::size_t ErrorMap::CountStatus(SampleStatus status) const {
  std::size_t count = 0;
  for (const MapSample& sample : samples) count += sample.status == status;
  return count;
}

std::uint64_t ErrorMap::ResultsChecksum() const {
  Fnv1a hash;
  auto mix = [&hash](const void* data, size_t size) { hash.Bytes(data, size); };
  for (const MapSample& s : samples) {
    mix(s.point.data(), sizeof s.point);
    for (double v : {s.l2_percent, s.max_magnitude_percent, s.max_direction_deg, s.reference_peak_n,
                     s.spectral_radius}) {
      mix(&v, sizeof v);
    }
    mix(&s.status, sizeof s.status);
    mix(&s.status_region, sizeof s.status_region);
  }
  return hash.value();
}

}  // namespace hapticsim
