#include "core/errormap/sweep_grid_file.hpp"

#include <toml++/toml.h>

#include "core/error.hpp"

namespace hapticsim {

SweepGrid LoadGridFile(const std::string& path, const MapPoint& base) {
  toml::table file;
  try {
    file = toml::parse_file(path);
  } catch (const toml::parse_error& e) {
    const auto& where = e.source().begin;
    throw Error("grid file " + path + ":" + std::to_string(where.line) + ": " +
                std::string(e.description()));
  }
  SweepGrid grid;
  grid.name = path;
  for (int a = 0; a < kNumMapAxes; ++a) grid.axes[a] = {base[a]};
  const toml::table* axes = file["axes"].as_table();
  HAPTICSIM_THROW_UNLESS(axes, "grid file " + path + " has no [axes] table of value lists");
  for (const auto& [key, node] : *axes) {
    const std::string name(key.str());
    const int axis = FindAxis(name);
    std::string where = "grid file ";  // appended: g++ 12 warns falsely on a chain of + here
    where.append(path).append(":").append(std::to_string(key.source().begin.line));
    if (axis < 0) {
      std::string known;
      for (int a = 0; a < kNumMapAxes; ++a) known.append(" ").append(AxisInfo(a).name);
      throw Error(where + ": '" + name + "' is not a map axis; axes are" + known);
    }
    const toml::array* list = node.as_array();
    HAPTICSIM_THROW_UNLESS(list && !list->empty(),
                           where + ": " + name + " must be a non-empty list of numbers");
    std::vector<double> values;
    for (const toml::node& element : *list) {
      const auto value = element.value<double>();
      HAPTICSIM_THROW_UNLESS(value.has_value(), where + ": " + name + " holds a non-number");
      values.push_back(*value);
    }
    grid.axes[axis] = values;
  }
  ValidateGrid(grid);
  return grid;
}

SweepGrid ChooseSweepGrid(const std::string& name, int monte_carlo, std::uint64_t seed,
                          const Scene& scene) {
  const MapPoint at = PointOfScene(scene);
  if (monte_carlo > 0) return MonteCarloGrid(monte_carlo, seed, at);
  if (name == "paper") return PaperGrid(at);
  if (name == "quick") return QuickGrid(scene);
  if (name == "scene") return SceneGrid(at);
  if (name.size() > 5 && name.substr(name.size() - 5) == ".toml") {
    return LoadGridFile(name, at);
  }
  throw Error("--grid " + name + ": choose paper, quick, scene or a FILE.toml");
}

}  // namespace hapticsim
