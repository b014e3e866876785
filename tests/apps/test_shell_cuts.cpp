// Cuts on shells: after refine::cut the membrane triangles follow the particles the cut
// duplicated, hinges whose two triangles still share their edge follow them, and hinges on a
// cut edge leave the Hinges term. A cut changes the energy by exactly the retired hinges' own
// at the state it is made in and no mass, keeps the map valid, leaves the pieces free of each
// other, and the forces stay the energy's gradient; random sequences of cuts keep all of it.
#include <doctest/doctest.h>

#include <algorithm>
#include <cmath>
#include <memory>
#include <random>
#include <set>

#include <Eigen/Geometry>

#include "sewn/apps/cell_models.hpp"
#include "sewn/apps/continuum.hpp"
#include "sewn/io/cleanup.hpp"
#include "sewn/refine/cut.hpp"

#include "force_check.hpp"

namespace test_shell_cuts {
namespace {

using sewn::app::test::force_error;
using sewn::physics::Index;

// A flat sheet of nx × ny squares of 0.1 m, two triangles each, in the plane z = 0.
struct ShellBody {
  sewn::IndexedMesh mesh;
  std::vector<sewn::physics::MaterialParams> materials{{1e7, 0.3, 1000, 0.002, 1e-4, sewn::physics::ElongatedPolicy::refuse}};
  std::unique_ptr<sewn::physics::MssModel<3>> model;
  sewn::app::ContinuumParts parts;

  ShellBody(std::uint32_t nx, std::uint32_t ny) {
    sewn::GridSpec g;
    g.spacing = {0.1, 0.1, 1.0};
    mesh = sewn::tri_grid(nx, ny, g);
    sewn::app::Scene s;
    s.file = "cuts.json";
    s.model = "shell";
    s.bending = "hinge";  // patch bending refuses cuts
    s.damping = "none";
    s.cuts.push_back({});  // cuts are scheduled: the builder must accept them
    s.cuts.back().type = "plane";
    sewn::physics::MssOptions mo;
    mo.gravity.setZero();
    mo.damping = sewn::physics::DampingModel::none;
    model = std::make_unique<sewn::physics::MssModel<3>>(mesh, materials, std::vector<std::uint32_t>{}, mo);
    parts = sewn::app::build_continuum(s, materials, mesh, sewn::app::cell_models(mesh, sewn::io::embedded_cells(mesh), s, "m"),
                                       std::vector<int>(mesh.num_cells(), -1), *model);
    REQUIRE(parts.membranes != nullptr);
    REQUIRE(parts.hinges != nullptr);
  }
  // Every particle moved by up to `amount` on each axis: the sheet stretches and bends.
  void deform(std::mt19937& rng, double amount) {
    std::uniform_real_distribution<double> u(-amount, amount);
    for (Index i = 0; i < model->nodes().size(); ++i)
      model->nodes().set_position(i, model->nodes().position(i) + Eigen::Vector3d(u(rng), u(rng), u(rng)));
  }
  // Each live hinge's energy now (0 for retired ones).
  [[nodiscard]] std::vector<double> hinge_energies() const { return sewn::app::test::hinge_energies(parts, *model); }
  // Every membrane sits on its model element's current corners (or left with it), and every
  // live hinge on two of those triangles: its edge's particles in both, its wings one in each.
  [[nodiscard]] bool terms_on_elements() const {
    for (Index k = 0; k < parts.element_of_membrane.size(); ++k) {
      // a membrane leaves its term exactly when its model element was pierced away
      if (parts.membranes->is_alive(k) != model->elements()[parts.element_of_membrane[k]].alive) return false;
      if (!parts.membranes->is_alive(k)) continue;
      const auto nodes = model->element_nodes(parts.element_of_membrane[k]);
      const auto& held = parts.membranes->element_nodes(k);
      if (!std::equal(held.begin(), held.end(), nodes.begin())) return false;
    }
    for (Index h = 0; h < parts.hinges->size(); ++h) {
      if (!parts.hinges->is_alive(h)) continue;
      const auto& n = parts.hinges->element_nodes(h);
      const auto& a = parts.membranes->element_nodes(parts.hinge_corners[h].a);
      const auto& b = parts.membranes->element_nodes(parts.hinge_corners[h].b);
      auto in = [](const auto& tri, Index v) { return std::find(tri.begin(), tri.end(), v) != tri.end(); };
      if (!in(a, n[0]) || !in(a, n[1]) || !in(a, n[2]) || !in(b, n[3]) || !in(b, n[1]) || !in(b, n[2])) return false;
    }
    return true;
  }
  [[nodiscard]] Index live_hinges() const {
    Index n = 0;
    for (Index h = 0; h < parts.hinges->size(); ++h) n += parts.hinges->is_alive(h) ? 1 : 0;
    return n;
  }
};

TEST_CASE("shell cut: the hinges of the cut edges leave, mass unchanged, the map valid, the two halves free") {
  ShellBody b(4, 2);
  std::mt19937 rng(3);
  b.deform(rng, 0.01);
  sewn::physics::System& sys = b.model->system();
  const double e0 = sys.potential_energy(), m0 = b.model->node_mass();
  const std::vector<double> before = b.hinge_energies();
  const Index hinges_before = b.live_hinges();
  REQUIRE(e0 > 0);
  const auto facets = sewn::refine::facets_across_plane(*b.model, Eigen::Vector3d(0.2, 0, 0), Eigen::Vector3d(1, 0, 0));
  REQUIRE(facets.size() == 2);  // the two vertical edges of the line x = 0.2
  const Index nodes_before = b.model->nodes().size();
  (void)sewn::refine::cut(*b.model, facets);
  sewn::app::follow_cut(b.parts, *b.model);
  CHECK(b.model->map().validate().ok());
  CHECK(b.model->nodes().size() == nodes_before + 3);
  CHECK(b.model->springs().num_alive() == 0);
  CHECK(b.terms_on_elements());
  CHECK(b.live_hinges() == hinges_before - 2);
  // the energy lost is exactly what the two retired hinges held
  double retired = 0;
  for (Index h = 0; h < before.size(); ++h)
    if (!b.parts.hinges->is_alive(h)) retired += before[h];
  REQUIRE(retired > 0);
  CHECK(std::abs(sys.potential_energy() - (e0 - retired)) <= 1e-12 * e0);
  CHECK(std::abs(b.model->node_mass() - m0) <= 1e-12 * m0);
  // the right half moved and turned away rigidly costs nothing: no membrane or hinge joins them
  std::set<Index> left, right;
  for (Index e = 0; e < b.model->elements().size(); ++e)
    for (Index n : b.model->element_nodes(e)) (b.model->element_centroid(e).x() < 0.2 ? left : right).insert(n);
  for (Index n : right) CHECK(left.count(n) == 0);
  const double e1 = sys.potential_energy();
  const Eigen::Matrix3d R = Eigen::AngleAxisd(0.4, Eigen::Vector3d(0, 1, 0)).toRotationMatrix();
  for (Index n : right) b.model->nodes().set_position(n, R * b.model->nodes().position(n) + Eigen::Vector3d(0.05, -0.02, 0.03));
  CHECK(std::abs(sys.potential_energy() - e1) <= 1e-9 * e1);
}

TEST_CASE("shell cut: random sequences of plane cuts keep the map valid, energy, mass and forces") {
  for (std::uint32_t seed = 1; seed <= 6; ++seed) {
    CAPTURE(seed);
    ShellBody b(5, 4);
    std::mt19937 rng(seed);
    std::uniform_real_distribution<double> u(-1, 1);
    sewn::physics::System& sys = b.model->system();
    std::size_t facets_cut = 0;
    for (int k = 0; k < 4; ++k) {
      b.deform(rng, 0.005);
      const double e0 = sys.potential_energy(), m0 = b.model->node_mass();
      const std::vector<double> before = b.hinge_energies();
      // planes through the sheet in any direction across it (a normal with an in-plane part)
      const Eigen::Vector3d normal = Eigen::Vector3d(u(rng), u(rng), 0.3 * u(rng)).normalized();
      const Eigen::Vector3d point(0.25 + 0.15 * u(rng), 0.2 + 0.15 * u(rng), 0);
      const auto facets = sewn::refine::facets_across_plane(*b.model, point, normal);
      facets_cut += sewn::refine::cut(*b.model, facets).facets;
      sewn::app::follow_cut(b.parts, *b.model);
      CHECK(b.model->map().validate().ok());
      CHECK(b.terms_on_elements());
      CHECK(b.model->springs().num_alive() == 0);
      double retired = 0;
      for (Index h = 0; h < before.size(); ++h)
        if (!b.parts.hinges->is_alive(h)) retired += before[h];
      CHECK(std::abs(sys.potential_energy() - (e0 - retired)) <= 1e-12 * e0);
      CHECK(std::abs(b.model->node_mass() - m0) <= 1e-12 * m0);
      // the forces are still the energy's gradient on the new particle numbering: the last
      // particle (one the cuts may have made) and a few others
      CHECK(force_error(*b.model, b.model->nodes().size() - 1) <= 1e-6);
      std::uniform_int_distribution<Index> any(0, b.model->nodes().size() - 1);
      for (int j = 0; j < 3; ++j) CHECK(force_error(*b.model, any(rng)) <= 1e-6);
    }
    CHECK(facets_cut > 0);
    CHECK(b.model->nodes().size() > 30);  // particles were duplicated
  }
}

TEST_CASE("shell pierce: random triangles pierced away or loosened, energy and mass follow, forces stay exact") {
  for (std::uint32_t seed = 1; seed <= 6; ++seed) {
    CAPTURE(seed);
    ShellBody b(5, 4);
    std::mt19937 rng(seed);
    sewn::physics::System& sys = b.model->system();
    for (int k = 0; k < 3; ++k) {
      const bool remove = (seed + static_cast<std::uint32_t>(k)) % 2 == 0;
      CAPTURE(remove);
      b.deform(rng, 0.005);
      const double e0 = sys.potential_energy();
      const std::vector<double> hinges_before = b.hinge_energies();
      std::vector<double> membranes_before(b.parts.membranes->size(), 0.0);
      for (Index m = 0; m < membranes_before.size(); ++m)
        if (b.parts.membranes->is_alive(m))
          membranes_before[m] = b.parts.membranes->element_energy(m, b.parts.membranes->gather(sys.state(), m));
      // two live triangles at random
      std::vector<Index> live;
      for (Index e = 0; e < b.model->elements().size(); ++e)
        if (b.model->elements()[e].alive) live.push_back(e);
      std::shuffle(live.begin(), live.end(), rng);
      live.resize(2);
      (void)sewn::refine::pierce(*b.model, live, remove);  // the continuum follows through after_edits
      CHECK(b.model->map().validate().ok());
      CHECK(b.terms_on_elements());
      // the energy lost is what the retired membranes and hinges held
      double lost = 0;
      for (Index m = 0; m < membranes_before.size(); ++m)
        if (!b.parts.membranes->is_alive(m)) lost += membranes_before[m];
      for (Index h = 0; h < hinges_before.size(); ++h)
        if (!b.parts.hinges->is_alive(h)) lost += hinges_before[h];
      CHECK(std::abs(sys.potential_energy() - (e0 - lost)) <= 1e-12 * e0);
      CHECK(std::abs(b.model->node_mass() - b.model->element_mass()) <= 1e-12 * b.model->node_mass());
      if (!remove)
        for (Index e : live) CHECK(b.model->elements()[e].alive);
      std::uniform_int_distribution<Index> any(0, b.model->nodes().size() - 1);
      for (int j = 0; j < 3; ++j) CHECK(force_error(*b.model, any(rng)) <= 1e-6);
    }
  }
}

}  // namespace
}  // namespace test_shell_cuts
