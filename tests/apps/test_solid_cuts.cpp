// Cuts on finite-element tetrahedra: after refine::cut the Tets term follows the particles the
// cut duplicated. A cut changes no energy or mass at the state it is made in, keeps the map
// valid, and leaves the pieces free of each other; random sequences of cuts keep all of it.
#include <doctest/doctest.h>

#include <algorithm>
#include <cmath>
#include <random>
#include <set>

#include <Eigen/Geometry>

#include "sewn/apps/cell_models.hpp"
#include "sewn/apps/continuum.hpp"
#include "sewn/io/cleanup.hpp"
#include "sewn/refine/cut.hpp"

#include "force_check.hpp"

namespace test_solid_cuts {

using namespace sewn;
using namespace sewn::app;

namespace solid_cuts_test {

struct SolidBody {
  IndexedMesh mesh;
  std::vector<physics::MaterialParams> materials{{1e6, 0.3, 1000, 1, 1e-4, physics::ElongatedPolicy::refuse}};
  std::unique_ptr<physics::MssModel<3>> model;
  ContinuumParts parts;

  SolidBody(std::uint32_t nx, std::uint32_t ny, std::uint32_t nz) {
    GridSpec g;
    g.spacing = {0.1, 0.1, 0.1};
    mesh = tet_grid(nx, ny, nz, TetSplit::kuhn6, g);
    Scene s;
    s.file = "cuts.json";
    s.model = "solid";
    s.law = "stvk";
    s.damping = "none";
    s.cuts.push_back({});  // cuts are scheduled: the builder must accept them
    s.cuts.back().type = "plane";
    physics::MssOptions mo;
    mo.gravity.setZero();
    mo.damping = physics::DampingModel::none;
    model = std::make_unique<physics::MssModel<3>>(mesh, materials, std::vector<std::uint32_t>{}, mo);
    parts = build_continuum(s, materials, mesh, cell_models(mesh, io::embedded_cells(mesh), s, "m"), std::vector<int>(mesh.num_cells(), -1), *model);
  }
  void deform(std::mt19937& rng, double amount) {
    std::uniform_real_distribution<double> u(-amount, amount);
    for (physics::Index i = 0; i < model->nodes().size(); ++i)
      model->nodes().set_position(i, model->nodes().position(i) + Eigen::Vector3d(u(rng), u(rng), u(rng)));
  }
  // Every tetrahedron of the term sits on its model element's current corners.
  [[nodiscard]] bool tets_on_elements() const {
    for (physics::Index k = 0; k < parts.element_of_tet.size(); ++k) {
      const auto nodes = model->element_nodes(parts.element_of_tet[k]);
      const auto& held = parts.tets->element_nodes(k);
      if (!std::equal(held.begin(), held.end(), nodes.begin())) return false;
    }
    return true;
  }
};



TEST_CASE("solid cut: energy and mass unchanged at the cut, the map valid, the two halves free") {
  SolidBody b(4, 1, 1);
  std::mt19937 rng(3);
  b.deform(rng, 0.01);
  physics::System& sys = b.model->system();
  const double e0 = sys.potential_energy(), m0 = b.model->node_mass();
  REQUIRE(e0 > 0);
  const auto facets = refine::facets_across_plane(*b.model, Eigen::Vector3d(0.2, 0, 0), Eigen::Vector3d(1, 0, 0));
  REQUIRE(facets.size() == 2);  // the two triangles of the 0.1 m square section
  const physics::Index nodes_before = b.model->nodes().size();
  (void)refine::cut(*b.model, facets);
  follow_cut(b.parts, *b.model);
  CHECK(b.model->map().validate().ok());
  CHECK(b.model->nodes().size() == nodes_before + 4);
  CHECK(b.model->springs().num_alive() == 0);
  CHECK(b.tets_on_elements());
  CHECK(std::abs(sys.potential_energy() - e0) <= 1e-12 * e0);
  CHECK(std::abs(b.model->node_mass() - m0) <= 1e-12 * m0);
  CHECK(std::abs(b.model->node_mass() - b.model->element_mass()) <= 1e-12 * m0);
  // the right half moved away rigidly costs nothing: no tetrahedron joins the halves any more
  std::set<physics::Index> left, right;
  for (physics::Index e = 0; e < b.model->elements().size(); ++e)
    for (physics::Index n : b.model->element_nodes(e)) (b.model->element_centroid(e).x() < 0.2 ? left : right).insert(n);
  for (physics::Index n : right) CHECK(left.count(n) == 0);
  for (physics::Index n : right) b.model->nodes().set_position(n, b.model->nodes().position(n) + Eigen::Vector3d(0.05, -0.02, 0.03));
  CHECK(std::abs(sys.potential_energy() - e0) <= 1e-9 * e0);
}

TEST_CASE("solid cut: random sequences of plane cuts keep the map valid, energy, mass and forces") {
  for (std::uint32_t seed = 1; seed <= 6; ++seed) {
    CAPTURE(seed);
    SolidBody b(3, 3, 3);
    std::mt19937 rng(seed);
    std::uniform_real_distribution<double> u(-1, 1);
    physics::System& sys = b.model->system();
    std::size_t facets_cut = 0;
    for (int k = 0; k < 4; ++k) {
      b.deform(rng, 0.005);
      const double e0 = sys.potential_energy(), m0 = b.model->node_mass();
      const Eigen::Vector3d normal = Eigen::Vector3d(u(rng), u(rng), u(rng)).normalized();
      const Eigen::Vector3d point(0.15 + 0.1 * u(rng), 0.15 + 0.1 * u(rng), 0.15 + 0.1 * u(rng));
      const auto facets = refine::facets_across_plane(*b.model, point, normal);
      facets_cut += refine::cut(*b.model, facets).facets;
      follow_cut(b.parts, *b.model);
      CHECK(b.model->map().validate().ok());
      CHECK(b.tets_on_elements());
      CHECK(b.model->springs().num_alive() == 0);
      CHECK(std::abs(sys.potential_energy() - e0) <= 1e-12 * e0);
      CHECK(std::abs(b.model->node_mass() - m0) <= 1e-12 * m0);
      // the forces are still the energy's gradient on the new particle numbering
      // (the last particle: one the cuts may have made)
      CHECK(sewn::app::test::force_error(*b.model, b.model->nodes().size() - 1) <= 1e-6);
    }
    CHECK(facets_cut > 0);
    CHECK(b.model->nodes().size() > 64);  // particles were duplicated
  }
}

TEST_CASE("solid pierce: random tetrahedra pierced away or loosened, energy and mass follow, forces stay exact") {
  for (std::uint32_t seed = 1; seed <= 4; ++seed) {
    CAPTURE(seed);
    SolidBody b(3, 2, 2);
    std::mt19937 rng(seed);
    physics::System& sys = b.model->system();
    for (int k = 0; k < 3; ++k) {
      const bool remove = (seed + static_cast<std::uint32_t>(k)) % 2 == 1;
      CAPTURE(remove);
      b.deform(rng, 0.005);
      const double e0 = sys.potential_energy();
      std::vector<double> before(b.parts.tets->size(), 0.0);
      for (physics::Index t = 0; t < before.size(); ++t)
        if (b.parts.tets->is_alive(t)) before[t] = b.parts.tets->element_energy(t, b.parts.tets->gather(sys.state(), t));
      std::vector<physics::Index> live;
      for (physics::Index e = 0; e < b.model->elements().size(); ++e)
        if (b.model->elements()[e].alive) live.push_back(e);
      std::shuffle(live.begin(), live.end(), rng);
      live.resize(3);
      (void)refine::pierce(*b.model, live, remove);  // the tetrahedra follow through after_edits
      CHECK(b.model->map().validate().ok());
      double lost = 0;
      for (physics::Index t = 0; t < before.size(); ++t) {
        const bool element_alive = b.model->elements()[b.parts.element_of_tet[t]].alive;
        CHECK(b.parts.tets->is_alive(t) == element_alive);
        if (!b.parts.tets->is_alive(t)) lost += before[t];
      }
      CHECK((lost > 0) == remove);
      CHECK(std::abs(sys.potential_energy() - (e0 - lost)) <= 1e-12 * e0);
      CHECK(std::abs(b.model->node_mass() - b.model->element_mass()) <= 1e-12 * b.model->node_mass());
      CHECK(sewn::app::test::force_error(*b.model, b.model->nodes().size() - 1) <= 1e-6);
    }
  }
}

}  // namespace solid_cuts_test

}  // namespace test_solid_cuts
