// A scene of any object (SceneModel over a geometry's labelled voxels, [[material]] tables per
// label, [[support]] tables): checked against what does not depend on it. The paper's cube given
// as voxels with its corners held by boxes must be the built-in cube to the bit; a label's table
// must act on exactly its voxels (two labels of one material are one material); a stiffer
// inclusion under the contact stiffens it monotonically with the contrast; and every scene the
// physics cannot run is refused with a message that says what to add or change.
#include "core/scene/scene_model.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <functional>
#include <memory>
#include <string>

#include "core/error.hpp"
#include "core/fem/static_solver.hpp"
#include "core/scene/label_materials.hpp"
#include "core/scene/scene_toml.hpp"
#include "core/scene/support_regions.hpp"
#include "core/trial/reference_trial.hpp"
#include "tests/support/voxel_scene.hpp"

namespace hapticsim {
namespace {

using testing::SupportBox;
using testing::VoxelScene;

// The cube's four back corners as boxes a tenth of a voxel wide around them.
std::vector<SupportRegion> CornerBoxes(double edge) {
  const double e = 0.01 * edge;
  std::vector<SupportRegion> boxes;
  for (double x : {0.0, edge}) {
    for (double y : {0.0, edge})
      boxes.push_back(SupportBox({x - e, y - e, edge - e}, {x + e, y + e, edge + e}));
  }
  return boxes;
}

std::string MessageOf(const std::function<void()>& run) {
  try {
    run();
  } catch (const Error& error) {
    return error.what();
  }
  return "(no error)";
}

TEST(SceneModel, ThePapersCubeAsVoxelsHeldByCornerBoxesIsTheBuiltInCubeToTheBit) {
  Scene voxels = VoxelScene(12, 0.25 / 12, [](int, int, int) { return 1; });
  voxels.supports = CornerBoxes(0.25);
  const SceneModel as_voxels(voxels);
  const SceneModel built_in{Scene{}};
  EXPECT_EQ(as_voxels.contact_node(), built_in.contact_node());
  EXPECT_EQ(as_voxels.fixed_nodes(), built_in.fixed_nodes());
  EXPECT_EQ(as_voxels.contact_normal(), (std::array<double, 3>{0, 0, 1}));
  const TrialResult a = RunReferenceTrial(as_voxels), b = RunReferenceTrial(built_in);
  ASSERT_EQ(a.samples.size(), b.samples.size());
  for (std::size_t i = 0; i < a.samples.size(); ++i) {
    ASSERT_EQ(a.samples[i].feedback_force_n, b.samples[i].feedback_force_n) << "sample " << i;
  }
  EXPECT_NEAR(b.peak_force_n, 1.486, 0.001);  // the paper scene's reference peak
}

double ContactStiffness(const Scene& scene) {
  const SceneModel object(scene);
  const double depth = 1e-3;
  std::array<double, 3> driven{};
  for (int c = 0; c < 3; ++c) driven[c] = depth * object.contact_normal()[c];
  const StaticSolution solution = SolveStatic(object.model(), driven);
  EXPECT_TRUE(solution.converged);
  double along = 0;
  for (int c = 0; c < 3; ++c) along += solution.driven_reaction[c] * object.contact_normal()[c];
  return along / depth;
}

// A 10-voxel block held on its back face, with a 4³ inclusion (label 2) two voxels under the
// contact.
Scene BlockWithInclusion(double contrast) {
  Scene scene = VoxelScene(10, 0.01, [](int x, int y, int z) {
    const bool inside = x >= 3 && x < 7 && y >= 3 && y < 7 && z >= 2 && z < 6;
    return inside ? 2 : 1;
  });
  testing::HoldPlaneZ(&scene, 0.1);
  LabelMaterial tissue{1, Material{}}, inclusion{2, Material{}};
  inclusion.material.youngs_modulus_pa *= contrast;
  scene.materials = {tissue, inclusion};
  return scene;
}

TEST(SceneModel, EachLabelTakesItsOwnTablesMaterial) {
  // Two labels of one material are one material: the same stiffness as one label.
  Scene one_label = BlockWithInclusion(1.0);
  auto relabelled = std::make_shared<LoadedGeometry>(*one_label.loaded_geometry);
  for (auto& label : relabelled->voxels.labels) label = 1;
  one_label.loaded_geometry = relabelled;
  one_label.materials.pop_back();
  const double k1 = ContactStiffness(one_label);
  EXPECT_NEAR(ContactStiffness(BlockWithInclusion(1.0)) / k1, 1.0, 1e-9);
  // A stiffer inclusion under the contact stiffens it, more the stiffer it is, and never more
  // than the contrast itself (the tissue around it stays as soft).
  const double k5 = ContactStiffness(BlockWithInclusion(5.0));
  const double k10 = ContactStiffness(BlockWithInclusion(10.0));
  std::printf("contact stiffness: plain %.2f N/m, inclusion 5x %.2f N/m, 10x %.2f N/m\n", k1, k5,
              k10);
  EXPECT_GT(k5, 1.05 * k1);
  EXPECT_GT(k10, k5);
  EXPECT_LT(k10, 10.0 * k1);
}

TEST(SceneModel, ThePlaneHoldsOneLayerAndTheLabelItsVoxelsNodes) {
  const Scene scene = BlockWithInclusion(5.0);
  const SceneModel object(scene);
  EXPECT_EQ(object.fixed_nodes().size(), 11u * 11u);  // the back face z = 0.1 m
  Scene by_label = scene;
  SupportRegion label;
  label.kind = SupportRegion::Kind::kLabel;
  label.label = 2;
  by_label.supports = {label};
  EXPECT_EQ(SceneModel(by_label).fixed_nodes().size(), 5u * 5u * 5u);  // the inclusion's nodes
}

TEST(SceneModel, RefusesWhatThePhysicsCannotRunSayingWhatToChange) {
  Scene no_support = BlockWithInclusion(5.0);
  no_support.supports.clear();
  EXPECT_NE(MessageOf([&] { SceneModel{no_support}; }).find("needs [[support]] tables"),
            std::string::npos);

  Scene one_edge = BlockWithInclusion(5.0);
  one_edge.supports = {SupportBox({0, 0, 0.1}, {0.1, 0, 0.1})};  // nodes on one line: it can turn
  EXPECT_NE(MessageOf([&] { SceneModel{one_edge}; }).find("could move as a rigid body"),
            std::string::npos);

  Scene missed = BlockWithInclusion(5.0);
  missed.supports = {SupportBox({1, 1, 1}, {2, 2, 2})};
  EXPECT_NE(MessageOf([&] { SceneModel{missed}; }).find("[[support]] 1 (box) holds no node"),
            std::string::npos);

  Scene unnamed_label = BlockWithInclusion(5.0);
  unnamed_label.materials.pop_back();
  EXPECT_NE(MessageOf([&] { SceneModel{unnamed_label}; })
                .find("has voxels labelled 2 but no [[material]] table names label 2"),
            std::string::npos);

  Scene extra_label = BlockWithInclusion(5.0);
  extra_label.materials.push_back({7, Material{}});
  EXPECT_NE(MessageOf([&] { SceneModel{extra_label}; }).find("label 7 is not in"),
            std::string::npos);

  Scene twice = BlockWithInclusion(5.0);
  twice.materials.push_back({2, Material{}});
  EXPECT_NE(MessageOf([&] { SceneModel{twice}; }).find("names label 2 again"), std::string::npos);

  Scene inside = BlockWithInclusion(5.0);
  SetSceneValue(&inside, "input.contact_node", "5,5,5");
  EXPECT_NE(MessageOf([&] { SceneModel{inside}; }).find("is not on the object's surface"),
            std::string::npos);

  Scene unread = BlockWithInclusion(5.0);
  unread.loaded_geometry.reset();
  EXPECT_NE(MessageOf([&] { SceneModel{unread}; }).find("has not been read"), std::string::npos);
}

TEST(SceneModel, TheCubesTablesRoundTripThroughTheSceneFile) {
  const std::string text = R"(
[input]
amplitude = 0.005

[[material]]
label = 1
youngs_modulus = 20000.0
poisson_ratio = 0.3

[[support]]
plane_point = [0.0, 0.0, 0.25]
plane_normal = [0.0, 0.0, 1.0]

[[support]]
box_min = [0.0, 0.0, 0.0]
box_max = [0.25, 0.0, 0.0]
)";
  const Scene scene = ParseSceneText(text, "tables.toml");
  ASSERT_EQ(scene.materials.size(), 1u);
  EXPECT_EQ(scene.materials[0].material.youngs_modulus_pa, 20000.0);
  EXPECT_EQ(scene.materials[0].material.poisson_ratio, 0.3);
  EXPECT_EQ(scene.materials[0].material.density_kg_m3, 1000.0);  // the default where not given
  ASSERT_EQ(scene.supports.size(), 2u);
  EXPECT_EQ(scene.supports[0].kind, SupportRegion::Kind::kPlane);
  EXPECT_EQ(scene.supports[1].box_max_m, (std::array<double, 3>{0.25, 0, 0}));
  const std::string again = FormatSceneToml(scene);
  EXPECT_EQ(FormatSceneToml(ParseSceneText(again, "again.toml")), again);
  // The cube held on its whole back face is stiffer than on four corners.
  Scene corners = scene;
  corners.supports.clear();
  Scene face = scene;
  face.supports.resize(1);
  EXPECT_GT(ContactStiffness(face), ContactStiffness(corners));
  EXPECT_EQ(SceneModel(face).fixed_nodes().size(), 13u * 13u);
}

TEST(SceneModel, BadTablesInASceneFileAreRefusedNamingThePlace) {
  const auto message = [](const std::string& text) {
    return MessageOf([&] { ParseSceneText(text, "bad.toml"); });
  };
  EXPECT_NE(message("[[material]]\nlabel = 1\npoisson_ratio = 0.7\n").find("bad.toml:3"),
            std::string::npos);
  EXPECT_NE(message("[[material]]\nlabel = 1\npoisson_ratio = 0.7\n").find("poisson_ratio = 0.7"),
            std::string::npos);
  EXPECT_NE(message("[[material]]\nlabel = 3\n").find("the cube is label 1"), std::string::npos);
  EXPECT_NE(message("[[material]]\nstiffness = 3\n").find("unknown [[material]] key 'stiffness'"),
            std::string::npos);
  EXPECT_NE(message("[[support]]\nlabel = 1\nbox_min = [0, 0, 0]\n").find("one of label"),
            std::string::npos);
  EXPECT_NE(message("[[support]]\nbox_min = [0, 0]\nbox_max = [1, 1, 1]\n").find("three numbers"),
            std::string::npos);
  EXPECT_NE(message("[[support]]\nbox_min = [1, 0, 0]\nbox_max = [0, 1, 1]\n").find("must not exceed"),
            std::string::npos);
  EXPECT_NE(message("[[support]]\nplane_point = [0, 0, 0]\nplane_normal = [0, 0, 0]\n")
                .find("must not be zero"),
            std::string::npos);
  EXPECT_NE(message("support = 3\n").find("must be tables written [[support]]"),
            std::string::npos);
}

}  // namespace
}  // namespace hapticsim
