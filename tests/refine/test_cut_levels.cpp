// Cutting across a level jump (a facet between elements of different levels, with T-junctions of
// the coarser element on it): the coarser side is refined to meet the finer one, then the facet
// is cut; with refinement and coarsening in seeded random sequences, in 2D and 3D.
#include <doctest/doctest.h>

#include <cmath>
#include <random>
#include <string>
#include <tuple>

#include "sewn/refine/coarsen.hpp"
#include "sewn/refine/cut.hpp"
#include "sewn/refine/hierarchy.hpp"
#include "sewn/refine/subdivide.hpp"
#include "support.hpp"

namespace test_cut_levels {  // one namespace per file: the unity build compiles several files as one

namespace {

using sewn::Dart;
using sewn::DartList;
using sewn::physics::Index;
using sewn::IndexedMesh;
using sewn::physics::MssModel;
using sewn::refine::Facet;
using Eigen::Vector3d;

const sewn::physics::MaterialParams material{1e5, 0.3, 100, 0.5};

IndexedMesh quads(std::uint32_t nx, std::uint32_t ny) { return sewn::quad_grid(nx, ny, {{0.1, 0.1, 1}, {}}); }
IndexedMesh hexes(std::uint32_t nx, std::uint32_t ny, std::uint32_t nz) {
  return sewn::hex_grid(nx, ny, nz, {{0.2, 0.15, 0.125}, {0.1, -0.2, 0.3}});
}

// An affine velocity field of the rest positions: every interpolation of refinement and
// coarsening is exact on it, so linear momentum must come out exactly whatever the sequence.
template <int D>
void affine_velocities(MssModel<D>& m) {
  Eigen::Matrix3d B;
  B << 0.3, -1.2, 0.5, 0.7, 0.1, -0.4, 0.2, 0.9, -0.6;
  const Vector3d a(1.5, -0.5, 0.25);
  for (Index i = 0; i < m.nodes().size(); ++i)
    if (m.nodes().is_alive(i)) {
      Vector3d v = a + B * m.rest_position(i);
      if constexpr (D == 2) v.z() = 0;
      m.nodes().set_velocity(i, v);
    }
}

template <int D>
Vector3d momentum(const MssModel<D>& m) {
  Vector3d p = Vector3d::Zero();
  for (Index i = 0; i < m.nodes().size(); ++i)
    if (m.nodes().is_alive(i)) p += m.nodes().mass(i) * m.nodes().velocity(i);
  return p;
}

template <int D>
Index element_across(const MssModel<D>& m, const Facet& f) {
  return m.element_of(m.map().beta(f.dart, f.index));
}

// The inner facets between elements of the given two levels (in either order).
template <int D>
std::vector<Facet> facets_between(const MssModel<D>& m, std::uint32_t la, std::uint32_t lb) {
  std::vector<Facet> out;
  for (const Facet& f : sewn::refine::inner_facets(m)) {
    const std::uint32_t a = m.elements()[m.element_of(f.dart)].level, b = m.elements()[element_across(m, f)].level;
    if ((a == la && b == lb) || (a == lb && b == la)) out.push_back(f);
  }
  return out;
}

// Live particles that are corners of no live element: nothing would weigh them.
template <int D>
std::size_t unweighed(const MssModel<D>& m) {
  std::vector<char> corner(m.nodes().size(), 0);
  for (Index e = 0; e < m.elements().size(); ++e)
    if (m.elements()[e].alive)
      for (Index n : m.element_nodes(e)) corner[n] = 1;
  std::size_t k = 0;
  for (Index i = 0; i < m.nodes().size(); ++i) k += m.nodes().is_alive(i) && !corner[i];
  return k;
}

// After the slaves took their masters' motion: the particles of each live element whose velocity
// is not the multilinear interpolation of its corners' (every particle of an element lies at a
// dyadic place of its rest box, and the velocity field starts affine). A T-junction that a cut
// left on the sides of two elements whose corners it separated would be slaved to one only.
template <int D>
std::size_t inconsistent_particles(const MssModel<D>& m) {
  std::size_t bad = 0;
  for (Index e = 0; e < m.elements().size(); ++e) {
    if (!m.elements()[e].alive) continue;
    const std::vector<Index> c = m.element_nodes(e);
    Vector3d lo = m.rest_position(c[0]), hi = lo;
    for (Index n : c) {
      lo = lo.cwiseMin(m.rest_position(n));
      hi = hi.cwiseMax(m.rest_position(n));
    }
    // the element's own cell: a membrane quad's 3-cell would be its whole surface
    const bool volume = m.elements()[e].kind == sewn::physics::ElementKind::hexahedron;
    const DartList ring = volume ? m.map().template cell<D>(m.elements()[e].dart) : m.map().template cell<2>(m.elements()[e].dart);
    for (Dart x : ring) {
      const Vector3d r = m.rest_position(m.node_of(x));
      Vector3d v = Vector3d::Zero();
      for (Index k : c) {
        double w = 1;
        for (int a = 0; a < 3; ++a) {
          if (!(hi[a] > lo[a])) continue;  // the axis normal to a flat element
          const double t = (r[a] - lo[a]) / (hi[a] - lo[a]);
          const double rk = m.rest_position(k)[a];
          w *= std::abs(rk - hi[a]) < std::abs(rk - lo[a]) ? t : 1 - t;  // rounding: corners on one face differ in the last bits
        }
        v += w * m.nodes().velocity(k);
      }
      if ((v - m.nodes().velocity(m.node_of(x))).norm() > 1e-9 * (1 + v.norm())) {
        if (bad == 0) {
          std::string cs;
          for (Index k : c) cs += std::to_string(k) + " ";
          MESSAGE("element " << e << " corners " << cs << " particle " << m.node_of(x));
        }
        ++bad;
      }
    }
  }
  return bad;
}

}  // namespace

TEST_CASE("cut across a level jump, 2D: the coarser element is refined first, its T-junction becomes a corner") {
  MssModel<2> m(quads(2, 1), {material}, {}, refine_test::no_gravity());
  (void)sewn::refine::refine_element(m, 0);
  affine_velocities(m);
  REQUIRE(sewn::refine::t_junctions(m).size() == 1);  // element 1's side midpoint
  const double mass0 = m.node_mass();
  const Vector3d p0 = momentum(m);
  const auto jump = facets_between(m, 2, 1);
  REQUIRE(jump.size() == 2);
  // given from the coarser side or from the finer: the same cut
  const Facet f = m.elements()[m.element_of(jump[0].dart)].level == 1 ? jump[0] : Facet{m.map().beta(jump[0].dart, 2), 2};
  const sewn::refine::CutReport r = sewn::refine::cut(m, std::vector<Facet>{f});
  refine_test::check_all(m);
  CHECK(r.refined == 1);
  CHECK(r.facets == 1);               // one half of the side: the other half stays sewn
  CHECK(!m.elements()[1].alive);      // element 1 is now its 4 children
  CHECK(sewn::refine::t_junctions(m).empty());
  CHECK(facets_between(m, 2, 1).empty());
  CHECK(unweighed(m) == 0);
  CHECK(std::abs(m.node_mass() - mass0) <= 1e-13 * mass0);
  CHECK((momentum(m) - p0).norm() <= 1e-13 * p0.norm());
}

TEST_CASE("cut across a level jump of 4:1, 2D: the coarser element is refined twice") {
  MssModel<2> m(quads(2, 1), {material}, {}, refine_test::no_gravity());
  const auto first = sewn::refine::refine_element(m, 0);
  // the child of element 0 at the side shared with element 1 (x = 0.1), refined again
  Index next = sewn::physics::invalid_index;
  for (Index c : first.children)
    if (m.element_centroid(c).x() > 0.05 && m.element_centroid(c).y() < 0.05) next = c;
  REQUIRE(next != sewn::physics::invalid_index);
  (void)sewn::refine::refine_element(m, next);
  affine_velocities(m);
  const double mass0 = m.node_mass();
  const Vector3d p0 = momentum(m);
  const auto jump = facets_between(m, 4, 1);
  REQUIRE(jump.size() == 2);
  const sewn::refine::CutReport r = sewn::refine::cut(m, std::vector<Facet>{jump[1]});
  refine_test::check_all(m);
  CHECK(r.refined == 2);
  CHECK(r.facets == 1);
  CHECK(unweighed(m) == 0);
  CHECK(facets_between(m, 4, 1).empty());
  CHECK(std::abs(m.node_mass() - mass0) <= 1e-13 * mass0);
  CHECK((momentum(m) - p0).norm() <= 1e-13 * p0.norm());
}

TEST_CASE("cut across a level jump: a batch whose refinements split another requested facet cuts all of it") {
  MssModel<2> m(quads(3, 1), {material}, {}, refine_test::no_gravity());
  (void)sewn::refine::refine_element(m, 0);
  // element 0's children | element 1 (a jump) and element 1 | element 2 (one level)
  std::vector<Facet> batch = facets_between(m, 2, 1);
  REQUIRE(batch.size() == 2);
  batch.resize(1);
  for (const Facet& f : sewn::refine::inner_facets(m)) {
    const Index a = m.element_of(f.dart), b = element_across(m, f);
    if ((a == 1 && b == 2) || (a == 2 && b == 1)) batch.push_back(f);
  }
  REQUIRE(batch.size() == 2);
  const sewn::refine::CutReport r = sewn::refine::cut(m, batch);
  refine_test::check_all(m);
  CHECK(r.refined == 2);  // element 1 for the jump, then element 2, which the first split left coarser
  CHECK(r.facets == 3);   // one half of the first side, both halves of the second
  const auto across = sewn::refine::facets_across_plane(m, Vector3d(0.2, 0, 0), Vector3d(1, 0, 0));
  CHECK(across.empty());  // the line x = 0.2 is cut all along
  CHECK(sewn::refine::facets_across_plane(m, Vector3d(0.1, 0, 0), Vector3d(1, 0, 0)).size() == 1);
  CHECK(unweighed(m) == 0);
}

TEST_CASE("cut across a level jump, 3D: the coarser hexahedron is refined first") {
  MssModel<3> m(hexes(2, 1, 1), {material}, {}, refine_test::no_gravity());
  (void)sewn::refine::refine_element(m, 0);
  affine_velocities(m);
  const double mass0 = m.node_mass();
  const Vector3d p0 = momentum(m);
  const auto jump = facets_between(m, 2, 1);
  REQUIRE(jump.size() == 4);
  const sewn::refine::CutReport r = sewn::refine::cut(m, std::vector<Facet>{jump[2]});
  refine_test::check_all(m);
  CHECK(r.refined == 1);
  CHECK(r.facets == 1);
  CHECK(sewn::refine::t_junctions(m).empty());
  CHECK(facets_between(m, 2, 1).empty());
  CHECK(unweighed(m) == 0);
  CHECK(std::abs(m.node_mass() - mass0) <= 1e-13 * mass0);
  CHECK((momentum(m) - p0).norm() <= 1e-13 * p0.norm());
  // the rest of the face, cut too: the two pieces come apart with the masses of their elements
  (void)sewn::refine::cut(m, facets_between(m, 2, 2));
  refine_test::check_all(m);
  CHECK(unweighed(m) == 0);
  CHECK(std::abs(m.node_mass() - mass0) <= 1e-13 * mass0);
}

TEST_CASE("a facet named by its mesh points after refinement split it: the cut takes its pieces") {
  // 2D: the inner edge x = 0.1 of two quads (points 1 and 4), split by refining one or both
  for (bool both : {false, true}) {
    MssModel<2> m(quads(2, 1), {material}, {}, refine_test::no_gravity());
    (void)(both ? sewn::refine::refine_all(m) : sewn::refine::refine_element(m, 0));
    const std::vector<std::vector<std::uint32_t>> edge{{1, 4}};
    const std::vector<Facet> pieces = sewn::refine::facets_with_points(m, std::span(edge));
    REQUIRE(pieces.size() == 2);
    for (const Facet& f : pieces) CHECK(std::abs(m.rest_position(m.node_of(f.dart)).x() - 0.1) < 1e-15);
    const sewn::refine::CutReport r = sewn::refine::cut(m, pieces);
    refine_test::check_all(m);
    CHECK(r.facets == 2);
    CHECK(m.map().count_components() == 2);
    CHECK(unweighed(m) == 0);
    CHECK_THROWS_WITH_AS(sewn::refine::facets_with_points(m, std::span(edge)), doctest::Contains("already cut"),
                         sewn::physics::InputError);
  }
  // 3D: the face x = 0.3 between two hexahedra (points 1, 4, 10, 7), the first refined: its 4
  // pieces, the coarser side refined by the cut to meet them
  MssModel<3> m(hexes(2, 1, 1), {material}, {}, refine_test::no_gravity());
  (void)sewn::refine::refine_element(m, 0);
  affine_velocities(m);
  const double mass0 = m.node_mass();
  const Vector3d p0 = momentum(m);
  const std::vector<std::vector<std::uint32_t>> face{{1, 4, 10, 7}}, other{{0, 1, 7, 6}};
  const std::vector<Facet> pieces = sewn::refine::facets_with_points(m, std::span(face));
  REQUIRE(pieces.size() == 4);
  const sewn::refine::CutReport r = sewn::refine::cut(m, pieces);
  refine_test::check_all(m);
  CHECK(r.facets == 4);
  CHECK(r.refined == 1);
  CHECK(m.map().count_components() == 2);
  CHECK(unweighed(m) == 0);
  CHECK(std::abs(m.node_mass() - mass0) <= 1e-13 * mass0);
  CHECK((momentum(m) - p0).norm() <= 1e-13 * p0.norm());
  // a boundary face of the refined hexahedron is still no face between two elements
  CHECK_THROWS_WITH_AS(sewn::refine::facets_with_points(m, std::span(other)), doctest::Contains("boundary"),
                       sewn::physics::InputError);
}

TEST_CASE("coarsening is refused where a cut ends at a side midpoint a coarser neighbour shares") {
  MssModel<2> m(quads(2, 1), {material}, {}, refine_test::no_gravity());
  (void)sewn::refine::refine_element(m, 0);
  (void)sewn::refine::refine_element(m, 1);
  const auto same = facets_between(m, 2, 2);
  std::vector<Facet> half;  // one half of the side x = 0.1, between the two families
  for (const Facet& f : same)
    if (m.elements()[m.element_of(f.dart)].parent != m.elements()[element_across(m, f)].parent) half.push_back(f);
  REQUIRE(half.size() == 2);
  half.resize(1);
  (void)sewn::refine::cut(m, half);
  (void)sewn::refine::coarsen(m, 1);  // element 1 back: the midpoint stays, its T-junction
  refine_test::check_all(m);
  const auto before = std::make_tuple(m.map().num_darts(), m.nodes().num_alive(), m.springs().num_alive());
  std::string why;
  CHECK(!sewn::refine::can_coarsen(m, 0, &why));
  CHECK(why.find("cut ending at the midpoint") != std::string::npos);
  CHECK_THROWS_WITH_AS(sewn::refine::coarsen(m, 0), doctest::Contains("cut ending"), sewn::physics::InputError);
  CHECK(before == std::make_tuple(m.map().num_darts(), m.nodes().num_alive(), m.springs().num_alive()));
  refine_test::check_all(m);
}

namespace {

// One random operation among refine (twice as likely), coarsen and cut (any inner facet).
template <int D>
int random_operation(MssModel<D>& m, std::mt19937& rng, const sewn::refine::RefineOptions& o, int& cuts) {
  std::vector<Index> leaves, families;
  for (Index e = 0; e < m.elements().size(); ++e) {
    if (m.elements()[e].alive && sewn::refine::level_index(m.elements()[e].level) < o.max_level) leaves.push_back(e);
    if (sewn::refine::can_coarsen(m, e)) families.push_back(e);
  }
  auto pick = [&](const auto& v) { return v[std::uniform_int_distribution<std::size_t>(0, v.size() - 1)(rng)]; };
  const int op = std::uniform_int_distribution<int>(0, 3)(rng);
  CAPTURE(op);
  if (op <= 1 && !leaves.empty()) {
    (void)sewn::refine::refine_element(m, pick(leaves), o);
    return 0;
  }
  if (op == 2 && !families.empty()) {
    (void)sewn::refine::coarsen(m, pick(families));
    return 1;
  }
  const auto inner = sewn::refine::inner_facets(m);
  if (inner.empty()) return -1;
  (void)sewn::refine::cut(m, std::vector<Facet>{pick(inner)});
  ++cuts;
  return 2;
}

template <int D>
void random_sequences(MssModel<D> (*make)(), int steps, int max_level, std::initializer_list<unsigned> seeds) {
  for (unsigned seed : seeds) {
    CAPTURE(seed);
    MssModel<D> m = make();
    affine_velocities(m);
    const double mass0 = m.node_mass();
    std::mt19937 rng(seed);
    sewn::refine::RefineOptions o;
    o.max_level = max_level;
    int cuts = 0;
    for (int step = 0; step < steps; ++step) {
      CAPTURE(step);
      // T-junctions move with their masters, as after every step: the state refinement expects
      m.system().slaves().after_step(m.nodes());
      REQUIRE(inconsistent_particles(m) == 0);
      const Vector3d p0 = momentum(m);
      const int op = random_operation(m, rng, o, cuts);
      CAPTURE(op);
      refine_test::check_all(m);
      refine_test::check_constraints_fresh(m);
      REQUIRE(unweighed(m) == 0);
      CHECK(std::abs(m.node_mass() - mass0) <= 1e-13 * mass0);
      REQUIRE((momentum(m) - p0).norm() <= 1e-12 * p0.norm());
    }
    CHECK(cuts > 0);
  }
}

MssModel<2> make_quads() { return MssModel<2>(quads(3, 3), {material}, {}, refine_test::no_gravity()); }
MssModel<3> make_hexes() { return MssModel<3>(hexes(2, 2, 1), {material}, {}, refine_test::no_gravity()); }
// quads as membranes of a 3-map (faces with no volume, as `sewn run` builds every mesh)
MssModel<3> make_membrane() { return MssModel<3>(quads(3, 3), {material}, {}, refine_test::no_gravity()); }

}  // namespace

TEST_CASE("cut, refine and coarsen: seeded random sequences across level jumps, 2D") {
  random_sequences<2>(make_quads, 100, 5, {1u, 2u, 3u, 4u, 5u, 6u, 7u, 8u, 9u, 10u, 11u, 12u, 13u, 14u, 15u, 16u, 17u, 18u, 19u, 20u, 21u, 22u, 23u, 24u});
}

TEST_CASE("cut, refine and coarsen: seeded random sequences across level jumps, 3D") {
  random_sequences<3>(make_hexes, 50, 4, {1u, 2u, 3u, 4u, 5u, 6u, 7u, 8u, 9u, 10u, 11u, 12u, 13u, 14u, 15u, 16u, 17u, 18u, 19u, 20u, 21u, 22u, 23u, 24u});
}

TEST_CASE("cut, refine and coarsen: seeded random sequences across level jumps, membrane quads of a 3-map") {
  random_sequences<3>(make_membrane, 100, 5, {1u, 2u, 3u, 4u, 5u, 6u, 7u, 8u, 9u, 10u, 11u, 12u, 13u, 14u, 15u, 16u, 17u, 18u, 19u, 20u, 21u, 22u, 23u, 24u});
}

}  // namespace test_cut_levels
