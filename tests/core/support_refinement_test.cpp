// Refinement around singular supports (adaptivity.support_layers): a point support or a held
// line of nodes has a displacement field that is unbounded in the continuum, so a coarse cell
// there is far too stiff; a held surface is not singular. Checked on the paper's cube held on
// two lines (the back face's top and bottom edges) against the full-resolution reference: the
// refinement brings the regions' force closer to it. Held on the whole back face, the setting
// changes nothing.
#include <gtest/gtest.h>

#include <cstdio>

#include "core/errormap/error_sweep.hpp"
#include "core/regions/region_partition.hpp"
#include "tests/support/voxel_scene.hpp"

namespace hapticsim {
namespace {

constexpr double kEdge = 0.25;  // the cube's, m
constexpr double kTolerance = 0.001;

// The cube held on its back face's bottom (y = 0) and top (y = edge) edges: two lines of 13.
Scene HeldOnTwoLines(int support_layers, int secondary_lod) {
  Scene scene;
  const double t = kTolerance, e = kEdge;
  scene.supports = {testing::SupportBox({-t, -t, e - t}, {e + t, t, e + t}),
                    testing::SupportBox({-t, e - t, e - t}, {e + t, e + t, e + t})};
  scene.adaptivity.primary_size = 1;
  scene.adaptivity.secondary_lod = secondary_lod;
  scene.adaptivity.secondary_rate_hz = 1000;  // in step with the primary
  scene.adaptivity.support_layers = support_layers;
  return scene;
}

Scene HeldOnTheBackFace(int support_layers) {
  Scene scene;
  testing::HoldPlaneZ(&scene, kEdge);
  scene.adaptivity.primary_size = 1;
  scene.adaptivity.secondary_lod = 2;
  scene.adaptivity.support_layers = support_layers;
  return scene;
}

int Nodes(const Scene& scene) {
  const RegionPartition partition(scene);
  int nodes = 0;
  for (int r = 0; r < partition.num_regions(); ++r) nodes += partition.num_nodes(r);
  return nodes;
}

// The relative L2 force error of the scene's own configuration against the reference.
double L2Percent(const Scene& scene) {
  SweepGrid grid;
  grid.name = "one";
  const MapPoint own = PointOfScene(scene);
  for (int a = 0; a < kNumMapAxes; ++a) grid.axes[a] = {own[a]};
  SweepStats stats;
  const ErrorMap map = RunSweep(scene, grid, {}, &stats);
  EXPECT_EQ(map.samples.at(0).status, SampleStatus::kOk);
  return map.samples.at(0).l2_percent;
}

TEST(SupportRefinement, AHeldLineIsRefinedAroundAndTheForceComesCloserToTheReference) {
  for (int k : {2, 3}) {
    const double coarse = L2Percent(HeldOnTwoLines(0, k));
    const double refined = L2Percent(HeldOnTwoLines(1, k));
    std::printf("k %d: relative L2 %.3f %% with no refinement, %.3f %% with one layer\n", k, coarse,
                refined);
    EXPECT_GT(Nodes(HeldOnTwoLines(1, k)), Nodes(HeldOnTwoLines(0, k)));
    EXPECT_LT(refined, 0.75 * coarse);
  }
}

TEST(SupportRefinement, AHeldSurfaceIsNotSingularAndNotRefined) {
  EXPECT_EQ(Nodes(HeldOnTheBackFace(1)), Nodes(HeldOnTheBackFace(0)));
  // A diagonal plane through lattice nodes (x + y = 16 h, across the cube's far corner) holds a
  // one node-thick staircase of nodes with no held neighbour along x or y: a surface all the same.
  Scene diagonal = HeldOnTheBackFace(1);
  diagonal.supports[0].point_m = {kEdge * 16 / 12, 0, 0};
  diagonal.supports[0].normal = {1, 1, 0};
  Scene unrefined = diagonal;
  unrefined.adaptivity.support_layers = 0;
  EXPECT_EQ(Nodes(diagonal), Nodes(unrefined));
}

}  // namespace
}  // namespace hapticsim
