#include "continuum_models.hpp"

#include <array>
#include <string>
#include <vector>

#include "sewn/physics/shells/shell_terms.hpp"
#include "sewn/physics/solids/tets.hpp"

namespace sewn::app::detail {

using physics::Index;
using Vec3d = Eigen::Vector3d;

namespace {

// Checks what a continuum model cannot take and removes the springs it replaces.
void drop_springs(const Scene& scene, physics::MssModel<3>& model) {
  const std::string m = "model \"" + scene.model + "\"";
  if (!scene.cuts.empty()) throw SceneError(scene.file, "cuts", "cutting is not supported with " + m + " yet");
  if (scene.damping == "viscous")
    throw SceneError(scene.file, "damping.model", "\"viscous\" is per-spring damping, which " + m + " has none of: use \"rayleigh\" (alpha) or \"none\"");
  if (scene.damping == "rayleigh" && scene.rayleigh_beta != 0.0)
    throw SceneError(scene.file, "damping.beta", "stiffness-proportional damping acts on springs, which " + m + " has none of: use alpha");
  physics::Springs& springs = model.springs();
  for (Index s = 0; s < springs.size(); ++s)
    if (springs.is_alive(s)) springs.remove(s);
}

}  // namespace

void use_shell_model(const Scene& scene, const std::vector<physics::MaterialParams>& materials, const IndexedMesh& mesh,
                     physics::MssModel<3>& model) {
  drop_springs(scene, model);
  auto& membranes = model.system().add<physics::shells::Membranes>();
  std::vector<std::array<Index, 3>> triangles;
  std::vector<double> k_b;
  for (const auto& el : model.elements()) {
    if (!el.alive) continue;
    const auto cell = mesh.cell(el.mesh_cell);
    if (el.kind != physics::ElementKind::triangle || cell.size() != 3)
      throw SceneError(scene.file, "model.type", "\"shell\" needs triangles only, but mesh cell " + std::to_string(el.mesh_cell) +
                                                     " has " + std::to_string(cell.size()) + " points (use a tri_grid or a triangle mesh file)");
    std::array<Index, 3> nodes{};
    physics::shells::TriPositions X;
    for (int a = 0; a < 3; ++a) {
      nodes[a] = model.node_of_point(cell[a]);
      X.col(a) = model.rest_position(nodes[a]);
    }
    const auto& mat = materials[el.material];
    membranes.add(nodes, X, mat.young, mat.poisson, mat.thickness);
    triangles.push_back(nodes);
    k_b.push_back(physics::shells::hinge_stiffness(mat.young, mat.poisson, mat.thickness));
  }
  std::vector<double> rest_x;
  for (Index i = 0; i < model.nodes().size(); ++i) {
    const Vec3d p = model.rest_position(i);
    rest_x.insert(rest_x.end(), {p.x(), p.y(), p.z()});
  }
  try {
    model.system().add<physics::shells::Hinges>().add_interior_edges(triangles, rest_x, k_b);
  } catch (const physics::InputError& e) {
    throw SceneError(scene.file, "meshes", e.what());
  }
}

void use_solid_model(const Scene& scene, const std::vector<physics::MaterialParams>& materials, const IndexedMesh& mesh,
                     physics::MssModel<3>& model) {
  drop_springs(scene, model);
  auto& tets = model.system().add<physics::solids::Tets>(scene.law == "stvk" ? physics::solids::TetLaw::stvk
                                                                                  : physics::solids::TetLaw::stable_neo_hookean);
  for (const auto& el : model.elements()) {
    if (!el.alive) continue;
    const auto cell = mesh.cell(el.mesh_cell);
    if (el.kind != physics::ElementKind::tetrahedron || cell.size() != 4)
      throw SceneError(scene.file, "model.type", "\"solid\" needs tetrahedra only, but mesh cell " + std::to_string(el.mesh_cell) +
                                                     " has " + std::to_string(cell.size()) + " points (use a tet_grid or a tetrahedral mesh file)");
    std::array<Index, 4> nodes{};
    physics::solids::TetPositions X;
    for (int a = 0; a < 4; ++a) {
      nodes[a] = model.node_of_point(cell[a]);
      X.col(a) = model.rest_position(nodes[a]);
    }
    const auto& mat = materials[el.material];
    tets.add(nodes, X, mat.young, mat.poisson);
  }
}


}  // namespace sewn::app::detail
