#pragma once

#include <array>
#include <cstdint>
#include <optional>
#include <random>
#include <string>
#include <vector>

namespace hapticsim::device {

/**
 * Where the object's front is over each point of the x–y plane: the least z of the voxels in the
 * column of voxels there (an object that leaves voxels empty has its front at several depths).
 * Empty (no columns): the box's front face, z = 0, everywhere.
 */
struct ObjectFront {
  double spacing_m = 0;          ///< the columns' width (the voxels' edge), m
  std::array<int, 2> columns{};  ///< along x and y
  std::vector<double> z_m;       ///< per column, x fastest; NaN where the column is empty
  /** The front's z over (x, y), m; none off the object (and, with columns, off the lattice). */
  std::optional<double> At(double x_m, double y_m) const;
};

/** What the simulated device does with its tool tip (object frame, m; see device_input_t). */
struct MotionSettings {
  std::string kind = "press";  ///< press | sine | walk | stroke | replay
  /// The daemon's object as the device meets it: its box's extent along x, y, z, m (the cube's
  /// edge three times; --edge, or --scene). The front face is z = 0, x and y from 0 to theirs.
  std::array<double, 3> extent_m{0.25, 0.25, 0.25};
  /// Where the object's front is (--scene); the presses, sines and strokes start from it at
  /// `at_m` and the walk's waypoints from it where they are.
  ObjectFront front;
  double amplitude_m = 0.01;                 ///< press depth / sine amplitude / deepest walk press
  double frequency_hz = 1.0;                 ///< press and sine
  std::array<double, 2> at_m{0.125, 0.125};  ///< press and sine: the point on the front face
  double hover_m = 0.002;                    ///< press: how far above the surface it starts
  double walk_speed_m_per_s = 0.05;          ///< walk: top speed between waypoints
  double stroke_length_m = 0.06;             ///< stroke: how far along +x it slides
  unsigned seed = 1;                         ///< walk
  std::string replay_path;                   ///< replay: an LCM log of device_input_t
  std::string replay_channel = "HAPTIC_DEVICE";
  double rate_hz = 1000;  ///< device periods per second
};

/**
 * The tool tip, period by period, reproducibly:
 * Depths and heights are from the object's front (`front`) at the point over which they are.
 * - press: from `hover_m` above the front face at `at_m` to `amplitude_m` deep and back,
 *   (1 − cos 2πft)/2 — the paper's press;
 * - sine: amplitude·sin 2πft around the surface at `at_m`, touching down and lifting off every
 *   period;
 * - walk: a seeded random walk over the front face from above `at_m` — waypoints up to 3 cm
 *   apart, alternately above the surface and pressed into it (up to `amplitude_m`), joined at up to
 *   `walk_speed_m_per_s` with smooth starts and stops, so it touches down and lifts off at a
 *   different surface point each time;
 * - stroke: a palpation stroke every 1/f (its depth the front's at `at_m` all along: over a
 *   curved object, the depth changes as the front does): from `hover_m` above `at_m` in to
 *   `amplitude_m` deep
 *   (the first 20 % of the period), along +x by `stroke_length_m` at that depth (50 %), out to
 *   `hover_m` above (10 %) and back above the surface to `at_m` (20 %), each leg a smoothstep —
 *   for a sliding tool (contact.model = "proxy");
 * - replay: a recorded LCM log's device inputs, in order and in time: where the device's own
 *   clock (utime) shows a pause of more than a period and a half, the replay is silent as long
 *   (up to kMaxReplaySilence_s each), as the recorded session was; then the last input held.
 */
class DeviceMotion {
 public:
  /** @throws Error for bad settings or an unreadable replay log (the message says which). */
  explicit DeviceMotion(const MotionSettings& settings);

  /** The tip for the next period; nothing for a period the recorded device was silent in. */
  std::optional<std::array<double, 3>> Next();

  /** The longest silence a replay keeps from a pause in its log, s (a bad utime is no hour). */
  static constexpr double kMaxReplaySilence_s = 10;
  /** Periods a replay holds (0 for the generated motions, which go on forever). */
  std::int64_t replay_periods() const { return static_cast<std::int64_t>(replay_.size()); }

 private:
  std::array<double, 3> NextWalk();
  std::array<double, 3> StrokeAt(double t_s) const;
  std::array<double, 3> NewWaypoint(bool inside);

  MotionSettings settings_;
  std::int64_t period_ = 0;
  std::mt19937_64 random_;
  std::array<double, 3> from_{}, to_{};
  std::int64_t leg_start_ = 0, leg_periods_ = 1;
  bool inside_next_ = true;
  double front_z_ = 0;  // the object's front at at_m (press, sine, stroke), m
  std::vector<std::optional<std::array<double, 3>>> replay_;
};

}  // namespace hapticsim::device
