#pragma once

#include <array>
#include <cstdint>
#include <string>
#include <string_view>
#include <vector>

#include "core/errormap/map_axes.hpp"

namespace hapticsim {

/** How a map sample ended. Stored in the map file: append, never renumber. */
enum class SampleStatus : std::uint8_t {
  kOk = 0,
  kPredictedUnstable = 1,  ///< refused before the first step (not simulated)
  kDiverged = 2,           ///< simulated, and divergence was detected during the run
  kNotComputed = 3,        ///< not in this shard, or not reached yet
};
std::string_view SampleStatusName(SampleStatus status);

/** Which region caused a non-ok status, when one did. */
inline constexpr std::int8_t kNoRegion = -1;
/** Every region is stable alone, their coupling is not. */
inline constexpr std::int8_t kCouplingRegion = -2;

/** The regions a sample records cost for (the primary and up to three secondaries). */
inline constexpr int kMapCostRegions = 4;

/** One point of the map: where it is, and how the adaptive force compared with the reference. */
struct MapSample {
  MapPoint point{};                  ///< the map's parameters (MapAxis order), SI units
  double l2_percent = 0;             ///< relative L2 force error over the trial, %
  double max_magnitude_percent = 0;  ///< worst | |F| − |F_ref| |, % of the reference peak
  double max_direction_deg = 0;      ///< worst angle where |F_ref| ≥ threshold × peak, degrees
  double reference_peak_n = 0;       ///< peak |F_ref| over the trial, N
  double spectral_radius = 0;        ///< coupled spectral radius per common period
  std::array<double, kMapCostRegions> cost_us_per_ms{};  ///< compute µs per simulated ms
  SampleStatus status = SampleStatus::kNotComputed;
  std::int8_t status_region = kNoRegion;  ///< region index, kCouplingRegion, or kNoRegion

  double total_cost_us_per_ms() const;
  bool computed() const { return status != SampleStatus::kNotComputed; }
};

/** The measures a lookup can return. */
enum class ErrorField : int { kL2 = 0, kMagnitude = 1, kDirection = 2 };
inline constexpr int kNumErrorFields = 3;
std::string_view ErrorFieldName(ErrorField field);  ///< "l2_percent", …
/** @throws Error listing the choices when `name` is none of l2, magnitude, direction. */
ErrorField ParseErrorField(std::string_view name);
double FieldOf(const MapSample& sample, ErrorField field);

/**
 * An error map: samples of the force error over parameter space, made by `hapticsim sweep`.
 *
 * A grid map has axes: its samples are the Cartesian product of the axis values in row-major
 * order (the last axis, secondary_rate, varies fastest), so it can be looked up by multilinear
 * interpolation (ErrorLookup). A scattered map (Monte Carlo) has samples at arbitrary points;
 * it serves analysis, not lookup.
 */
struct ErrorMap {
  /** Where the map came from: written to and read from the file's metadata. */
  struct Provenance {
    std::string scene_toml;    ///< the base scene (every key), TOML
    std::string model;         ///< the deformation model and its version
    std::string code_version;  ///< hapticsim's version and git revision
    std::string grid;  ///< "paper", "quick", "scene", a file name, or "monte-carlo N seed S"
    std::string shard = "1/1";         ///< the slice this file holds, "I/N" (1-based)
    double direction_threshold = 0.1;  ///< fraction of the peak below which direction is ignored
    bool linearity_used = false;       ///< amplitude axis derived from linearity
    /** The order its trials stepped the regions in (SteppingOrderName): "substeps", or
     *  "threads", hapticsimd's. Maps written before the key: "substeps". */
    std::string stepping_order = "substeps";
  };

  Provenance provenance;
  bool grid = true;
  std::array<std::vector<double>, kNumMapAxes> axes;  ///< grid maps: ascending values per axis
  std::vector<MapSample> samples;

  /** Number of grid points, the product of the axis lengths. */
  std::size_t GridSize() const;
  /** Row-major index of the grid point with per-axis indices `index`. */
  std::size_t GridIndex(const std::array<int, kNumMapAxes>& index) const;
  /** A grid map with every sample placed at its point, not computed. */
  static ErrorMap MakeGrid(const std::array<std::vector<double>, kNumMapAxes>& axes);

  std::size_t CountStatus(SampleStatus status) const;
  /** Checksum of the deterministic results (everything but the measured costs). */
  std::uint64_t ResultsChecksum() const;
};

}  // namespace hapticsim
