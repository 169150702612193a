#include "core/errormap/sweep_grid.hpp"

#include <algorithm>
#include <random>

#include "core/error.hpp"
#include "core/scene/scene_model.hpp"

namespace hapticsim {

std::size_t SweepGrid::NumSamples() const {
  if (scattered) return points.size();
  std::size_t n = 1;
  for (const auto& values : axes) n *= values.size();
  return n;
}

namespace {

// The axes a grid of the paper's does not vary: the scene's contact node and material contrast.
void SetSceneAxes(const MapPoint& scene_point, SweepGrid* grid) {
  for (MapAxis axis : {MapAxis::kContactNodeX, MapAxis::kContactNodeY, MapAxis::kContactNodeZ,
                       MapAxis::kMaterialContrast}) {
    const int a = static_cast<int>(axis);
    grid->axes[a] = {scene_point[a]};
  }
}

}  // namespace

SweepGrid PaperGrid(const MapPoint& scene_point) {
  SweepGrid grid;
  grid.name = "paper";
  grid.axes = {{
      {0.40, 0.45, 0.49},
      {800, 1000, 1200},
      {10, 20, 30, 40},
      {5000, 10000, 15000, 20000},
      {0.005, 0.010, 0.015},
      {0.5, 1.0, 1.25},
      {1, 2, 3},
      {1, 2, 3, 4},
      {600, 700, 800, 900, 1000},
  }};
  SetSceneAxes(scene_point, &grid);
  return grid;
}

SweepGrid QuickGrid(const Scene& scene) {
  const MapPoint scene_point = PointOfScene(scene);
  SweepGrid grid;
  grid.name = "quick";
  grid.axes = {{
      {0.40, 0.49},
      {800, 1200},
      {10, 40},
      {5000, 20000},
      {0.005, 0.015},
      {1.0, 1.25},
      {2, 3},
      {1, 4},
      {600, 1000},
  }};
  SetSceneAxes(scene_point, &grid);
  // An object of several materials: from one material (contrast 1) to the scene's contrast.
  const int contrast = static_cast<int>(MapAxis::kMaterialContrast);
  if (scene_point[contrast] != 1) {
    grid.axes[contrast] = {std::min(1.0, scene_point[contrast]),
                           std::max(1.0, scene_point[contrast])};
  }
  const LatticeIndex node = SceneContactNode(scene);
  for (int axis = 0; axis < 3; ++axis) {
    for (int step : {-1, 1}) {
      LatticeIndex neighbour = node;
      neighbour[axis] += step;
      if (!ContactNodeProblemOn(scene, neighbour).empty()) continue;
      const double a = node[axis], b = neighbour[axis];
      grid.axes[static_cast<int>(MapAxis::kContactNodeX) + axis] = {std::min(a, b), std::max(a, b)};
      return grid;
    }
  }
  return grid;
}

SweepGrid SceneGrid(const MapPoint& scene_point) {
  SweepGrid grid = PaperGrid(scene_point);
  grid.name = "scene";
  for (MapAxis axis :
       {MapAxis::kPoissonRatio, MapAxis::kDensity, MapAxis::kDamping, MapAxis::kYoungsModulus}) {
    const int a = static_cast<int>(axis);
    grid.axes[a] = {scene_point[a]};
  }
  return grid;
}

SweepGrid MonteCarloGrid(int count, std::uint64_t seed, const MapPoint& scene_point) {
  HAPTICSIM_THROW_UNLESS(count > 0, "--monte-carlo needs a positive sample count");
  const SweepGrid paper = PaperGrid(scene_point);
  SweepGrid grid;
  grid.name = "monte-carlo " + std::to_string(count) + " seed " + std::to_string(seed);
  grid.scattered = true;
  std::mt19937_64 rng(seed);
  // Uniform in [0, 1) from the top 53 bits: the same on every standard library.
  auto uniform = [&rng] { return static_cast<double>(rng() >> 11) * 0x1.0p-53; };
  grid.points.resize(static_cast<size_t>(count));
  for (MapPoint& point : grid.points) {
    for (int a = 0; a < kNumMapAxes; ++a) {
      const std::vector<double>& v = paper.axes[a];
      if (v.size() == 1) {  // no draw: the sequence of the other axes stays as it was
        point[a] = v.front();
        continue;
      }
      // Rates from the paper's values too: the coupled schedule repeats after the common period
      // of the rates (10 ms for these, up to 1 s for arbitrary whole-Hz rates), and the stability
      // estimate runs hundreds of common periods.
      if (AxisInfo(a).integer || a == static_cast<int>(MapAxis::kSecondaryRate)) {
        point[a] = v[static_cast<size_t>(uniform() * static_cast<double>(v.size()))];
      } else {
        point[a] = v.front() + uniform() * (v.back() - v.front());
      }
    }
  }
  return grid;
}

void ValidateGrid(const SweepGrid& grid) {
  if (grid.scattered) {
    HAPTICSIM_THROW_UNLESS(!grid.points.empty(), "the sweep has no sample points");
    return;
  }
  for (int a = 0; a < kNumMapAxes; ++a) {
    const auto& values = grid.axes[a];
    const std::string key(AxisInfo(a).scene_key);
    HAPTICSIM_THROW_UNLESS(!values.empty(), key + ": the grid needs at least one value");
    for (size_t i = 1; i < values.size(); ++i) {
      HAPTICSIM_THROW_UNLESS(values[i] > values[i - 1],
                             key + ": grid values must be strictly increasing");
    }
  }
}

}  // namespace hapticsim
