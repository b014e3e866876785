#pragma once
// Scene files: what to simulate, read from JSON and validated against one schema
// (scene_schema()), which also generates docs/scenes.md.

#include <array>
#include <map>
#include <optional>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "sewn/apps/connection_keys.hpp"
#include "sewn/apps/motion_keys.hpp"
#include "sewn/apps/obstacle_keys.hpp"
#include "sewn/apps/schema.hpp"
#include "sewn/physics/solve/linear_solver.hpp"

namespace sewn::app {

using Vec3 = std::array<double, 3>;

/// How scene keys number mesh points (`points` selectors, cuts' faces and particles), for their
/// documentation and the messages about them.
inline constexpr const char* point_numbering =
    "from 0, over the scene's meshes in order (a mesh's `regions`: over that mesh alone), each mesh's points in its "
    "file's order without those no cell uses";

/// Where a rule applies: points (or cells, by their centroid) inside a region, or a mesh tag.
struct Selector {
  enum class Type { all, box, sphere, tag, points } type = Type::all;
  Vec3 min{}, max{};       // box
  Vec3 center{};           // sphere
  double radius = 0;       // sphere
  int tag = 0;             // tag
  std::vector<std::uint32_t> points;  // points: mesh point indices
  [[nodiscard]] bool contains(const Vec3& p) const;
};

struct MaterialSpec {
  double young = 0, poisson = 0, density = 0;
  double thickness = 1;  // 2D cells: membrane thickness (m)
  double area = 0;       // 1D cells: cross-section (m²)
  std::string elongated = "refuse";  // Baudet edge stiffness < 0: "refuse", "clamp" or "split"
  double volume_stiffness = 0;   // bulk stiffness κ of the volume term (Pa), 0 for none
};

struct LatticeBoxSpec {
  std::array<int, 3> lo{}, hi{};
};

struct MeshSpec {
  std::string type;  // hex_grid, tet_grid, quad_grid, tri_grid, disc, cylinder, boxes, polyline, surface, file
  std::string name;
  std::string material;
  std::vector<std::pair<Selector, std::string>> regions;  // later rules win
  std::array<std::uint32_t, 3> cells{1, 1, 1};
  Vec3 size{1, 1, 1}, origin{0, 0, 0};
  std::string split = "kuhn6";  // tet_grid
  std::string plane = "xy";     // quad_grid, tri_grid, disc
  double radius = 0, height = 0;
  std::uint32_t rings = 0, sectors = 0, layers = 0;
  std::vector<Vec3> points;  // polyline
  std::vector<LatticeBoxSpec> boxes;  // boxes (size holds the lattice spacing)
  std::string path;          // file, surface (resolved against the scene's folder); surface: cells[0] along the longest side
  double scale = 1;
  Vec3 translate{0, 0, 0};
};

struct FixSpec {
  Selector where;
  std::array<bool, 3> axes{true, true, true};
};

/// Initial velocity of the free axes of the particles in `where` (at their rest positions x):
/// v = linear + angular × (x − center), a uniform motion plus a rigid rotation.
struct VelocitySpec {
  Selector where;
  Vec3 linear{0, 0, 0}, angular{0, 0, 0}, center{0, 0, 0};
};

struct CutSpec {
  std::string type;  // plane, faces, particles, pierce
  double time = 0;
  Vec3 point{}, normal{};                        // plane
  std::optional<Selector> within;                // plane: restrict to a region
  std::vector<std::vector<std::uint32_t>> faces; // faces: point indices of each face
  std::vector<std::uint32_t> particles;          // particles
  Selector where;                                // pierce: volumes whose centroid is inside
  bool remove = true;                            // pierce: remove the freed volumes
};

/// model.groups[k]: the cells of one mesh tag simulated as a solid, shell or rod, or a label.
/// The tag is given as a number, or as a Gmsh physical name that each mesh resolves through its
/// own $PhysicalNames (cell_models.hpp): two files may number the same name differently.
struct ModelGroup {
  int tag = 0;
  std::string name;                   // a Gmsh physical name; empty: select by `tag`
  std::string as;                     // solid, shell, rod, label
  std::array<double, 2> semi_axes{};  // rod section (a = b: circular); 0: from the material's area
};

/// One refinement criterion (docs/refinement.md): `diagonal_strain` (threshold, percent),
/// `strain_energy` (threshold, J/m³), `region` (where: box, sphere or all, at rest), `point`
/// (point, radius) or `contact` (with the scene's obstacles).
struct RefineCriterionSpec {
  std::string type;
  double threshold = 0;  // diagonal_strain, percent; strain_energy, J/m³
  Selector where;        // region
  Vec3 point{};          // point
  double radius = 0;     // point
};

/// Elements whose rest centroid is in `where`, refined `levels` times before the run.
struct PreRefineSpec {
  Selector where;
  std::uint32_t levels = 1;
};

/// Hierarchical adaptive refinement during the run (the 2014 paper; `refinement` key).
struct RefinementSpec {
  bool enabled = false;  // the key is present
  std::vector<RefineCriterionSpec> criteria;  // refine where any wants it
  std::uint32_t max_level = 3;                // as an index, 1 + log2 of the level
  std::vector<PreRefineSpec> pre_refine;
  bool coarsen = false;
  std::uint32_t calm_steps = 20;
  bool balance = false;  // 2:1 balance across edges and faces
  std::string t_junctions = "reduction";  // or "paper_projection"
  double max_elements = 0;  // live elements limits.memory allows (not a key: derived from it)
};

struct Scene {
  std::string file;  // where it was read from ("(default)" for the embedded scene)
  std::string skip;  // why `sewn run` skips the scene ("" if it runs): optional data not present
  std::string name, description;
  std::map<std::string, MaterialSpec> materials;
  std::vector<MeshSpec> meshes;
  std::vector<FixSpec> fixed;
  std::vector<VelocitySpec> velocities;  // later entries win
  std::vector<MotionSpec> motion;        // prescribed motions, each driving motion_where[k]
  std::vector<Selector> motion_where;
  Vec3 gravity{0, 0, -9.81};
  std::string model = "mass-spring", law = "stable_neo_hookean";  // model.type, model.law
  std::string bending = "patch";                                     // model.bending (shells)
  std::vector<ModelGroup> model_groups;                             // model.groups
  ConnectionsSpec connections;                                      // model.connections
  std::string damping = "viscous";
  double rayleigh_alpha = 0, rayleigh_beta = 0, environment_damping = 0;
  std::string integrator = "implicit";
  double step = 1e-3, duration = 1;
  std::string solver = "auto";
  double tolerance = physics::solve::default_tolerance;
  double absolute_tolerance = physics::solve::default_absolute_tolerance;
  double absolute_acceleration = physics::solve::default_absolute_acceleration;  // m/s², floor a step of h scales
  std::uint32_t max_iterations = physics::solve::default_max_iterations;
  double newton_tolerance = 1e-6;  // m/s, integrator "newton"
  std::uint32_t newton_iterations = 50;
  double newton_forcing = 0.0;  // largest relative CG tolerance, cholmod-pcg (0: off)
  bool allow_unstable = false;
  double energy_rise_tolerance = 1e-4;  // relative, see physics::EnergyLedger
  bool stop_on_inversion = false;       // check every step, stop at the first inverted element
  std::vector<CutSpec> cuts;
  std::uint32_t threads = 0;  // 0: SEWN_THREADS, else 1
  std::vector<ObstacleSpec> obstacles;
  RefinementSpec refinement;
  std::uint32_t frames = 50;
  bool write_vtu = true, write_csv = true, write_picture = true;
  std::string color_by = "displacement", style = "shaded";
  std::uint32_t width = 1280, height = 800;
};

/// The schema of a region key (`where`, `within`): all, box, sphere, tag or points.
Field selector_schema(std::string key, std::string doc);
/// Reads a validated region key.
Selector read_selector(const nlohmann::json& j, const Field& schema);

/// The schema of scene files (see docs/scenes.md, generated from it).
const Field& scene_schema();
/// Validates and reads a scene; throws SceneError naming file, key path and reason.
Scene parse_scene(const nlohmann::json& j, const std::string& file);
/// Reads a scene file (JSON); throws SceneError for unreadable files and JSON syntax errors too.
Scene load_scene(const std::string& path);
/// The embedded default scene: a cantilever beam sagging under gravity, cut part-way through.
const char* default_scene_json();
Scene default_scene();

}  // namespace sewn::app
