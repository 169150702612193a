// The error-map commands as a user runs them: sweep (with Ctrl-C and --resume), map info,
// export and merge, lookup, analyze, and the HTML report rendered in a real browser.
#include <gtest/gtest.h>
#include <signal.h>
#include <unistd.h>

#include <chrono>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <thread>

#include "tests/support/hapticsim_cli.hpp"

namespace hapticsim {
namespace {

using testing::CommandResult;

using testing::Hapticsim;
using testing::Json;

// Per process: CTest runs each test in its own process, several at a time.
std::string Temp(const std::string& name) {
  return ::testing::TempDir() + "hsmap_cli_" + std::to_string(getpid()) + "_" + name;
}

// A 9³ cube, half-second trials and a grid file that varies five axes: seconds per sweep.
const std::vector<std::string> kScene = {"--set", "mesh.nodes=9", "--set", "input.frequency=2"};

std::string GridFile() {
  const std::string path = Temp("grid.toml");
  std::ofstream(path) << "# a test grid\n[axes]\n"
                         "poisson_ratio = [0.40, 0.49]\n"
                         "youngs_modulus = [5000.0, 20000.0]\n"
                         "\"input.amplitude\" = [0.005, 0.01]\n"
                         "primary_size = [1, 3]\n"
                         "secondary_rate = [600.0, 1000.0]\n";
  return path;
}

std::vector<std::string> SweepArgs(const std::string& out, std::vector<std::string> extra = {}) {
  std::vector<std::string> args = {"sweep", "--grid", GridFile(), "--out", out, "--json"};
  args.insert(args.end(), kScene.begin(), kScene.end());
  args.insert(args.end(), extra.begin(), extra.end());
  return args;
}

const nlohmann::json& FullSweep() {
  static const nlohmann::json summary = Json(Hapticsim(SweepArgs(Temp("full.hsmap"))));
  return summary;
}

TEST(ErrorMapCli, SweepWritesAMapThatInfoDescribes) {
  const nlohmann::json& sweep = FullSweep();
  EXPECT_EQ(sweep["samples"], 32);
  EXPECT_EQ(sweep["not_computed"], 0);
  EXPECT_EQ(sweep["ok"].get<int>() + sweep["predicted_unstable"].get<int>() +
                sweep["diverged"].get<int>(),
            32);
  EXPECT_GT(sweep["saved"]["linearity_trials"].get<int>(), 0);
  const auto info = Json(Hapticsim({"map", "info", Temp("full.hsmap"), "--json"}));
  EXPECT_EQ(info["samples"], 32);
  EXPECT_EQ(info["kind"], "grid");
  EXPECT_EQ(info["axes"]["poisson_ratio"]["values"], nlohmann::json({0.40, 0.49}));
  EXPECT_EQ(info["axes"]["youngs_modulus"]["unit"], "Pa");
  EXPECT_EQ(info["results_checksum"], sweep["results_checksum"]);
  EXPECT_NE(info["scene_toml"].get<std::string>().find("nodes = 9"), std::string::npos);
}

// Two materials of one E/ρ (10 kPa / 800 kg/m³ and 15 kPa / 1200 kg/m³): the second is derived
// from the first unless --no-similarity.
TEST(ErrorMapCli, MaterialsOfOneWaveSpeedAreRunOnceUnlessNoSimilarity) {
  const std::string grid = Temp("similar.toml");
  std::ofstream(grid) << "[axes]\ndensity = [800.0, 1200.0]\nyoungs_modulus = [10000.0, 15000.0]\n"
                         "primary_size = [1]\nsecondary_rate = [1000.0]\n";
  std::vector<std::string> args = {"sweep", "--grid", grid, "--out", Temp("similar.hsmap"),
                                   "--json"};
  args.insert(args.end(), kScene.begin(), kScene.end());
  const nlohmann::json shared = Json(Hapticsim(args));
  args.push_back("--no-similarity");
  const nlohmann::json each = Json(Hapticsim(args));
  EXPECT_EQ(shared["samples"], 4);
  EXPECT_EQ(shared["saved"]["similarity_trials"], 1);
  EXPECT_EQ(shared["adaptive_trials"], 3);
  EXPECT_EQ(shared["reference_trials"], 3);
  EXPECT_EQ(each["saved"]["similarity_trials"], 0);
  EXPECT_EQ(each["adaptive_trials"], 4);
  EXPECT_EQ(each["ok"], shared["ok"]);
}

TEST(ErrorMapCli, ExportWritesOneCsvRowPerSampleWithUnitsInTheHeader) {
  FullSweep();
  const std::string csv = Temp("full.csv");
  ASSERT_EQ(Hapticsim({"map", "export", Temp("full.hsmap"), "--csv", csv}).exit_status, 0);
  std::ifstream in(csv);
  std::string header, line;
  std::getline(in, header);
  EXPECT_EQ(header.rfind("poisson_ratio,density_kg/m^3,damping_1/s,youngs_modulus_Pa,", 0), 0u)
      << header;
  int rows = 0;
  while (std::getline(in, line)) ++rows;
  EXPECT_EQ(rows, 32);
}

TEST(ErrorMapCli, LookupInterpolatesClampsWithAFlagAndRefusesUnknownAxes) {
  FullSweep();
  const std::string map = Temp("full.hsmap");
  const auto inside = Json(Hapticsim({"lookup", map, "--set", "youngs_modulus=12000", "--set",
                                      "primary_size=3", "--set", "secondary_rate=1000", "--json"}));
  EXPECT_FALSE(inside["clamped"].get<bool>());
  EXPECT_GE(inside["error"].get<double>(), 0.0);
  const auto outside =
      Json(Hapticsim({"lookup", map, "--set", "youngs_modulus=90000", "--set", "primary_size=3",
                      "--set", "secondary_rate=1000", "--json"}));
  EXPECT_TRUE(outside["clamped"].get<bool>());
  EXPECT_EQ(outside["clamped_axis"], "youngs_modulus");
  const CommandResult bad = Hapticsim({"lookup", map, "--set", "stiffness=3"});
  EXPECT_EQ(bad.exit_status, 2);
  EXPECT_NE(bad.err.find("not a map axis"), std::string::npos) << bad.err;
  // A contact node inside the object is no node a tool can press: refused, not clamped.
  const CommandResult inner = Hapticsim({"lookup", map, "--set", "contact_node=3,3,3"});
  EXPECT_EQ(inner.exit_status, 2);
  EXPECT_NE(inner.err.find("contact_node=3,3,3: on the map's object this node is inside the object"),
            std::string::npos)
      << inner.err;
}

TEST(ErrorMapCli, ADamagedMapIsRefusedWithAMessageThatSaysHow) {
  FullSweep();
  const std::string damaged = Temp("damaged.hsmap");
  std::filesystem::copy_file(Temp("full.hsmap"), damaged,
                             std::filesystem::copy_options::overwrite_existing);
  std::filesystem::resize_file(damaged, std::filesystem::file_size(damaged) - 100);
  const CommandResult result = Hapticsim({"map", "info", damaged});
  EXPECT_EQ(result.exit_status, 2);
  EXPECT_NE(result.err.find("truncated"), std::string::npos) << result.err;
}

// A map is swept in hapticsimd's threads' order unless asked for the substeps' (sweep --order
// substeps); each says which, their results differ where a secondary runs at another rate in
// several substeps (ν 0.49 here), and one does not merge with a shard of the other order.
TEST(ErrorMapCli, AMapSweptInTheThreadsOrderSaysSoAndMergesOnlyWithItsOwnOrder) {
  const std::string substeps = Temp("substeps.hsmap"), shard = Temp("threads-shard.hsmap");
  const nlohmann::json& threads = FullSweep();  // writes full.hsmap (each test is a process)
  ASSERT_EQ(Hapticsim(SweepArgs(substeps, {"--order", "substeps"})).exit_status, 0);
  const auto info = Json(Hapticsim({"map", "info", Temp("full.hsmap"), "--json"}));
  EXPECT_EQ(info["stepping_order"], "threads");
  const auto other = Json(Hapticsim({"map", "info", substeps, "--json"}));
  EXPECT_EQ(other["stepping_order"], "substeps");
  EXPECT_EQ(info["not_computed"], 0);
  EXPECT_EQ(info["results_checksum"], threads["results_checksum"]);
  EXPECT_NE(other["results_checksum"], threads["results_checksum"]);
  const std::string text = Hapticsim({"map", "info", Temp("full.hsmap")}).out;
  EXPECT_NE(text.find("regions stepped in the threads' order"), std::string::npos) << text;

  ASSERT_EQ(Hapticsim(SweepArgs(shard, {"--shard", "2/2"})).exit_status, 0);
  const std::string first = Temp("substeps-shard.hsmap");
  ASSERT_EQ(Hapticsim(SweepArgs(first, {"--shard", "1/2", "--order", "substeps"})).exit_status, 0);
  const CommandResult merged = Hapticsim({"map", "merge", Temp("mixed.hsmap"), first, shard});
  EXPECT_EQ(merged.exit_status, 2);
  EXPECT_NE(merged.err.find("threads' order"), std::string::npos) << merged.err;
}

TEST(ErrorMapCli, ShardsMergeToTheSameResultsAsOneSweep) {
  const std::string a = Temp("shard1.hsmap"), b = Temp("shard2.hsmap"), merged = Temp("m.hsmap");
  ASSERT_EQ(Hapticsim(SweepArgs(a, {"--shard", "1/2"})).exit_status, 0);
  ASSERT_EQ(Hapticsim(SweepArgs(b, {"--shard", "2/2", "--jobs", "1"})).exit_status, 0);
  const CommandResult result = Hapticsim({"map", "merge", merged, a, b});
  ASSERT_EQ(result.exit_status, 0) << result.err;
  const auto info = Json(Hapticsim({"map", "info", merged, "--json"}));
  EXPECT_EQ(info["not_computed"], 0);
  EXPECT_EQ(info["results_checksum"], FullSweep()["results_checksum"]);
}

TEST(ErrorMapCli, CtrlCKeepsTheDoneWorkAndResumeFinishesTheSameMap) {
  const std::string out = Temp("interrupted.hsmap"), journal = out + ".journal";
  std::filesystem::remove(out);
  std::filesystem::remove(journal);
  // SIGINT as Ctrl-C sends it, once the journal holds its first finished task.
  std::vector<std::string> args = {HAPTICSIM_CLI_PATH};
  for (const std::string& a : SweepArgs(out, {"--jobs", "1"})) args.push_back(a);
  testing::BackgroundProcess sweep(args, Temp("interrupted.log"));
  auto journal_lines = [&] {
    std::ifstream in(journal);
    int lines = 0;
    for (std::string line; std::getline(in, line);) ++lines;
    return lines;
  };
  const auto deadline = std::chrono::steady_clock::now() + std::chrono::seconds(60);
  while (journal_lines() < 2 && sweep.running() && std::chrono::steady_clock::now() < deadline) {
    std::this_thread::sleep_for(std::chrono::milliseconds(5));
  }
  sweep.Signal(SIGINT);
  ASSERT_EQ(sweep.Wait(30), 130) << sweep.Log();
  EXPECT_NE(sweep.Log().find("--resume"), std::string::npos) << sweep.Log();
  EXPECT_FALSE(std::filesystem::exists(out));
  EXPECT_TRUE(std::filesystem::exists(journal));
  const auto resumed = Json(Hapticsim(SweepArgs(out, {"--resume"})));
  EXPECT_GT(resumed["samples_resumed"].get<int>(), 0);
  EXPECT_LT(resumed["samples_resumed"].get<int>(), 32);
  EXPECT_FALSE(std::filesystem::exists(journal));
  EXPECT_EQ(resumed["results_checksum"], FullSweep()["results_checksum"]);
}

TEST(ErrorMapCli, AnalyzePrintsTableOneAndTheReportRendersInABrowser) {
  FullSweep();
  const std::string report = Temp("report.html");
  const auto analysis =
      Json(Hapticsim({"analyze", Temp("full.hsmap"), "--json", "--report", report}));
  const auto& c = analysis["correlations"];
  for (const char* name : {"poisson_ratio", "youngs_modulus", "amplitude", "primary_size",
                           "secondary_rate", "reference_force"}) {
    ASSERT_TRUE(c.contains(name)) << name;
    EXPECT_TRUE(c[name].contains("spearman_p")) << name;
  }
  EXPECT_TRUE(c["density"]["pearson"].is_null());  // constant in this grid
  const double r = c["poisson_ratio"]["pearson"].get<double>();
  EXPECT_TRUE(r >= -1 && r <= 1);

  // Headless Chromium runs the page's script: it reports how many samples it drew.
  const std::string profile = Temp("chromium-profile");
  std::filesystem::remove_all(profile);
  const CommandResult page = testing::RunCommand(
      {"/usr/bin/chromium", "--headless", "--no-sandbox", "--disable-gpu", "--disable-quic",
       "--no-first-run", "--disable-background-networking", "--disable-component-update",
       "--disable-sync", "--user-data-dir=" + profile, "--dump-dom", "file://" + report});
  ASSERT_EQ(page.exit_status, 0) << page.err;
  const int ok = analysis["samples"].get<int>();
  // The five axes the grid varies, and the error.
  EXPECT_NE(page.out.find("rendered " + std::to_string(ok) + " samples on 6 axes"),
            std::string::npos)
      << "the report's script did not finish drawing";
  EXPECT_NE(page.out.find("<td>poisson_ratio</td>"), std::string::npos);
  std::filesystem::remove_all(profile);
}

}  // namespace
}  // namespace hapticsim
