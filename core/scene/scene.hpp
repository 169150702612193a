#pragma once

#include <array>
#include <memory>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "core/fem/material.hpp"
#include "core/geometry/label_volume.hpp"

namespace hapticsim {

/** How the device drives the contact node along its face's inward normal (+z on the front). */
enum class Waveform {
  kPress,  ///< s·(1 − cos 2πft)/2: a smooth press into the object and back, no velocity jump
  kSine,   ///< s·sin 2πft: in and out of the object around the rest position
  /// A tool stroked across the surface: pressed s deep in the first quarter of the trial, then
  /// moved input.stroke_length along input.stroke_direction, touching through a sliding
  /// (god-object) contact with friction ([contact]) instead of a node it sticks to.
  kStroke,
};

/** Lattice indices (ix, iy, iz) of a node of the cube. */
using LatticeIndex = std::array<int, 3>;

struct MeshSettings {
  int nodes = 13;        ///< nodes per axis of the cube (mesh.nodes)
  double edge_m = 0.25;  ///< cube edge length, m (mesh.edge)
};

/**
 * Where the object's shape comes from (geometry.*): the paper's cube of mesh.*, or a file — a
 * labelled NIfTI volume or a closed STL/OBJ surface — voxelised on a lattice of spacing_m.
 */
struct GeometrySettings {
  std::string file;         ///< geometry.file; "" = the built-in cube
  double spacing_m = 0;     ///< geometry.spacing_m, m; 0 = a NIfTI volume's own voxel edge
  double mesh_unit_m = 1;   ///< geometry.mesh_unit: metres per unit of an STL/OBJ file

  bool from_file() const { return !file.empty(); }
  bool operator==(const GeometrySettings&) const = default;
};

/** A [[material]] table: the material of every voxel labelled `label` (the cube is label 1). */
struct LabelMaterial {
  int label = 1;
  Material material;
};

/**
 * A [[support]] table: the object's nodes it holds fixed, chosen by one of three selectors in
 * the geometry's own frame (a file's coordinates; the cube's, front face z = 0), metres.
 */
struct SupportRegion {
  enum class Kind {
    kLabel,  ///< every node of the voxels labelled `label` (a bone, a frame the tissue is glued to)
    kBox,    ///< every node inside the box [box_min_m, box_max_m]
    kPlane,  ///< every node within half a voxel of the plane through point_m, normal to `normal`
  };
  Kind kind = Kind::kLabel;
  int label = 0;
  std::array<double, 3> box_min_m{}, box_max_m{};
  std::array<double, 3> point_m{}, normal{};

  bool operator==(const SupportRegion&) const = default;
};

/** A geometry file read and voxelised, with the settings it was made from. */
struct LoadedGeometry {
  GeometrySettings source;
  LabelVolume voxels;  ///< cropped to the labelled voxels
};

struct InputSettings {
  double amplitude_m = 0.01;             ///< s, m (input.amplitude)
  double frequency_hz = 1.0;             ///< f, Hz (input.frequency)
  Waveform waveform = Waveform::kPress;  ///< input.waveform
  double periods = 1.0;                  ///< trial length in periods of f (input.periods)
  /// The driven surface node (input.contact_node); none: the paper's, the middle node of the
  /// front face. It moves along the inward normal of its face (see InwardNormal).
  std::optional<LatticeIndex> contact_node;
  double stroke_length_m = 0.03;  ///< how far a stroke moves along the surface (input.stroke_length)
  /// The lattice axis a stroke moves along, 0 x, 1 y, 2 z, and its sign (input.stroke_direction)
  int stroke_axis = 0;
  int stroke_sign = 1;
};

/** How hapticsimd's contact meets the device's tool (contact.model). */
enum class ContactModel {
  kNode,   ///< the paper's: the touched surface node follows the tool tip, stuck until lift-off
  kProxy,  ///< a tool that slides: a proxy on the surface, a spring and friction (as a stroke)
};

/**
 * The sliding contact of a stroke, and of hapticsimd's tool with contact.model = "proxy"
 * (contact.*): the tool touches the surface through a proxy that stays on it, joined to the tool
 * by a spring; the proxy sticks until the spring's tangential pull exceeds static_friction × its
 * normal push, then slides keeping it at kinetic_friction ×.
 */

struct ContactSettings {
  ContactModel model = ContactModel::kNode;  ///< hapticsimd's contact (contact.model)
  double static_friction = 0.5;      ///< μ_s (contact.static_friction)
  double kinetic_friction = 0.4;     ///< μ_k ≤ μ_s (contact.kinetic_friction)
  double stiffness_n_per_m = 1000;   ///< the proxy spring (contact.stiffness), N/m
  /// The tool tip's radius (contact.radius), m: the spring's push spread over the face nodes
  /// within it; 0, or less than a lattice spacing: the face cell under the proxy (bilinear).
  double radius_m = 0;
};

struct SolverSettings {
  double dt_s = 1e-3;  ///< time step, s (solver.dt)
};

/**
 * Asynchronous regions (the paper's adaptivity parameters). primary_size = 0 switches them off:
 * the whole object is then solved on the finest mesh at the primary rate (the reference).
 */
struct AdaptivitySettings {
  int primary_size = 0;   ///< nodes from the contact in every direction (adaptivity.primary_size)
  int secondary_lod = 2;  ///< secondary spacing factor k (adaptivity.secondary_lod)
  double secondary_rate_hz = 600;  ///< secondary region rate, Hz (adaptivity.secondary_rate)
  int support_layers =
      1;  ///< coarse cells refined around each fixed node (adaptivity.support_layers)
  int secondary_regions =
      1;                ///< nested secondary shells, one thread each (adaptivity.secondary_regions)
  int shell_cells = 1;  ///< thickness of each inner shell, coarse cells (adaptivity.shell_cells)
  double outer_rate_hz = 600;  ///< rate of the shells beyond the first, Hz (adaptivity.outer_rate)
  /// What the primary sends the secondary for the interface (adaptivity.coupling):
  /// true = its displacements next to Γ ("displacement", the default), false = its Γ forces.
  bool displacement_coupling = true;

  bool enabled() const { return primary_size > 0; }
};

/**
 * Everything that defines a simulation trial. The defaults are the paper's scene: a cube of
 * edge 0.25 m with 13×13×13 nodes, the four back-face corners fixed, the middle node of the
 * front face driven by a 1 cm press at 1 Hz for one period, E = 10 kPa, ν = 0.45,
 * ρ = 1000 kg/m³, d = 10 1/s, dt = 1 ms.
 */
struct Scene {
  GeometrySettings geometry;
  /// The geometry file's voxels once read (scene files do it; LoadSceneGeometry); null for the cube.
  std::shared_ptr<const LoadedGeometry> loaded_geometry;
  MeshSettings mesh;
  Material material;  ///< every voxel's, unless `materials` names them per label
  std::vector<LabelMaterial> materials;  ///< [[material]] tables
  std::vector<SupportRegion> supports;   ///< [[support]] tables; none: the cube's four back corners
  InputSettings input;
  ContactSettings contact;
  SolverSettings solver;
  AdaptivitySettings adaptivity;

  /** Trial length in seconds: periods / frequency. */
  double duration_s() const { return input.periods / input.frequency_hz; }
  /** Number of time steps in the trial (the duration rounded to whole steps). */
  long num_steps() const;
};

std::string_view WaveformName(Waveform waveform);
/** Whether the tool touches `scene`'s object through a sliding proxy: a stroke always does, and
 *  hapticsimd's device does with contact.model = "proxy". */
bool UsesProxyContact(const Scene& scene);

/** The shortest text that reads back to exactly `value` ("10000.0", "0.45", "1e-05"). */
std::string FormatReal(double value);

/** Three reals as a TOML array that reads back to them: "[0.0, 0.125, 1e-05]". */
std::string FormatTriple(const std::array<double, 3>& values);

/**
 * One settable scene key ("section.key"). The table of keys is the single source of truth for
 * scene files, --set overrides, printing and validation.
 */
struct SceneKeyInfo {
  std::string_view name;     ///< e.g. "material.poisson_ratio"
  std::string_view unit;     ///< SI unit, or "" when dimensionless
  std::string_view allowed;  ///< the allowed range, as a message fragment
  std::string_view meaning;  ///< one line for --help and docs
};

/** All keys, in the order they are printed. */
const std::vector<SceneKeyInfo>& SceneKeys();

/**
 * Sets `key` from its textual value (as given to --set or read from a scene file).
 * @throws Error naming the key when the key is unknown, the text is not a value of the key's
 *         type, or the value is outside the key's allowed range.
 */
void SetSceneValue(Scene* scene, std::string_view key, std::string_view value_text);

/** The value of `key` as text that SetSceneValue() reads back to the same value. */
std::string GetSceneValue(const Scene& scene, std::string_view key);

/**
 * Checks every key's range and the relations between keys, and each [[material]] and [[support]]
 * table; with the geometry loaded, that its labels and the tables' agree.
 * @throws Error with one message naming the key and its allowed range.
 */
void ValidateScene(const Scene& scene);

/**
 * The paper's contact: the middle node of the front face (z = 0); with an even node count, the
 * one just below the centre in x and y. The one definition every model of the cube uses.
 */
LatticeIndex CubeContactNode(const MeshSettings& mesh);

/** The paper's supports: the four corner nodes of the back face (z = edge). */
std::array<LatticeIndex, 4> CubeSupportNodes(const MeshSettings& mesh);

/** The scene's driven node: input.contact_node, or the paper's (CubeContactNode). */
LatticeIndex ContactNode(const Scene& scene);

/** True for a node on the cube's surface (some index 0 or nodes − 1). */
bool IsSurfaceNode(const MeshSettings& mesh, const LatticeIndex& node);

/** True for one of the fixed back-face corners. */
bool IsSupportNode(const MeshSettings& mesh, const LatticeIndex& node);

/**
 * Why `node` cannot be the driven node of `mesh` — "is outside the mesh: …", "is inside the
 * object: …", "is a fixed back corner: …" (only with `corners_held`: the default supports, no
 * [[support]] tables) — or "" when it can (ValidateScene's check).
 */
std::string ContactNodeProblem(const MeshSettings& mesh, const LatticeIndex& node,
                               bool corners_held = true);

/**
 * The unit inward normal of the face a surface node lies on. Nodes on an edge or a corner belong
 * to the first of their faces in the order front/back (z), left/right (x), bottom/top (y): the
 * paper presses along z, so the front face wins.
 */
std::array<double, 3> InwardNormal(const MeshSettings& mesh, const LatticeIndex& node);

/** The primary region's rate 1/solver.dt, Hz. */
double PrimaryRateHz(const Scene& scene);

/**
 * True when a primary box of `primary_size` nodes around the scene's contact node, refined in whole
 * coarse cells of adaptivity.secondary_lod, would cover every cell of the object.
 */
bool PrimaryBoxCoversObject(const Scene& scene, int primary_size);

}  // namespace hapticsim
