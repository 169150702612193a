#pragma once

#include <Eigen/Core>
#include <array>
#include <cstdint>
#include <utility>
#include <vector>

#include "core/fem/material.hpp"

namespace hapticsim {

/** Which region an element belongs to: 0 is the primary region, 1… the secondary shells. */
using RegionIndex = int;
constexpr RegionIndex kPrimaryRegion = 0;
constexpr RegionIndex kSecondaryRegion = 1;

/** A cube element of the hybrid mesh. */
struct HybridElement {
  std::array<int, 8> nodes{};  ///< mesh nodes in Hex8Element's local order
  int size_factor = 1;         ///< edge = size_factor · h (1 fine, k coarse)
  RegionIndex region = kPrimaryRegion;
  std::int16_t material = 0;  ///< index into the object's materials (MaterialField order)
};

/** One term of a node's displacement in terms of independent DOFs: u_node += weight·u_r. */
struct GatherTerm {
  int independent = 0;
  double weight = 1.0;
};

/**
 * An object on a lattice meshed at two resolutions: coarse cells of k × k × k fine intervals, of
 * which some are refined into their fine cells — those meeting the primary box around the contact,
 * those around point and line supports, and those the object fills only in part or with more than
 * one material (its surface and its material boundaries, so a coarse element is always whole and of
 * one material). Where a refined cell meets an unrefined one, the fine nodes that are not coarse
 * vertices ("hanging nodes") are constrained to the coarse cell's trilinear field, which on the
 * shared face is bilinear, so the displacement stays continuous (conforming).
 *
 * The object is the lattice's occupied fine cells (Options::cell_material; every cell, the paper's
 * cube, when it is empty). A refined cell contributes only its occupied fine cells. The lattice's
 * node counts need not be k·m + 1: the coarse cells past its end are partly empty, so refined.
 *
 * The unknowns are the *independent* nodes (all nodes but the hanging ones), component-blocked
 * like HexGrid: dof(r, c) = c·N_r + r. A hanging node's displacement is gathered from its masters
 * with the interpolation weights; its forces and lumped mass are scattered back with the same
 * weights (u = T·u_r, f_r = Tᵀ·f, M_r = row sums of TᵀMT).
 *
 * Nodes live on the fine lattice, so a lattice index names every node whatever its cell's
 * resolution. With k = 1 there are no hanging nodes and the mesh is the full-resolution grid.
 */
class HybridMesh {
 public:
  struct Options {
    std::array<int, 3> lattice_nodes{13, 13, 13};  ///< fine lattice points along x, y, z
    double spacing_m = 0.25 / 12;                  ///< fine spacing h, m
    int coarse_factor = 2;                         ///< k
    /// Per fine lattice cell, x fastest (MaterialField's element order): its material index, or
    /// −1 where the object is not. Empty: every cell of material 0.
    std::vector<std::int16_t> cell_material;
    std::array<int, 3> primary_lo{}, primary_hi{};  ///< primary box, lattice indices (closed)
    /// Lattice indices of the held nodes. A held node that would hang from a coarse cell whose
    /// field it does not share (a vertex of that cell is free) refines the cell, so every support
    /// is held exactly.
    std::vector<std::array<int, 3>> supports;
    /// Coarse cells refined around each point or line support (a held node that is no corner of
    /// a held parallelogram of lattice neighbours), per direction: a coarse cell at a singular
    /// support is far too stiff. Held surfaces (axis-aligned or not) are not and are not refined.
    int support_layers = 1;
    /// Secondary cells split into this many nested shells around the primary cells (regions
    /// 1…n), each shell_cells coarse cells thick (Chebyshev distance); the last takes the rest.
    int secondary_regions = 1;
    int shell_cells = 1;
  };

  /** @throws Error when the options are inconsistent (sizes, k < 1, an unoccupied lattice). */
  explicit HybridMesh(const Options& options);

  const Options& options() const { return options_; }
  int num_independent() const { return static_cast<int>(independent_lattice_.size()); }
  int num_dofs() const { return 3 * num_independent(); }
  int Dof(int independent, int component) const {
    return component * num_independent() + independent;
  }
  const std::vector<HybridElement>& elements() const { return elements_; }
  int num_hanging() const { return num_hanging_; }

  /** Independent index of the node at a lattice point, or −1 (no node there, or hanging). */
  int IndependentAt(int ix, int iy, int iz) const;
  /**
   * The mesh's displacement at any lattice point as a sum of independent nodes' values: an
   * independent node's own (one term of weight 1); elsewhere — a point inside or on an unrefined
   * coarse cell, a hanging node among them — the cell's trilinear field of its 8 vertices, which
   * are always independent (terms of weight 0 left out). A point on a face shared with a refined
   * cell gets the same field from either: it depends on the face's vertices alone. A point no
   * element touches (outside the object) has no term. Returns the number of terms written.
   */
  int FieldAt(const std::array<int, 3>& point, std::array<GatherTerm, 8>* terms) const;
  /**
   * The region of the element covering each fine lattice cell ((nx−1)(ny−1)(nz−1) cells, ix
   * slowest), −1 where the object is not: a coarse element gives its region to the k³ fine cells
   * inside it.
   */
  std::vector<RegionIndex> RegionPerLatticeCell() const;
  /** Lattice indices of an independent node. */
  const std::array<int, 3>& LatticeOf(int independent) const {
    return independent_lattice_[independent];
  }

  /** How many of the 8 fine lattice cells around lattice point p the object fills (0 to 8). */
  int OccupiedCellsAround(const std::array<int, 3>& p) const;

  /** The gather terms of mesh node `node` (one term of weight 1 for an independent node). */
  std::pair<const GatherTerm*, const GatherTerm*> Gather(int node) const {
    return {gather_terms_.data() + gather_start_[node],
            gather_terms_.data() + gather_start_[node + 1]};
  }

  /** Lumped mass of each independent DOF, kg (component-blocked): ρ of each element's material. */
  Eigen::VectorXd DofMass(const std::vector<Material>& materials) const;
  /**
   * Each independent DOF's damping rate, 1/s: with C = Σ_e d_e·M_e lumped, the mass-weighted mean
   * of the rates of the elements around it (ElasticModel::dof_damping on the fine grid); exactly
   * the material's d when one rate is everywhere.
   */
  Eigen::VectorXd DofDamping(const std::vector<Material>& materials) const;
  /** Whether the elements are all of one material (which one, else −1). */
  int uniform_material() const;

  /** Number of regions that have elements (primary + secondary shells). */
  int num_regions() const { return num_regions_; }
  /** Bit r set when elements of region r touch the independent node (through its gathers). */
  const std::vector<unsigned>& region_mask() const { return region_mask_; }

 private:
  template <typename Plan>
  std::vector<std::array<int, 3>> BuildElements(const Plan& plan);
  void BuildGather(const std::vector<std::vector<std::pair<int, double>>>& masters,
                   const std::vector<std::array<int, 3>>& node_lattice);
  void BuildRegionMasks();

  // Each independent node's lumped mass, kg (its share of every element's ρ·volume, through the
  // gathers); with times_damping each share times its element's damping rate d, kg/s.
  Eigen::VectorXd NodeMass(const std::vector<Material>& materials, bool times_damping) const;
  int LatticePoint(int ix, int iy, int iz) const {
    return ix + padded_[0] * (iy + padded_[1] * iz);
  }

  Options options_;
  std::array<int, 3> coarse_cells_{};  // per axis: ⌈(n − 1) / k⌉
  std::array<int, 3> padded_{};        // lattice points the coarse cells span: coarse_cells·k + 1
  std::vector<char> coarse_;           // per coarse cell (x fastest): one coarse element
  std::vector<HybridElement> elements_;
  std::vector<int> node_at_lattice_;  // mesh node id per padded lattice point, −1 if none
  std::vector<int> gather_start_;     // per mesh node, into gather_terms_ (size nodes + 1)
  std::vector<GatherTerm> gather_terms_;
  std::vector<int> independent_of_node_;  // −1 for hanging nodes
  std::vector<std::array<int, 3>> independent_lattice_;
  std::vector<unsigned> region_mask_;
  int num_hanging_ = 0;
  int num_regions_ = 0;
};

}  // namespace hapticsim
