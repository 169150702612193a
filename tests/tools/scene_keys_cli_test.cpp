// Every key `hapticsim scene` prints is one the programs read back and act on: each, changed in
// the printed file, is printed back changed and changes what `hapticsim simulate` computes.
#include <gtest/gtest.h>

#include <fstream>
#include <map>
#include <regex>
#include <set>
#include <sstream>
#include <string>
#include <vector>

#include "tests/support/hapticsim_cli.hpp"

namespace hapticsim {
namespace {

using testing::CommandResult;
using testing::Hapticsim;

std::string Temp(const std::string& name) { return ::testing::TempDir() + name; }

std::string ReadFile(const std::string& path) {
  std::ifstream in(path);
  std::stringstream text;
  text << in.rdbuf();
  return text.str();
}

// "section.key" → the value as printed, in the order printed.
std::vector<std::pair<std::string, std::string>> PrintedKeys(const std::string& toml) {
  std::vector<std::pair<std::string, std::string>> keys;
  const std::regex section(R"(^\[([a-z_]+)\]\s*$)");
  const std::regex entry(R"(^([a-z_]+) = (("[^"]*")|[^ #]+)\s*(#.*)?$)");
  std::istringstream lines(toml);
  std::string line, current;
  std::smatch match;
  while (std::getline(lines, line)) {
    if (std::regex_match(line, match, section)) current = match[1];
    if (std::regex_match(line, match, entry)) keys.emplace_back(current + "." + match[1].str(), match[2]);
  }
  return keys;
}

// The printed file with one key's value replaced.
std::string WithValue(const std::string& toml, const std::string& dotted, const std::string& value) {
  const std::string section = dotted.substr(0, dotted.find('.'));
  const std::string key = dotted.substr(dotted.find('.') + 1);
  std::istringstream lines(toml);
  std::string line, current, out;
  while (std::getline(lines, line)) {
    if (line.size() > 2 && line.front() == '[') current = line.substr(1, line.find(']') - 1);
    if (current == section && line.rfind(key + " = ", 0) == 0) line = key + " = " + value;
    out += line + "\n";
  }
  return out;
}

// Each printed key, changed to another value this scene accepts. A key printed without an entry
// here fails the test: say what the new key should change.
const std::map<std::string, std::string>& ChangedValues() {
  static const std::map<std::string, std::string> values = {
      {"mesh.nodes", "9"},
      {"mesh.edge", "0.2"},
      {"material.youngs_modulus", "20000.0"},
      {"material.poisson_ratio", "0.3"},
      {"material.density", "1500.0"},
      {"material.damping", "5.0"},
      {"input.amplitude", "0.005"},
      {"input.frequency", "2.0"},
      {"input.waveform", "\"sine\""},
      {"input.contact_node", "\"3,6,0\""},
      {"input.periods", "0.5"},
      {"solver.dt", "5e-04"},  // as the scene prints 0.0005
      {"adaptivity.primary_size", "2"},
      {"adaptivity.secondary_lod", "3"},
      {"adaptivity.secondary_rate", "300.0"},
      {"adaptivity.support_layers", "0"},
      {"adaptivity.secondary_regions", "1"},
      {"adaptivity.shell_cells", "2"},
      {"adaptivity.outer_rate", "250.0"},
      {"adaptivity.coupling", "\"force\""},
  };
  return values;
}

TEST(SceneKeys, EveryPrintedKeyIsReadBackAndChangesTheRun) {
  // The baseline runs the regions with two shells, so that the keys of the regions and of the
  // outer shell act too.
  const std::string printed = Hapticsim({"scene"}).out;
  const std::string baseline_toml =
      WithValue(WithValue(printed, "adaptivity.primary_size", "3"), "adaptivity.secondary_regions",
                "2");
  const std::vector<std::pair<std::string, std::string>> keys = PrintedKeys(baseline_toml);
  ASSERT_GE(keys.size(), 20u) << printed;

  auto simulate = [](const std::string& name, const std::string& toml) {
    const std::string scene = Temp("scene_keys_" + name + ".toml");
    const std::string csv = Temp("scene_keys_" + name + ".csv");
    std::ofstream(scene) << toml;
    const CommandResult run = Hapticsim({"simulate", "--scene", scene, "--out", csv});
    EXPECT_EQ(run.exit_status, 0) << name << ": " << run.err;
    const CommandResult shown = Hapticsim({"scene", "--scene", scene});
    EXPECT_EQ(shown.exit_status, 0) << name << ": " << shown.err;
    return std::pair{ReadFile(csv), shown.out};
  };
  const auto [baseline_csv, baseline_shown] = simulate("baseline", baseline_toml);
  ASSERT_GT(baseline_csv.size(), 1000u);
  EXPECT_EQ(PrintedKeys(baseline_shown), keys) << "the baseline is printed back as written";

  std::set<std::string> covered;
  for (const auto& [key, baseline_value] : keys) {
    const auto changed = ChangedValues().find(key);
    if (changed == ChangedValues().end()) {
      ADD_FAILURE() << key << " is printed but this test has no other value for it";
      continue;
    }
    covered.insert(key);
    ASSERT_NE(changed->second, baseline_value) << key;
    std::string name = key;
    for (char& c : name) c = c == '.' ? '_' : c;
    const auto [csv, shown] = simulate(name, WithValue(baseline_toml, key, changed->second));
    EXPECT_EQ(PrintedKeys(shown), PrintedKeys(WithValue(baseline_toml, key, changed->second)))
        << key << " is not printed back as it was written";
    EXPECT_FALSE(csv.empty()) << key;
    EXPECT_NE(csv, baseline_csv) << key << " = " << changed->second << " did not change the run";
  }
  EXPECT_EQ(covered.size(), ChangedValues().size()) << "a key this test knows is no longer printed";
}

}  // namespace
}  // namespace hapticsim
