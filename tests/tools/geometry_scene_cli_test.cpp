// A scene whose object comes from a file, as a user runs it: a closed STL surface drawn by hand,
// voxelised, materials and supports from the scene file, and the static press and the reference
// run of hapticsim. The paper's cube drawn as an STL box and held at its corners by [[support]]
// boxes must give the built-in cube's answers, the reference's and the asynchronous regions' (to
// the bit); what cannot run is refused naming what to fix.
#include <gtest/gtest.h>

#include <cstdio>
#include <fstream>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "tests/support/box_stl.hpp"
#include "tests/support/hapticsim_cli.hpp"

namespace hapticsim {
namespace {

using testing::CommandResult;
using testing::Hapticsim;
using testing::Json;
using testing::WriteBoxStl;

std::string Temp(const std::string& name) { return ::testing::TempDir() + name; }

// A number as TOML that reads back to it exactly.
std::string Exact(double value) {
  char text[32];
  std::snprintf(text, sizeof text, "%.17g", value);
  return text;
}

// The cube's scene with its object drawn as `stl` and its corners held by boxes.
std::string BoxScene(const std::string& stl) {
  std::string text = "[geometry]\nfile = \"" + stl + "\"\nspacing_m = " + Exact(0.25 / 12) + "\n";
  for (double x : {0.0, 0.25}) {
    for (double y : {0.0, 0.25}) {
      text += "\n[[support]]\nbox_min = [" + std::to_string(x - 0.001) + ", " +
              std::to_string(y - 0.001) + ", 0.249]\nbox_max = [" + std::to_string(x + 0.001) +
              ", " + std::to_string(y + 0.001) + ", 0.251]\n";
    }
  }
  return text;
}

TEST(GeometrySceneCli, ThePapersCubeDrawnAsAnStlBoxIsTheBuiltInCube) {
  WriteBoxStl(Temp("box.stl"), 0.25);
  {
    std::ofstream scene(Temp("box_scene.toml"));
    scene << BoxScene("box.stl");  // relative: found next to the scene file
  }
  const auto from_stl = Json(Hapticsim({"static", "--json", "--scene", Temp("box_scene.toml")}));
  const auto built_in = Json(Hapticsim({"static", "--json"}));
  EXPECT_EQ(from_stl["lattice_nodes"], built_in["lattice_nodes"]);
  EXPECT_EQ(from_stl["contact_node"], built_in["contact_node"]);
  EXPECT_NEAR(from_stl["contact_stiffness_N_per_m"].get<double>(),
              built_in["contact_stiffness_N_per_m"].get<double>(), 1e-9);

  const auto run = Json(Hapticsim({"simulate", "--json", "--scene", Temp("box_scene.toml")}));
  EXPECT_EQ(run["outcome"], "completed");
  EXPECT_NEAR(run["peak_force_N"].get<double>(), 1.486, 0.001);  // the paper scene's reference

  // The asynchronous regions on the drawn box: the same hybrid mesh, so the same run to the bit.
  const std::vector<std::string> regions = {"--json", "--set", "adaptivity.primary_size=3"};
  auto args = [&](std::vector<std::string> head) {
    head.insert(head.end(), regions.begin(), regions.end());
    return head;
  };
  const auto drawn = Json(Hapticsim(args({"simulate", "--scene", Temp("box_scene.toml")})));
  const auto cube = Json(Hapticsim(args({"simulate"})));
  EXPECT_EQ(drawn["outcome"], "completed");
  EXPECT_EQ(drawn["peak_force_N"].get<double>(), cube["peak_force_N"].get<double>());
  EXPECT_EQ(drawn["regions"][0]["elements"], cube["regions"][0]["elements"]);
}

// The error map of the cube drawn as an STL box (9³ nodes here, for speed) is the built-in
// cube's map to the bit: the same references, the same regions, the same contact node.
TEST(GeometrySceneCli, TheErrorMapOfTheCubeDrawnAsAnStlBoxIsTheBuiltInCubesMap) {
  WriteBoxStl(Temp("box9.stl"), 0.25);
  std::string scene = BoxScene("box9.stl");
  scene.replace(scene.find(Exact(0.25 / 12)), Exact(0.25 / 12).size(), Exact(0.25 / 8));
  std::ofstream(Temp("box9.toml")) << scene;
  std::ofstream(Temp("box9_grid.toml"))
      << "[axes]\nprimary_size = [1, 3]\nsecondary_rate = [600.0, 1000.0]\n"
         "\"input.amplitude\" = [0.005, 0.01]\n";
  const std::vector<std::string> common = {"sweep",  "--grid", Temp("box9_grid.toml"),
                                           "--json", "--set",  "input.frequency=2"};
  auto sweep = [&](std::vector<std::string> extra) {
    std::vector<std::string> args = common;
    args.insert(args.end(), extra.begin(), extra.end());
    return Json(Hapticsim(args));
  };
  const auto drawn = sweep({"--scene", Temp("box9.toml"), "--out", Temp("box9.hsmap")});
  const auto cube = sweep({"--set", "mesh.nodes=9", "--out", Temp("cube9.hsmap")});
  EXPECT_EQ(drawn["samples"], 8);
  EXPECT_EQ(drawn["ok"], cube["ok"]);
  EXPECT_EQ(drawn["results_checksum"], cube["results_checksum"]);
  const auto info = Json(Hapticsim({"map", "info", "--json", Temp("box9.hsmap")}));
  EXPECT_EQ(info["axes"]["contact_node_x"]["values"], nlohmann::json({4.0}));
  EXPECT_EQ(info["axes"]["contact_node_z"]["values"], nlohmann::json({0.0}));
  // Looked up on the drawn object: a node inside it is refused with the object's reason.
  const CommandResult inside =
      Hapticsim({"lookup", Temp("box9.hsmap"), "--set", "contact_node=4,4,3"});
  EXPECT_EQ(inside.exit_status, 2);
  EXPECT_NE(inside.err.find("this node is not on the object's surface"), std::string::npos)
      << inside.err;
  const CommandResult on = Hapticsim({"lookup", Temp("box9.hsmap"), "--set", "primary_size=3",
                                      "--set", "secondary_rate=1000", "--json"});
  ASSERT_EQ(on.exit_status, 0) << on.err;
  EXPECT_GT(Json(on)["error"].get<double>(), 0) << on.out;
}

TEST(GeometrySceneCli, EveryConfigurationOnASmallObjectHasAVerdictOrIsNotApplicable) {
  // A 5-voxel box: a primary of 4 nodes at spacing factor 3 leaves no secondary region, which
  // only building the regions finds: n/a, and the other configurations still get their verdict.
  WriteBoxStl(Temp("small.stl"), 0.05);
  std::ofstream(Temp("small.toml")) << "[geometry]\nfile = \"small.stl\"\nspacing_m = 0.01\n\n"
                                       "[[support]]\nplane_point = [0, 0, 0.05]\n"
                                       "plane_normal = [0, 0, 1]\n\n[input]\namplitude = 0.002\n";
  const CommandResult all =
      Hapticsim({"stability", "--scene", Temp("small.toml"), "--all-configurations"});
  ASSERT_EQ(all.exit_status, 0) << all.err;
  EXPECT_NE(all.out.find("  3 4         n/a"), std::string::npos) << all.out;
  EXPECT_NE(all.out.find("of 55 configurations stable"), std::string::npos) << all.out;
}

TEST(GeometrySceneCli, AGeometrySceneThatCannotRunIsRefusedSayingWhatToChange) {
  WriteBoxStl(Temp("box.stl"), 0.25);
  const auto refused = [](const std::string& scene_text, std::vector<std::string> extra = {}) {
    std::ofstream(Temp("refused.toml")) << scene_text;
    std::vector<std::string> args = {"static", "--scene", Temp("refused.toml")};
    args.insert(args.end(), extra.begin(), extra.end());
    const CommandResult result = Hapticsim(args);
    EXPECT_EQ(result.exit_status, 2) << result.out;
    return result.err;
  };
  const std::string box = Temp("box.stl");
  EXPECT_NE(refused("[geometry]\nfile = \"" + box + "\"\n").find("geometry.spacing_m > 0"),
            std::string::npos);
  EXPECT_NE(refused("[geometry]\nfile = \"" + box + "\"\nspacing_m = 0.05\n")
                .find("needs [[support]] tables"),
            std::string::npos);
  EXPECT_NE(refused("[geometry]\nfile = \"missing.stl\"\nspacing_m = 0.05\n").find("missing.stl"),
            std::string::npos);
  EXPECT_NE(refused("[geometry]\nfile = \"shape.ply\"\nspacing_m = 0.05\n").find(".nii, .nii.gz"),
            std::string::npos);
  // One [[material]] table is an object of one material: the map has no contrast for it but 1.
  {
    std::ofstream(Temp("sweep.toml"))
        << BoxScene(box)
        << "\n[[material]]\nlabel = 1\nyoungs_modulus = 10000.0\npoisson_ratio = 0.45\n"
           "density = 1000.0\ndamping = 10.0\n";
    std::ofstream(Temp("contrast.toml")) << "[axes]\nmaterial_contrast = [1.0, 5.0]\n";
    const CommandResult sweep =
        Hapticsim({"sweep", "--scene", Temp("sweep.toml"), "--grid", Temp("contrast.toml"), "--out",
                   Temp("never.hsmap"), "--set", "adaptivity.primary_size=3"});
    EXPECT_EQ(sweep.exit_status, 2) << sweep.out;
    EXPECT_NE(sweep.err.find("material contrast = 5.0 needs an object of several materials"),
              std::string::npos)
        << sweep.err;
  }
  EXPECT_NE(refused(BoxScene(box), {"--set", "geometry.spacing_m=0.00001"})
                .find("coarser geometry.spacing_m"),
            std::string::npos);
}

}  // namespace
}  // namespace hapticsim
