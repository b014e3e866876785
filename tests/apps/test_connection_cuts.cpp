// The rule for connections under cuts (apps/connections.hpp, docs/connect.md): after every
// topology edit each connection's nodes are taken again from the model elements its sides were
// built on; a connection is kept (on the nodes its elements now have) when every such element
// is alive and the two sides still share the joint's nodes, and removed otherwise. So a cut
// that separates the sides removes the connection, one elsewhere renames it onto the particles
// it duplicated, and none is left dangling. Random plane cuts through a block with three shells
// joined to it and to each other keep the map valid, lose exactly the removed connections' and
// retired hinges' energy, and keep the forces the energy's gradient.
#include <doctest/doctest.h>

#include <algorithm>
#include <cmath>
#include <map>
#include <memory>
#include <random>
#include <set>

#include "sewn/apps/connections.hpp"
#include "sewn/apps/continuum.hpp"
#include "sewn/io/cleanup.hpp"
#include "sewn/refine/cut.hpp"

#include "force_check.hpp"

namespace test_connection_cuts {
namespace {

using sewn::app::test::force_error;
using sewn::physics::Index;

// A block of 2 × 2 × 1 cubes of 0.1 m (tetrahedra); flap A, two squares of triangles, hanging
// from its bottom front edge (shell–solid curve connections); flap B, two triangles touching
// the block's bottom back corner by one node (a shell–solid point connection); flap C, two
// triangles hanging from flap A's bottom middle node (a shell–shell point connection).
sewn::IndexedMesh block_and_flaps() {
  sewn::GridSpec g;
  g.spacing = {0.1, 0.1, 0.1};
  sewn::IndexedMesh m = sewn::tet_grid(2, 2, 1, sewn::TetSplit::kuhn6, g);
  // grid point (i, j, k) = i + 3(j + 3k): the bottom front edge is 0, 1, 2; the back corner 8
  const std::uint32_t a = m.num_points();
  for (int i = 0; i < 3; ++i) m.points.push_back({0.1 * i, 0.0, -0.1});
  m.add_cell(sewn::CellType::triangle, {0, 1, a + 1}, 2);
  m.add_cell(sewn::CellType::triangle, {0, a + 1, a}, 2);
  m.add_cell(sewn::CellType::triangle, {1, 2, a + 2}, 2);
  m.add_cell(sewn::CellType::triangle, {1, a + 2, a + 1}, 2);
  const std::uint32_t b = m.num_points();
  m.points.push_back({0.28, 0.24, -0.04});
  m.points.push_back({0.24, 0.28, -0.06});
  m.points.push_back({0.3, 0.3, -0.12});
  m.add_cell(sewn::CellType::triangle, {8, b, b + 1}, 3);
  m.add_cell(sewn::CellType::triangle, {b, b + 2, b + 1}, 3);
  const std::uint32_t c = m.num_points();
  m.points.push_back({0.05, -0.02, -0.18});
  m.points.push_back({0.13, 0.02, -0.18});
  m.points.push_back({0.1, 0.0, -0.26});
  m.add_cell(sewn::CellType::triangle, {a + 1, c, c + 1}, 4);
  m.add_cell(sewn::CellType::triangle, {c, c + 2, c + 1}, 4);
  return m;
}

struct Joined {
  sewn::IndexedMesh mesh = block_and_flaps();
  std::vector<sewn::physics::MaterialParams> materials{{1e6, 0.3, 1000, 0.002, 1e-4, sewn::physics::ElongatedPolicy::refuse}};
  std::unique_ptr<sewn::physics::MssModel<3>> model;
  sewn::app::ContinuumParts parts;
  sewn::app::ConnectionParts joints;

  Joined() {
    sewn::app::Scene s;
    s.file = "cuts.json";
    s.model = "mixed";
    s.damping = "none";
    s.integrator = "newton";
    s.cuts.push_back({});  // cuts are scheduled: the builders must accept them
    s.cuts.back().type = "plane";
    s.connections.enabled = true;
    s.bending = "hinge";  // the shell bending that follows cuts (patch bending refuses them)
    sewn::physics::MssOptions mo;
    mo.gravity.setZero();
    mo.damping = sewn::physics::DampingModel::none;
    model = std::make_unique<sewn::physics::MssModel<3>>(mesh, materials, std::vector<std::uint32_t>{}, mo);
    const auto models = sewn::app::cell_models(mesh, sewn::io::embedded_cells(mesh), s, "m");
    parts = sewn::app::build_continuum(s, materials, mesh, models, std::vector<int>(mesh.num_cells(), -1), *model);
    joints = sewn::app::build_connections(s, mesh, models, materials, parts, *model);
  }
  void deform(std::mt19937& rng, double amount) {
    std::uniform_real_distribution<double> u(-amount, amount);
    for (Index i = 0; i < model->nodes().size(); ++i)
      model->nodes().set_position(i, model->nodes().position(i) + Eigen::Vector3d(u(rng), u(rng), u(rng)));
  }
  // Each connection's energy now, by name.
  [[nodiscard]] std::map<std::string, double> connection_energies() const {
    const auto s = model->system().state();
    std::map<std::string, double> e;
    for (Index c = 0; c < joints.points->size(); ++c) e[joints.points->connection(c).name()] = joints.points->evaluate(c, s).energy;
    for (Index c = 0; c < joints.curves->size(); ++c) e[joints.curves->connection(c).name()] = joints.curves->evaluate(c, s).energy;
    return e;
  }
  [[nodiscard]] std::vector<double> hinge_energies() const { return sewn::app::test::hinge_energies(parts, *model); }
  // `nodes` are all corners of one live element.
  [[nodiscard]] bool on_live_element(const std::vector<Index>& nodes) const {
    for (Index e = 0; e < model->elements().size(); ++e) {
      if (!model->elements()[e].alive) continue;
      const auto en = model->element_nodes(e);
      if (std::all_of(nodes.begin(), nodes.end(), [&](Index n) { return std::find(en.begin(), en.end(), n) != en.end(); })) return true;
    }
    return false;
  }
  // No connection dangles: a point connection's sides (a triangle's 3 nodes, a tet's 4) are each
  // on a live element and share the joint; a curve connection's edge with each apex is a face
  // of a live element.
  [[nodiscard]] bool connections_on_elements() const {
    for (Index c = 0; c < joints.points->size(); ++c) {
      const auto& pc = joints.points->connection(c);
      const auto& n = pc.position_nodes();
      // a triangle side has 3 nodes, a tet side 4; with 7 either may come first
      bool ok = false;
      for (std::size_t first : {std::size_t{3}, std::size_t{4}}) {
        if (n.size() - first < 3 || n.size() - first > 4) continue;
        const std::vector<Index> m_side(n.begin(), n.begin() + static_cast<std::ptrdiff_t>(first)),
            n_side(n.begin() + static_cast<std::ptrdiff_t>(first), n.end());
        ok = ok || (on_live_element(m_side) && on_live_element(n_side) && m_side[0] == pc.joint() && n_side[0] == pc.joint());
      }
      if (!ok) return false;
    }
    for (Index c = 0; c < joints.curves->size(); ++c) {
      const auto& n = joints.curves->connection(c).stencil_nodes();
      for (std::size_t k = 2; k < n.size(); ++k)
        if (!on_live_element({n[0], n[1], n[k]})) return false;
    }
    return true;
  }
};

TEST_CASE("connections under cuts: built on the block and flaps, two points and two curve edges") {
  Joined j;
  REQUIRE(j.joints.points != nullptr);
  REQUIRE(j.joints.curves != nullptr);
  CHECK(j.joints.point_joints == 2);
  CHECK(j.joints.curve_joints == 2);
  CHECK(j.connections_on_elements());
}

// Each connection's stencil nodes, by name.
std::map<std::string, std::vector<Index>> connection_nodes(const Joined& j) {
  std::map<std::string, std::vector<Index>> out;
  for (Index c = 0; c < j.joints.points->size(); ++c) out[j.joints.points->connection(c).name()] = j.joints.points->connection(c).position_nodes();
  for (Index c = 0; c < j.joints.curves->size(); ++c) out[j.joints.curves->connection(c).name()] = j.joints.curves->connection(c).stencil_nodes();
  return out;
}

TEST_CASE("connections under cuts: a cut away from the joints keeps them as they are; one through a joint's node follows the rule") {
  Joined j;
  std::mt19937 rng(5);
  j.deform(rng, 0.004);
  sewn::physics::System& sys = j.model->system();
  auto nodes0 = connection_nodes(j);
  const auto energies0 = j.connection_energies();
  // y = 0.1: between the block's front and back cubes; no joint is there (a tet side's other
  // corners may be, and move onto copies): every connection is kept, with its energy
  (void)sewn::refine::cut(*j.model, sewn::refine::facets_across_plane(*j.model, Eigen::Vector3d(0, 0.1, 0), Eigen::Vector3d(0, 1, 0)));
  CHECK(j.model->map().validate().ok());
  CHECK(j.connections_on_elements());
  CHECK(j.connection_energies() == energies0);
  for (const auto& [name, nodes] : connection_nodes(j)) CHECK(nodes.front() == nodes0.at(name).front());
  // x = 0.1: through node 1, the middle of the flap's joint line, splitting both the block and
  // the flap there; each curve edge is kept exactly if its flap triangle and its block faces
  // still share both its nodes (on_live_element), else removed
  const double e0 = sys.potential_energy();
  const std::vector<double> hinges_before = j.hinge_energies();
  nodes0 = connection_nodes(j);
  (void)sewn::refine::cut(*j.model, sewn::refine::facets_across_plane(*j.model, Eigen::Vector3d(0.1, 0, 0), Eigen::Vector3d(1, 0, 0)));
  CHECK(j.model->map().validate().ok());
  CHECK(j.connections_on_elements());
  const auto nodes1 = connection_nodes(j);
  const auto energies1 = j.connection_energies();
  CHECK(nodes1 != nodes0);  // node 1 was duplicated: a curve edge was renamed onto a copy or removed
  double lost = 0;
  for (const auto& [name, e] : energies0)
    if (!energies1.count(name)) lost += e;
  for (Index h = 0; h < hinges_before.size(); ++h)
    if (!j.parts.hinges->is_alive(h)) lost += hinges_before[h];
  CHECK(std::abs(sys.potential_energy() - (e0 - lost)) <= 1e-12 * e0);
}

TEST_CASE("connections under cuts: random plane cuts keep the map valid, no connection dangling, energy and forces exact") {
  std::size_t removed_total = 0, kept_total = 0;
  for (std::uint32_t seed = 1; seed <= 8; ++seed) {
    CAPTURE(seed);
    Joined j;
    std::mt19937 rng(seed);
    std::uniform_real_distribution<double> u(-1, 1);
    sewn::physics::System& sys = j.model->system();
    for (int k = 0; k < 3; ++k) {
      j.deform(rng, 0.003);
      const double e0 = sys.potential_energy();
      const auto before = j.connection_energies();
      const std::vector<double> hinges_before = j.hinge_energies();
      const Eigen::Vector3d normal = Eigen::Vector3d(u(rng), u(rng), u(rng)).normalized();
      const Eigen::Vector3d point(0.15 + 0.1 * u(rng), 0.1 + 0.1 * u(rng), -0.05 + 0.1 * u(rng));
      (void)sewn::refine::cut(*j.model, sewn::refine::facets_across_plane(*j.model, point, normal));
      CHECK(j.model->map().validate().ok());
      CHECK(j.connections_on_elements());
      // kept connections keep their energy (renamed onto copies at the same place); the energy
      // lost is exactly the removed connections' and the retired hinges'
      const auto after = j.connection_energies();
      double lost = 0;
      for (const auto& [name, e] : before) {
        if (!after.count(name)) {
          lost += e;
          ++removed_total;
        } else {
          CHECK(after.at(name) == doctest::Approx(e).epsilon(1e-12));
        }
      }
      kept_total += after.size();
      for (Index h = 0; h < hinges_before.size(); ++h)
        if (!j.parts.hinges->is_alive(h)) lost += hinges_before[h];
      CHECK(std::abs(sys.potential_energy() - (e0 - lost)) <= 1e-12 * e0);
      // forces are the energy's gradient: at every node a connection holds, and the newest
      for (Index c = 0; c < j.joints.points->size(); ++c)
        for (Index n : j.joints.points->connection(c).position_nodes()) CHECK(force_error(*j.model, n) <= 1e-6);
      for (Index c = 0; c < j.joints.curves->size(); ++c)
        for (Index n : j.joints.curves->connection(c).stencil_nodes()) CHECK(force_error(*j.model, n) <= 1e-6);
      CHECK(force_error(*j.model, j.model->nodes().size() - 1) <= 1e-6);
    }
  }
  // the sequences exercised both branches of the rule (7 removals, 77 kept measured)
  CHECK(removed_total > 0);
  CHECK(kept_total > 0);
}

TEST_CASE("connections under piercing: a side pierced away removes its connection before the particles are compacted") {
  std::size_t removed_total = 0;
  for (std::uint32_t seed = 1; seed <= 6; ++seed) {
    CAPTURE(seed);
    Joined j;
    std::mt19937 rng(seed);
    j.deform(rng, 0.003);
    const std::size_t before = j.connection_energies().size();
    // three live elements at random, removed: the model then compacts its particles, and every
    // term's node check refuses anything left on a removed particle
    std::vector<Index> live;
    for (Index e = 0; e < j.model->elements().size(); ++e)
      if (j.model->elements()[e].alive) live.push_back(e);
    std::shuffle(live.begin(), live.end(), rng);
    live.resize(3);
    (void)sewn::refine::pierce(*j.model, live, true);
    CHECK(j.model->map().validate().ok());
    CHECK(j.connections_on_elements());
    removed_total += before - j.connection_energies().size();
    for (Index c = 0; c < j.joints.points->size(); ++c)
      for (Index n : j.joints.points->connection(c).position_nodes()) CHECK(force_error(*j.model, n) <= 1e-6);
    for (Index c = 0; c < j.joints.curves->size(); ++c)
      for (Index n : j.joints.curves->connection(c).stencil_nodes()) CHECK(force_error(*j.model, n) <= 1e-6);
  }
  CHECK(removed_total > 0);
}

}  // namespace
}  // namespace test_connection_cuts
