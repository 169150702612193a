// The daemon takes an error map only for the object it serves: a map records the scene it was
// made for, and one of another object (a cube of other mesh.*, a geometry file, other supports
// or material labels) is refused when loaded, naming both objects, because its errors are of
// another object's regions. What a map varies (the material, the input, the configuration)
// is no reason to refuse it.
#include <gtest/gtest.h>

#include <string>

#include "core/error.hpp"
#include "core/errormap/error_map_file.hpp"
#include "core/scene/scene_toml.hpp"
#include "daemon/error_map_loading.hpp"
#include "tests/support/box_stl.hpp"
#include "tests/support/voxel_scene.hpp"

namespace hapticsim {
namespace {

std::string Temp(const std::string& name) { return ::testing::TempDir() + "map_object_" + name; }

// A one-sample map of the scene's own point, recorded as made for `made_for`.
ErrorMap MapMadeFor(const Scene& scene, const Scene& made_for) {
  std::array<std::vector<double>, kNumMapAxes> axes;
  const MapPoint at = PointOfScene(scene);
  for (int a = 0; a < kNumMapAxes; ++a) axes[a] = {at[a]};
  ErrorMap map = ErrorMap::MakeGrid(axes);
  map.samples[0].status = SampleStatus::kOk;
  map.samples[0].max_magnitude_percent = 1;
  map.provenance.scene_toml = FormatSceneToml(made_for);
  return map;
}

std::string LoadError(const Scene& scene, const ErrorMap& map, const std::string& name) {
  const std::string path = Temp(name + ".hsmap");
  SaveErrorMap(map, path);
  try {
    LoadUsableMap(path, scene);
  } catch (const Error& e) {
    return e.what();
  }
  return "";
}

TEST(MapObject, AMapOfTheSameObjectIsTakenWhateverItsMaterialAndInput) {
  const Scene scene;
  Scene other_material = scene;
  other_material.material.youngs_modulus_pa = 5e3;
  other_material.input.amplitude_m = 0.005;
  EXPECT_EQ(MapObjectProblem(scene, MapMadeFor(scene, other_material)), "");
  EXPECT_EQ(LoadError(scene, MapMadeFor(scene, other_material), "same"), "");
}

TEST(MapObject, ACubeOfOtherNodesIsRefusedNamingBoth) {
  Scene scene;
  Scene nine = scene;
  nine.mesh.nodes = 9;
  const std::string error = LoadError(scene, MapMadeFor(scene, nine), "nine");
  EXPECT_NE(error.find("refused: it was made for the built-in cube of mesh.nodes = 9, mesh.edge = "
                       "0.25 m, and this scene's object is the built-in cube of mesh.nodes = 13"),
            std::string::npos)
      << error;
}

TEST(MapObject, AGeometrysMapIsRefusedOnTheCube) {
  const std::string stl = Temp("box.stl");
  testing::WriteBoxStl(stl, 0.25);
  const Scene box = ParseSceneText("[geometry]\nfile = \"" + stl +
                                       "\"\nspacing_m = 0.025\n[[support]]\n"
                                       "plane_point = [0.0, 0.0, 0.25]\nplane_normal = [0.0, 0.0, "
                                       "1.0]\n",
                                   "the box scene");
  const Scene cube;
  const std::string error = MapObjectProblem(cube, MapMadeFor(cube, box));
  EXPECT_NE(error.find("it was made for geometry.file = \"" + stl + "\""), std::string::npos)
      << error;
  // The map's file is not read to compare: one made on another machine says what it was for.
  Scene elsewhere = cube;
  elsewhere.geometry.file = "/nowhere/on/this/machine/organ.nii";
  elsewhere.geometry.spacing_m = 0.002;
  const std::string away = MapObjectProblem(cube, MapMadeFor(cube, elsewhere));
  EXPECT_NE(away.find("made for geometry.file = \"/nowhere/on/this/machine/organ.nii\""),
            std::string::npos)
      << away;
}

TEST(MapObject, OtherSupportsOrMaterialLabelsAreRefused) {
  const Scene scene;
  Scene held = scene;
  testing::HoldPlaneZ(&held, 0.25);
  EXPECT_NE(MapObjectProblem(scene, MapMadeFor(scene, held)).find("other [[support]] tables"),
            std::string::npos);
  Scene tabled = scene;
  tabled.materials = {{1, scene.material}};
  EXPECT_NE(MapObjectProblem(scene, MapMadeFor(scene, tabled)).find("[[material]] tables of other"),
            std::string::npos);
}

// A map swept in the substeps' order measured an exchange the daemon's threads do not run: the
// daemon says so and how to sweep it again, and keeps using it (it is the user's, and most of its
// configurations are the same in both orders). A map of the threads' order draws no warning.
TEST(MapObject, AMapOfTheSubstepsOrderIsTakenWithAWarning) {
  const Scene scene;
  ErrorMap substeps = MapMadeFor(scene, scene);
  substeps.provenance.stepping_order = "substeps";
  const std::string path = Temp("substeps.hsmap");
  SaveErrorMap(substeps, path);
  const std::string warning = MapOrderWarning(path, substeps);
  EXPECT_NE(warning.find(path + " was swept in the substeps' order"), std::string::npos) << warning;
  EXPECT_NE(warning.find("Sweep it again with hapticsim sweep"), std::string::npos) << warning;
  const MapState loaded = LoadMap(path, scene);
  ASSERT_NE(loaded.map, nullptr) << "a map of the substeps' order was refused";
  EXPECT_EQ(loaded.map->provenance.stepping_order, "substeps");

  ErrorMap threads = substeps;
  threads.provenance.stepping_order = "threads";
  EXPECT_EQ(MapOrderWarning(path, threads), "");
}

}  // namespace
}  // namespace hapticsim
