#pragma once

#include <Eigen/Core>
#include <array>
#include <limits>
#include <span>
#include <vector>

#include "core/fem/elastic_model.hpp"
#include "core/fem/region_integrator.hpp"
#include "core/scene/scene.hpp"

namespace hapticsim {

/**
 * The object as a proxy touches it: its fine lattice, the cells it fills, and for each lattice
 * node where its displacement is in the state vector the proxy reads and whether the proxy may
 * push it. Nodes and cells are numbered x fastest (HexGrid::Node, MaterialField::Element).
 */
struct ProxySurface {
  std::array<int, 3> lattice_nodes{};
  double spacing_m = 0;
  std::vector<char> occupied;  ///< per lattice cell: the object fills it
  std::vector<int> dof;        ///< per lattice node: its x DOF in the state vector, −1 if none
  int component_stride = 0;    ///< its y and z DOFs: dof + stride, dof + 2·stride
  /// Per lattice node: 1 the proxy may push it; 0 a support holds it (the support takes the
  /// proxy's share); −1 neither: it is not the object's, or another region steps it.
  std::vector<signed char> loadable;
  std::vector<double> mass_kg;  ///< per lattice node, its lumped mass (0 off the object)

  int num_nodes() const { return lattice_nodes[0] * lattice_nodes[1] * lattice_nodes[2]; }
  int Node(const std::array<int, 3>& at) const {
    return at[0] + lattice_nodes[0] * (at[1] + lattice_nodes[1] * at[2]);
  }
};

/** The full-resolution object's surface: every node on it, every free one pushable. */
ProxySurface ProxySurfaceOf(const ElasticModel& model);

/**
 * A sliding tool contact (god-object) on one flat face of the object: a proxy point stays on the
 * deformed surface, joined to the tool tip by a spring of contact.stiffness k. Where the tool is
 * inside, the spring pushes the surface at the proxy (spread over the face cell's 4 nodes with
 * the bilinear weights of where the proxy is in it) and the user feels the opposite force.
 *
 * A tip of contact.radius r wider than a cell spreads the push over the face nodes less than r from
 * the proxy along both tangents (a square) instead, with tent weights (1 − |Δ1|/r)(1 − |Δ2|/r)
 * normalised to sum 1, and reads the surface there: on a
 * lattice finer than the press is deep, a push on one cell's nodes dimples the surface under the
 * proxy, and sliding over its own dimple the proxy was measured to diverge.
 *
 * Friction (Coulomb, on the spring's pull): with g the tool's depth below the proxy along the
 * inward normal and d_t the tangential offset, the normal force is k·g and the tangential k·|d_t|.
 * The proxy sticks (stays at its material point of the surface) while k·|d_t| ≤ μ_s·k·g; past
 * that it slides towards the tool until k·|d_t| = μ_k·k·g, and keeps sliding while the pull stays
 * above μ_k·k·g. Out of contact (g ≤ 0) the proxy sits under the tool and no force is felt.
 *
 * The face is the plane of the contact node, normal to its inward normal's axis; the proxy moves
 * over its cells that are faces of occupied voxels with nothing outside them. A cell of the plane
 * with the object outside it is a wall rising from the face (a concave corner): the proxy stops at
 * its foot, and while the tool is past it, below the face, the spring's pull into the wall is the
 * wall's push, not friction's (Result::wall_holds); along the foot the proxy slides as anywhere.
 * The proxy does not climb the wall: the tool risen out of the face into it has left the surface
 * this contact renders. Update() never allocates.
 */
class ProxyContact {
 public:
  /**
   * @param contact_node   where the proxy starts (a lattice node on the face)
   * @param inward_normal  ±e_axis: the face's inward normal
   * @throws Error when the normal is not along a lattice axis.
   */
  ProxyContact(ProxySurface surface, const LatticeIndex& contact_node,
               const std::array<double, 3>& inward_normal, const ContactSettings& contact);
  /** On the full-resolution object (ProxySurfaceOf), from its grid node `contact_node`. */
  ProxyContact(const ElasticModel& model, int contact_node,
               const std::array<double, 3>& inward_normal, const ContactSettings& contact);

  /**
   * The same proxy (where it is on the face, whether it slides) over another state vector: the
   * object's regions moved (the primary re-centred under the proxy). The lattice must be the
   * same. Allocates.
   * @throws Error for a surface of another lattice.
   */
  void Rebind(ProxySurface surface);

  /** The DOFs the contact loads, in the order Update() writes loads: x, y, z of each node of the
   *  face the proxy may push (ProxySurface::loadable). */
  const std::vector<int>& loaded_dofs() const { return loaded_dofs_; }
  /** The lightest of those nodes' masses, kg: the spring's share of the step limit. */
  double lightest_loaded_mass_kg() const { return lightest_mass_kg_; }
  /** The rest position of the contact node, m (grid frame): where the tool starts. */
  const std::array<double, 3>& start_m() const { return start_m_; }

  struct Result {
    /// The spring's push on the surface, N, taken at the step's end: k·(offset − C·push).
    std::array<double, 3> force_on_object_n{};
    std::array<double, 3> offset_m{};  ///< tool − surface at the step's end without the push, m
    double compliance_m_per_n = 0;     ///< C: how far the push moves the surface there, m/N
    bool in_contact = false;
    bool sliding = false;       ///< the proxy slid this period
    bool left_surface = false;  ///< the proxy reached the face's edge: no surface under it
    /// … because the tool has risen out of the face into a wall rising from it, this far past
    /// the wall's foot (m; 0: not). The wall's face is another contact's to render.
    double into_wall_m = 0;
    std::array<double, 3> into_wall_inward{};  ///< … that wall's face's inward normal
    /// The proxy's face cell has a node this surface can neither push nor leave to a support
    /// (another region steps it): nothing was loaded. The regions must move under the proxy.
    bool left_region = false;
    /// Per axis (grid frame): the push along it is a wall's, not friction's. The proxy stands at
    /// the foot of a wall rising from its face (a concave corner) and the tool is past it; or the
    /// wall has just stopped holding it (past its end) and it is catching up with the tool.
    std::array<bool, 3> wall_holds{};
  };
  /**
   * One step: the proxy moved for the tool at `tool_m` (grid frame, m) over `u`, the state at
   * the step's end without the push, and the push on loaded_dofs() written to `loads`; the
   * spring is taken at the step's end (EndOfStepLoad, `compliance` per loaded DOF, m/N), so that
   * a light node under a stiff spring does not ring. Never allocates or throws.
   */
  Result Update(const std::array<double, 3>& tool_m, const Eigen::VectorXd& u,
                std::span<const double> compliance, std::span<double> loads) noexcept;
  /** Writes to `loads` the push `force_on_object_n` spread as the last Update in contact spread
   *  its own (the same nodes and weights): a push blended or ramped by the caller. Zero loads if
   *  the last Update pushed nothing, unless it left the surface (Result::left_surface): then the
   *  push before it is spread there, for a caller fading it out. Never allocates. */
  void SpreadLoads(const std::array<double, 3>& force_on_object_n,
                   std::span<double> loads) const noexcept;
  /** Whether a tool at `tool_m` could push here: over a face cell whose tip patch this surface
   *  reads and may push (or leave to a support). Never allocates. */
  bool CanTouchAt(const std::array<double, 3>& tool_m) const noexcept;
  /** Goes on where `other` is on the same face, sliding or not (the regions moved under the
   *  proxy: `other` is the proxy on the old ones). False, and nothing changed, for another face.
   *  Never allocates. */
  bool ContinueFrom(const ProxyContact& other) noexcept;
  /** The proxy put under the tool at `tool_m` (a touch-down), sticking. Never allocates. */
  void PlaceUnder(const std::array<double, 3>& tool_m) noexcept;
  /** The face's inward normal (±e_axis). */
  std::array<double, 3> inward_normal() const noexcept {
    std::array<double, 3> normal{};
    normal[static_cast<std::size_t>(axis_)] = sign_;
    return normal;
  }
  /** The proxy's rest position on the face, m (grid frame). */
  std::array<double, 3> proxy_rest_m() const;
  /** The lattice node of the face's plane nearest the proxy. */
  LatticeIndex NearestNode() const;
  /** Whether `node` is inside the face: on its plane, each of the four cells around it an
   *  exposed face of the object (its inward normal is the face's, not a rim's). */
  bool InsideFace(const LatticeIndex& node) const;

 private:
  // The widest tip, in lattice spacings, and the most nodes it can touch.
  static constexpr int kMaxReach = 8;
  static constexpr int kMaxPatch = (2 * kMaxReach + 1) * (2 * kMaxReach + 1);
  // How far short of a wall's foot a stopped proxy stays, in node spacings: on its own cell.
  static constexpr double kWallGap = 1e-6;
  // How much of the force rendered a proxy catching up after a wall stopped holding may shed in
  // one Update beyond what the tool's own motion sheds, N (SlideByFriction): 0.02 N per
  // substep, 0.04 N a period at 2 substeps.
  static constexpr double kSlideCatchUp_n = 0.02;
  // The face nodes the spring pushes and reads, with their weights (summing to 1).
  struct Patch {
    int count = 0;
    std::array<int, kMaxPatch> nodes{};
    std::array<double, kMaxPatch> weights{};
  };
  // The face nodes at the proxy: the cell under it with its bilinear weights (a tip within a
  // cell), or TentPatch; false off the surface.
  bool PatchAt(const std::array<double, 2>& proxy, Patch* patch) const;
  bool TentPatch(const std::array<double, 2>& proxy, Patch* patch) const;
  // The deformed surface point at the proxy: the patch's weighted displacement.
  std::array<double, 3> SurfacePoint(const Patch& patch, const Eigen::VectorXd& u) const;
  // Whether the object fills the voxel at `along` (the face's axis) under plane cell (i1, i2).
  bool Occupied(int along, int i1, int i2) const;
  bool ExposedFace(int i1, int i2) const;
  // Whether the face's plane at cell (i1, i2) has the object outside it: a wall rising from the
  // face (a concave corner's other face, or the object going on past the face's plane). The proxy
  // does not slide onto it.
  bool WallCell(int i1, int i2) const;
  // The plane's cell under a proxy at `proxy` (node spacings along t1, t2).
  std::array<int, 2> CellOf(const std::array<double, 2>& proxy) const;
  bool OverFaceOrWall(const std::array<double, 2>& proxy) const;
  // Whether the proxy sits against a wall's foot along tangent `tangent` (0: t1, 1: t2), the way
  // `direction`'s sign says.
  bool AgainstWall(int tangent, double direction) const;
  // Moves the proxy towards `target`, stopping at the foot of any wall on the way.
  void SlideTowards(std::array<double, 2> target) noexcept;
  // Coulomb friction on the tangential pull of the offset `d` (tool − surface, m) at `depth`:
  // sticks, or slides the proxy towards the tool (SlideTowards); catching up after a wall stopped
  // holding, by at most `tool_shed_m` (what the tool's motion since the last Update sheds: how
  // far it moved, and μ_k times how far it rose) plus kSlideCatchUp_n of the force rendered at
  // the surface's compliance over `corners` (Compliance). Returns whether it slid.
  bool SlideByFriction(const std::array<double, 3>& d, double depth, double tool_shed_m,
                       const Patch& corners, std::span<const double> compliance) noexcept;
  // A wall let go of the proxy's pull and it is still catching up with the tool.
  bool CatchingUp() const noexcept { return let_go_[0] || let_go_[1]; }
  // No wall holds the proxy, none let go of it (it left the region, or the face).
  void ForgetWalls() noexcept;
  // In contact: the spring's push at offset `d` (tool − surface, m) over `corners`, taken at the
  // step's end, written to `loads` and `result` (what walls hold of it too).
  void Push(const Patch& corners, const std::array<double, 3>& d,
            std::span<const double> compliance, std::span<double> loads, Result* result) noexcept;
  // Out of contact (the tool above the face's plane): whether the tool is past a wall's foot the
  // proxy is held at, or over a wall, and the contact lets go (`result`: left_surface, and
  // into_wall_m over a wall).
  bool LetGoAboveTheFace(const std::array<double, 3>& tool_m, Result* result) const noexcept;
  // Σ w²·c over the patch's pushed nodes: how far a push moves the surface point, m/N.
  double Compliance(const Patch& patch, std::span<const double> compliance) const noexcept;
  // Whether every node of the patch has its displacement in the state vector (ProxySurface::dof),
  // and whether every one is pushable or held (ProxySurface::loadable ≥ 0).
  bool Readable(const Patch& patch) const;
  bool Reachable(const Patch& patch) const;
  // Whether the face cells around node (i1, i2) of the plane are exposed: any one, or `every`.
  bool OnFace(int i1, int i2, bool every) const;

  ProxySurface surface_;
  ContactSettings contact_;
  int axis_ = 2, sign_ = 1, plane_ = 0, t1_ = 0, t2_ = 1;
  std::array<double, 3> start_m_{};
  std::array<double, 2> proxy_{};  // along t1, t2 in node spacings
  // The tool at the last Update, the same way (NaN before the first: no bound on that slide).
  std::array<double, 2> last_tool_{std::numeric_limits<double>::quiet_NaN(),
                                   std::numeric_limits<double>::quiet_NaN()};
  double reach_ = 1;               // the tip's radius in node spacings, at least one
  bool sliding_ = false;
  std::array<bool, 2> wall_held_{};  // along t1, t2: a wall held the pull at the last slide
  std::array<bool, 2> let_go_{};     // … and has let it go since: the proxy catches up
  double last_depth_m_ = std::numeric_limits<double>::quiet_NaN();  // the tool's, last in contact
  Patch pushed_;  // the nodes and weights the last Update pushed (count 0: none)
  std::vector<int> loaded_dofs_;
  std::vector<int> slot_of_node_;  // index into the loaded nodes, −1 if not loaded
  double lightest_mass_kg_ = 0;
};

/**
 * One step of a region or object pushed by a proxy (RegionIntegrator::Step with an
 * EndOfStepLoad): the proxy touched with the tool at `tool_m` on the state at the step's end.
 * The result is the last step's.
 */
class ProxyPush final : public EndOfStepLoad {
 public:
  ProxyPush(ProxyContact& proxy, const std::array<double, 3>& tool_m)
      : proxy_(proxy), tool_m_(tool_m) {}
  void Load(const Eigen::VectorXd& predicted, std::span<const double> compliance,
            std::span<double> load) noexcept override {
    touch = proxy_.Update(tool_m_, predicted, compliance, load);
  }
  ProxyContact::Result touch;

 private:
  ProxyContact& proxy_;
  std::array<double, 3> tool_m_;
};

}  // namespace hapticsim
