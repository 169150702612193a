#include <algorithm>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <iomanip>
#include <iostream>
#include <nlohmann/json.hpp>

#include "core/error.hpp"
#include "core/errormap/error_map_file.hpp"
#include "core/errormap/map_statistics.hpp"
#include "tools/hapticsim/command.hpp"
#include "tools/hapticsim/format.hpp"

namespace hapticsim::cli {

/** The report page's HTML (generated from tools/hapticsim/report_page.html). */
extern const char* const kReportPage;

namespace {

struct AnalyzeOptions {
  std::string map;
  std::string field = "l2";
  std::string report;
  bool json = false;
};

nlohmann::ordered_json Nullable(const std::optional<Correlation>& c, bool p) {
  if (!c) return nullptr;
  return p ? c->p_value : c->coefficient;
}

// In the table's order (the paper's), not alphabetical.
nlohmann::ordered_json CorrelationsJson(const PartialCorrelationTable& table) {
  nlohmann::ordered_json out = nlohmann::ordered_json::object();
  for (const PartialCorrelationRow& row : table.rows) {
    out[row.name] = {{"pearson", Nullable(row.pearson, false)},
                     {"pearson_p", Nullable(row.pearson, true)},
                     {"spearman", Nullable(row.spearman, false)},
                     {"spearman_p", Nullable(row.spearman, true)}};
  }
  return out;
}

// Six significant digits: the page stays small and nothing it shows needs more.
nlohmann::json Rounded(double v) {
  if (!std::isfinite(v)) return nullptr;
  char buffer[32];
  std::snprintf(buffer, sizeof buffer, "%.6g", v);
  return std::strtod(buffer, nullptr);
}

void WriteReport(const ErrorMap& map, const PartialCorrelationTable& table, ErrorField field,
                 const std::string& path) {
  nlohmann::ordered_json data;
  std::vector<std::string> columns, units;
  for (int a = 0; a < kNumMapAxes; ++a) {
    columns.emplace_back(AxisInfo(a).name);
    units.emplace_back(AxisInfo(a).unit);
  }
  for (const auto& [name, unit] :
       std::vector<std::pair<std::string, std::string>>{{"l2_percent", "%"},
                                                        {"max_magnitude_percent", "% of peak"},
                                                        {"max_direction_deg", "°"},
                                                        {"reference_peak_n", "N"},
                                                        {"cost_total", "µs/ms"},
                                                        {"status", ""}}) {
    columns.push_back(name);
    units.push_back(unit);
  }
  nlohmann::json rows = nlohmann::json::array();
  for (const MapSample& s : map.samples) {
    nlohmann::json row = nlohmann::json::array();
    for (double v : s.point) row.push_back(Rounded(v));
    for (double v : {s.l2_percent, s.max_magnitude_percent, s.max_direction_deg, s.reference_peak_n,
                     s.total_cost_us_per_ms()}) {
      row.push_back(Rounded(v));
    }
    row.push_back(static_cast<int>(s.status));
    rows.push_back(row);
  }
  // Parameters the map varies (an axis with one value, e.g. the contact node of most maps, would
  // be a flat line through every sample).
  std::vector<std::string> parallel;
  for (int a = 0; a < kNumMapAxes; ++a) {
    const bool varies =
        std::any_of(map.samples.begin(), map.samples.end(),
                    [&](const MapSample& s) { return s.point[a] != map.samples.front().point[a]; });
    if (varies) parallel.emplace_back(AxisInfo(a).name);
  }
  parallel.emplace_back(ErrorFieldName(field));
  const auto& p = map.provenance;
  data["columns"] = columns;
  data["units"] = units;
  data["rows"] = rows;
  data["parallel_axes"] = parallel;
  data["field"] = ErrorFieldName(field);
  data["field_unit"] = field == ErrorField::kDirection ? "°" : "%";
  data["correlations"] = CorrelationsJson(table);
  data["correlation_note"] =
      "Of " + std::string(ErrorFieldName(field)) + ", over " + std::to_string(table.samples) +
      " ok samples; each parameter controlling for all the others. p: two-sided t test. — "
      "marks a parameter that does not vary in this map.";
  data["provenance"] = "Map '" + p.grid + "' (" + std::to_string(map.samples.size()) +
                       " samples, shard " + p.shard + ") made by hapticsim " + p.code_version +
                       "; model: " + p.model + ".";
  std::string json = data.dump();
  // Inside <script>, "</" would end the element early.
  for (size_t at = 0; (at = json.find("</", at)) != std::string::npos; at += 3) {
    json.replace(at, 2, "<\\/");
  }
  std::string page = kReportPage;
  const std::string marker = "/*DATA*/";
  page.replace(page.find(marker), marker.size(), json);
  std::ofstream out(path);
  out << page;
  HAPTICSIM_THROW_UNLESS(out.good(), "cannot write the report " + path);
}

int Run(const AnalyzeOptions& o) {
  const ErrorMap map = LoadErrorMap(o.map);
  const ErrorField field = ParseErrorField(o.field);
  const PartialCorrelationTable table = PartialCorrelations(map, field);
  if (!o.report.empty()) WriteReport(map, table, field, o.report);
  if (o.json) {
    nlohmann::ordered_json out = {{"map", o.map},
                                  {"field", ErrorFieldName(field)},
                                  {"samples", table.samples},
                                  {"correlations", CorrelationsJson(table)}};
    if (!o.report.empty()) out["report"] = o.report;
    std::cout << out.dump(2) << "\n";
    return kExitOk;
  }
  std::cout << "Partial correlation of " << ErrorFieldName(field) << " with each parameter, "
            << "controlling for the others (" << table.samples << " ok samples of "
            << map.samples.size() << ")\n\n"
            << std::left << std::setw(18) << "parameter" << std::right << std::setw(11)
            << "Pearson r" << std::setw(11) << "p" << std::setw(13) << "Spearman ρ" << std::setw(11)
            << "p"
            << "\n";
  auto cell = [](const std::optional<Correlation>& c, bool p) {
    char buffer[32];
    if (!c) return std::string("—");
    std::snprintf(buffer, sizeof buffer, p ? "%.3g" : "%.4f", p ? c->p_value : c->coefficient);
    return std::string(buffer);
  };
  for (const PartialCorrelationRow& row : table.rows) {
    std::cout << std::left << std::setw(18) << row.name << std::right << std::setw(11)
              << cell(row.pearson, false) << std::setw(11) << cell(row.pearson, true)
              << std::setw(11) << cell(row.spearman, false) << std::setw(11)
              << cell(row.spearman, true) << "\n";
  }
  std::cout << "\n— : the parameter does not vary in this map (or is fixed by the others).\n";
  if (!o.report.empty()) std::cout << "Report: " << o.report << "\n";
  return kExitOk;
}

}  // namespace

Command AddAnalyzeCommand(CLI::App& parent) {
  auto o = std::make_shared<AnalyzeOptions>();
  CLI::App* app = parent.add_subcommand(
      "analyze",
      "Table I of an error map: partial correlations (Pearson and Spearman, t-test p-values) of "
      "the error with every parameter; --report writes an interactive HTML page");
  app->add_option("MAP", o->map, "Map file (.hsmap)")->required()->check(CLI::ExistingFile);
  app->add_option("--field", o->field, "l2, magnitude or direction")->capture_default_str();
  app->add_option("--report", o->report,
                  "Write one self-contained HTML page: parallel coordinates with brushing, the "
                  "correlation table, run time against error")
      ->type_name("FILE.html");
  app->add_flag("--json", o->json, "Print one JSON object");
  return {app, [o] { return Run(*o); }};
}

}  // namespace hapticsim::cli
