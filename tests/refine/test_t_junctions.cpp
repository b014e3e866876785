// T-junctions as slave nodes (PHYSICS_NOTES §2.6): a free body under internal forces only keeps
// its momenta with the virtual-work reduction, in both integrators; the 2014 paper's equal-share
// force split and projection keeps the total force but not the torque.
#include <doctest/doctest.h>

#include <cmath>
#include <random>

#include <Eigen/Geometry>

#include "sewn/physics/integrators.hpp"
#include "sewn/refine/criterion.hpp"
#include "sewn/refine/hierarchy.hpp"
#include "sewn/refine/subdivide.hpp"

namespace test_t_junctions {

using namespace sewn;
using namespace sewn::physics;
using namespace sewn::refine;
using Eigen::Vector3d;

namespace {

MssOptions free_body() {
  MssOptions o;
  o.gravity.setZero();
  o.damping = DampingModel::none;
  return o;
}

// A 3×3 quad grid with its centre refined, then a child of it twice more: border T-junctions
// at levels 1 and 2, some with a master that is itself a T-junction.
void refine_2d(MssModel<2>& m) {
  const RefineReport a = refine_element(m, 4);
  const RefineReport b = refine_element(m, a.children[0]);
  (void)refine_element(m, b.children[2]);
}

// A 2×2×1 hexahedral block with one hexahedron refined, then one of its children: border and
// middle T-junctions.
void refine_3d(MssModel<3>& m) {
  const RefineReport a = refine_element(m, 0);
  (void)refine_element(m, a.children[6]);
}

// Random state, then the constraints applied: positions and velocities of T-junctions from their masters.
template <int D>
void random_state(MssModel<D>& m, unsigned seed) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> u(-1, 1);
  for (Index i = 0; i < m.nodes().size(); ++i) {
    m.nodes().set_position(i, m.rest_position(i) + 0.02 * Vector3d(u(rng), u(rng), D == 3 ? u(rng) : 0.3 * u(rng)));
    m.nodes().set_velocity(i, Vector3d(u(rng), u(rng), u(rng)));
  }
  SlaveNodes plain = m.system().slaves();
  plain.set_treatment(SlaveTreatment::reduction);
  plain.after_step(m.nodes());
}

struct Momenta {
  Vector3d linear = Vector3d::Zero(), angular = Vector3d::Zero();
};

// Momenta of the particles the integrator moves, with the masses it moves them with: every
// particle with its own mass (no slaves, or the paper's treatment), or the masters with the
// slaves' masses lumped onto them (the reduction). The linear momentum is the same either way
// when the slaves follow their masters.
Momenta momenta(const System& sys) {
  const NodeTable& n = sys.nodes();
  const SlaveNodes& s = sys.slaves();
  std::vector<double> mass(n.masses().begin(), n.masses().end());
  if (s.reduces())
    for (std::size_t i = s.slaves().size(); i-- > 0;) {
      const SlaveNode& v = s.slaves()[i];
      for (int k = 0; k < v.masters; ++k) mass[v.master[k]] += v.weight[k] * mass[v.node];
      mass[v.node] = 0;
    }
  Momenta p;
  for (Index i = 0; i < n.size(); ++i) {
    if (!n.is_alive(i)) continue;
    p.linear += mass[i] * n.velocity(i);
    p.angular += mass[i] * n.position(i).cross(n.velocity(i));
  }
  return p;
}

Vector3d physical_momentum(const NodeTable& n) {
  Vector3d p = Vector3d::Zero();
  for (Index i = 0; i < n.size(); ++i)
    if (n.is_alive(i)) p += n.mass(i) * n.velocity(i);
  return p;
}

template <int D>
double worst_off_constraint(const MssModel<D>& m) {
  double worst = 0;
  for (const TJunction& t : t_junctions(m)) {
    Vector3d x = Vector3d::Zero();
    for (int k = 0; k < t.masters; ++k) x += t.weight[static_cast<std::size_t>(k)] * m.nodes().position(t.master[static_cast<std::size_t>(k)]);
    worst = std::max(worst, (m.nodes().position(t.node) - x).norm());
  }
  return worst;
}

template <int D>
void symplectic_run(MssModel<D>& m, SlaveTreatment treatment, Momenta& before, Momenta& after) {
  constrain_t_junctions(m, treatment);
  random_state(m, 7);
  before = momenta(m.system());
  const double h = 0.5 * m.system().stable_step().h_max;
  SymplecticEuler euler;
  // short: the paper's treatment leaves a T-junction's velocity as it was (its force is shared
  // out), so it drifts along its edge and the body soon tangles
  for (int s = 0; s < 40; ++s) (void)euler.step(m.system(), h);
  after = momenta(m.system());
}

const MaterialParams material{1e5, 0.3, 100};

}  // namespace

TEST_CASE_TEMPLATE("T-junctions: the reduction keeps linear and angular momentum, the paper's projection does not", M,
                   MssModel<2>, MssModel<3>) {
  auto build = [] {
    if constexpr (std::is_same_v<M, MssModel<2>>) {
      auto m = std::make_unique<M>(quad_grid(3, 3, {{0.1, 0.1, 1}, {}}), std::vector{material}, std::vector<std::uint32_t>{}, free_body());
      refine_2d(*m);
      return m;
    } else {
      auto m = std::make_unique<M>(hex_grid(2, 2, 1, {{0.1, 0.1, 0.1}, {}}), std::vector{material}, std::vector<std::uint32_t>{}, free_body());
      refine_3d(*m);
      return m;
    }
  };
  Momenta p0, p1, q0, q1;
  auto reduced = build();
  REQUIRE(!t_junctions(*reduced).empty());
  symplectic_run(*reduced, SlaveTreatment::reduction, p0, p1);
  const double scale_p = p0.linear.norm(), scale_l = p0.angular.norm();
  CHECK((p1.linear - p0.linear).norm() <= 1e-12 * scale_p);
  CHECK((p1.angular - p0.angular).norm() <= 1e-11 * scale_l);
  CHECK((physical_momentum(reduced->nodes()) - p0.linear).norm() <= 1e-12 * scale_p);
  CHECK(worst_off_constraint(*reduced) <= 1e-14);

  auto paper = build();
  symplectic_run(*paper, SlaveTreatment::paper_projection, q0, q1);
  CHECK((q1.linear - q0.linear).norm() <= 1e-12 * q0.linear.norm());  // total force is kept
  CHECK((q1.angular - q0.angular).norm() > 1e-6 * q0.angular.norm());  // torque is not
}

TEST_CASE("T-junctions: the linearly implicit step solves the reduced system and keeps linear momentum") {
  MssModel<3> m(hex_grid(2, 2, 1, {{0.1, 0.1, 0.1}, {}}), {material}, {}, free_body());
  refine_3d(m);
  random_state(m, 3);
  const Vector3d p0 = physical_momentum(m.nodes());
  ImplicitEulerOptions o;
  o.cg_tolerance = 1e-12;
  o.cg_max_iterations = 2000;
  LinearlyImplicitEuler euler(o);
  for (int s = 0; s < 50; ++s) {
    const StepReport r = euler.step(m.system(), 1e-3);
    REQUIRE(r.cg_converged);
  }
  CHECK((physical_momentum(m.nodes()) - p0).norm() <= 1e-9 * p0.norm());
  CHECK(worst_off_constraint(m) <= 1e-14);
}

TEST_CASE("T-junctions: the semi-implicit inverse masses are kept between steps and remade when what they are made of changes") {
  MssModel<3> m(hex_grid(2, 2, 1, {{0.1, 0.1, 0.1}, {}}), {material}, {}, free_body());
  refine_3d(m);
  // what inverse_mass_dof must return, made afresh from lumped_masses (never kept)
  auto check_fresh = [&] {
    System& sys = m.system();
    const std::vector<double> lumped = sys.slaves().lumped_masses(sys.nodes());
    const auto own = sys.nodes().inverse_mass_dof();
    std::vector<double> expected(own.size(), 0.0);
    for (std::size_t a = 0; a < own.size(); ++a) expected[a] = own[a] != 0 && lumped[a / 3] > 0 ? 1 / lumped[a / 3] : 0;
    const auto got = sys.slaves().inverse_mass_dof(sys.nodes());
    REQUIRE(got.size() == expected.size());
    for (std::size_t a = 0; a < got.size(); ++a) CHECK(got[a] == expected[a]);
  };
  REQUIRE_FALSE(m.system().slaves().empty());
  check_fresh();
  const Index master = m.system().slaves().slaves()[0].master[0];
  random_state(m, 5);  // the state alone changes nothing
  check_fresh();
  m.nodes().set_mass(master, 3 * m.nodes().mass(master));
  check_fresh();
  m.nodes().fix(master, axis_y);
  check_fresh();
  m.nodes().unfix(master);
  check_fresh();
  (void)refine_element(m, 1);  // new particles and a new set of slaves
  check_fresh();
  m.system().slaves().set_treatment(SlaveTreatment::paper_projection);
  CHECK(m.system().slaves().inverse_mass_dof(m.nodes()).data() == m.nodes().inverse_mass_dof().data());
  m.system().slaves().set_treatment(SlaveTreatment::reduction);
  check_fresh();
}

TEST_CASE("T-junctions: nested T-junctions are listed coarse to fine and bad slave lists are refused") {
  MssModel<2> m(quad_grid(3, 3, {{0.1, 0.1, 1}, {}}), {material}, {}, free_body());
  refine_2d(m);
  const auto tj = t_junctions(m);
  std::vector<SlaveNode> s;
  for (const TJunction& t : tj) s.push_back({t.node, t.master, t.weight, t.masters});
  bool nested = false;  // some master is itself a T-junction listed earlier
  for (std::size_t i = 0; i < tj.size(); ++i)
    for (std::size_t j = 0; j < i; ++j)
      nested = nested || tj[i].master[0] == tj[j].node || tj[i].master[1] == tj[j].node;
  CHECK(nested);
  SlaveNodes sn;
  std::vector<SlaveNode> reversed(s.rbegin(), s.rend());
  CHECK_THROWS_WITH_AS(sn.set(reversed), doctest::Contains("listed later"), InputError);
  std::vector<SlaveNode> bad = s;
  bad[0].weight[0] += 0.1;
  CHECK_THROWS_WITH_AS(sn.set(bad), doctest::Contains("weights sum"), InputError);
  CHECK_NOTHROW(sn.set(s));
}

TEST_CASE("adaptive refinement: the diagonal-strain criterion refines strained elements, one level per step") {
  MssModel<2> m(quad_grid(4, 1, {{0.1, 0.1, 1}, {}}), {material}, {}, free_body());
  // stretch the right end: only the last element's diagonals strain
  for (Index i = 0; i < m.nodes().size(); ++i)
    if (m.rest_position(i).x() > 0.35) m.nodes().set_position(i, m.rest_position(i) + Vector3d(0.005, 0, 0));
  const DiagonalStrain<2> criterion(2.0);
  CHECK(DiagonalStrain<2>::strain_percent(m, 3) > 2.0);
  CHECK(DiagonalStrain<2>::strain_percent(m, 0) == 0.0);
  RefineOptions o;
  o.max_level = 3;
  const RefineReport r1 = adapt(m, criterion, o);
  CHECK(r1.elements == 1);
  CHECK(m.elements()[3].first_child != invalid_index);
  const auto report = check_hierarchy(m);
  INFO(report.str());
  CHECK(report.ok());
  // the children of the strained element hold the same strain (rest data is exact): next call refines
  // them, once each, and then the maximum level stops it
  const RefineReport r2 = adapt(m, criterion, o);
  CHECK(r2.elements >= 1);
  for (Index c : r2.children) CHECK(level_index(m.elements()[c].level) == 3);
  CHECK(adapt(m, criterion, o).elements == 0);
  CHECK(check_hierarchy(m).ok());
  CHECK_THROWS_AS(DiagonalStrain<2>(0.0), InputError);
}

TEST_CASE("adaptive refinement: the adapter refines under strain and coarsens back after the hysteresis") {
  MssModel<2> m(quad_grid(4, 1, {{0.1, 0.1, 1}, {}}), {material}, {}, free_body());
  const Index particles0 = m.nodes().num_alive();
  const DiagonalStrain<2> criterion(2.0);
  Adapter<2>::Options o;
  o.refine.max_level = 2;
  o.calm_steps = 3;
  Adapter<2> adapter(criterion, o);
  auto stretch = [&](double dx) {
    for (Index i = 0; i < m.nodes().size(); ++i)
      if (m.nodes().is_alive(i)) {
        const Vector3d r = m.rest_position(i);
        m.nodes().set_position(i, r + Vector3d(r.x() > 0.35 ? dx * (r.x() - 0.3) / 0.1 : 0, 0, 0));
      }
  };
  stretch(0.005);
  CHECK(adapter.update(m).refined.elements == 1);
  CHECK(adapter.update(m).refined.elements == 0);  // at the maximum level
  stretch(0.0);                                     // released: calm from now on
  for (int s = 0; s < 2; ++s) CHECK(adapter.update(m).coarsened == 0);
  const auto r = adapter.update(m);
  CHECK(r.coarsened == 1);
  CHECK(m.nodes().num_alive() == particles0);
  CHECK(check_hierarchy(m).ok());
}

TEST_CASE("adaptive refinement: the docs/refinement.md example runs and refines the clamped end") {
  MssModel<3> beam(hex_grid(4, 1, 1, {{0.25, 0.25, 0.25}, {}}), {{100e3, 0.3, 100}}, {});
  for (Index i = 0; i < beam.nodes().size(); ++i)
    if (beam.rest_position(i).x() == 0) beam.nodes().fix(i);
  RefineOptions opt;
  opt.max_level = 3;
  const DiagonalStrain<3> strained(0.5);  // this stubby beam's root reaches about 0.8 %
  LinearlyImplicitEuler euler;
  std::uint32_t refined = 0;
  for (int s = 0; s < 200; ++s) {  // 2 s: a quarter of the beam's first period, it sags
    (void)euler.step(beam.system(), 1e-2);
    refined += adapt(beam, strained, opt).elements;
  }
  CHECK(refined > 0);
  CHECK(check_hierarchy(beam).ok());
  CHECK(beam.map().validate().ok());
}

TEST_CASE("T-junctions: the reduced solve's preconditioner is the diagonal blocks of W^T D W, nested slaves included") {
  // particle 2 on the edge 0-1, particle 3 nested on the edge 2-4: W's rows are
  // e2 = (e0 + e1)/2 and e3 = e2/4 + 3 e4/4 = e0/8 + e1/8 + 3 e4/4
  SlaveNodes sn;
  sn.set({{2, {0, 1, invalid_index, invalid_index}, {0.5, 0.5, 0, 0}, 2}, {3, {2, 4, invalid_index, invalid_index}, {0.25, 0.75, 0, 0}, 2}});
  BlockMatrix A;
  A.build_pattern(5, {});
  std::array<Eigen::Matrix3d, 5> d;
  for (Index i = 0; i < 5; ++i) {
    Eigen::Matrix3d r;
    r << 1.0 + i, 0.2, -0.1, 0.3 * i, 2.0, 0.4, 0.1, -0.2, 3.0 + 0.5 * i;
    d[i] = r * r.transpose() + Eigen::Matrix3d::Identity();  // symmetric positive definite
    A.block(A.diagonal(i)) = d[i];
  }
  const std::vector<double> free(15, 1.0);
  std::vector<double> inverse(45);
  sn.reduced_block_jacobi(A, free, inverse);
  const std::array<Eigen::Matrix3d, 3> expected = {d[0] + 0.25 * d[2] + d[3] / 64, d[1] + 0.25 * d[2] + d[3] / 64, d[4] + 0.5625 * d[3]};
  const std::array<Index, 3> masters = {0, 1, 4};
  for (std::size_t k = 0; k < 3; ++k) {
    const Eigen::Matrix3d inv = Eigen::Map<const Eigen::Matrix3d>(inverse.data() + 9 * masters[k]);
    CHECK((inv * expected[k] - Eigen::Matrix3d::Identity()).norm() <= 1e-12);
  }
  // a fixed axis is filtered out as block_jacobi_inverse does: identity on it
  std::vector<double> held = free;
  held[3 * 4 + 2] = 0;
  sn.reduced_block_jacobi(A, held, inverse);
  const Eigen::Matrix3d inv4 = Eigen::Map<const Eigen::Matrix3d>(inverse.data() + 36);
  CHECK(std::abs(inv4(2, 2) - 1.0) <= 1e-12);  // the 3x3 inverse by cofactors rounds
  CHECK(inv4(0, 2) == 0.0);
  CHECK((inv4.topLeftCorner<2, 2>() * expected[2].topLeftCorner<2, 2>() - Eigen::Matrix2d::Identity()).norm() <= 1e-12);
}

}  // namespace test_t_junctions
