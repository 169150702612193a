#include "core/errormap/error_map_file.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <fstream>

#include "core/error.hpp"

namespace hapticsim {
namespace {

std::string TempPath(const std::string& name) {
  return (std::filesystem::temp_directory_path() / ("hapticsim_" + name)).string();
}

ErrorMap ExampleMap() {
  std::array<std::vector<double>, kNumMapAxes> axes;
  for (auto& axis : axes) axis = {1.0};
  axes[0] = {0.40, 0.49};
  axes[7] = {1, 2, 3};
  ErrorMap map = ErrorMap::MakeGrid(axes);
  map.provenance.scene_toml = "[mesh]\nnodes = 13\n";
  map.provenance.model = "test model";
  map.provenance.code_version = "test";
  map.provenance.grid = "test";
  map.provenance.stepping_order = "threads";
  for (size_t i = 0; i < map.samples.size(); ++i) {
    MapSample& s = map.samples[i];
    s.status = i == 4 ? SampleStatus::kPredictedUnstable : SampleStatus::kOk;
    s.status_region = i == 4 ? kCouplingRegion : kNoRegion;
    s.l2_percent = i == 4 ? NAN : 1.5 * i;
    s.max_magnitude_percent = 0.25 * i;
    s.max_direction_deg = 0.125 * i;
    s.reference_peak_n = 0.8 + i;
    s.spectral_radius = 0.99;
    s.cost_us_per_ms = {10.0 + i, 20.0, 0, 0};
  }
  return map;
}

std::string ReadAll(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  return {std::istreambuf_iterator<char>(in), {}};
}
void WriteAll(const std::string& path, const std::string& bytes) {
  std::ofstream(path, std::ios::binary | std::ios::trunc) << bytes;
}

std::string LoadError(const std::string& path, MapLoadParts parts = MapLoadParts::kEverything) {
  try {
    LoadErrorMap(path, parts);
  } catch (const Error& e) {
    return e.what();
  }
  return "";
}

TEST(ErrorMapFile, RoundTripKeepsEveryField) {
  const std::string path = TempPath("roundtrip.hsmap");
  const ErrorMap map = ExampleMap();
  SaveErrorMap(map, path);
  const ErrorMap back = LoadErrorMap(path);
  EXPECT_EQ(back.axes, map.axes);
  EXPECT_EQ(back.provenance.scene_toml, map.provenance.scene_toml);
  EXPECT_EQ(back.provenance.stepping_order, "threads");
  EXPECT_EQ(back.ResultsChecksum(), map.ResultsChecksum());
  ASSERT_EQ(back.samples.size(), map.samples.size());
  EXPECT_TRUE(std::isnan(back.samples[4].l2_percent));
  EXPECT_EQ(back.samples[4].status_region, kCouplingRegion);
  EXPECT_EQ(back.samples[3].cost_us_per_ms, map.samples[3].cost_us_per_ms);
  std::filesystem::remove(path);
}

TEST(ErrorMapFile, TruncatedCorruptedWrongVersionAndForeignFilesAreRefusedSayingWhich) {
  const std::string path = TempPath("damaged.hsmap");
  SaveErrorMap(ExampleMap(), path);
  const std::string good = ReadAll(path);

  WriteAll(path, good.substr(0, good.size() - 10));
  EXPECT_NE(LoadError(path).find("truncated"), std::string::npos) << LoadError(path);
  WriteAll(path, good.substr(0, 20));
  EXPECT_NE(LoadError(path).find("truncated"), std::string::npos) << LoadError(path);

  std::string flipped = good;
  flipped[good.size() - 30] ^= 0x40;  // inside the last section, "details"
  WriteAll(path, flipped);
  EXPECT_NE(LoadError(path).find("corrupted: checksum of section 'details'"), std::string::npos)
      << LoadError(path);
  // The daemon reads only the lookup tables: damage elsewhere does not stop it.
  EXPECT_EQ(LoadError(path, MapLoadParts::kLookupOnly), "");

  std::string version = good;
  version[8] = 7;
  WriteAll(path, version);
  EXPECT_NE(LoadError(path).find("wrong format version 7"), std::string::npos) << LoadError(path);
  version[8] = 1;  // a map from before the contact-node axes
  WriteAll(path, version);
  EXPECT_NE(LoadError(path).find("version 1 maps have no contact-node axes"), std::string::npos)
      << LoadError(path);
  version[8] = 2;  // a map from before the material-contrast axis
  WriteAll(path, version);
  EXPECT_NE(LoadError(path).find("version 2 maps have no material-contrast axis"),
            std::string::npos)
      << LoadError(path);

  WriteAll(path, "[mesh]\nnodes = 13\n# a scene file, not a map\n");
  EXPECT_NE(LoadError(path).find("not an error map"), std::string::npos) << LoadError(path);

  EXPECT_NE(LoadError(TempPath("does-not-exist.hsmap")).find("cannot open"), std::string::npos);
  std::filesystem::remove(path);
}

// The order the trials stepped the regions in: a map from before the key was made in the
// substeps' order; an order no one knows is refused, named.
TEST(ErrorMapFile, ASteppingOrderIsReadAndAnUnknownOneIsRefused) {
  EXPECT_EQ(LoadErrorMap(HAPTICSIM_SMALL_MAP).provenance.stepping_order, "substeps");
  const std::string path = TempPath("unknown-order.hsmap");
  ErrorMap map = ExampleMap();
  map.provenance.stepping_order = "sideways";
  SaveErrorMap(map, path);
  EXPECT_NE(LoadError(path).find("stepping_order \"sideways\""), std::string::npos)
      << LoadError(path);
  std::filesystem::remove(path);
}

TEST(ErrorMapFile, AxesWhoseSizesOverflowAreRefusedNotWrappedRound) {
  // 32¹⁰ × 16384 = 2⁶⁴ samples: the product wrapped round to 0 and a map of 0 samples on those
  // axes was taken for a whole one.
  ErrorMap map;
  map.grid = true;
  for (int a = 0; a < kNumMapAxes; ++a) {
    const int values = a < 10 ? 32 : a == 10 ? 16384 : 1;
    for (int i = 0; i < values; ++i) map.axes[a].push_back(i + 1.0);
  }
  const std::string path = TempPath("overflow.hsmap");
  SaveErrorMap(map, path);
  EXPECT_NE(LoadError(path).find("corrupted: sample count differs from the axes"),
            std::string::npos)
      << LoadError(path);
  EXPECT_NE(LoadError(path, MapLoadParts::kLookupOnly).find("sample count differs"),
            std::string::npos);
  std::filesystem::remove(path);
}

TEST(ErrorMapFile, TheDaemonsLookupTableLoadsAloneAndAgreesWithTheWholeMap) {
  const std::string path = TempPath("lookup.hsmap");
  const ErrorMap map = ExampleMap();
  SaveErrorMap(map, path);
  const ErrorLookup alone = LoadErrorLookup(path, ErrorField::kMagnitude);
  const ErrorLookup whole(LoadErrorMap(path), ErrorField::kMagnitude);
  int usable = 0;
  for (double nu : {0.40, 0.43, 0.49}) {
    for (double size : {1.0, 2.0, 3.0}) {
      MapPoint p = map.samples.front().point;
      p[0] = nu, p[7] = size;
      const LookupResult a = alone.Lookup(LookupQuery::At(p)), b = whole.Lookup(LookupQuery::At(p));
      EXPECT_EQ(a.usable(), b.usable());
      if (a.usable()) {
        EXPECT_EQ(a.error, b.error);
        ++usable;
      }
    }
  }
  EXPECT_GT(usable, 0) << "no query looked anything up";
  std::string bytes = ReadAll(path);
  const size_t table = bytes.find("lookup.max_magnitude_percent");
  ASSERT_NE(table, std::string::npos);
  const auto offset = *reinterpret_cast<const std::uint64_t*>(bytes.data() + table + 32);
  bytes[offset + 3] ^= 0x01;  // one bit of the table the daemon reads
  WriteAll(path, bytes);
  try {
    LoadErrorLookup(path, ErrorField::kMagnitude);
    ADD_FAILURE() << "a corrupted lookup table was accepted";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("checksum of section 'lookup.max_magnitude_percent'"),
              std::string::npos)
        << e.what();
  }
  std::filesystem::remove(path);
}

}  // namespace
}  // namespace hapticsim
