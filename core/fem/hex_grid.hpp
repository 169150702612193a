#pragma once

#include <array>
#include <cstdint>

namespace hapticsim {

/**
 * A structured grid of nx × ny × nz nodes with spacing h (metres), its origin at (0, 0, 0).
 *
 * Node numbering is lexicographic with x fastest: node(ix, iy, iz) = ix + nx·(iy + ny·iz).
 * Degrees of freedom are stored component-blocked ("structure of arrays"): the x components of
 * all nodes first, then all y, then all z, so dof(node, c) = c·N + node with N the node count.
 * The blocked layout lets the stencil kernel stream each component with unit stride.
 *
 * Object frame of the built-in scene: the front face is z = 0, x and y run along it and z points
 * into the object.
 */
class HexGrid {
 public:
  /** @pre every count ≥ 2, spacing > 0 (throws hapticsim::Error otherwise). */
  HexGrid(int nx, int ny, int nz, double spacing_m);

  int nx() const { return nx_; }
  int ny() const { return ny_; }
  int nz() const { return nz_; }
  /** Node spacing h in metres. */
  double spacing() const { return spacing_; }
  int num_nodes() const { return nx_ * ny_ * nz_; }
  int num_dofs() const { return 3 * num_nodes(); }
  int num_elements() const { return (nx_ - 1) * (ny_ - 1) * (nz_ - 1); }

  int Node(int ix, int iy, int iz) const { return ix + nx_ * (iy + ny_ * iz); }
  int Dof(int node, int component) const { return component * num_nodes() + node; }
  std::array<int, 3> NodeIndices(int node) const;
  /** Position of a node in metres. */
  std::array<double, 3> NodePosition(int node) const;

  /**
   * The 8 nodes of the element whose lowest corner is node (ex, ey, ez), in the local order
   * used by Hex8Element: local index = bx + 2·by + 4·bz for corner offsets (bx, by, bz) ∈ {0,1}³.
   */
  std::array<int, 8> ElementNodes(int ex, int ey, int ez) const;

 private:
  int nx_, ny_, nz_;
  double spacing_;
};

}  // namespace hapticsim
