#pragma once

#include <array>
#include <cstdint>
#include <vector>

#include "core/errormap/error_map.hpp"

namespace hapticsim {

/** What to look up: a point, or a box where a parameter is known only as a range. */
struct LookupQuery {
  /** How a range of material (or any) values is reduced to one error (Section VI-E). */
  enum class Neighbourhood {
    kWorst,    ///< the largest error anywhere in the box: safe for heterogeneous material
    kAverage,  ///< the error at the box's centre: less safe, as the paper warns
  };
  MapPoint lo{}, hi{};  ///< per axis (MapAxis order); lo == hi for a known value
  /** False when the input frequency is not measured: the bound over the frequency axis. */
  bool frequency_known = true;
  Neighbourhood neighbourhood = Neighbourhood::kWorst;

  static LookupQuery At(const MapPoint& point);
};

struct LookupResult {
  double error = 0;  ///< looked-up error (% or degrees, by field); +inf when !usable()
  bool clamped =
      false;  ///< some value was outside the map: clamped to its edge, never extrapolated
  int clamped_axis = -1;    ///< the first such axis (MapAxis), or -1
  bool unstable = false;    ///< a sample it depends on is predicted unstable or diverged
  bool incomplete = false;  ///< a sample it depends on was not computed
  bool usable() const { return !unstable && !incomplete; }
};

/**
 * The run-time error lookup of Section VI-E on a grid map: multilinear interpolation between
 * the grid points around the query (integer axes such as primary_size hit grid points exactly),
 * worst case or average over a box, the frequency bound when the frequency is unknown, and
 * clamping with a flag outside the map. A result depending on a non-ok sample says so: an
 * unstable configuration is never given a finite error.
 *
 * Lookup() allocates nothing, takes no lock and does not throw: the 1 kHz thread may call it.
 */
class ErrorLookup {
 public:
  /** Longest axis a lookup supports (bounds the stack arrays of a box query). */
  static constexpr int kMaxAxisValues = 64;

  /** @throws Error for a scattered map or an axis longer than kMaxAxisValues. */
  ErrorLookup(const ErrorMap& map, ErrorField field);
  /** From a grid's axes, the field per grid point and each point's SampleStatus (row-major). */
  ErrorLookup(const std::array<std::vector<double>, kNumMapAxes>& axes, std::vector<double> values,
              std::vector<std::uint8_t> statuses, ErrorField field);

  LookupResult Lookup(const LookupQuery& query) const noexcept;

  ErrorField field() const { return field_; }
  const std::array<std::vector<double>, kNumMapAxes>& axes() const { return axes_; }

 private:
  // Interpolates at one point already inside the map. Accumulates flags into *result.
  double Interpolate(const MapPoint& point, LookupResult* result) const noexcept;

  ErrorField field_;
  std::array<std::vector<double>, kNumMapAxes> axes_;
  std::array<std::size_t, kNumMapAxes> stride_{};
  std::vector<double> value_;         // the field per grid point
  std::vector<std::uint8_t> status_;  // SampleStatus per grid point
};

}  // namespace hapticsim
