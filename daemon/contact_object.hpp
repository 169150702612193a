#pragma once

#include <algorithm>
#include <array>
#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include "core/scene/scene.hpp"
#include "core/scene/scene_model.hpp"

namespace hapticsim {

/**
 * The object as the tool meets it in hapticsimd: its voxels on a lattice of nx × ny × nz nodes at
 * spacing h, from 0 to (n − 1)·h on each axis in the object frame (node 0 at the origin), and
 * which of its surface nodes the tool may drive (every one not held by a support). The paper's
 * cube fills the box of mesh.nodes³; a geometry file's object is whichever voxels it occupies
 * (an organ's, a notched block's), the rest of its lattice empty.
 *
 * The object's surface is the faces between an occupied voxel and an empty one (or the lattice's
 * end). Built once, before the loop runs; the primary thread only reads it (no allocation there;
 * every query walks at most one row of voxels per axis).
 */
class ContactObject {
 public:
  /** @throws Error when the supports hold every surface node (nothing to touch). */
  explicit ContactObject(const SceneObject& object);
  /** The object of `scene` (DescribeSceneObject). @throws Error as that, and as above. */
  static ContactObject Of(const Scene& scene);

  const std::array<int, 3>& nodes() const { return nodes_; }
  double spacing_m() const { return spacing_m_; }
  /** The lattice's box along each axis, m: (n − 1)·h (the object lies inside it). */
  const std::array<double, 3>& extent_m() const { return extent_m_; }

  /** How many voxels it occupies, and how many surface nodes a tool may drive. */
  int occupied_voxels() const { return occupied_voxels_; }
  int drivable_nodes() const { return drivable_nodes_; }

  /** True for a tool tip strictly inside the lattice's box and in an occupied voxel, m. */
  bool Inside(const std::array<double, 3>& tip_m) const noexcept;
  /** Where a tip inside the object came in: of the six ways out along the axes, the one it is
   *  least deep behind (the front, −z, first on a tie), the tip projected onto that face of the
   *  object's surface, its inward normal and the tip's depth behind it. */
  struct Entry {
    std::array<double, 3> point_m{};
    std::array<double, 3> inward_normal{};
    double depth_m = 0;
  };
  Entry EntryOf(const std::array<double, 3>& tip_m) const noexcept;
  /** All six ways out of a tip inside the object, along ±x, ±y, ±z, least deep first (EntryOf's
   *  is the first): where the face the tip is least deep behind cannot be touched, the next. */
  std::array<Entry, 6> WaysOut(const std::array<double, 3>& tip_m) const noexcept;
  /** Where a tip outside the object would come down: the point of a voxel near it nearest to
   *  the tip (NearestPoint), with that voxel's way out as EntryOf gives it (depth 0 on a face
   *  of the surface where the voxel is the nearest). */
  Entry HoverEntry(const std::array<double, 3>& tip_m) const noexcept;

  /** True for a node on the object's surface (beside an occupied voxel and an empty one, or the
   *  lattice's end) that no support holds. */
  bool Drivable(const LatticeIndex& node) const noexcept;

  /**
   * The node a touch at a point on the surface (or projected onto it), m, drives: the lattice node
   * it rounds to; if a support holds that one, its drivable neighbour on the surface nearest to
   * the point (beside a held corner, the node on the side the touch came down on). None when
   * the node and all its neighbours are held: a touch on a held face touches the support, which
   * the model does not render (a far node driven instead would feel like soft tissue where the
   * object is held rigid).
   */
  std::optional<LatticeIndex> NearestDrivable(
      const std::array<double, 3>& surface_point_m) const noexcept;

  /** The point of the object near `tip_m` (a tip inside: itself; outside: the point nearest to
   *  it of the nearest occupied voxel around the flood's and the tip's own voxel — the nearest
   *  point of the object but where a gap hides a nearer voxel further away). */
  std::array<double, 3> NearestPoint(const std::array<double, 3>& tip_m) const noexcept;

  /** The inward normal of the flat face `node` lies inside of — its four voxels on one side of
   *  an axis plane occupied and the four on the other empty — or zero (an edge, a corner, a
   *  step of the surface, a node off it). A sliding tool's proxy stays on such a face. */
  std::array<double, 3> FlatFaceNormal(const LatticeIndex& node) const noexcept;

  /** A node as one integer, (ix · ny + iy) · nz + iz (the order of the regions' surface ids),
   *  for an atomic; Decode gives it back. */
  std::int64_t Code(const LatticeIndex& node) const noexcept;
  LatticeIndex Decode(std::int64_t code) const noexcept;

  /**
   * The lattice as deformation_t and the shared-memory segment give it: one node count n for all
   * three axes, node id = (ix · n + iy) · n + iz. n is the box's largest count, so every node of
   * the box has an id and a reader that decodes with n gets its indices (the cube's ids are the
   * regions' own). The object's faces: ObjectSurfaceQuads (core/scene/object_surface.hpp).
   */
  int wire_nodes_per_axis() const { return std::max({nodes_[0], nodes_[1], nodes_[2]}); }
  /** The regions' surface ids (Code's order) as wire ids, into `wire` (resized). */
  void ToWireIds(const std::vector<std::int32_t>& codes, std::vector<std::int32_t>* wire) const;

 private:
  std::size_t Index(const LatticeIndex& node) const noexcept {
    return static_cast<std::size_t>(Code(node));
  }
  // Voxels by index (ix, iy, iz) of their lowest node, x fastest; false outside the lattice.
  bool Occupied(int vx, int vy, int vz) const noexcept;
  std::array<int, 3> VoxelOf(const std::array<double, 3>& point_m) const noexcept;
  // WaysOut and EntryOf for a point in (or on) voxel `voxel`.
  std::array<Entry, 6> WaysOutFrom(const std::array<double, 3>& point_m,
                                   const std::array<int, 3>& voxel) const noexcept;
  Entry EntryFrom(const std::array<double, 3>& point_m,
                  const std::array<int, 3>& voxel) const noexcept;
  // 0, or ±(axis + 1) of the inward normal of the flat face `node` lies inside of.
  std::int8_t FlatFaceCode(const LatticeIndex& node) const noexcept;
  void FloodNearestVoxels();
  // The point of `voxel` nearest to `tip_m`.
  std::array<double, 3> PointOf(const std::array<int, 3>& voxel,
                                const std::array<double, 3>& tip_m) const noexcept;
  // The occupied voxel nearest to `point_m`, among those around the flood's voxel for it and
  // around its own.
  std::array<int, 3> NearestVoxel(const std::array<double, 3>& point_m) const noexcept;

  std::array<int, 3> nodes_{};
  double spacing_m_ = 0;
  std::array<double, 3> extent_m_{};
  std::vector<bool> drivable_;          // by Code
  std::vector<std::int8_t> flat_face_;  // by Code: 0, or ±(axis + 1) of the inward normal
  std::vector<bool> occupied_;          // by voxel, x fastest
  std::vector<std::int32_t> nearest_;   // by voxel: the nearest occupied voxel (itself if so)
  int occupied_voxels_ = 0, drivable_nodes_ = 0;
};

}  // namespace hapticsim
