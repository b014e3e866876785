// The mass-spring system built on the combinatorial map: counts of the 2013 paper, masses,
// stiffness accumulation, agreement with the map-free lattice, refusals, and a cut.
#include <doctest/doctest.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <set>
#include <tuple>

#include "helpers.hpp"
#include "sewn/physics/cell_input_error.hpp"
#include "sewn/physics/lattice.hpp"
#include "sewn/physics/mss_model.hpp"
#include "sewn/physics/stiffness.hpp"

namespace test_mss_model {

using namespace sewn;
using namespace sewn::physics;

namespace {

using sewn::physics::test::paper_material;

MssOptions no_gravity() {
  MssOptions o;
  o.gravity.setZero();
  o.damping = DampingModel::none;
  return o;
}

// Bound on the rounding of a sum of n positive terms of total s (n·ε·s, ε = 2⁻⁵³).
double sum_rounding(double n, double s) { return n * std::numeric_limits<double>::epsilon() * s; }

// Every spring as (lower node, higher node, k, l), sorted, for comparing two systems.
std::vector<std::tuple<Index, Index, double, double>> spring_list(const Springs& s) {
  std::vector<std::tuple<Index, Index, double, double>> out;
  for (Index i = 0; i < s.size(); ++i)
    if (s.is_alive(i))
      out.emplace_back(std::min(s.node_i(i), s.node_j(i)), std::max(s.node_i(i), s.node_j(i)), s.stiffness(i), s.rest_length(i));
  std::sort(out.begin(), out.end());
  return out;
}

// Each diagonal spring of element e joins the particles its corners carry now (Fig. 6).
template <int D>
void check_diagonals_attached(const MssModel<D>& m) {
  for (Index e = 0; e < m.elements().size(); ++e) {
    const Element& el = m.elements()[e];
    if (!el.alive || el.kind != ElementKind::hexahedron) continue;
    const auto corner = m.element_nodes(e);
    static constexpr int diag[4][2] = {{0, 6}, {1, 7}, {2, 4}, {3, 5}};
    for (int k = 0; k < 4; ++k) {
      const Index s = el.diagonal[static_cast<std::size_t>(k)];
      const std::set<Index> ends{m.springs().node_i(s), m.springs().node_j(s)};
      CHECK(ends == std::set<Index>{corner[static_cast<std::size_t>(diag[k][0])], corner[static_cast<std::size_t>(diag[k][1])]});
    }
  }
}

}  // namespace

TEST_CASE("the 2013 paper's meshes have its particle and spring counts") {
  struct Case {
    IndexedMesh mesh;
    Index particles, springs;
  };
  Case cases[] = {
      {hex_grid(1, 1, 1, {{0.1, 0.1, 0.1}, {}}), 8, 16},
      {tet_grid(1, 1, 1, TetSplit::five, {{0.1, 0.1, 0.1}, {}}), 8, 18},
      {hex_grid(8, 8, 10, {{0.0125, 0.0125, 0.0125}, {}}), 891, 4954},
      {tet_grid(5, 7, 9, TetSplit::kuhn6, {{0.02, 0.02, 0.02}, {}}), 480, 2655},
  };
  for (const auto& c : cases) {
    MssModel<3> m(c.mesh, {paper_material}, {});
    CHECK(m.nodes().num_alive() == c.particles);
    CHECK(m.springs().num_alive() == c.springs);
    CHECK(m.map().validate().ok());
  }
}

TEST_CASE("masses add up to rho times the volume, lumped per corner") {
  const double L = 0.1;
  MssModel<3> hex(hex_grid(4, 3, 5, {{L, L, L}, {}}), {paper_material}, {});
  const double total = 1000 * (4 * L) * (3 * L) * (5 * L);
  CHECK(std::abs(hex.node_mass() - total) <= sum_rounding(120 * 8, total));
  CHECK(std::abs(hex.element_mass() - total) <= sum_rounding(60, total));
  // a corner particle carries one eighth of one cell; an interior one, eight eighths
  CHECK(hex.nodes().mass(hex.node_of_point(0)) == doctest::Approx(1000 * L * L * L / 8));
  CHECK(hex.nodes().mass(hex.node_of_point(1 + 5 * (1 + 4 * 1))) == doctest::Approx(1000 * L * L * L));
  // the 5-tet cube: corner tets V/6 and a central V/3 give masses in the ratio 1:5 (PHYSICS_NOTES §1.1)
  MssModel<3> five(tet_grid(1, 1, 1, TetSplit::five, {{L, L, L}, {}}), {paper_material}, {});
  std::vector<double> m;
  for (Index i = 0; i < 8; ++i) m.push_back(five.nodes().mass(i));
  std::sort(m.begin(), m.end());
  CHECK(m.front() == doctest::Approx(1000 * L * L * L / 24));
  CHECK(m.back() == doctest::Approx(5 * 1000 * L * L * L / 24));
}

TEST_CASE("edge springs sum their elements' Baudet stiffness; the map model equals the map-free lattice") {
  const double a = 0.0125;
  MssModel<3> m(hex_grid(8, 8, 10, {{a, a, a}, {}}), {paper_material}, {}, no_gravity());
  const BoxStiffness s = baudet_box(100e6, 0.3, a, a, a);
  // an interior edge lies in 4 cubes, a face edge in 2, a corner edge in 1
  std::multiset<long> multiples;
  for (Index i = 0; i < m.springs().size(); ++i)
    if (m.springs().kind(i) == SpringKind::edge) multiples.insert(std::lround(m.springs().stiffness(i) / s.edge[0]));
    else CHECK(m.springs().stiffness(i) == doctest::Approx(s.diagonal));
  CHECK(multiples.count(4) > 0);
  CHECK(multiples.count(2) > 0);
  CHECK(multiples.count(1) == 4 * (8 + 8 + 10));  // the 12 box edges hold 4(nx+ny+nz) unit edges
  System ref;
  build_box_lattice(ref, {8, 8, 10, a, a, a, 100e6, 0.3, 1000, SpringDamping::none, 0});
  const Springs& rs = dynamic_cast<const Springs&>(*ref.terms()[0]);
  const auto ours = spring_list(m.springs()), theirs = spring_list(rs);
  REQUIRE(ours.size() == theirs.size());
  for (std::size_t k = 0; k < ours.size(); ++k) {
    CHECK(std::get<0>(ours[k]) == std::get<0>(theirs[k]));
    CHECK(std::get<1>(ours[k]) == std::get<1>(theirs[k]));
    CHECK(std::get<2>(ours[k]) == doctest::Approx(std::get<2>(theirs[k])).epsilon(1e-12));
    CHECK(std::get<3>(ours[k]) == doctest::Approx(std::get<3>(theirs[k])).epsilon(1e-12));
  }
  for (Index i = 0; i < m.nodes().size(); ++i) CHECK(m.nodes().mass(i) == doctest::Approx(ref.nodes().mass(i)).epsilon(1e-12));
}

TEST_CASE("the rest state is an equilibrium, and a 2D membrane builds in 2- and 3-maps") {
  MssModel<3> solid(tet_grid(3, 2, 2, TetSplit::kuhn6, {{0.1, 0.1, 0.1}, {}}), {paper_material}, {}, no_gravity());
  solid.system().compute_forces();
  // d - l vanishes up to the rounding of |x_j - x_i| (a few ulps): forces are round-off of E·L²
  CHECK(solid.nodes().forces().cwiseAbs().maxCoeff() <= 64 * std::numeric_limits<double>::epsilon() * 100e6 * 0.1 * 0.1);
  MaterialParams sheet{1e6, 0.3, 1000, 0.002};
  const IndexedMesh quads = quad_grid(5, 4, {{0.1, 0.1, 1}, {}});
  MssModel<2> m2(quads, {sheet}, {});
  MssModel<3> m3(quads, {sheet}, {});
  for (const auto* springs : {&m2.springs(), &m3.springs()}) CHECK(springs->num_alive() == (5 * 5 + 6 * 4) + 2 * 20);
  CHECK(m2.node_mass() == doctest::Approx(1000 * 0.5 * 0.4 * 0.002));
  CHECK(spring_list(m2.springs()) == spring_list(m3.springs()));
  MssModel<3> tris(tri_grid(5, 4, {{0.1, 0.1, 1}, {}}), {sheet}, {});
  CHECK(tris.springs().num_alive() == 5 * 5 + 6 * 4 + 20);
}

TEST_CASE("bad input is refused with the element or material named") {
  // 3:1 boxes: Baudet's edge stiffness is negative (PHYSICS_NOTES §1.2)
  const IndexedMesh long_boxes = hex_grid(2, 1, 1, {{0.3, 0.1, 0.1}, {}});
  CHECK_THROWS_WITH_AS(MssModel<3>(long_boxes, {paper_material}, {}), doctest::Contains("cell 0 (hexahedron)"), InputError);
  CHECK_THROWS_WITH_AS(MssModel<3>(long_boxes, {paper_material}, {}), doctest::Contains("elongated"), InputError);
  // the cell and the problem apart, for a caller that names the cell as its file does
  try {
    (void)MssModel<3>(long_boxes, {paper_material}, {});
    FAIL("no error");
  } catch (const CellInputError& e) {
    REQUIRE(e.message().refs().size() == 1);
    CHECK(e.message().refs()[0].kind == IndexedMessage::Ref::Kind::cell);
    CHECK(e.message().refs()[0].index == 0);
    const std::string renamed = e.message().render([](const IndexedMessage::Ref& r) { return "cell " + std::to_string(r.index + 40); });
    CHECK(renamed.rfind("cell 40 (hexahedron): too elongated", 0) == 0);
    CHECK(std::string(e.what()).find(e.message().str()) != std::string::npos);
  }
  MaterialParams clamped = paper_material;
  clamped.elongated = ElongatedPolicy::clamp;
  MssModel<3> m(long_boxes, {clamped}, {});
  for (Index i = 0; i < m.springs().size(); ++i) CHECK(m.springs().stiffness(i) >= 0);
  MaterialParams bad = paper_material;
  bad.poisson = 0.5;
  CHECK_THROWS_WITH_AS(MssModel<3>(hex_grid(1, 1, 1), {bad}, {}), doctest::Contains("Poisson"), InputError);
  bad = paper_material;
  bad.young = -1;
  CHECK_THROWS_WITH_AS(MssModel<3>(hex_grid(1, 1, 1), {bad}, {}), doctest::Contains("material 0"), InputError);
  CHECK_THROWS_WITH_AS(MssModel<3>(hex_grid(2, 1, 1), {paper_material}, {0, 3}), doctest::Contains("cell 1 uses material 3"),
                       InputError);
  IndexedMesh flat = tet_grid(1, 1, 1, TetSplit::kuhn6);
  flat.points[6] = flat.points[0];  // collapse the shared diagonal: degenerate tetrahedra
  CHECK_THROWS_AS(MssModel<3>(flat, {paper_material}, {}), std::exception);
}

TEST_CASE("a cut through edit(): the paper's Fig. 5 and Fig. 6") {
  const double L = 0.1;
  const IndexedMesh mesh = hex_grid(2, 1, 2, {{L, L, L}, {}});
  MssModel<3> m(mesh, {paper_material}, {}, no_gravity());
  const BoxStiffness s = baudet_box(100e6, 0.3, L, L, L);
  // give every particle a distinct velocity so that momentum is a real check
  for (Index i = 0; i < m.nodes().size(); ++i) m.nodes().set_velocity(i, Eigen::Vector3d(0.1 * i, -0.2, 0.03 * i * i));
  auto momentum = [&] {
    Eigen::Vector3d p = Eigen::Vector3d::Zero();
    for (Index i = 0; i < m.nodes().size(); ++i)
      if (m.nodes().is_alive(i)) p += m.nodes().mass(i) * m.nodes().velocity(i);
    return p;
  };
  const Eigen::Vector3d p0 = momentum();
  const double mass0 = m.node_mass();
  // the face x = L between the two upper hexahedra (cells 2 and 3)
  Dart on_face;
  for (Dart d : m.map().darts()) {
    if (m.element_of(d) != 2) continue;
    const auto a = m.rest_position(m.node_of(d)), b = m.rest_position(m.node_of(m.map().beta(d, 1))),
               c = m.rest_position(m.node_of(m.map().beta(d, 1, 1)));
    if (a.x() == L && b.x() == L && c.x() == L) on_face = d;
  }
  REQUIRE(on_face);
  const Dart partner = m.map().beta(on_face, 3);
  REQUIRE(partner);
  const Index nodes0 = m.nodes().num_alive(), springs0 = m.springs().num_alive();
  m.edit([&](auto& map) { map.template unsew<3>(on_face); });
  CHECK(m.map().validate().ok());
  CHECK(m.nodes().num_alive() == nodes0 + 2);     // v1, v2 duplicated
  CHECK(m.springs().num_alive() == springs0 + 3);  // (v4,v1), (v1,v2), (v2,v3) duplicated
  CHECK(std::abs(m.node_mass() - mass0) <= sum_rounding(64, mass0));
  CHECK((momentum() - p0).norm() <= 1e-14 * (p0.norm() + 1));
  check_diagonals_attached(m);
  // every edge spring's stiffness is again the sum over the elements now around it
  for (Index i = 0; i < m.springs().size(); ++i) {
    if (!m.springs().is_alive(i) || m.springs().kind(i) != SpringKind::edge) continue;
    const double k = m.springs().stiffness(i) / s.edge[0];
    CHECK(std::abs(k - std::round(k)) < 1e-12);
  }
  // the duplicated top vertices now carry a quarter-cell each side: one upper hexahedron apiece
  for (Index i = nodes0; i < m.nodes().size(); ++i) CHECK(m.nodes().mass(i) == doctest::Approx(1000 * L * L * L / 8));
  // the cut can be sewn back: particles merge, springs merge, masses return
  m.edit([&](auto& map) { map.template sew<3>(on_face, partner); });
  CHECK(m.nodes().num_alive() == nodes0);
  CHECK(m.springs().num_alive() == springs0);
  CHECK(std::abs(m.node_mass() - mass0) <= sum_rounding(64, mass0));
  CHECK((momentum() - p0).norm() <= 1e-12 * (p0.norm() + 1));
}

}  // namespace test_mss_model
