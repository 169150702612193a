#include <iostream>
#include <nlohmann/json.hpp>

#include "core/error.hpp"
#include "core/errormap/error_lookup.hpp"
#include "core/errormap/error_map_file.hpp"
#include "core/scene/scene_model.hpp"
#include "core/scene/scene_toml.hpp"
#include "tools/hapticsim/command.hpp"
#include "tools/hapticsim/format.hpp"

namespace hapticsim::cli {
namespace {

struct LookupCommandOptions {
  std::string map;
  std::vector<std::string> assignments;
  std::string field = "magnitude";
  bool unknown_frequency = false;
  bool average = false;
  bool json = false;
};

double ParseNumber(const std::string& key, const std::string& text) {
  try {
    size_t used = 0;
    const double value = std::stod(text, &used);
    if (used == text.size()) return value;
  } catch (const std::exception&) {
  }
  throw hapticsim::Error(key + " = '" + text + "' is not a number");
}

int Run(const LookupCommandOptions& o) {
  const ErrorField field = ParseErrorField(o.field);
  const ErrorMap map = LoadErrorMap(o.map, MapLoadParts::kLookupOnly);
  const ErrorLookup lookup(map, field);
  // Unset parameters: the map's own scene.
  const Scene map_scene = ParseSceneText(map.provenance.scene_toml, o.map);
  const MapPoint base = PointOfScene(map_scene);
  LookupQuery query = LookupQuery::At(base);
  query.frequency_known = !o.unknown_frequency;
  query.neighbourhood =
      o.average ? LookupQuery::Neighbourhood::kAverage : LookupQuery::Neighbourhood::kWorst;
  for (const std::string& assignment : o.assignments) {
    const size_t eq = assignment.find('=');
    HAPTICSIM_THROW_UNLESS(eq != std::string::npos,
                           "--set " + assignment + ": expected KEY=VALUE or KEY=LOW:HIGH");
    const std::string key = assignment.substr(0, eq), value = assignment.substr(eq + 1);
    if (key == "contact_node" || key == "input.contact_node") {  // the three axes at once
      Scene scene = map_scene;  // "middle": the map's object's default contact node
      SetSceneValue(&scene, "input.contact_node", value);  // "ix,iy,iz", refused with the format
      const LatticeIndex node = SceneContactNode(scene);
      const std::string problem = ContactNodeProblemOn(scene, node);
      HAPTICSIM_THROW_UNLESS(problem.empty(),
                             "--set " + assignment + ": on the map's object this node " + problem);
      for (int c = 0; c < 3; ++c) {
        const int axis = static_cast<int>(MapAxis::kContactNodeX) + c;
        query.lo[axis] = query.hi[axis] = node[c];
      }
      continue;
    }
    const int axis = FindAxis(key);
    if (axis < 0) {
      std::string known;
      for (int a = 0; a < kNumMapAxes; ++a) known += " " + std::string(AxisInfo(a).name);
      throw hapticsim::Error("--set " + key + ": not a map axis; axes are" + known);
    }
    const size_t colon = value.find(':');
    query.lo[axis] = ParseNumber(key, value.substr(0, colon));
    query.hi[axis] =
        colon == std::string::npos ? query.lo[axis] : ParseNumber(key, value.substr(colon + 1));
  }
  const LookupResult result = lookup.Lookup(query);
  const char* unit = field == ErrorField::kDirection ? "°" : "%";
  if (o.json) {
    nlohmann::json point = nlohmann::json::object();
    for (int a = 0; a < kNumMapAxes; ++a) {
      const std::string name(AxisInfo(a).name);
      point[name] = query.lo[a] == query.hi[a] ? nlohmann::json(query.lo[a])
                                               : nlohmann::json{query.lo[a], query.hi[a]};
    }
    nlohmann::json out = {{"field", ErrorFieldName(field)},
                          {"error", result.usable() ? nlohmann::json(result.error) : nullptr},
                          {"clamped", result.clamped},
                          {"clamped_axis", result.clamped_axis >= 0
                                               ? nlohmann::json(AxisInfo(result.clamped_axis).name)
                                               : nlohmann::json(nullptr)},
                          {"unstable", result.unstable},
                          {"incomplete", result.incomplete},
                          {"frequency_known", query.frequency_known},
                          {"neighbourhood", o.average ? "average" : "worst"},
                          {"query", point}};
    std::cout << out.dump(2) << "\n";
  } else if (!result.usable()) {
    std::cout << ErrorFieldName(field) << ": none — "
              << (result.unstable ? "the configuration is predicted unstable or diverged here"
                                  : "the map has samples here that were not computed")
              << "\n";
  } else {
    std::cout << ErrorFieldName(field) << " = " << Quantity(result.error, unit);
    if (result.clamped) {
      std::cout << "  (CLAMPED: " << AxisInfo(result.clamped_axis).scene_key
                << " is outside the map; the value at its edge is used)";
    }
    std::cout << "\n";
  }
  return result.usable() ? kExitOk : kExitUnstable;
}

}  // namespace

Command AddLookupCommand(CLI::App& parent) {
  auto o = std::make_shared<LookupCommandOptions>();
  CLI::App* app = parent.add_subcommand(
      "lookup",
      "Look up the force error of a configuration in an error map (Section VI-E): multilinear "
      "interpolation, worst case over ranges, clamped with a flag outside the map. Exit 3 when "
      "the configuration is unstable there.");
  app->add_option("MAP", o->map, "Map file (.hsmap)")->required()->check(CLI::ExistingFile);
  app->add_option("--set", o->assignments,
                  "A parameter (axis name or scene key) = value, or LOW:HIGH for a neighbourhood "
                  "of heterogeneous material; unset ones take the map's scene values. "
                  "contact_node=IX,IY,IZ sets the three contact-node axes (between mapped nodes "
                  "the error is interpolated)")
      ->type_name("KEY=VALUE")
      ->take_all();
  app->add_option("--field", o->field,
                  "magnitude (worst force-magnitude error, % of peak; the 7 % JND applies), l2 "
                  "(relative L2 %), direction (degrees)")
      ->capture_default_str();
  app->add_flag("--unknown-frequency", o->unknown_frequency,
                "The input frequency is not measured: the bound over the frequency axis");
  app->add_flag("--average", o->average,
                "Ranges take their centre instead of the worst case (less safe)");
  app->add_flag("--json", o->json, "Print one JSON object");
  return {app, [o] { return Run(*o); }};
}

}  // namespace hapticsim::cli
