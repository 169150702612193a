// hapticsimd serving an object that leaves most of its lattice empty — examples/organ/, an
// organ-like ellipsoid of 100 × 70 × 50 mm drawn as an STL, voxelised at 5 mm, its back cap held —
// to the simulated device over the real LCM bus (in the private network namespace the test binary
// runs in), as a user runs it: quiet, and with two busy threads beside the daemon.
#include <gtest/gtest.h>
#include <signal.h>

#include <cmath>
#include <cstdio>
#include <fstream>
#include <nlohmann/json.hpp>
#include <sstream>
#include <string>
#include <vector>

#include "core/fem/static_solver.hpp"
#include "core/scene/scene_model.hpp"
#include "core/scene/scene_toml.hpp"
#include "tests/support/daemon_harness.hpp"
#include "tests/support/run_command.hpp"

namespace hapticsim {
namespace {

const std::string kOrganScene = std::string(HAPTICSIM_EXAMPLES_DIR) + "/organ/organ.toml";

std::string Temp(const std::string& name) {
  return ::testing::TempDir() + "hapticsimd_organ_" + name;
}

nlohmann::json Device(const std::vector<std::string>& motion, const std::string& load) {
  std::vector<std::string> args{HAPTICSIM_CLI_PATH, "device", "--scene", kOrganScene};
  args.insert(args.end(), motion.begin(), motion.end());
  for (const std::string& a : {std::string("--cpu-load"), load, std::string("--json")}) {
    args.push_back(a);
  }
  const auto run = testing::RunCommand(args);
  EXPECT_EQ(run.exit_status, 0) << run.out << run.err;
  return nlohmann::json::parse(run.out);
}

void ExpectSafe(const nlohmann::json& report) {
  const std::string what = "load " + report["cpu_load"].dump();
  EXPECT_EQ(report["lost_answers"], 0) << what;
  EXPECT_EQ(report["nonfinite_forces"], 0) << what;
  EXPECT_EQ(report["force_out_of_contact"], 0) << what;
  EXPECT_EQ(report["daemon"]["latched_faults"], 0) << what;
}

// Presses 4 mm deep at 0.5 Hz off the organ's middle, at (20, 35) mm, where its front is 5 mm
// behind the bounding box's (node (4, 7, 1)): the regions move there, and each press's peak is
// the static solution's at 4 mm within 5 % (the press is slow; measured 0.164 N against 0.160 N),
// quiet and under load alike. Then a 15 s random walk over the organ's front under load, touching
// down where its front is at several depths: every answer arrives, no fault, no force out of
// contact, no step over 0.25 N (the cube's bound under load) in contact or across a lift-off, and
// the regions follow the tool.
TEST(HapticsimdOnAnOrgan, PressesAndAWalkOverItsFrontKeepTheForceRightUnderLoad) {
  const std::string config = Temp("config.toml");
  std::ofstream(config) << "[scene]\nfile = \"" << kOrganScene << "\"\n";
  testing::BackgroundProcess daemon({HAPTICSIMD_PATH, "--config", config}, Temp("daemon.log"));
  ASSERT_NO_FATAL_FAILURE(testing::WaitUntilServing(daemon));
  const std::vector<std::string> press{"--input",     "press", "--amplitude", "0.004",
                                       "--frequency", "0.5",   "--at",        "0.02,0.035",
                                       "--duration",  "6"};
  const nlohmann::json quiet = Device(press, "0"), loaded = Device(press, "2");
  const nlohmann::json walk =
      Device({"--input", "walk", "--amplitude", "0.004", "--duration", "15"}, "2");
  daemon.Signal(SIGTERM);
  EXPECT_EQ(daemon.Wait(5), 0) << daemon.Log();

  Scene scene = LoadSceneFile(kOrganScene);
  scene.input.contact_node = LatticeIndex{4, 7, 1};
  const SceneModel model(scene);
  const std::vector<double> driven{0.0, 0.0, 0.004};
  const StaticSolution solved = SolveStatic(model.model(), driven, 1e-12);
  ASSERT_TRUE(solved.converged);
  const double expected = solved.driven_reaction[2];
  ASSERT_GT(expected, 0.05);
  for (const nlohmann::json& report : {quiet, loaded}) {
    ExpectSafe(report);
    EXPECT_EQ(report["daemon"]["contact_node"], (nlohmann::json{4, 7, 1})) << report.dump();
    ASSERT_GE(report["press_peaks_n"].size(), 2u) << report.dump();
    for (const auto& peak : report["press_peaks_n"]) {
      EXPECT_NEAR(peak.get<double>(), expected, 0.05 * expected) << report.dump();
    }
    EXPECT_LT(report["max_force_step_in_contact_n"].get<double>(), 0.1) << report.dump();
  }
  EXPECT_GT(loaded["cpu_load"]["cpu_s"].get<double>(), 2.0) << loaded.dump();
  ExpectSafe(walk);
  EXPECT_GT(walk["contact_answers"].get<int>(), 2000) << walk.dump();
  EXPECT_GE(walk["daemon"]["reconfigurations"].get<int>(), 5) << walk.dump();
  // In contact under load the walk's largest step between answers was 0.087–0.095 N in 13 of 24
  // walks and 0.099–0.217 N in 11 (2026-12-07). 10 of those 11 came right after a gap in the
  // device's own input (its sender beside the two busy threads in its process, 2–5 ms late): the
  // daemon answered meanwhile, carrying the tip on by itself, and the next input brought the tip's
  // motion of several periods at once (the force here moves at up to 0.09 N per ms); the other
  // was the port's passivity controller taking a lift-off's force out in one period (0.119 N).
  // Between answers that each took one new input, the next (a period's own step), 0.080–0.090 N
  // in 10 walks (docs/operations.md). The bounds are under the port guard's slew ceiling (0.5 N
  // per ms) and the lift-off's old 0.49 N below.
  EXPECT_LT(walk["max_force_step_in_contact_n"].get<double>(), 0.4) << walk.dump();
  EXPECT_LT(walk["max_force_step_one_period_n"].get<double>(), 0.2) << walk.dump();
  // Across lift-offs too: a node dragged along its entry face and lifted off through it still
  // pulls sideways (the node contact does not slide), and the port guard releases that at its
  // lift-off rate, 0.1 N per ms. At the slew ceiling, as until 2026-12-06, it stepped 0.15–0.24 N
  // in most walks and 0.49–0.50 N in 4 of 29; since, 0.100 N in every walk (18 of 24) whose step
  // in contact was smaller.
  EXPECT_LT(walk["max_force_step_any_n"].get<double>(), 0.4) << walk.dump();
  std::printf(
      "organ: press peaks quiet %.4f, loaded %.4f N (static %.4f N); walk under load: %d answers "
      "in contact, %d region moves, largest step %.3f N (%.3f N across lift-offs too; %.3f N "
      "between answers of one input each), largest force %.3f N; %d primary deadline misses\n",
      quiet["press_peaks_n"][1].get<double>(), loaded["press_peaks_n"][1].get<double>(), expected,
      walk["contact_answers"].get<int>(), walk["daemon"]["reconfigurations"].get<int>(),
      walk["max_force_step_in_contact_n"].get<double>(), walk["max_force_step_any_n"].get<double>(),
      walk["max_force_step_one_period_n"].get<double>(), walk["max_force_n"].get<double>(),
      walk["daemon"]["regions"][0]["deadline_misses"].get<int>());
}

// The same walk with a tool that slides (contact.model = "proxy" added to the organ's scene):
// the organ's voxel staircase has risers one voxel high with no node inside them to slide on, and
// a tip that came in through one pushed nothing until it left again (1,038–1,611 answers in
// contact in 15 s; it touches through the tread above since: 6,115–6,731, where the node contact
// gives about 6,800). Every answer arrives, no fault, no force out of contact, no step over
// 0.25 N (the cube's bound under load).
TEST(HapticsimdOnAnOrgan, AToolThatSlidesStaysInContactOverItsStaircaseUnderLoad) {
  std::ifstream organ(kOrganScene);
  std::stringstream text;
  text << organ.rdbuf();
  std::string scene = text.str();
  const std::string geometry = "file = \"organ.stl\"";
  const std::size_t at = scene.find(geometry);
  ASSERT_NE(at, std::string::npos) << "examples/organ/organ.toml names its STL otherwise";
  scene.replace(at, geometry.size(),
                "file = \"" + std::string(HAPTICSIM_EXAMPLES_DIR) + "/organ/organ.stl\"");
  const std::string scene_path = Temp("proxy.toml");
  std::ofstream(scene_path) << scene << "\n[contact]\nmodel = \"proxy\"\n";
  const std::string config = Temp("proxy_config.toml");
  std::ofstream(config) << "[scene]\nfile = \"" << scene_path << "\"\n";
  testing::BackgroundProcess daemon({HAPTICSIMD_PATH, "--config", config}, Temp("proxy.log"));
  ASSERT_NO_FATAL_FAILURE(testing::WaitUntilServing(daemon));
  const nlohmann::json walk =
      Device({"--input", "walk", "--amplitude", "0.004", "--duration", "15"}, "2");
  daemon.Signal(SIGTERM);
  EXPECT_EQ(daemon.Wait(5), 0) << daemon.Log();
  ExpectSafe(walk);
  EXPECT_GT(walk["contact_answers"].get<int>(), 4000) << walk.dump();
  EXPECT_GE(walk["daemon"]["reconfigurations"].get<int>(), 5) << walk.dump();
  EXPECT_LT(walk["max_force_step_any_n"].get<double>(), 0.25) << walk.dump();
  std::printf(
      "organ, sliding tool: walk under load: %d answers in contact, %d region moves, largest "
      "step %.3f N, largest force %.3f N\n",
      walk["contact_answers"].get<int>(), walk["daemon"]["reconfigurations"].get<int>(),
      walk["max_force_step_any_n"].get<double>(), walk["max_force_n"].get<double>());
}

}  // namespace
}  // namespace hapticsim
