// The driven node anywhere on the surface (input.contact_node): checked against the cube's own
// symmetries, which no code path knows about. The supports (the four back corners) are invariant
// under x → L − x, y → L − y and x ↔ y, so pressing at mirrored nodes must give mirrored forces.
#include <gtest/gtest.h>

#include <cmath>

#include "core/error.hpp"
#include "core/regions/async_regions.hpp"
#include "core/trial/force_error.hpp"
#include "core/trial/reference_trial.hpp"
#include "tests/support/voxel_scene.hpp"

namespace hapticsim {
namespace {

Scene Pressed(const std::string& node) {
  Scene scene;
  scene.mesh.nodes = 7;
  scene.input.periods = 0.5;  // the press in and the first half of the way back
  SetSceneValue(&scene, "input.contact_node", node);
  return scene;
}

using Map = std::array<int, 3>;  // output component c comes from input component map[c]

// Relative difference of the force histories after mapping b's components (with signs).
double MirroredDifference(const TrialResult& a, const TrialResult& b, const Map& from,
                          const std::array<double, 3>& sign) {
  EXPECT_EQ(a.samples.size(), b.samples.size());
  double diff2 = 0, ref2 = 0;
  for (size_t i = 0; i < a.samples.size(); ++i) {
    for (int c = 0; c < 3; ++c) {
      const double fa = a.samples[i].feedback_force_n[c];
      const double fb = sign[c] * b.samples[i].feedback_force_n[from[c]];
      diff2 += (fa - fb) * (fa - fb);
      ref2 += fa * fa;
    }
  }
  return std::sqrt(diff2 / ref2);
}

TEST(ContactNode, KeyReadsBackAndDefaultsToThePapersNode) {
  Scene scene;
  EXPECT_EQ(GetSceneValue(scene, "input.contact_node"), "\"middle\"");
  EXPECT_EQ(ContactNode(scene), (LatticeIndex{6, 6, 0}));
  SetSceneValue(&scene, "input.contact_node", "\"3,12,5\"");
  EXPECT_EQ(ContactNode(scene), (LatticeIndex{3, 12, 5}));
  EXPECT_EQ(GetSceneValue(scene, "input.contact_node"), "\"3,12,5\"");
  EXPECT_NO_THROW(ValidateScene(scene));
  EXPECT_EQ(InwardNormal(scene.mesh, ContactNode(scene)), (std::array<double, 3>{0, -1, 0}));
}

TEST(ContactNode, RejectsNodesInsideOutsideOrFixed) {
  Scene scene;
  EXPECT_THROW(SetSceneValue(&scene, "input.contact_node", "6,6"), Error);
  EXPECT_THROW(SetSceneValue(&scene, "input.contact_node", "a,b,c"), Error);
  EXPECT_THROW(SetSceneValue(&scene, "input.contact_node", "-1,6,0"), Error);
  auto message = [&](const std::string& node) {
    Scene s;
    SetSceneValue(&s, "input.contact_node", node);
    try {
      ValidateScene(s);
    } catch (const Error& e) {
      return std::string(e.what());
    }
    return std::string("accepted");
  };
  EXPECT_NE(message("6,6,6").find("inside the object"), std::string::npos);
  EXPECT_NE(message("6,6,13").find("outside the mesh"), std::string::npos);
  EXPECT_NE(message("0,0,12").find("fixed back corner"), std::string::npos);
  EXPECT_EQ(message("0,0,11"), "accepted");
  // [[support]] tables replace the corners: held by the whole back face, the corner is still
  // refused (by the model, as held); held by the left face only, the back corner is free.
  Scene back = scene, left = scene;
  testing::HoldPlaneZ(&back, 0.25);
  left.supports = {testing::SupportBox({-0.001, -0.001, -0.001}, {0.001, 0.251, 0.251})};
  EXPECT_NE(ContactNodeProblemOn(back, {12, 12, 12}), "");
  EXPECT_EQ(ContactNodeProblemOn(left, {12, 0, 12}), "");
  left.input.contact_node = LatticeIndex{12, 0, 12};
  EXPECT_NO_THROW(ValidateScene(left));
  EXPECT_NO_THROW(SceneModel{left});
}

TEST(ContactNode, EdgeNodesPressAlongTheFrontOrBackFirst) {
  const MeshSettings mesh;  // 13 nodes
  EXPECT_EQ(InwardNormal(mesh, {0, 6, 0}), (std::array<double, 3>{0, 0, 1}));
  EXPECT_EQ(InwardNormal(mesh, {12, 6, 12}), (std::array<double, 3>{0, 0, -1}));
  EXPECT_EQ(InwardNormal(mesh, {12, 0, 6}), (std::array<double, 3>{-1, 0, 0}));
  EXPECT_EQ(InwardNormal(mesh, {6, 12, 6}), (std::array<double, 3>{0, -1, 0}));
}

TEST(ContactNode, ReferenceForcesMirrorWithTheCube) {
  // x → L − x: the off-centre front node 1 ↔ 5; the force's x component flips.
  const TrialResult left = RunReferenceTrial(SceneModel(Pressed("1,3,0")));
  const TrialResult right = RunReferenceTrial(SceneModel(Pressed("5,3,0")));
  ASSERT_EQ(left.outcome, TrialOutcome::kCompleted);
  EXPECT_GT(std::abs(left.samples[200].feedback_force_n[0]), 1e-3 * left.peak_force_n)
      << "an off-centre press must pull sideways, or the test shows nothing";
  EXPECT_LT(MirroredDifference(left, right, {0, 1, 2}, {-1, 1, 1}), 1e-10);

  // x ↔ y: the left face (normal +x) and the bottom face (normal +y).
  const TrialResult side = RunReferenceTrial(SceneModel(Pressed("0,3,2")));
  const TrialResult bottom = RunReferenceTrial(SceneModel(Pressed("3,0,2")));
  EXPECT_LT(MirroredDifference(side, bottom, {1, 0, 2}, {1, 1, 1}), 1e-10);
  // Pressing along +x: the user feels a force along −x.
  EXPECT_LT(side.samples[250].feedback_force_n[0], 0.0);
  EXPECT_GT(side.samples[250].contact_displacement_m[0], 0.0);
}

TEST(ContactNode, RegionsAtEqualRatesReproduceTheReferenceOffCentre) {
  // The primary region is built around the contact wherever it is (clipped at the faces): at
  // k = 1 and equal rates the regions are exactly monolithic central difference.
  for (const std::string node : {"0,3,2", "1,1,0", "3,6,6"}) {
    Scene scene = Pressed(node);
    const TrialResult reference = RunReferenceTrial(SceneModel(scene));
    scene.adaptivity.primary_size = 1;
    scene.adaptivity.secondary_lod = 1;
    scene.adaptivity.secondary_rate_hz = 1000;
    AsyncRegions regions(scene);
    const TrialResult result = regions.RunTrial();
    ASSERT_EQ(result.outcome, TrialOutcome::kCompleted) << node;
    EXPECT_LT(CompareForces(result.samples, reference.samples).l2_percent, 1e-9) << node;
  }
}

TEST(ContactNode, AdaptiveRegionsMirrorWithTheCube) {
  // Adaptive regions at unequal rates around mirrored contacts: mirrored partitions, mirrored
  // forces (up to summation order).
  auto run = [](const std::string& node) {
    Scene scene = Pressed(node);
    scene.adaptivity.primary_size = 1;
    scene.adaptivity.secondary_lod = 2;
    scene.adaptivity.secondary_rate_hz = 500;
    AsyncRegions regions(scene);
    return regions.RunTrial();
  };
  const TrialResult a = run("1,3,0"), b = run("5,3,0");
  ASSERT_EQ(a.outcome, TrialOutcome::kCompleted);
  EXPECT_LT(MirroredDifference(a, b, {0, 1, 2}, {-1, 1, 1}), 1e-9);
}

}  // namespace
}  // namespace hapticsim
