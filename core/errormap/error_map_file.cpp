#include "core/errormap/error_map_file.hpp"

#include <cmath>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <map>
#include <nlohmann/json.hpp>

#include "core/error.hpp"
#include "core/fnv1a.hpp"
#include "core/regions/stepping_order.hpp"

namespace hapticsim {
namespace {

// Coverage-guided fuzzing cannot forge checksums; a fuzzing build (FUZZING_BUILD_MODE_UNSAFE_FOR_
// PRODUCTION, the libFuzzer convention) skips them so the parsers behind them are reached.
#ifdef FUZZING_BUILD_MODE_UNSAFE_FOR_PRODUCTION
constexpr bool kFuzzing = true;
#else
constexpr bool kFuzzing = false;
#endif

using Json = nlohmann::json;

constexpr char kMagic[8] = {'H', 'S', 'I', 'M', 'M', 'A', 'P', '\x1a'};
constexpr size_t kNameBytes = 32;
constexpr size_t kHeaderBytes = 8 + 4 + 4 + 8;
constexpr size_t kEntryBytes = kNameBytes + 8 + 8 + 8;
constexpr int kDetailDoubles = kNumMapAxes + 2 + kMapCostRegions;

// FNV-1a over 64-bit words (the tail zero-padded): fast enough that checking a lookup table
// costs a fraction of reading it.
std::uint64_t Checksum(const std::string& bytes) {
  Fnv1a hash;
  size_t i = 0;
  for (; i + 8 <= bytes.size(); i += 8) {
    std::uint64_t word;
    std::memcpy(&word, bytes.data() + i, 8);
    hash.Word(word);
  }
  std::uint64_t word = 0;
  std::memcpy(&word, bytes.data() + i, bytes.size() - i);
  hash.Word(word ^ (static_cast<std::uint64_t>(bytes.size()) << 56));
  return hash.value();
}

template <typename T>
void Append(std::string* out, const T& value) {
  out->append(reinterpret_cast<const char*>(&value), sizeof value);
}
template <typename T>
T Read(const std::string& in, size_t offset) {
  T value;
  std::memcpy(&value, in.data() + offset, sizeof value);
  return value;
}

std::string SectionName(ErrorField field) { return "lookup." + std::string(ErrorFieldName(field)); }

Json MetaOf(const ErrorMap& map) {
  const auto& p = map.provenance;
  Json meta = {{"kind", map.grid ? "grid" : "scattered"},
               {"samples", map.samples.size()},
               {"scene_toml", p.scene_toml},
               {"model", p.model},
               {"code_version", p.code_version},
               {"grid", p.grid},
               {"shard", p.shard},
               {"direction_threshold_fraction_of_peak", p.direction_threshold},
               {"linearity_used", p.linearity_used},
               {"stepping_order", p.stepping_order},
               {"fields",
                {{"l2_percent", "relative L2 force error over the trial, %"},
                 {"max_magnitude_percent", "worst force-magnitude error, % of the reference peak"},
                 {"max_direction_deg", "worst direction error, degrees"},
                 {"reference_peak_n", "peak reference force, N"},
                 {"spectral_radius", "coupled spectral radius per common period"},
                 {"cost_us_per_ms", "compute µs per simulated ms, per region"}}}};
  Json axes = Json::array();
  for (int a = 0; a < kNumMapAxes; ++a) {
    const MapAxisInfo& info = AxisInfo(a);
    Json axis = {{"name", info.name}, {"scene_key", info.scene_key}, {"unit", info.unit}};
    if (map.grid) axis["values"] = map.axes[a];
    axes.push_back(axis);
  }
  meta["axes"] = axes;
  return meta;
}

[[noreturn]] void Refuse(const std::string& path, const std::string& why) {
  throw Error("error map " + path + " refused: " + why);
}

}  // namespace

void SaveErrorMap(const ErrorMap& map, const std::string& path) {
  const size_t n = map.samples.size();
  std::vector<std::pair<std::string, std::string>> sections;
  sections.emplace_back("meta", MetaOf(map).dump(1));
  for (int f = 0; f < kNumErrorFields; ++f) {
    std::string table;
    table.reserve(n * 8);
    for (const MapSample& s : map.samples) Append(&table, FieldOf(s, static_cast<ErrorField>(f)));
    sections.emplace_back(SectionName(static_cast<ErrorField>(f)), std::move(table));
  }
  std::string status;
  for (const MapSample& s : map.samples) {
    Append(&status, static_cast<std::uint8_t>(s.status));
    Append(&status, s.status_region);
  }
  sections.emplace_back("status", std::move(status));
  std::string details;
  details.reserve(n * kDetailDoubles * 8);
  for (const MapSample& s : map.samples) {
    for (double v : s.point) Append(&details, v);
    Append(&details, s.reference_peak_n);
    Append(&details, s.spectral_radius);
    for (double v : s.cost_us_per_ms) Append(&details, v);
  }
  sections.emplace_back("details", std::move(details));

  std::string directory;
  std::uint64_t offset = kHeaderBytes + sections.size() * kEntryBytes;
  for (const auto& [name, bytes] : sections) {
    char padded[kNameBytes] = {};
    std::memcpy(padded, name.data(), std::min(name.size(), kNameBytes - 1));
    directory.append(padded, kNameBytes);
    Append(&directory, offset);
    Append(&directory, static_cast<std::uint64_t>(bytes.size()));
    Append(&directory, Checksum(bytes));
    offset += bytes.size();
  }
  std::string file(kMagic, sizeof kMagic);
  Append(&file, kErrorMapFormatVersion);
  Append(&file, static_cast<std::uint32_t>(sections.size()));
  Append(&file, Checksum(directory));
  file += directory;
  for (const auto& section : sections) file += section.second;

  const std::string temporary = path + ".partial";
  {
    std::ofstream out(temporary, std::ios::binary | std::ios::trunc);
    out.write(file.data(), static_cast<std::streamsize>(file.size()));
    out.flush();
    HAPTICSIM_THROW_UNLESS(out.good(), "cannot write error map " + temporary);
  }
  std::error_code ec;
  std::filesystem::rename(temporary, path, ec);
  HAPTICSIM_THROW_UNLESS(!ec, "cannot rename " + temporary + " to " + path + ": " + ec.message());
}

namespace {

// Opens a map file and checks its header and directory; reads and checks sections on demand.
class MapFileReader {
 public:
  explicit MapFileReader(const std::string& path) : path_(path), in_(path, std::ios::binary) {
    Open();
  }
  const std::string& path() const { return path_; }
  std::uint64_t file_size() const { return file_size_; }

  std::string Section(const std::string& name) {
    const auto it = entries_.find(name);
    if (it == entries_.end()) Refuse(path_, "section '" + name + "' is missing");
    const Entry& e = it->second;
    if (e.offset + e.size > file_size_ || e.offset + e.size < e.offset) {
      Refuse(path_, "truncated: section '" + name + "' ends at byte " +
                        std::to_string(e.offset + e.size) + ", the file has " +
                        std::to_string(file_size_));
    }
    std::string bytes = ReadRange(e.offset, e.size);
    if (Checksum(bytes) != e.checksum && !kFuzzing) {
      Refuse(path_, "corrupted: checksum of section '" + name + "'");
    }
    return bytes;
  }

 private:
  struct Entry {
    std::uint64_t offset, size, checksum;
  };

  std::string ReadRange(std::uint64_t offset, std::uint64_t size) {
    std::string bytes(size, '\0');
    in_.seekg(static_cast<std::streamoff>(offset));
    in_.read(bytes.data(), static_cast<std::streamsize>(size));
    if (!in_) Refuse(path_, "truncated (cannot read bytes " + std::to_string(offset) + "…)");
    return bytes;
  }

  void Open() {
    if (!in_) throw Error("cannot open error map " + path_ + ": " + std::strerror(errno));
    in_.seekg(0, std::ios::end);
    file_size_ = static_cast<std::uint64_t>(in_.tellg());
    const std::uint64_t file_size = file_size_;
    if (file_size < sizeof kMagic) Refuse(path_, "truncated: too short to be an error map");
    const std::string header = ReadRange(0, std::min<std::uint64_t>(file_size, kHeaderBytes));
    if (std::memcmp(header.data(), kMagic, sizeof kMagic) != 0) {
      Refuse(path_, "not an error map file (no HSIMMAP signature)");
    }
    if (file_size < kHeaderBytes) Refuse(path_, "truncated inside the header");
    const auto version = Read<std::uint32_t>(header, 8);
    if (version != kErrorMapFormatVersion) {
      Refuse(path_, "wrong format version " + std::to_string(version) + "; this hapticsim reads " +
                        std::to_string(kErrorMapFormatVersion) +
                        (version == 1   ? " (version 1 maps have no contact-node axes)"
                         : version == 2 ? " (version 2 maps have no material-contrast axis)"
                                        : "") +
                        ": remake it with hapticsim sweep");
    }
    const auto count = Read<std::uint32_t>(header, 12);
    if (count > 64) Refuse(path_, "corrupted: " + std::to_string(count) + " sections");
    if (kHeaderBytes + count * kEntryBytes > file_size)
      Refuse(path_, "truncated inside the directory");
    const std::string directory = ReadRange(kHeaderBytes, count * kEntryBytes);
    if (Checksum(directory) != Read<std::uint64_t>(header, 16) && !kFuzzing) {
      Refuse(path_, "corrupted: directory checksum mismatch");
    }
    for (size_t i = 0; i < count; ++i) {
      const size_t at = i * kEntryBytes;
      std::string name(directory.data() + at, kNameBytes);
      name.resize(std::strlen(name.c_str()));
      entries_[name] = {Read<std::uint64_t>(directory, at + kNameBytes),
                        Read<std::uint64_t>(directory, at + kNameBytes + 8),
                        Read<std::uint64_t>(directory, at + kNameBytes + 16)};
    }
  }

  std::string path_;
  std::ifstream in_;
  std::uint64_t file_size_ = 0;
  std::map<std::string, Entry> entries_;
};

}  // namespace

// Reads the metadata into `map` (provenance, kind, axes; no samples). Returns the sample count.
std::uint64_t ReadMeta(MapFileReader& reader, ErrorMap* out) {
  const std::string& path = reader.path();
  ErrorMap& map = *out;
  try {
    const Json meta = Json::parse(reader.Section("meta"));
    map.grid = meta.at("kind").get<std::string>() == "grid";
    auto& p = map.provenance;
    p.scene_toml = meta.at("scene_toml").get<std::string>();
    p.model = meta.at("model").get<std::string>();
    p.code_version = meta.at("code_version").get<std::string>();
    p.grid = meta.at("grid").get<std::string>();
    p.shard = meta.at("shard").get<std::string>();
    p.direction_threshold = meta.at("direction_threshold_fraction_of_peak").get<double>();
    p.linearity_used = meta.at("linearity_used").get<bool>();
    p.stepping_order = meta.value("stepping_order", std::string("substeps"));
    if (!SteppingOrderNamed(p.stepping_order)) {
      Refuse(path, "its stepping_order \"" + p.stepping_order +
                       "\" is neither \"substeps\" nor \"threads\"");
    }
    const auto& axes = meta.at("axes");
    if (axes.size() != kNumMapAxes) Refuse(path, "corrupted: wrong number of axes");
    std::uint64_t grid_size = 1;
    for (int a = 0; a < kNumMapAxes; ++a) {
      if (axes[a].at("name").get<std::string>() != AxisInfo(a).name) {
        Refuse(path, "axis " + std::to_string(a) + " is not " + std::string(AxisInfo(a).name));
      }
      if (map.grid) {
        std::vector<double>& values = map.axes[a];
        values = axes[a].at("values").get<std::vector<double>>();
        if (values.empty())
          Refuse(path, "corrupted: axis " + std::string(AxisInfo(a).name) + " is empty");
        for (size_t i = 0; i < values.size(); ++i) {
          if (!std::isfinite(values[i]) || (i > 0 && !(values[i] > values[i - 1]))) {
            Refuse(path, "corrupted: the values of axis " + std::string(AxisInfo(a).name) +
                             " are not finite and ascending");
          }
        }
        // Capped without overflowing (the product once wrapped round to 0, and a map of 0 samples
        // passed for one of 2⁶⁴): the file size bounds the sample count anyway.
        constexpr std::uint64_t kCap = std::uint64_t{1} << 50;
        grid_size =
            values.size() > kCap / grid_size ? kCap : std::min(kCap, grid_size * values.size());
      }
    }
    const auto n = meta.at("samples").get<std::uint64_t>();
    if (map.grid && n != grid_size) Refuse(path, "corrupted: sample count differs from the axes");
    // Every sample takes at least 8 bytes in each error table: a count the file cannot hold is
    // refused before anything is allocated for it.
    if (n > reader.file_size() / 8) {
      Refuse(path, "corrupted: " + std::to_string(n) + " samples cannot fit in " +
                       std::to_string(reader.file_size()) + " bytes");
    }
    return n;
  } catch (const Json::exception& e) {
    Refuse(path, std::string("corrupted metadata: ") + e.what());
  }
}

ErrorMap LoadErrorMap(const std::string& path, MapLoadParts parts) {
  MapFileReader reader(path);
  auto section = [&reader](const std::string& name) { return reader.Section(name); };
  ErrorMap map;
  const std::uint64_t n = ReadMeta(reader, &map);
  if (map.grid) {
    ErrorMap grid = ErrorMap::MakeGrid(map.axes);
    map.samples = std::move(grid.samples);
  } else {
    if (parts == MapLoadParts::kLookupOnly) {
      Refuse(path, "a scattered (Monte Carlo) map has no lookup table; make a grid map");
    }
    map.samples.resize(n);
  }
  auto check_size = [&](const std::string& name, const std::string& bytes, size_t per_sample) {
    if (bytes.size() != n * per_sample) {
      Refuse(path, "corrupted: section '" + name + "' has " + std::to_string(bytes.size()) +
                       " bytes, expected " + std::to_string(n * per_sample));
    }
  };
  for (int f = 0; f < kNumErrorFields; ++f) {
    const std::string name = SectionName(static_cast<ErrorField>(f));
    const std::string table = section(name);
    check_size(name, table, 8);
    for (size_t i = 0; i < n; ++i) {
      const double v = Read<double>(table, i * 8);
      MapSample& s = map.samples[i];
      (f == 0 ? s.l2_percent : f == 1 ? s.max_magnitude_percent : s.max_direction_deg) = v;
    }
  }
  const std::string status = section("status");
  check_size("status", status, 2);
  for (size_t i = 0; i < n; ++i) {
    const auto code = Read<std::uint8_t>(status, 2 * i);
    if (code > static_cast<std::uint8_t>(SampleStatus::kNotComputed)) {
      Refuse(path, "corrupted: unknown status " + std::to_string(code) + " at sample " +
                       std::to_string(i));
    }
    map.samples[i].status = static_cast<SampleStatus>(code);
    map.samples[i].status_region = Read<std::int8_t>(status, 2 * i + 1);
  }
  if (parts == MapLoadParts::kEverything) {
    const std::string details = section("details");
    check_size("details", details, kDetailDoubles * 8);
    for (size_t i = 0; i < n; ++i) {
      size_t at = i * kDetailDoubles * 8;
      MapSample& s = map.samples[i];
      for (double& v : s.point) v = Read<double>(details, at), at += 8;
      s.reference_peak_n = Read<double>(details, at), at += 8;
      s.spectral_radius = Read<double>(details, at), at += 8;
      for (double& v : s.cost_us_per_ms) v = Read<double>(details, at), at += 8;
    }
  }
  return map;
}

ErrorLookup LoadErrorLookup(const std::string& path, ErrorField field) {
  MapFileReader reader(path);
  ErrorMap map;
  const std::uint64_t n = ReadMeta(reader, &map);
  if (!map.grid) Refuse(path, "a scattered (Monte Carlo) map has no lookup table; make a grid map");
  const std::string name = SectionName(field);
  const std::string table = reader.Section(name);
  const std::string status = reader.Section("status");
  if (table.size() != n * 8 || status.size() != n * 2) {
    Refuse(path, "corrupted: section '" + name + "' or 'status' does not hold " +
                     std::to_string(n) + " samples");
  }
  std::vector<double> values(n);
  std::memcpy(values.data(), table.data(), table.size());
  std::vector<std::uint8_t> statuses(n);
  for (size_t i = 0; i < n; ++i) {
    statuses[i] = static_cast<std::uint8_t>(status[2 * i]);
    if (statuses[i] > static_cast<std::uint8_t>(SampleStatus::kNotComputed)) {
      Refuse(path, "corrupted: unknown status at sample " + std::to_string(i));
    }
  }
  return ErrorLookup(map.axes, std::move(values), std::move(statuses), field);
}

ErrorMap MergeErrorMaps(const std::vector<ErrorMap>& shards) {
  HAPTICSIM_THROW_UNLESS(!shards.empty(), "map merge: no maps given");
  ErrorMap merged = shards.front();
  for (size_t k = 1; k < shards.size(); ++k) {
    const ErrorMap& shard = shards[k];
    const std::string which = "map merge: map " + std::to_string(k + 1) + " ";
    const auto& a = merged.provenance;
    const auto& b = shard.provenance;
    HAPTICSIM_THROW_UNLESS(shard.grid == merged.grid && shard.axes == merged.axes &&
                               shard.samples.size() == merged.samples.size(),
                           which + "has other axes or samples than map 1");
    HAPTICSIM_THROW_UNLESS(b.scene_toml == a.scene_toml, which + "was made for another scene");
    HAPTICSIM_THROW_UNLESS(b.model == a.model && b.code_version == a.code_version,
                           which + "was made by another model or code version (" + b.code_version +
                               " vs " + a.code_version + ")");
    HAPTICSIM_THROW_UNLESS(b.grid == a.grid, which + "is from another grid (" + b.grid + ")");
    HAPTICSIM_THROW_UNLESS(b.stepping_order == a.stepping_order,
                           which + "stepped the regions in the " + b.stepping_order +
                               "' order, map 1 in the " + a.stepping_order + "'");
    for (size_t i = 0; i < shard.samples.size(); ++i) {
      const MapSample& s = shard.samples[i];
      if (!s.computed()) continue;
      MapSample& m = merged.samples[i];
      if (!merged.grid) {
        HAPTICSIM_THROW_UNLESS(s.point == m.point || !m.computed(),
                               which + "places sample " + std::to_string(i) + " elsewhere");
      }
      if (m.computed()) {
        HAPTICSIM_THROW_UNLESS(
            m.status == s.status && (m.l2_percent == s.l2_percent ||
                                     (std::isnan(m.l2_percent) && std::isnan(s.l2_percent))),
            which + "disagrees with an earlier map at sample " + std::to_string(i));
        continue;
      }
      m = s;
    }
  }
  merged.provenance.shard = "1/1";
  return merged;
}

}  // namespace hapticsim
