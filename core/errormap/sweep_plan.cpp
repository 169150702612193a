#include "core/errormap/sweep_plan.hpp"

#include <cmath>
#include <map>
#include <string>

#include "core/error.hpp"
#include "core/regions/region_partition.hpp"
#include "core/scene/scene_model.hpp"

namespace hapticsim {
namespace {

using Axes = std::array<std::vector<double>, kNumMapAxes>;
using AxisIndex = std::array<int, kNumMapAxes>;

constexpr int Axis(MapAxis axis) { return static_cast<int>(axis); }
constexpr std::array<int, 3> kContactAxes = {
    Axis(MapAxis::kContactNodeX), Axis(MapAxis::kContactNodeY), Axis(MapAxis::kContactNodeZ)};

std::size_t ContactCount(const Axes& ax) {
  std::size_t contacts = 1;
  for (int a : kContactAxes) contacts *= ax[a].size();
  return contacts;
}

// The contact node number `c`'s axis indices into `index`, the last axis fastest.
void SetContactIndex(const Axes& ax, std::size_t c, AxisIndex* index) {
  for (int k = 2; k >= 0; --k) {
    const int a = kContactAxes[k];
    (*index)[a] = static_cast<int>(c % ax[a].size());
    c /= ax[a].size();
  }
}

MapPoint PointAt(const Axes& ax, const AxisIndex& index) {
  MapPoint p;
  for (int a = 0; a < kNumMapAxes; ++a) p[a] = ax[a][index[a]];
  return p;
}

// Identifies the regions a configuration produces: per region its element and node counts.
// Primary boxes around the same contact are nested, so equal counts mean equal regions.
std::vector<int> RegionSignature(const Scene& scene) {
  const RegionPartition partition(scene);
  std::vector<int> signature;
  for (int r = 0; r < partition.num_regions(); ++r) {
    signature.push_back(partition.num_elements(r));
    signature.push_back(partition.num_nodes(r));
  }
  return signature;
}

// The map's material axes: the base material's four, then the contrast of the others to it.
constexpr std::array<int, 5> kMaterialAxes = {
    Axis(MapAxis::kPoissonRatio), Axis(MapAxis::kDensity), Axis(MapAxis::kDamping),
    Axis(MapAxis::kYoungsModulus), Axis(MapAxis::kMaterialContrast)};
using MaterialIndex = std::array<int, kMaterialAxes.size()>;  // per material axis, in that order

// The grid's materials (the material axes, the last fastest) and, per material, the one that is
// run for it: the first of equal E/ρ, ν, d and contrast when `similar`, else itself. (At equal
// contrast every material's E and ρ scale with the base's, so equal E/ρ of the base is equal
// wave speeds everywhere: SceneWithMaterials.)
struct GridMaterials {
  std::vector<MaterialIndex> index;  // per material: its index on each material axis
  std::vector<std::size_t> run_as;
};
GridMaterials MaterialsOf(const Axes& ax, bool similar) {
  enum { kNu, kRho, kD, kE, kContrast };  // positions in kMaterialAxes
  auto value = [&ax](const MaterialIndex& index, int k) { return ax[kMaterialAxes[k]][index[k]]; };
  GridMaterials out;
  size_t count = 1;
  for (int a : kMaterialAxes) count *= ax[a].size();
  for (size_t m = 0; m < count; ++m) {
    MaterialIndex index{};
    for (int k = static_cast<int>(kMaterialAxes.size()) - 1, rest = static_cast<int>(m); k >= 0;
         --k) {
      const int size = static_cast<int>(ax[kMaterialAxes[k]].size());
      index[k] = rest % size;
      rest /= size;
    }
    out.index.push_back(index);
    out.run_as.push_back(m);
    if (!similar) continue;
    const double wave_speed_squared = value(index, kE) / value(index, kRho);
    for (size_t earlier = 0; earlier < m; ++earlier) {
      if (out.run_as[earlier] != earlier) continue;  // only a material that is run answers
      const MaterialIndex& o = out.index[earlier];
      if (o[kNu] == index[kNu] && o[kD] == index[kD] && o[kContrast] == index[kContrast] &&
          std::abs(value(o, kE) / value(o, kRho) - wave_speed_squared) <=
              1e-12 * wave_speed_squared) {
        out.run_as.back() = earlier;
        break;
      }
    }
  }
  return out;
}

void SetMaterialIndex(const MaterialIndex& material, AxisIndex* index) {
  for (size_t k = 0; k < kMaterialAxes.size(); ++k) (*index)[kMaterialAxes[k]] = material[k];
}

// Per contact node and spacing factor, the primary sizes grouped by the regions they give: each
// group is run once, copied to the others. (Boxes near an edge of the object are cut by it, so
// this depends on the node.) Indexed [contact][lod][group] → the sizes' indices.
using SizeGroups = std::vector<std::vector<std::vector<std::vector<int>>>>;
SizeGroups GroupSizesByRegions(const Scene& base, const Axes& ax, const ErrorMap& layout) {
  const int lod_axis = Axis(MapAxis::kSecondaryLod), size_axis = Axis(MapAxis::kPrimarySize);
  SizeGroups size_groups(ContactCount(ax));
  for (std::size_t c = 0; c < size_groups.size(); ++c) {
    size_groups[c].resize(ax[lod_axis].size());
    AxisIndex index{};
    SetContactIndex(ax, c, &index);
    MapPoint at_node = layout.samples.front().point;
    for (int a : kContactAxes) at_node[a] = ax[a][index[a]];
    // A node that cannot be pressed is the grid's mistake, not the configuration's: said so.
    const LatticeIndex node = *SceneAtPoint(base, at_node).input.contact_node;
    const std::string problem = ContactNodeProblemOn(base, node);
    HAPTICSIM_THROW_UNLESS(problem.empty(), "the grid's contact node (contact_node_x, _y, _z) = (" +
                                                std::to_string(node[0]) + ", " +
                                                std::to_string(node[1]) + ", " +
                                                std::to_string(node[2]) + ") " + problem);
    for (size_t l = 0; l < ax[lod_axis].size(); ++l) {
      std::map<std::vector<int>, size_t> seen;
      for (size_t s = 0; s < ax[size_axis].size(); ++s) {
        MapPoint point = at_node;
        point[lod_axis] = ax[lod_axis][l];
        point[size_axis] = ax[size_axis][s];
        std::vector<int> signature;
        try {
          signature = RegionSignature(SceneAtPoint(base, point));
        } catch (const Error& e) {
          throw Error("configuration secondary_lod = " + FormatReal(point[lod_axis]) +
                      ", primary_size = " + FormatReal(point[size_axis]) + " at contact node (" +
                      FormatReal(point[kContactAxes[0]]) + ", " +
                      FormatReal(point[kContactAxes[1]]) + ", " +
                      FormatReal(point[kContactAxes[2]]) + "): " + e.what());
        }
        const auto [it, inserted] = seen.emplace(signature, size_groups[c][l].size());
        if (inserted) size_groups[c][l].emplace_back();
        size_groups[c][l][it->second].push_back(static_cast<int>(s));
      }
    }
  }
  return size_groups;
}

// One task: the material of `index` (and the materials it answers, itself first) in the
// configuration of `index` with the primary sizes `group`: a run per frequency, and per amplitude
// unless `linear`, each answering every sample it stands for.
SweepTask TaskFor(const Axes& ax, const ErrorMap& layout, const GridMaterials& materials,
                  const std::vector<size_t>& answered, AxisIndex index,
                  const std::vector<int>& group, bool linear) {
  const int size_axis = Axis(MapAxis::kPrimarySize), amp_axis = Axis(MapAxis::kAmplitude);
  const int density = Axis(MapAxis::kDensity);
  const size_t amps = ax[amp_axis].size();
  SweepTask task;
  for (size_t f = 0; f < ax[Axis(MapAxis::kFrequency)].size(); ++f) {
    index[Axis(MapAxis::kFrequency)] = static_cast<int>(f);
    const size_t run_amps = linear ? 1 : amps;
    for (size_t ra = 0; ra < run_amps; ++ra) {
      SweepRun run;
      index[amp_axis] = static_cast<int>(ra);
      index[size_axis] = group.front();
      run.point = PointAt(ax, index);
      const double amplitude = run.point[amp_axis];
      for (size_t member : answered) {
        AxisIndex target_index = index;
        SetMaterialIndex(materials.index[member], &target_index);
        const double density_ratio =
            ax[density][target_index[density]] / ax[density][index[density]];
        for (int s : group) {
          for (size_t a = 0; a < amps; ++a) {
            if (!linear && a != ra) continue;
            target_index[size_axis] = s;
            target_index[amp_axis] = static_cast<int>(a);
            run.targets.push_back(
                {layout.GridIndex(target_index), ax[amp_axis][a] / amplitude * density_ratio});
          }
        }
      }
      // Counted in this order: similarity, then linearity, then same regions.
      task.saved_by_similarity += (answered.size() - 1) * (linear ? amps : 1) * group.size();
      task.saved_by_linearity += linear ? (amps - 1) * group.size() : 0;
      task.saved_by_same_regions += group.size() - 1;
      task.runs.push_back(std::move(run));
    }
  }
  task.point = task.runs.front().point;
  return task;
}

}  // namespace

ReferenceKey ReferenceKeyOf(const MapPoint& p) {
  return {p[Axis(MapAxis::kPoissonRatio)], p[Axis(MapAxis::kDensity)],
          p[Axis(MapAxis::kDamping)],      p[Axis(MapAxis::kYoungsModulus)],
          p[Axis(MapAxis::kAmplitude)],    p[Axis(MapAxis::kFrequency)],
          p[Axis(MapAxis::kContactNodeX)], p[Axis(MapAxis::kContactNodeY)],
          p[Axis(MapAxis::kContactNodeZ)], p[Axis(MapAxis::kMaterialContrast)]};
}

std::vector<SweepTask> PlanGridTasks(const Scene& base, const SweepGrid& grid, bool linear,
                                     bool similar) {
  const Axes& ax = grid.axes;
  const ErrorMap layout = ErrorMap::MakeGrid(ax);
  const SizeGroups size_groups = GroupSizesByRegions(base, ax, layout);
  const int lod_axis = Axis(MapAxis::kSecondaryLod), rate_axis = Axis(MapAxis::kSecondaryRate);
  // A material run as an earlier one has no tasks: the earlier one's runs fill its samples too.
  const GridMaterials materials = MaterialsOf(ax, similar);
  std::vector<SweepTask> tasks;
  AxisIndex index{};
  for (size_t m = 0; m < materials.index.size(); ++m) {
    if (materials.run_as[m] != m) continue;
    std::vector<size_t> answered;  // the materials this one's runs answer: itself first
    for (size_t other = m; other < materials.index.size(); ++other) {
      if (materials.run_as[other] == m) answered.push_back(other);
    }
    SetMaterialIndex(materials.index[m], &index);
    for (std::size_t c = 0; c < size_groups.size(); ++c) {
      SetContactIndex(ax, c, &index);
      for (size_t l = 0; l < ax[lod_axis].size(); ++l) {
        index[lod_axis] = static_cast<int>(l);
        for (size_t r = 0; r < ax[rate_axis].size(); ++r) {
          index[rate_axis] = static_cast<int>(r);
          for (const std::vector<int>& group : size_groups[c][l]) {
            tasks.push_back(TaskFor(ax, layout, materials, answered, index, group, linear));
          }
        }
      }
    }
  }
  return tasks;
}

std::vector<SweepTask> PlanScatteredTasks(const SweepGrid& grid) {
  std::vector<SweepTask> tasks;
  for (size_t i = 0; i < grid.points.size(); ++i) {
    SweepTask task;
    task.point = grid.points[i];
    task.runs.push_back({grid.points[i], {{i, 1.0}}});
    tasks.push_back(std::move(task));
  }
  return tasks;
}

}  // namespace hapticsim
