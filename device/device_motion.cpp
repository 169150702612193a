#include "device/device_motion.hpp"

#include <algorithm>
#include <cmath>
#include <lcm/lcm-cpp.hpp>
#include <numbers>
#include <sstream>

#include "core/error.hpp"
#include "hapticsim/device_input_t.hpp"

namespace hapticsim::device {
namespace {

// One entry per device period: the inputs in order, and where the device's own clock (utime, µs)
// jumps by more than a period and a half, as many silent periods as it paused for. The device's
// clock, not the logger's: a logger woken late receives a burst, which is no silence.
std::vector<std::optional<std::array<double, 3>>> ReadReplay(const std::string& path,
                                                             const std::string& channel,
                                                             double rate_hz) {
  lcm::LogFile log(path, "r");
  if (!log.good()) throw Error("--replay " + path + ": cannot open it as an LCM log");
  std::vector<std::optional<std::array<double, 3>>> positions;
  std::int64_t undecodable = 0;
  std::optional<std::int64_t> last_utime;
  const auto max_silence = static_cast<std::int64_t>(DeviceMotion::kMaxReplaySilence_s * rate_hz);
  while (const lcm::LogEvent* event = log.readNextEvent()) {
    if (event->channel != channel) continue;
    device_input_t input;
    if (input.decode(event->data, 0, event->datalen) < 0) {
      ++undecodable;
      continue;
    }
    if (last_utime && input.utime > *last_utime) {
      const double periods = static_cast<double>(input.utime - *last_utime) * 1e-6 * rate_hz;
      const std::int64_t silent = std::min<std::int64_t>(max_silence, std::llround(periods) - 1);
      for (std::int64_t k = 0; k < silent; ++k) positions.emplace_back(std::nullopt);
    }
    last_utime = input.utime;
    positions.push_back(
        std::array<double, 3>{input.position[0], input.position[1], input.position[2]});
  }
  if (positions.empty()) {
    throw Error("--replay " + path + ": no device_input_t on channel " + channel +
                (undecodable ? " (" + std::to_string(undecodable) + " messages did not decode)"
                             : std::string()));
  }
  return positions;
}

// A length as a user wrote it: 0.04, not 0.040000.
std::string Metres(double value) {
  std::ostringstream text;
  text << value;
  return text.str();
}

}  // namespace

std::optional<double> ObjectFront::At(double x_m, double y_m) const {
  if (z_m.empty()) return 0.0;
  const std::array<double, 2> at{x_m, y_m};
  std::array<int, 2> column{};
  for (int c = 0; c < 2; ++c) {
    const double edge = columns[c] * spacing_m;
    if (!(at[c] >= 0 && at[c] <= edge)) return std::nullopt;
    column[c] = std::min(static_cast<int>(std::floor(at[c] / spacing_m)), columns[c] - 1);
  }
  const double z = z_m[static_cast<std::size_t>(column[0] + columns[0] * column[1])];
  if (std::isnan(z)) return std::nullopt;
  return z;
}

DeviceMotion::DeviceMotion(const MotionSettings& s) : settings_(s), random_(s.seed) {
  for (double e : s.extent_m) {
    if (!(e > 0 && std::isfinite(e))) throw Error("--edge must be positive, m");
  }
  if (!(s.amplitude_m >= 0 && s.amplitude_m < s.extent_m[2])) {
    throw Error("--amplitude must be in [0, the object's depth along z = " + Metres(s.extent_m[2]) +
                "), m");
  }
  if (!(s.frequency_hz > 0)) throw Error("--frequency must be positive, Hz");
  if (!(s.walk_speed_m_per_s > 0)) throw Error("--walk-speed must be positive, m/s");
  for (int c = 0; c < 2; ++c) {
    if (!(s.at_m[c] >= 0 && s.at_m[c] <= s.extent_m[c])) {
      throw Error("--at must lie on the front face: 0 ≤ x ≤ " + Metres(s.extent_m[0]) +
                  " and 0 ≤ y ≤ " + Metres(s.extent_m[1]) + " m");
    }
  }
  if (s.kind == "stroke" &&
      !(s.stroke_length_m >= 0 && s.at_m[0] + s.stroke_length_m <= s.extent_m[0])) {
    throw Error("--length " + Metres(s.stroke_length_m) + " from --at x = " + Metres(s.at_m[0]) +
                " leaves the front face (0 ≤ x ≤ " + Metres(s.extent_m[0]) +
                " m): a stroke slides along +x on it; shorten it or start further left");
  }
  if (s.kind == "press" || s.kind == "sine" || s.kind == "stroke") {
    const auto over = [&](double x) {
      if (s.front.At(x, s.at_m[1])) return;
      throw Error("--at " + Metres(s.at_m[0]) + "," + Metres(s.at_m[1]) +
                  (x != s.at_m[0] ? " and --length " + Metres(s.stroke_length_m) : "") +
                  ": the object has no voxel under (" + Metres(x) + ", " + Metres(s.at_m[1]) +
                  ") m; choose a point over it");
    };
    over(s.at_m[0]);
    if (s.kind == "stroke") over(s.at_m[0] + s.stroke_length_m);
    front_z_ = *s.front.At(s.at_m[0], s.at_m[1]);
    if (!(front_z_ + s.amplitude_m < s.extent_m[2])) {
      throw Error("--amplitude " + Metres(s.amplitude_m) +
                  " from the object's front at --at (z = " + Metres(front_z_) +
                  ") reaches past its lattice's back (z = " + Metres(s.extent_m[2]) +
                  " m): press less deep or elsewhere");
    }
  }
  if (s.kind == "replay") {
    replay_ = ReadReplay(s.replay_path, s.replay_channel, s.rate_hz);
  } else if (s.kind == "walk") {
    to_ = {s.at_m[0], s.at_m[1], 0.0};  // the walk starts above --at
    from_ = to_ = NewWaypoint(false);
    inside_next_ = true;
  } else if (s.kind != "press" && s.kind != "sine" && s.kind != "stroke") {
    throw Error("--input " + s.kind + ": use press, sine, walk, stroke or replay");
  }
}

std::array<double, 3> DeviceMotion::NewWaypoint(bool inside) {
  // A step of up to 3 cm across the face from the last waypoint, kept away from the edges so
  // every touch lands on the front face.
  std::uniform_real_distribution<double> step(-0.03, 0.03);
  std::uniform_real_distribution<double> depth(0.2 * settings_.amplitude_m, settings_.amplitude_m);
  std::uniform_real_distribution<double> height(0.001, 0.01);
  const std::array<double, 3>& e = settings_.extent_m;
  // Over the object only: a step that lands off it (an object that leaves voxels empty) is drawn
  // again; after 100 misses the walk stays over its last point.
  double x = to_[0], y = to_[1];
  for (int attempt = 0; attempt < 100; ++attempt) {
    const double tx = std::clamp(to_[0] + step(random_), 0.1 * e[0], 0.9 * e[0]);
    const double ty = std::clamp(to_[1] + step(random_), 0.1 * e[1], 0.9 * e[1]);
    if (settings_.front.At(tx, ty)) {
      x = tx, y = ty;
      break;
    }
  }
  const double front = settings_.front.At(x, y).value_or(0.0);
  return {x, y, front + (inside ? depth(random_) : -height(random_))};
}

std::array<double, 3> DeviceMotion::NextWalk() {
  if (period_ - leg_start_ >= leg_periods_) {
    from_ = to_;
    to_ = NewWaypoint(inside_next_);
    inside_next_ = !inside_next_;
    const double distance = std::hypot(to_[0] - from_[0], to_[1] - from_[1], to_[2] - from_[2]);
    // A smoothstep's top speed is 1.5 × its mean.
    leg_periods_ = std::max<std::int64_t>(
        1, std::llround(1.5 * distance / settings_.walk_speed_m_per_s * settings_.rate_hz));
    leg_start_ = period_;
  }
  const double tau = static_cast<double>(period_ - leg_start_ + 1) / leg_periods_;
  const double w = tau * tau * (3 - 2 * tau);
  std::array<double, 3> tip{};
  for (int c = 0; c < 3; ++c) tip[c] = from_[c] + w * (to_[c] - from_[c]);
  return tip;
}

std::array<double, 3> DeviceMotion::StrokeAt(double t_s) const {
  // The legs' ends as shares of the period: in, along, out, back.
  static constexpr std::array<double, 5> kEnds = {0.0, 0.2, 0.7, 0.8, 1.0};
  const double phase = t_s * settings_.frequency_hz - std::floor(t_s * settings_.frequency_hz);
  const std::array<double, 3> start{settings_.at_m[0], settings_.at_m[1],
                                    front_z_ - settings_.hover_m};
  std::array<std::array<double, 3>, 5> corners{start, start, start, start, start};
  corners[1][2] = corners[2][2] = front_z_ + settings_.amplitude_m;
  corners[2][0] = corners[3][0] = settings_.at_m[0] + settings_.stroke_length_m;
  int leg = 0;
  while (leg < 3 && phase >= kEnds[static_cast<std::size_t>(leg) + 1]) ++leg;
  const auto k = static_cast<std::size_t>(leg);
  const double tau = (phase - kEnds[k]) / (kEnds[k + 1] - kEnds[k]);
  const double w = tau * tau * (3 - 2 * tau);
  std::array<double, 3> tip{};
  for (std::size_t c = 0; c < 3; ++c)
    tip[c] = corners[k][c] + w * (corners[k + 1][c] - corners[k][c]);
  return tip;
}

std::optional<std::array<double, 3>> DeviceMotion::Next() {
  if (settings_.kind == "replay") {
    // Past the end, the last input held (the log's last entry is an input, never a silence).
    return replay_[std::min<std::size_t>(static_cast<std::size_t>(period_++), replay_.size() - 1)];
  }
  const double t = static_cast<double>(period_) / settings_.rate_hz;
  const double phase = 2 * std::numbers::pi * settings_.frequency_hz * t;
  std::array<double, 3> tip{settings_.at_m[0], settings_.at_m[1], 0.0};
  if (settings_.kind == "press") {
    tip[2] = front_z_ - settings_.hover_m +
             (settings_.amplitude_m + settings_.hover_m) * 0.5 * (1 - std::cos(phase));
  } else if (settings_.kind == "sine") {
    tip[2] = front_z_ + settings_.amplitude_m * std::sin(phase);
  } else if (settings_.kind == "stroke") {
    tip = StrokeAt(t);
  } else {  // walk: the constructor refused any other kind
    tip = NextWalk();
  }
  ++period_;
  return tip;
}

}  // namespace hapticsim::device
