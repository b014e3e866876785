// Cutting and piercing (the 2013 paper's §5) on the mass-spring model.
#include <doctest/doctest.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <map>
#include <random>
#include <set>

#include "sewn/physics/integrators.hpp"
#include "sewn/physics/stiffness.hpp"
#include "sewn/refine/cut.hpp"

namespace test_cut {

using namespace sewn;
using namespace sewn::physics;
using namespace sewn::refine;
using Eigen::Vector3d;

namespace {

const MaterialParams paper_material{100e6, 0.3, 1000};

MssOptions options(bool gravity) {
  MssOptions o;
  if (!gravity) o.gravity.setZero();
  return o;
}

double sum_rounding(double n, double s) { return n * std::numeric_limits<double>::epsilon() * s; }

Vector3d momentum(const NodeTable& n) {
  Vector3d p = Vector3d::Zero();
  for (Index i = 0; i < n.size(); ++i)
    if (n.is_alive(i)) p += n.mass(i) * n.velocity(i);
  return p;
}

bool close(double a, double b) { return std::abs(a - b) <= 1e-12 * std::max(std::abs(a), std::abs(b)); }

// Each particle's mass, the stiffness between each pair of particles and each spring's
// viscosity, recomputed from the live elements alone, as if the cut mesh had been built from
// scratch: the model's incremental update after a cut must agree with them. Springs between the
// same particles (an edge split along a slit whose ends stay shared) add up.
template <int D>
void check_physics(const MssModel<D>& m) {
  const NodeTable& nodes = m.nodes();
  const Springs& s = m.springs();
  std::vector<double> mass(nodes.size(), 0.0);
  std::map<std::pair<Index, Index>, double> edge_k;
  auto pair = [](Index i, Index j) { return std::make_pair(std::min(i, j), std::max(i, j)); };
  for (Index e = 0; e < m.elements().size(); ++e) {
    const Element& el = m.elements()[e];
    if (!el.alive) continue;
    const auto corner = m.element_nodes(e);
    for (Index n : corner) mass[n] += m.materials()[el.material].density * el.measure / static_cast<double>(corner.size());
    const auto edges = MssModel<D>::local_edges(el.kind);
    for (std::size_t k = 0; k < edges.size(); ++k) edge_k[pair(corner[edges[k][0]], corner[edges[k][1]])] += el.edge_k[k];
  }
  for (Index i = 0; i < nodes.size(); ++i)
    if (nodes.is_alive(i)) {
      CAPTURE(i);
      REQUIRE(close(nodes.mass(i), mass[i]));
    }
  std::map<std::pair<Index, Index>, double> spring_k;
  for (Index sp = 0; sp < s.size(); ++sp) {
    if (!s.is_alive(sp)) continue;
    CAPTURE(sp);
    if (s.kind(sp) == SpringKind::edge) spring_k[pair(s.node_i(sp), s.node_j(sp))] += s.stiffness(sp);
    if (m.options().damping == DampingModel::viscous)
      REQUIRE(close(s.viscosity(sp), paper_viscosity(s.stiffness(sp), nodes.mass(s.node_i(sp)), nodes.mass(s.node_j(sp)))));
  }
  REQUIRE(spring_k.size() == edge_k.size());
  for (const auto& entry : spring_k) {
    const auto& ij = entry.first;  // CAPTURE cannot take bindings (clang 14)
    const double k = entry.second;
    CAPTURE(ij.first);
    CAPTURE(ij.second);
    REQUIRE(edge_k.count(ij) == 1);
    REQUIRE(close(k, edge_k.at(ij)));
  }
}

// Every spring hangs on the particles its cells carry now, every particle has an element, and
// the masses add up: what a cut must never break.
template <int D>
void check_consistent(const MssModel<D>& m) {
  const auto& map = m.map();
  const auto report = map.validate();
  INFO(report.str());
  REQUIRE(report.ok());
  const Springs& s = m.springs();
  std::vector<char> referenced(m.nodes().size(), 0);
  for (AttrId<1> a : map.template attributes<1>()) {
    const Dart d = map.dart_of(a);
    const Index sp = map.value(a).spring;
    Dart end = map.beta(d, 1);
    if (!end) end = map.beta(d, 2);
    const std::set<Index> want{m.node_of(d), m.node_of(end)}, have{s.node_i(sp), s.node_j(sp)};
    REQUIRE(want == have);
  }
  for (Index e = 0; e < m.elements().size(); ++e) {
    const Element& el = m.elements()[e];
    if (!el.alive) continue;
    const auto corner = m.element_nodes(e);
    for (Index n : corner) referenced[n] = 1;
    const auto& diag = el.kind == ElementKind::hexahedron ? std::vector<std::array<int, 2>>{{0, 6}, {1, 7}, {2, 4}, {3, 5}}
                       : el.kind == ElementKind::quad     ? std::vector<std::array<int, 2>>{{0, 2}, {1, 3}}
                                                          : std::vector<std::array<int, 2>>{};
    for (std::size_t k = 0; k < diag.size(); ++k) {
      const std::set<Index> want{corner[static_cast<std::size_t>(diag[k][0])], corner[static_cast<std::size_t>(diag[k][1])]},
          have{s.node_i(el.diagonal[k]), s.node_j(el.diagonal[k])};
      REQUIRE(want == have);
    }
  }
  for (Index i = 0; i < m.nodes().size(); ++i)
    if (m.nodes().is_alive(i)) REQUIRE(referenced[i]);
  const double total = m.element_mass();
  REQUIRE(std::abs(m.node_mass() - total) <= sum_rounding(8.0 * static_cast<double>(m.elements().size()), total));
  check_physics(m);
}

// Live particles of the elements whose rest centroid satisfies pred.
template <int D, class P>
std::set<Index> particles_of(const MssModel<D>& m, P pred) {
  std::set<Index> out;
  for (Index e = 0; e < m.elements().size(); ++e)
    if (m.elements()[e].alive && pred(m.element_centroid(e)))
      for (Index n : m.element_nodes(e)) out.insert(n);
  return out;
}

Vector3d centre_of_mass(const NodeTable& n, const std::set<Index>& which, double* mass = nullptr) {
  Vector3d c = Vector3d::Zero();
  double m = 0;
  for (Index i : which) {
    c += n.mass(i) * n.position(i);
    m += n.mass(i);
  }
  if (mass) *mass = m;
  return c / m;
}

}  // namespace

TEST_CASE("Fig. 5 and Fig. 6 through the cutting API") {
  const double L = 0.1;
  const IndexedMesh mesh = hex_grid(2, 1, 2, {{L, L, L}, {}});
  MssModel<3> m(mesh, {paper_material}, {}, options(false));
  // the face x = L between the upper hexahedra: points (1,0,1) (1,1,1) (1,0,2) (1,1,2)
  auto point = [](std::uint32_t i, std::uint32_t j, std::uint32_t k) { return i + 3 * (j + 2 * k); };
  const std::vector<std::vector<std::uint32_t>> face{{point(1, 0, 1), point(1, 1, 1), point(1, 1, 2), point(1, 0, 2)}};
  const auto facets = facets_with_points(m, std::span(face));
  REQUIRE(facets.size() == 1);
  const Index before = m.nodes().size();
  const CutReport r = cut(m, std::span(facets));
  CHECK(r.facets == 1);
  CHECK(r.particles == 2);
  CHECK(r.springs == 3);
  CHECK(r.elements == 0);
  check_consistent(m);
  // the two new particles stand for the top points v1, v2 (Fig. 5)
  std::set<std::uint32_t> duplicated;
  for (Index i = before; i < m.nodes().size(); ++i) duplicated.insert(m.point_of_node(i));
  CHECK(duplicated == std::set<std::uint32_t>{point(1, 0, 2), point(1, 1, 2)});
  // naming it again selects nothing (it is already cut); a boundary face is an error
  CHECK(facets_with_points(m, std::span(face)).empty());
  const std::vector<std::vector<std::uint32_t>> bottom{{point(0, 0, 0), point(1, 0, 0), point(1, 1, 0), point(0, 1, 0)}};
  CHECK_THROWS_WITH_AS(facets_with_points(m, std::span(bottom)), doctest::Contains("boundary"), InputError);
}

template <int D>
void edges_by_points() {
  // a 2 x 1 grid of quads (points i + 3 j): the inner edge x = 1, a boundary edge, both ends
  MssModel<D> m(sewn::quad_grid(2, 1, {{0.1, 0.1, 1}, {}}), {paper_material}, {}, options(false));
  const std::vector<std::vector<std::uint32_t>> inner{{1, 4}}, boundary{{0, 1}};
  const auto facets = facets_with_points(m, std::span(inner));
  REQUIRE(facets.size() == 1);
  CHECK(facets[0].index == 2);
  CHECK(cut(m, std::span(facets)).facets == 1);
  check_consistent(m);
  // named again: already cut, so nothing; a boundary edge (β2 free) is an error, not a crash
  CHECK(facets_with_points(m, std::span(inner)).empty());
  CHECK_THROWS_WITH_AS(facets_with_points(m, std::span(boundary)), doctest::Contains("boundary"), InputError);
}

TEST_CASE("edges of 2D cells named by their points: a 2-map and membranes of a 3-map") {
  edges_by_points<2>();
  edges_by_points<3>();
}

TEST_CASE("selections: faces among a path of particles, faces across a plane within a region, elements in a region") {
  const double a = 0.05;
  const IndexedMesh mesh = hex_grid(10, 2, 2, {{a, a, a}, {}});
  // The particles of the section x = 0.25 with z <= a: the lower half of the section (3 × 2).
  std::vector<std::uint32_t> path;
  for (std::uint32_t p = 0; p < mesh.num_points(); ++p)
    if (std::abs(mesh.points[p][0] - 0.25) < 1e-12 && mesh.points[p][2] < a + 1e-12) path.push_back(p);
  REQUIRE(path.size() == 6);
  MssModel<3> by_path(mesh, {paper_material}, {}, options(false));
  const auto among = facets_among_points(by_path, std::span(path));
  CHECK(among.size() == 2);  // the section's two lower faces
  MssModel<3> by_plane(mesh, {paper_material}, {}, options(false));
  const auto across = facets_across_plane(by_plane, Vector3d(0.25, 0, 0), Vector3d(1, 0, 0),
                                          [&](const Vector3d& c) { return c.z() < a; });
  CHECK(across.size() == 2);
  // Both name the same two faces: cutting them splits the 3 particles of the section's bottom
  // edge and its 5 edges (2 along the bottom, 3 upright), and nothing else.
  for (MssModel<3>* m : {&by_path, &by_plane}) {
    const CutReport r = cut(*m, std::span(m == &by_path ? among : across));
    check_consistent(*m);
    CHECK(r.particles == 3);
    CHECK(r.springs == 5);
    CHECK(m->map().count_components() == 1);
  }
  CHECK(by_path.nodes().num_alive() == by_plane.nodes().num_alive());
  for (Index i = 0; i < by_path.nodes().size(); ++i) CHECK(by_path.nodes().position(i) == by_plane.nodes().position(i));
  // Elements whose centroid is in x < 0.1: the first two slabs of 2 × 2.
  CHECK(elements_in(by_path, [](const Vector3d& c) { return c.x() < 0.1; }).size() == 8);
}

TEST_CASE("a cut between two steps conserves mass and momentum") {
  MssModel<3> m(tet_grid(4, 2, 2, TetSplit::kuhn6, {{0.05, 0.05, 0.05}, {}}), {paper_material}, {}, options(false));
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> u(-1, 1);
  for (Index i = 0; i < m.nodes().size(); ++i) m.nodes().set_velocity(i, Vector3d(u(rng), u(rng), u(rng)));
  const double mass = m.node_mass();
  const Vector3d p = momentum(m.nodes());
  const auto facets = facets_across_plane(m, Vector3d(0.1, 0, 0), Vector3d(1, 0.2, 0));
  CHECK(!facets.empty());
  cut(m, std::span(facets));
  check_consistent(m);
  CHECK(std::abs(m.node_mass() - mass) <= sum_rounding(8 * 96, mass));
  CHECK((momentum(m.nodes()) - p).norm() <= 1e-14 * p.norm() * 100);
}

TEST_CASE("a beam cut fully in two: free halves fall with the right masses; a held half stays") {
  const double a = 0.05;
  for (bool hold_left : {false, true}) {
    CAPTURE(hold_left);
    MssModel<3> m(hex_grid(10, 2, 2, {{a, a, a}, {}}), {paper_material}, {}, options(true));
    if (hold_left)
      for (Index i = 0; i < m.nodes().size(); ++i)
        if (m.rest_position(i).x() == 0) m.nodes().fix(i);
    const auto facets = facets_across_plane(m, Vector3d(0.25, 0, 0), Vector3d(1, 0, 0));
    CHECK(facets.size() == 4);  // the 2x2 faces of the section
    cut(m, std::span(facets));
    check_consistent(m);
    CHECK(m.map().count_components() == 2);
    const auto left = particles_of(m, [](const Vector3d& c) { return c.x() < 0.25; });
    const auto right = particles_of(m, [](const Vector3d& c) { return c.x() > 0.25; });
    std::vector<Index> shared;
    std::set_intersection(left.begin(), left.end(), right.begin(), right.end(), std::back_inserter(shared));
    CHECK(shared.empty());
    double ml = 0, mr = 0;
    const Vector3d cl0 = centre_of_mass(m.nodes(), left, &ml), cr0 = centre_of_mass(m.nodes(), right, &mr);
    const double half = 1000 * 0.25 * 0.1 * 0.1;
    CHECK(std::abs(ml - half) <= sum_rounding(500, half));
    CHECK(std::abs(mr - half) <= sum_rounding(500, half));
    LinearlyImplicitEuler euler;
    const double h = 1e-3;
    const int n = 200;
    for (int s = 0; s < n; ++s) {
      const StepReport rep = euler.step(m.system(), h);
      REQUIRE(rep.cg_converged);
    }
    // a free body's centre of mass obeys v += h g, x += h v exactly (internal forces cancel up
    // to the CG residual): after n steps it has fallen g h² n(n+1)/2
    const double fall = 9.81 * h * h * n * (n + 1) / 2;
    const double dz_right = centre_of_mass(m.nodes(), right).z() - cr0.z();
    const double dz_left = centre_of_mass(m.nodes(), left).z() - cl0.z();
    CHECK(dz_right == doctest::Approx(-fall).epsilon(1e-4));
    if (hold_left)
      CHECK(std::abs(dz_left) < 1e-3 * fall);  // held at x = 0: it only sags
    else
      CHECK(dz_left == doctest::Approx(-fall).epsilon(1e-4));
  }
}

TEST_CASE("full disassembly: every element on its own, with its own particles, masses and springs") {
  SUBCASE("hexahedra") {
    const double a = 0.1;
    MssModel<3> m(hex_grid(3, 2, 2, {{a, a, a}, {}}), {paper_material}, {}, options(false));
    const auto all = inner_facets(m);
    CHECK(all.size() == 2 * 2 * 2 + 3 * 1 * 2 + 3 * 2 * 1);
    cut(m, std::span(all));
    check_consistent(m);
    CHECK(m.nodes().num_alive() == 8 * 12);
    CHECK(m.springs().num_alive() == 16 * 12);
    CHECK(m.map().count_components() == 12);
    for (Index i = 0; i < m.nodes().size(); ++i) CHECK(m.nodes().mass(i) == doctest::Approx(1000 * a * a * a / 8));
    const double k_edge = baudet_box(100e6, 0.3, a, a, a).edge[0];
    for (Index s = 0; s < m.springs().size(); ++s)
      if (m.springs().kind(s) == SpringKind::edge) CHECK(m.springs().stiffness(s) == doctest::Approx(k_edge));
  }
  SUBCASE("tetrahedra") {
    MssModel<3> m(tet_grid(2, 1, 1, TetSplit::kuhn6, {{0.1, 0.1, 0.1}, {}}), {paper_material}, {}, options(false));
    cut(m, inner_facets(m));
    check_consistent(m);
    CHECK(m.nodes().num_alive() == 4 * 12);
    CHECK(m.springs().num_alive() == 6 * 12);
    CHECK(m.map().count_components() == 12);
  }
}

TEST_CASE("2D cuts: a membrane of quads and one of triangles, in 2- and 3-maps") {
  MaterialParams sheet{1e6, 0.3, 1000, 0.001};
  MssModel<2> quads(quad_grid(6, 4, {{0.1, 0.1, 1}, {}}), {sheet}, {}, options(false));
  auto line = facets_across_plane(quads, Vector3d(0.3, 0, 0), Vector3d(1, 0, 0), [](const Vector3d& c) { return c.y() < 0.3; });
  CHECK(line.size() == 3);  // a slit through three of the four rows, from the y = 0 border
  const CutReport r = cut(quads, std::span(line));
  CHECK(r.particles == 3);  // the border point and two inner points open; the slit's tip stays shared
  CHECK(r.springs == 3);
  check_consistent(quads);
  CHECK(quads.map().count_components() == 1);
  MssModel<3> tris(tri_grid(6, 4, {{0.1, 0.1, 1}, {}}), {sheet}, {}, options(false));
  cut(tris, facets_across_plane(tris, Vector3d(0.3, 0, 0), Vector3d(1, 0, 0)));
  check_consistent(tris);
  CHECK(tris.map().count_components() == 2);
}

TEST_CASE("piercing the paper's 5x3x3 beam: 3 cubes freed by unsewing 14 faces") {
  const double a = 0.1;
  auto middle = [&](const Vector3d& c) { return c.x() > a && c.x() < 4 * a && std::abs(c.y() - 1.5 * a) < 0.1 * a && std::abs(c.z() - 1.5 * a) < 0.1 * a; };
  for (bool remove : {true, false}) {
    CAPTURE(remove);
    MssModel<3> m(hex_grid(5, 3, 3, {{a, a, a}, {}}), {paper_material}, {}, options(true));
    const double mass = m.node_mass();
    const auto cubes = elements_in(m, middle);
    REQUIRE(cubes.size() == 3);
    const CutReport r = pierce(m, std::span(cubes), remove);
    CHECK(r.facets == 14);
    check_consistent(m);
    if (remove) {
      CHECK(r.elements == -3);
      CHECK(std::abs(m.node_mass() - (mass - 3 * 1000 * a * a * a)) <= sum_rounding(400, mass));
      CHECK(m.nodes().num_alive() == m.nodes().size());  // compacted
      CHECK(m.map().count_components() == 1);
    } else {
      CHECK(r.elements == 0);
      CHECK(std::abs(m.node_mass() - mass) <= sum_rounding(400, mass));
      CHECK(m.map().count_components() == 2);  // the block is a loose piece inside the beam
    }
    LinearlyImplicitEuler euler;
    CHECK(euler.step(m.system(), 1e-3).cg_converged);
  }
}

TEST_CASE("randomized sequences of cuts and piercings on hexahedral and tetrahedral beams") {
  for (int tets = 0; tets < 2; ++tets) {
    const unsigned seed = 2013 + static_cast<unsigned>(tets);
    CAPTURE(seed);
    std::mt19937 rng(seed);
    const IndexedMesh mesh = tets ? tet_grid(5, 3, 3, TetSplit::kuhn6, {{0.02, 0.02, 0.02}, {}}) : hex_grid(6, 3, 3, {{0.02, 0.02, 0.02}, {}});
    MssModel<3> m(mesh, {paper_material}, {}, options(true));
    for (Index i = 0; i < m.nodes().size(); ++i)
      if (m.rest_position(i).x() == 0) m.nodes().fix(i);
    LinearlyImplicitEuler euler;
    int cuts = 0, piercings = 0;
    for (int round = 0; round < 25; ++round) {
      auto facets = inner_facets(m);
      if (facets.empty()) break;
      if (rng() % 4 != 0) {
        std::shuffle(facets.begin(), facets.end(), rng);
        facets.resize(std::min<std::size_t>(facets.size(), 1 + rng() % 6));
        cut(m, std::span(facets));
        ++cuts;
      } else {
        std::vector<Index> alive;
        for (Index e = 0; e < m.elements().size(); ++e)
          if (m.elements()[e].alive) alive.push_back(e);
        if (alive.size() < 4) break;
        const std::vector<Index> pick{alive[rng() % alive.size()]};
        pierce(m, std::span(pick), rng() % 2 == 0);
        ++piercings;
      }
      check_consistent(m);
      // dynamic check: the next implicit step converges and stays finite
      const StepReport rep = euler.step(m.system(), 1e-3);
      REQUIRE(rep.cg_converged);
      REQUIRE(m.nodes().positions().allFinite());
    }
    CHECK(cuts > 5);
    CHECK(piercings > 1);
  }
}

}  // namespace test_cut
