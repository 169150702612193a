// The hapticsim binary as a user runs it: exit statuses, JSON shapes, files written, and the
// messages bad input gets.
#include "tests/support/hapticsim_cli.hpp"

#include <gtest/gtest.h>

#include <cstdio>
#include <fstream>
#include <nlohmann/json.hpp>
#include <sstream>

namespace hapticsim {
namespace {

using testing::CommandResult;

using testing::Hapticsim;
using testing::Json;

std::string Temp(const std::string& name) { return ::testing::TempDir() + name; }

TEST(HapticsimCli, HelpListsTheSubcommands) {
  const CommandResult result = Hapticsim({"--help"});
  EXPECT_EQ(result.exit_status, 0);
  for (const char* sub : {"simulate", "static", "stability", "scene", "sweep", "map", "lookup",
                          "analyze", "device", "soak", "log", "stress", "bench"}) {
    EXPECT_NE(result.out.find(sub), std::string::npos) << sub;
  }
}

TEST(HapticsimCli, SimulateJsonReportsTheRunAndWritesTheSeries) {
  const std::string csv = Temp("cli_forces.csv");
  const auto json = Json(Hapticsim({"simulate", "--json", "--out", csv}));
  EXPECT_EQ(json["outcome"], "completed");
  EXPECT_EQ(json["diverged"], false);
  EXPECT_EQ(json["predicted_stable"], true);
  EXPECT_EQ(json["steps"], 1001);
  EXPECT_DOUBLE_EQ(json["duration_s"].get<double>(), 1.0);
  EXPECT_GT(json["peak_force_N"].get<double>(), 0.5);
  EXPECT_GT(json["wall_time_s"].get<double>(), 0.0);
  EXPECT_EQ(json["time_series_csv"], csv);

  std::ifstream in(csv);
  std::string header, line;
  std::getline(in, header);
  EXPECT_EQ(header, "t_s,contact_ux_m,contact_uy_m,contact_uz_m,force_x_N,force_y_N,force_z_N");
  int rows = 0;
  while (std::getline(in, line)) ++rows;
  EXPECT_EQ(rows, 1001);
}

TEST(HapticsimCli, SimulateDrawsAPlot) {
  const std::string svg = Temp("cli_forces.svg");
  const CommandResult result = Hapticsim({"simulate", "--set", "mesh.nodes=7", "--plot", svg});
  ASSERT_EQ(result.exit_status, 0) << result.err;
  std::ifstream in(svg);
  std::stringstream text;
  text << in.rdbuf();
  EXPECT_EQ(text.str().rfind("<svg", 0), 0u);
  EXPECT_NE(text.str().find("polyline"), std::string::npos);
}

TEST(HapticsimCli, StaticJsonGivesTheReactionThatHoldsTheContact) {
  const auto json = Json(Hapticsim({"static", "--json"}));
  ASSERT_EQ(json["reaction_force_N"].size(), 3u);
  EXPECT_GT(json["reaction_force_N"][2].get<double>(), 0.0);
  EXPECT_DOUBLE_EQ(json["feedback_force_N"][2].get<double>(),
                   -json["reaction_force_N"][2].get<double>());
  EXPECT_EQ(json["converged"], true);
}

TEST(HapticsimCli, StabilityJsonComparesDtWithTheCriticalStep) {
  const auto stable = Json(Hapticsim({"stability", "--json"}));
  EXPECT_EQ(stable["stable"], true);
  EXPECT_DOUBLE_EQ(stable["dt_s"].get<double>(), 1e-3);
  EXPECT_GT(stable["critical_dt_s"].get<double>(), 1e-3);

  const auto unstable = Json(Hapticsim({"stability", "--json", "--set", "solver.dt=0.005"}));
  EXPECT_EQ(unstable["stable"], false);
}

TEST(HapticsimCli, SimulateRefusesAPredictedUnstableStep) {
  const CommandResult result = Hapticsim({"simulate", "--set", "solver.dt=0.005"});
  EXPECT_EQ(result.exit_status, 3);
  EXPECT_NE(result.out.find("predicted unstable"), std::string::npos) << result.out;
}

TEST(HapticsimCli, SimulateReportsDetectedDivergence) {
  const auto result = Hapticsim({"simulate", "--json", "--allow-unstable", "--set", "mesh.nodes=7",
                                 "--set", "solver.dt=0.01"});
  EXPECT_EQ(result.exit_status, 3);
  const auto json = nlohmann::json::parse(result.out);
  EXPECT_EQ(json["diverged"], true);
  EXPECT_NE(json["outcome"].get<std::string>().find("diverged"), std::string::npos);
}

TEST(HapticsimCli, SceneOutputReadsBackAsAScene) {
  const CommandResult printed =
      Hapticsim({"scene", "--set", "material.poisson_ratio=0.49", "--set", "input.waveform=sine"});
  ASSERT_EQ(printed.exit_status, 0) << printed.err;
  const std::string file = Temp("cli_scene.toml");
  std::ofstream(file) << printed.out;
  const auto json = Json(Hapticsim({"scene", "--json", "--scene", file}));
  EXPECT_DOUBLE_EQ(json["scene"]["material.poisson_ratio"].get<double>(), 0.49);
  EXPECT_EQ(json["scene"]["input.waveform"], "sine");
  EXPECT_EQ(json["units"]["material.density"], "kg/m^3");
}

TEST(HapticsimCli, AdaptiveSimulateComparesWithTheReference) {
  const auto json = Json(
      Hapticsim({"simulate", "--json", "--compare-reference", "--set", "adaptivity.primary_size=3",
                 "--set", "adaptivity.secondary_lod=2", "--set", "adaptivity.secondary_rate=600"}));
  EXPECT_EQ(json["adaptive"], true);
  EXPECT_EQ(json["predicted_stable"], true);
  ASSERT_EQ(json["regions"].size(), 2u);
  EXPECT_EQ(json["regions"][0]["name"], "primary");
  EXPECT_DOUBLE_EQ(json["regions"][0]["rate_Hz"].get<double>(), 1000);
  EXPECT_DOUBLE_EQ(json["regions"][1]["rate_Hz"].get<double>(), 600);
  EXPECT_GT(json["regions"][1]["nodes"].get<int>(), 0);
  EXPECT_GE(json["regions"][1]["substeps"].get<int>(), 1);
  const auto& error = json["error"];
  EXPECT_GT(error["l2_percent"].get<double>(), 0.0);
  EXPECT_LT(error["l2_percent"].get<double>(), 7.0);
  EXPECT_TRUE(error.contains("max_magnitude_percent"));
  EXPECT_TRUE(error.contains("max_direction_deg"));
}

TEST(HapticsimCli, AdaptiveStabilityReportsEachRegionsOwnLimitAndEstimatesOnlyWhenAsked) {
  // Not estimated, nothing is said of the coupled verdict: neither a radius nor "stable" (a
  // configuration the daemon would refuse must not read as stable).
  const auto alone =
      Json(Hapticsim({"stability", "--json", "--set", "adaptivity.primary_size=2", "--set",
                      "adaptivity.secondary_lod=1", "--set", "adaptivity.secondary_rate=700",
                      "--set", "material.poisson_ratio=0.49"}));
  EXPECT_EQ(alone["coupled_estimated"], false);
  EXPECT_FALSE(alone.contains("coupled_spectral_radius"));
  EXPECT_FALSE(alone.contains("stable"));
  ASSERT_EQ(alone["regions"].size(), 2u);
  // ν 0.49 at spacing 1: the secondary region needs 2 substeps at 700 Hz for its own limit.
  EXPECT_EQ(alone["regions"][1]["substeps"], 2);
  const std::string text = Hapticsim({"stability", "--set", "adaptivity.primary_size=2"}).out;
  EXPECT_NE(text.find("add --estimate"), std::string::npos) << text;
}

TEST(HapticsimCli, AdaptiveStabilityEstimateReportsEachRegionAndTheCoupledVerdict) {
  const auto stable =
      Json(Hapticsim({"stability", "--json", "--estimate", "--set", "adaptivity.primary_size=2"}));
  EXPECT_EQ(stable["stable"], true);
  EXPECT_EQ(stable["coupled_estimated"], true);
  EXPECT_LT(stable["coupled_spectral_radius"].get<double>(), 1.0);
  ASSERT_EQ(stable["regions"].size(), 2u);
  EXPECT_GT(stable["regions"][1]["critical_dt_s"].get<double>(), 0.0);

  // ν = 0.49 at 700 Hz: the bare lagged exchange grows (1.47 per 10 ms), as run it decays.
  const auto unstable =
      Json(Hapticsim({"stability", "--json", "--estimate", "--set", "adaptivity.primary_size=2",
                      "--set", "adaptivity.secondary_lod=1", "--set",
                      "adaptivity.secondary_rate=700", "--set", "material.poisson_ratio=0.49"}));
  EXPECT_EQ(unstable["stable"], false);
  EXPECT_GT(unstable["coupled_spectral_radius"].get<double>(), 1.0);
  EXPECT_LT(unstable["controlled_spectral_radius"].get<double>(), 1.0);
}

TEST(HapticsimCli, AdaptiveSimulateRunsWhatTheBareExchangeCannotHoldAndReportsTheEnergy) {
  const auto result =
      Hapticsim({"simulate", "--json", "--set", "adaptivity.primary_size=2", "--set",
                 "adaptivity.secondary_lod=1", "--set", "adaptivity.secondary_rate=700", "--set",
                 "material.poisson_ratio=0.49"});
  ASSERT_EQ(result.exit_status, 0) << result.out << result.err;
  const auto json = Json(result);
  EXPECT_EQ(json["outcome"], "completed");
  EXPECT_EQ(json["predicted_stable"], false);  // the bare exchange: what hapticsimd verifies
  EXPECT_GT(json["energy_J"]["interface_dissipated"].get<double>(), 0.0);
  EXPECT_LT(json["energy_J"]["stored"].get<double>(), json["energy_J"]["input_work"].get<double>());
  EXPECT_LT(json["peak_force_N"].get<double>(), 3.0);  // the reference's: 2.0 N
}

// simulate steps the virtual-time run as hapticsimd's threads step the regions, unless asked for
// the substeps' order. Where a secondary runs at another rate in several substeps that is another
// force: ν 0.49, primary one element deep at spacing 2, 600 Hz (the secondary in 2 substeps) —
// measured 2.44 % from the reference in the substeps' order and 35.05 % in the threads'
// (docs/regions.md, "Known"): the default reports the daemon's error, not the lower one.
TEST(HapticsimCli, SimulateStepsTheThreadsOrderUnlessAskedForTheSubsteps) {
  std::vector<std::string> args{"simulate",
                                "--json",
                                "--compare-reference",
                                "--set",
                                "adaptivity.primary_size=2",
                                "--set",
                                "adaptivity.secondary_lod=1",
                                "--set",
                                "adaptivity.secondary_rate=600",
                                "--set",
                                "material.poisson_ratio=0.49"};
  const auto threads = Json(Hapticsim(args));  // the default
  args.insert(args.end(), {"--order", "substeps"});
  const auto substeps = Json(Hapticsim(args));
  EXPECT_EQ(substeps["stepping_order"], "substeps");
  EXPECT_EQ(threads["stepping_order"], "threads");
  EXPECT_EQ(threads["outcome"], "completed");
  const double in_substeps = substeps["error"]["l2_percent"].get<double>();
  const double in_threads = threads["error"]["l2_percent"].get<double>();
  EXPECT_LT(in_substeps, 7.0);
  EXPECT_GT(in_threads, 3 * in_substeps);
  std::printf("ν 0.49 k 1 r 2 600 Hz: %.2f %% in the substeps' order, %.2f %% in the threads'\n",
              in_substeps, in_threads);
}

struct BadInvocation {
  std::string name;
  std::vector<std::string> args;
  std::string must_mention;
  friend void PrintTo(const BadInvocation& bad, std::ostream* out) { *out << bad.name; }
};

class HapticsimCliRejects : public ::testing::TestWithParam<BadInvocation> {};

TEST_P(HapticsimCliRejects, WithStatus2AndAMessageNamingTheProblem) {
  const CommandResult result = Hapticsim(GetParam().args);
  EXPECT_EQ(result.exit_status, 2);
  EXPECT_NE(result.err.find(GetParam().must_mention), std::string::npos) << result.err;
  EXPECT_TRUE(result.out.empty()) << "bad input must print no result: " << result.out;
}

INSTANTIATE_TEST_SUITE_P(
    BadInput, HapticsimCliRejects,
    ::testing::Values(
        BadInvocation{
            "PoissonRatio", {"simulate", "--set", "material.poisson_ratio=0.6"}, "(-1, 0.5)"},
        BadInvocation{"NegativeModulus",
                      {"static", "--json", "--set", "material.youngs_modulus=-5"},
                      "material.youngs_modulus must be finite and > 0"},
        BadInvocation{"OneNode", {"stability", "--set", "mesh.nodes=1"}, "mesh.nodes"},
        BadInvocation{"NanTimeStep", {"simulate", "--set", "solver.dt=nan"}, "solver.dt"},
        BadInvocation{
            "UnknownKey", {"simulate", "--set", "material.colour=red"}, "unknown scene key"},
        BadInvocation{
            "MissingFile", {"simulate", "--scene", "/nonexistent.toml"}, "/nonexistent.toml"},
        BadInvocation{"UnknownOption", {"simulate", "--bogus"}, "--bogus"},
        BadInvocation{"UnknownOrder", {"simulate", "--order", "sideways"}, "--order"},
        BadInvocation{"UnknownSubcommand", {"frobnicate"}, "unknown subcommand 'frobnicate'"},
        BadInvocation{"PrimaryTooLarge",
                      {"simulate", "--set", "adaptivity.primary_size=40"},
                      "adaptivity.primary_size"},
        BadInvocation{"LodNotDividing",
                      {"simulate", "--set", "adaptivity.primary_size=2", "--set",
                       "adaptivity.secondary_lod=5"},
                      "adaptivity.secondary_lod"},
        BadInvocation{"NegativeRate",
                      {"stability", "--set", "adaptivity.secondary_rate=-5"},
                      "adaptivity.secondary_rate"},
        BadInvocation{"EmptyShell",
                      {"simulate", "--set", "adaptivity.primary_size=4", "--set",
                       "adaptivity.secondary_regions=8"},
                      "adaptivity.secondary_regions = 8"},
        BadInvocation{"OuterRateTooHigh",
                      {"simulate", "--set", "adaptivity.primary_size=2", "--set",
                       "adaptivity.outer_rate=2000"},
                      "adaptivity.outer_rate"}),
    [](const ::testing::TestParamInfo<BadInvocation>& info) { return info.param.name; });

}  // namespace
}  // namespace hapticsim
