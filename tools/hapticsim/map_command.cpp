#include <cmath>
#include <fstream>
#include <iomanip>
#include <iostream>
#include <nlohmann/json.hpp>

#include "core/error.hpp"
#include "core/errormap/error_map_file.hpp"
#include "tools/hapticsim/command.hpp"
#include "tools/hapticsim/format.hpp"

namespace hapticsim::cli {
namespace {

struct MapCommandOptions {
  std::string map;
  bool json = false;
  std::string csv;
  std::string out;
  std::vector<std::string> shards;
};

int Info(const MapCommandOptions& o) {
  const ErrorMap map = LoadErrorMap(o.map);
  const auto& p = map.provenance;
  std::size_t ok = map.CountStatus(SampleStatus::kOk);
  double worst = 0, best = INFINITY;
  for (const MapSample& s : map.samples) {
    if (s.status != SampleStatus::kOk) continue;
    worst = std::max(worst, s.l2_percent);
    best = std::min(best, s.l2_percent);
  }
  if (o.json) {
    nlohmann::json axes = nlohmann::json::object();
    for (int a = 0; a < kNumMapAxes; ++a) {
      nlohmann::json axis = {{"scene_key", AxisInfo(a).scene_key}, {"unit", AxisInfo(a).unit}};
      if (map.grid) axis["values"] = map.axes[a];
      axes[std::string(AxisInfo(a).name)] = axis;
    }
    nlohmann::json out = {
        {"file", o.map},
        {"format_version", kErrorMapFormatVersion},
        {"kind", map.grid ? "grid" : "scattered"},
        {"samples", map.samples.size()},
        {"ok", ok},
        {"predicted_unstable", map.CountStatus(SampleStatus::kPredictedUnstable)},
        {"diverged", map.CountStatus(SampleStatus::kDiverged)},
        {"not_computed", map.CountStatus(SampleStatus::kNotComputed)},
        {"l2_percent_range", ok ? nlohmann::json{best, worst} : nlohmann::json(nullptr)},
        {"grid", p.grid},
        {"shard", p.shard},
        {"model", p.model},
        {"code_version", p.code_version},
        {"linearity_used", p.linearity_used},
        {"stepping_order", p.stepping_order},
        {"direction_threshold_fraction_of_peak", p.direction_threshold},
        {"results_checksum", map.ResultsChecksum()},
        {"axes", axes},
        {"scene_toml", p.scene_toml}};
    std::cout << out.dump(2) << "\n";
    return kExitOk;
  }
  std::cout << "Error map " << o.map << " (format " << kErrorMapFormatVersion << ", "
            << (map.grid ? "grid" : "scattered") << ")\n"
            << "  made by " << p.code_version << " from grid '" << p.grid << "', shard " << p.shard
            << (p.linearity_used ? ", amplitude axis from linearity" : "")
            << ", regions stepped in the " << p.stepping_order << "' order\n"
            << "  model: " << p.model << "\n"
            << "  samples: " << map.samples.size() << " — ok " << ok << ", predicted unstable "
            << map.CountStatus(SampleStatus::kPredictedUnstable) << ", diverged "
            << map.CountStatus(SampleStatus::kDiverged) << ", not computed "
            << map.CountStatus(SampleStatus::kNotComputed) << "\n";
  if (ok) {
    std::cout << "  relative L2 force error of ok samples: " << Quantity(best, "%") << " to "
              << Quantity(worst, "%") << "\n";
  }
  if (map.grid) {
    std::cout << "  axes:\n";
    for (int a = 0; a < kNumMapAxes; ++a) {
      std::cout << "    " << std::left << std::setw(28) << AxisInfo(a).scene_key << " {";
      for (size_t i = 0; i < map.axes[a].size(); ++i) {
        const double v = map.axes[a][i];
        std::cout << (i ? ", " : "")
                  << (AxisInfo(a).integer ? std::to_string(std::lround(v)) : FormatReal(v));
      }
      std::cout << "}" << (AxisInfo(a).unit.empty() ? "" : " " + std::string(AxisInfo(a).unit))
                << "\n";
    }
  }
  std::cout << "  base scene (hapticsim map info --json prints it as TOML)\n";
  return kExitOk;
}

int Export(const MapCommandOptions& o) {
  const ErrorMap map = LoadErrorMap(o.map);
  std::ofstream file;
  if (o.csv != "-") {
    file.open(o.csv);
    HAPTICSIM_THROW_UNLESS(file.good(), "cannot write " + o.csv);
  }
  std::ostream& out = o.csv == "-" ? std::cout : file;
  for (int a = 0; a < kNumMapAxes; ++a) {
    const MapAxisInfo& info = AxisInfo(a);
    out << info.name << (info.unit.empty() ? "" : "_" + std::string(info.unit)) << ",";
  }
  out << "l2_percent,max_magnitude_percent,max_direction_deg,reference_peak_N,spectral_radius,"
         "cost_total_us_per_ms";
  for (int r = 0; r < kMapCostRegions; ++r) out << ",cost_region" << r << "_us_per_ms";
  out << ",status,status_region\n";
  out << std::setprecision(17);
  for (const MapSample& s : map.samples) {
    for (double v : s.point) out << v << ",";
    out << s.l2_percent << "," << s.max_magnitude_percent << "," << s.max_direction_deg << ","
        << s.reference_peak_n << "," << s.spectral_radius << "," << s.total_cost_us_per_ms();
    for (double c : s.cost_us_per_ms) out << "," << c;
    const std::string region = s.status_region == kCouplingRegion ? "coupling"
                               : s.status_region == kNoRegion     ? ""
                                                                  : std::to_string(s.status_region);
    out << "," << SampleStatusName(s.status) << "," << region << "\n";
  }
  if (o.csv != "-") {
    std::cerr << "wrote " << map.samples.size() << " samples to " << o.csv << "\n";
  }
  return kExitOk;
}

int Merge(const MapCommandOptions& o) {
  std::vector<ErrorMap> shards;
  for (const std::string& path : o.shards) shards.push_back(LoadErrorMap(path));
  const ErrorMap merged = MergeErrorMaps(shards);
  SaveErrorMap(merged, o.out);
  const std::size_t missing = merged.CountStatus(SampleStatus::kNotComputed);
  std::cout << "merged " << shards.size() << " maps into " << o.out << ": "
            << merged.samples.size() - missing << " of " << merged.samples.size()
            << " samples computed"
            << (missing ? " (" + std::to_string(missing) + " still missing: a shard is absent)"
                        : "")
            << "\n";
  return kExitOk;
}

}  // namespace

Command AddMapCommand(CLI::App& parent) {
  auto o = std::make_shared<MapCommandOptions>();
  CLI::App* app = parent.add_subcommand("map", "Inspect, export and merge error map files");
  app->require_subcommand(1);
  CLI::App* info = app->add_subcommand("info", "Axes, provenance and status counts of a map");
  info->add_option("MAP", o->map, "Map file (.hsmap)")->required()->check(CLI::ExistingFile);
  info->add_flag("--json", o->json, "Print one JSON object");
  CLI::App* exp = app->add_subcommand("export", "Every sample as a CSV row (units in the header)");
  exp->add_option("MAP", o->map, "Map file (.hsmap)")->required()->check(CLI::ExistingFile);
  exp->add_option("--csv", o->csv, "CSV file to write, - for stdout")->required();
  CLI::App* merge = app->add_subcommand("merge", "Join the shards of one sweep into one map");
  merge->add_option("OUT", o->out, "Merged map to write")->required();
  merge->add_option("SHARDS", o->shards, "Shard maps from sweep --shard I/N")
      ->required()
      ->check(CLI::ExistingFile);
  return {app, [o, info, exp, merge] {
            if (info->parsed()) return Info(*o);
            if (exp->parsed()) return Export(*o);
            if (merge->parsed()) return Merge(*o);
            return static_cast<int>(kExitBadInput);
          }};
}

}  // namespace hapticsim::cli
