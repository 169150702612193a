#include "core/errormap/sweep_journal.hpp"

#include <cmath>
#include <cstring>
#include <limits>
#include <nlohmann/json.hpp>
#include <sstream>

#include "core/error.hpp"
#include "core/errormap/error_sweep.hpp"
#include "core/fnv1a.hpp"

namespace hapticsim {
namespace {

using Json = nlohmann::json;
constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

Json SampleRecord(std::size_t index, const MapSample& s) {
  auto num = [](double v) { return std::isfinite(v) ? Json(v) : Json(nullptr); };
  Json record =
      Json::array({index, static_cast<int>(s.status), static_cast<int>(s.status_region),
                   num(s.l2_percent), num(s.max_magnitude_percent), num(s.max_direction_deg),
                   num(s.reference_peak_n), num(s.spectral_radius)});
  for (double c : s.cost_us_per_ms) record.push_back(num(c));
  return record;
}

void ReadSampleRecord(const Json& record, ErrorMap* map) {
  auto num = [](const Json& v) { return v.is_null() ? kNaN : v.get<double>(); };
  const auto index = record.at(0).get<std::size_t>();
  if (index >= map->samples.size()) throw Error("journal sample index out of range");
  MapSample& s = map->samples[index];
  s.status = static_cast<SampleStatus>(record.at(1).get<int>());
  s.status_region = static_cast<std::int8_t>(record.at(2).get<int>());
  s.l2_percent = num(record.at(3));
  s.max_magnitude_percent = num(record.at(4));
  s.max_direction_deg = num(record.at(5));
  s.reference_peak_n = num(record.at(6));
  s.spectral_radius = num(record.at(7));
  for (int c = 0; c < kMapCostRegions; ++c) s.cost_us_per_ms[c] = num(record.at(8 + c));
}

}  // namespace

std::string SweepFingerprint(const ErrorMap& map, const SweepGrid& grid,
                             const SweepOptions& options) {
  std::ostringstream text;
  text << map.provenance.scene_toml << map.provenance.model << map.provenance.code_version
       << grid.name << options.shard_index << '/' << options.shard_count << options.use_linearity
       << options.use_similarity << map.provenance.stepping_order;
  Fnv1a hash;
  const std::string words = text.str();
  hash.Bytes(words.data(), words.size());
  for (const MapSample& s : map.samples) {
    for (double v : s.point) {
      std::uint64_t bits;
      std::memcpy(&bits, &v, sizeof bits);
      hash.Word(bits);
    }
  }
  std::ostringstream hex;
  hex << std::hex << hash.value();
  return hex.str();
}

std::vector<bool> ReadSweepJournal(const std::string& path, const std::string& fingerprint,
                                   std::size_t num_tasks, ErrorMap* map) {
  std::vector<bool> done(num_tasks, false);
  std::ifstream in(path);
  if (!in) return done;
  std::string line;
  if (!std::getline(in, line)) return done;
  Json header;
  try {
    header = Json::parse(line);
  } catch (const Json::exception&) {
    throw Error("journal " + path + " is not a sweep journal; delete it or drop --resume");
  }
  if (header.value("fingerprint", "") != fingerprint) {
    throw Error("journal " + path +
                " belongs to another sweep (other grid, scene, shard or code version); delete "
                "it or drop --resume");
  }
  while (std::getline(in, line)) {
    Json entry;
    try {
      entry = Json::parse(line);
    } catch (const Json::exception&) {
      break;  // torn write
    }
    const auto task = entry.at("task").get<std::size_t>();
    if (task >= num_tasks) throw Error("journal " + path + " names task " + std::to_string(task));
    for (const Json& record : entry.at("samples")) ReadSampleRecord(record, map);
    done[task] = true;
  }
  return done;
}

SweepJournal::SweepJournal(const std::string& path, const std::string& fingerprint, bool resume) {
  if (path.empty()) return;
  const bool append = resume && std::ifstream(path).good();
  out_.open(path, append ? std::ios::app : std::ios::trunc);
  HAPTICSIM_THROW_UNLESS(out_.good(), "cannot write the journal " + path);
  if (!append) out_ << Json{{"journal", 1}, {"fingerprint", fingerprint}}.dump() << "\n";
  out_.flush();
}

void SweepJournal::Append(std::size_t task,
                          const std::vector<std::pair<std::size_t, MapSample>>& samples) {
  if (!out_.is_open()) return;
  Json entry = {{"task", task}, {"samples", Json::array()}};
  for (const auto& [index, sample] : samples)
    entry["samples"].push_back(SampleRecord(index, sample));
  out_ << entry.dump() << "\n";
  out_.flush();
}

}  // namespace hapticsim
