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
 * The object as the tool meets it in hapticsimd: a box of lattice nodes — nx × ny × nz at spacing
 * h, from 0 to (n − 1)·h on each axis in the object frame (node 0 at the origin) — and which of
 * its surface nodes the tool may drive (every one not held by a support). The paper's cube is the
 * box of mesh.nodes³; a geometry file's object is its lattice, so far only when it fills the box
 * (BoxObjectProblem).
 *
 * Built once, before the loop runs; the primary thread only reads it (no allocation there).
 */
class ContactBox {
 public:
  /** @throws Error when `object` leaves voxels of its lattice empty (BoxObjectProblem). */
  explicit ContactBox(const SceneObject& object);
  /** The box of `scene`'s object (DescribeSceneObject). @throws Error as that, and as above. */
  static ContactBox Of(const Scene& scene);

  const std::array<int, 3>& nodes() const { return nodes_; }
  double spacing_m() const { return spacing_m_; }
  /** The box's size along each axis, m: (n − 1)·h. */
  const std::array<double, 3>& extent_m() const { return extent_m_; }

  /** True for a tool tip strictly inside the box, m (object frame). */
  bool Inside(const std::array<double, 3>& tip_m) const noexcept;
  /** Where a tip inside the box came in: the face it is least deep behind (the front face first
   *  on a tie), the tip projected onto it, its inward normal and the tip's depth behind it. */
  struct Entry {
    std::array<double, 3> point_m{};
    std::array<double, 3> inward_normal{};
    double depth_m = 0;
  };
  Entry EntryOf(const std::array<double, 3>& tip_m) const noexcept;

  /** True for a node on the box's surface (some index 0 or n − 1) that no support holds. */
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

  /** The point of the box nearest to `tip_m` (a tip outside: the point it hovers over). */
  std::array<double, 3> NearestPoint(const std::array<double, 3>& tip_m) const noexcept {
    std::array<double, 3> nearest = tip_m;
    for (int c = 0; c < 3; ++c) nearest[c] = std::clamp(nearest[c], 0.0, extent_m_[c]);
    return nearest;
  }

  /** A node as one integer, (ix · ny + iy) · nz + iz (the order of the regions' surface ids),
   *  for an atomic; Decode gives it back. */
  std::int64_t Code(const LatticeIndex& node) const noexcept;
  LatticeIndex Decode(std::int64_t code) const noexcept;

  /**
   * The lattice as deformation_t and the shared-memory segment give it: one node count n for all
   * three axes, node id = (ix · n + iy) · n + iz. n is the box's largest count, so every node of
   * the box has an id and a reader that decodes with n gets its indices (the cube's ids are the
   * regions' own). A reader finds the box's far faces at the largest index along each axis.
   */
  int wire_nodes_per_axis() const { return std::max({nodes_[0], nodes_[1], nodes_[2]}); }
  /** The regions' surface ids (Code's order) as wire ids, into `wire` (resized). */
  void ToWireIds(const std::vector<std::int32_t>& codes, std::vector<std::int32_t>* wire) const;

 private:
  std::size_t Index(const LatticeIndex& node) const noexcept {
    return static_cast<std::size_t>(Code(node));
  }
  bool OnSurface(const LatticeIndex& node) const noexcept;

  std::array<int, 3> nodes_{};
  double spacing_m_ = 0;
  std::array<double, 3> extent_m_{};
  std::vector<bool> drivable_;  // by Code
};

/**
 * Why hapticsimd cannot run `object` yet, or "": the contact tracker, the input guard and the
 * deformation output take the object to be the box of its lattice, so every voxel must be filled.
 */
std::string BoxObjectProblem(const SceneObject& object);

}  // namespace hapticsim
