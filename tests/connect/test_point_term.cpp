// PointConnections as a force term under the Newton integrator: the assembled forces, torques
// and Jacobian of a rod–shell joint against finite differences (the rod's θ a System angle),
// the 2019 paper's Fig. 10 release (a rod turned 3.5π inside a held triangle; released, the
// triangle counter-rotates by the whole 3.5π with the incremental angles; the direct one,
// whose energy jumps where the angle wraps, fails), the singular-configuration guard, the cap
// on a Newton trial's joint turn (a spin that flings the initial guess past the guard converges
// to the answer of small trials; a rigid rotation is not capped and costs no force), the
// stiff option for a rigid joint, and the errors of a rod side whose twist is not a DOF.

#include <cmath>
#include <limits>
#include <numbers>
#include <random>
#include <vector>

#include <Eigen/Dense>
#include <doctest/doctest.h>

#include "spun_step.hpp"
#include "sewn/connect/point_term.hpp"
#include "sewn/physics/basic_terms.hpp"
#include "sewn/physics/integrate/newton_euler.hpp"
#include "sewn/physics/springs.hpp"
#include "sewn/physics/system.hpp"

namespace test_point_term {

using namespace sewn;
using namespace sewn::connect;
using physics::Index;

namespace point_term_test {

constexpr double pi = std::numbers::pi;

// A rod edge (node 0 → joint 1) along −z into the joint, and a triangle (joint, 2, 3) hanging
// below it in the xz plane, its corner's bisector continuing the rod; springs hold its shape.
struct RodInShell {
  physics::System sys;
  physics::rods::Rods* rods = nullptr;
  PointConnections* joint = nullptr;
  Index theta = 0;
  explicit RodInShell(TwistUpdate update, double triangle_mass = 0.01) {
    auto& nodes = sys.nodes();
    const Index r0 = nodes.add(Vec3(0, 0, 0.1), Vec3::Zero(), 0.01);
    const Index j = nodes.add(Vec3(0, 0, 0), Vec3::Zero(), 0.01);
    const Index a = nodes.add(Vec3(0.05, 0, -0.1), Vec3::Zero(), triangle_mass);
    const Index b = nodes.add(Vec3(-0.05, 0, -0.1), Vec3::Zero(), triangle_mass);
    nodes.fix(r0);
    nodes.fix(j);
    rods = &sys.add<physics::rods::Rods>();
    const std::vector<Index> ids{r0, j};
    (void)rods->add_rod(ids, nodes.x(), false, physics::rods::Section::circular(1e7, 0.3, 0.005));
    rods->use_angle_dofs(sys.angles(), 1e-7);
    theta = rods->angle_of(0, 0);
    auto& springs = sys.add<physics::Springs>();
    for (auto [p, q] : {std::pair{j, a}, std::pair{j, b}, std::pair{a, b}})
      (void)springs.add(p, q, 100.0, (nodes.position(p) - nodes.position(q)).norm());
    joint = &sys.add<PointConnections>(rods, update);
    (void)joint->add("rod in shell", RodEdgeRef{0, 0}, TriangleSide{{j, a, b}, std::nullopt}, {1e-3, 1e-3}, sys.state());
  }
  // The triangle's turn about +z: the angle of its far edge (b → a) in the xy plane.
  [[nodiscard]] double triangle_angle() const {
    const Vec3 e = sys.nodes().position(2) - sys.nodes().position(3);
    return std::atan2(e.y(), e.x());
  }
};

double unwrap_to(double raw, double previous) { return raw + 2 * pi * std::round((previous - raw) / (2 * pi)); }



TEST_CASE("point connections term: forces, torques and Jacobian of a rod-shell joint against finite differences") {
  RodInShell s(TwistUpdate::incremental_ii);
  std::mt19937 rng(10);
  std::normal_distribution<double> noise(0, 0.01);
  for (double& x : s.sys.nodes().x()) x += noise(rng);
  s.sys.angles().values()[s.theta] += 0.7;
  const std::size_t n3 = 3 * std::size_t{s.sys.nodes().size()}, total = n3 + 3;
  std::vector<double> q(total, 0.0), zero(total, 0.0);
  std::copy(s.sys.nodes().x().begin(), s.sys.nodes().x().end(), q.begin());
  q[n3] = s.sys.angles().values()[0];
  auto view = [&](const std::vector<double>& qq) {
    return physics::StateView{std::span<const double>(qq).first(n3), std::span<const double>(zero).first(n3),
                              s.sys.nodes().masses(), std::span<const double>(qq).subspan(n3, 1),
                              std::span<const double>(zero).subspan(n3, 1)};
  };
  auto force = [&](const std::vector<double>& qq) {
    std::vector<double> f(total, 0.0);
    s.joint->add_forces(view(qq), f);
    return f;
  };
  const std::vector<double> f0 = force(q);
  physics::BlockMatrix& A = s.sys.matrix();
  A.set_zero();
  physics::JacobianRequest req;
  req.matrix = &A;
  req.cx = 1.0;
  s.joint->add_jacobians(view(q), req);
  const Eigen::MatrixXd J(A.to_sparse());
  const double eps = 1e-6;
  double worst_f = 0, worst_j = 0, scale_f = 0, scale_j = 0;
  for (std::size_t k = 0; k <= n3; ++k) {
    std::vector<double> qp = q, qm = q;
    qp[k] += eps;
    qm[k] -= eps;
    const double fd = -(s.joint->potential_energy(view(qp)) - s.joint->potential_energy(view(qm))) / (2 * eps);
    worst_f = std::max(worst_f, std::abs(fd - f0[k]));
    scale_f = std::max(scale_f, std::abs(f0[k]));
    const std::vector<double> fp = force(qp), fm = force(qm);
    for (std::size_t r = 0; r <= n3; ++r) {
      const double d = (fp[r] - fm[r]) / (2 * eps);
      worst_j = std::max(worst_j, std::abs(d - J(static_cast<Eigen::Index>(r), static_cast<Eigen::Index>(k))));
      scale_j = std::max(scale_j, std::abs(d));
    }
  }
  MESSAGE("rod-shell joint: |f - fd| " << worst_f << " of " << scale_f << ", |J - fd| " << worst_j << " of " << scale_j);
  CHECK(std::abs(f0[n3]) > 1e-4);  // the torque on θ
  CHECK(worst_f < 1e-6 * scale_f);
  CHECK(worst_j < 1e-5 * scale_j);
}

// Turns the rod 3.5π with the triangle held, releases the triangle, lets it settle; returns
// the triangle's tracked turn about +z.
double released_turn(TwistUpdate update, double* largest_step_turn = nullptr) {
  RodInShell s(update);
  s.sys.nodes().fix(2);
  s.sys.nodes().fix(3);
  s.sys.add<physics::MassDamping>(3.0);
  physics::integrate::NewtonEuler newton;
  const double h = 0.01;
  s.sys.angles().set_fixed(s.theta, true);
  s.sys.angles().rates()[s.theta] = 0.35 * pi / h;
  for (int k = 0; k < 10; ++k) (void)newton.step(s.sys, h);
  CHECK(s.sys.angles().values()[s.theta] == doctest::Approx(3.5 * pi));
  s.sys.angles().rates()[s.theta] = 0.0;
  s.sys.nodes().unfix(2);
  s.sys.nodes().unfix(3);
  double turn = s.triangle_angle(), largest = 0;
  for (int k = 0; k < 1000; ++k) {
    (void)newton.step(s.sys, h);
    const double next = unwrap_to(s.triangle_angle(), turn);
    largest = std::max(largest, std::abs(next - turn));
    turn = next;
  }
  if (largest_step_turn) *largest_step_turn = largest;
  return turn;
}

TEST_CASE("point connections term: the paper's Fig. 10 release, the shell counter-rotates by the tracked angle") {
  double largest = 0;
  const double incremental = released_turn(TwistUpdate::incremental_ii, &largest);
  const double incremental_i = released_turn(TwistUpdate::incremental_i);
  const double direct = released_turn(TwistUpdate::direct);
  MESSAGE("released triangle turned " << incremental / pi << " pi (update II), " << incremental_i / pi << " pi (I), "
                                      << direct / pi << " pi (direct); largest turn per step " << largest << " rad");
  CHECK(std::abs(incremental) == doctest::Approx(3.5 * pi).epsilon(1e-3));
  CHECK(incremental_i == doctest::Approx(incremental).epsilon(1e-6));
  // The direct angle wraps at ±π; with δ̄ ≠ 0 its energy jumps down at each wrap, so the
  // released triangle never finds the rod's 3.5π: it ends far from it (here it is spun on).
  CHECK(std::abs(direct - incremental) > pi);
  CHECK(largest < 1.0);
}

TEST_CASE("point connections term: singular configurations have infinite energy, a step onto one is refused") {
  RodInShell s(TwistUpdate::incremental_ii);
  CHECK(std::isfinite(s.sys.potential_energy()));
  // A twist increment past max_twist_increment since the accepted state: it would alias.
  s.sys.angles().values()[s.theta] += 3.0;
  CHECK(std::isinf(s.sys.potential_energy()));
  s.sys.angles().values()[s.theta] -= 3.0;
  // The triangle folded back along the rod: the transport's singular axes.
  auto& nodes = s.sys.nodes();
  for (Index i : {Index{2}, Index{3}}) {
    Vec3 p = nodes.position(i);
    p.z() = -p.z();
    nodes.set_position(i, p);
  }
  CHECK(s.joint->evaluate(0, s.sys.state()).near_antiparallel);
  CHECK(std::isinf(s.sys.potential_energy()));
  for (Index i : {Index{2}, Index{3}}) {
    Vec3 p = nodes.position(i);
    p.z() = -p.z();
    nodes.set_position(i, p);
  }
  // A prescribed turn of 3 rad in one step: the predicted state is singular, the step refused.
  s.sys.angles().set_fixed(s.theta, true);
  s.sys.angles().rates()[s.theta] = 3.0 / 0.01;
  physics::integrate::NewtonEuler newton;
  const double before = s.sys.angles().values()[s.theta];
  CHECK_THROWS_AS((void)newton.step(s.sys, 0.01), physics::integrate::NewtonError);
  CHECK(s.sys.angles().values()[s.theta] == before);
}

// The change dq (a state's layout, velocities zero) turning RodInShell's whole body rigidly by
// `angle` about x (rod, θ and triangle) and its rod's θ by `twist` more.
struct Change {
  std::vector<double> x, theta;
};
Change rigid_turn_and_twist(const RodInShell& s, double angle, double twist) {
  const Eigen::Matrix3d R = Eigen::AngleAxisd(angle, Vec3::UnitX()).toRotationMatrix();
  Change c{std::vector<double>(s.sys.nodes().x().size()), {twist}};
  for (Index i = 0; i < s.sys.nodes().size(); ++i) {
    const Vec3 p = s.sys.nodes().position(i);
    const Vec3 d = R * p - p;
    for (int a = 0; a < 3; ++a) c.x[3 * std::size_t{i} + static_cast<std::size_t>(a)] = d[a];
  }
  return c;
}

TEST_CASE("point connections term: a trial's joint turn is capped; a rigid rotation is not, and costs no force") {
  RodInShell s(TwistUpdate::incremental_ii);
  const physics::StateView at = s.sys.state();
  auto fraction = [&](const Change& c) {
    const std::vector<double> zero(c.x.size(), 0.0), zero_theta(1, 0.0);
    return s.joint->step_fraction(at, {c.x, zero, at.mass, c.theta, zero_theta});
  };
  // The rod's frame is transported along the turn of its tangent, which a turn about x is: the
  // joint's twist and bend do not move, so 1.5 rad in one trial is allowed.
  CHECK(fraction(rigid_turn_and_twist(s, 1.5, 0.0)) == 1.0);
  // 3 rad of twist: halved until 3α ≤ π/4.
  CHECK(fraction(rigid_turn_and_twist(s, 0.0, 3.0)) == 0.25);
  CHECK(fraction(rigid_turn_and_twist(s, 1.5, 3.0)) == 0.25);
  s.joint->set_max_trial_turn(std::numeric_limits<double>::infinity());
  CHECK(fraction(rigid_turn_and_twist(s, 0.0, 3.0)) == 1.0);
  CHECK_THROWS_WITH_AS(s.joint->set_max_trial_turn(0.0), doctest::Contains("max_trial_turn"), physics::InputError);
  // the turned body: the same energy (zero) and no force
  const Change c = rigid_turn_and_twist(s, 1.5, 0.0);
  auto x = s.sys.nodes().x();
  for (std::size_t k = 0; k < x.size(); ++k) x[k] += c.x[k];
  std::vector<double> f(x.size() + 1, 0.0);
  s.joint->add_forces(s.sys.state(), f);
  double largest = 0;
  for (double v : f) largest = std::max(largest, std::abs(v));
  CHECK(s.joint->potential_energy(s.sys.state()) < 1e-20);
  CHECK(largest < 1e-12);
}

// One step of RodInShell (triangle free) whose rod spins at 3 rad per step, θ free: the initial
// guess θ_n + 3 rad lies past the jump guard. Returns the state after the step (x, then θ).
std::vector<double> spun_step(double max_turn, physics::integrate::NewtonReport& rep) {
  RodInShell s(TwistUpdate::incremental_ii);
  s.joint->set_max_trial_turn(max_turn);
  std::vector<double> q = sewn::connect::test::spun_step(s.sys, s.theta, 3.0, rep);
  REQUIRE(s.sys.angles().size() == 1);  // q ends with θ
  CHECK(std::isfinite(s.sys.potential_energy()));
  return q;
}

TEST_CASE("point connections term: a joint driven past its guard by the initial guess converges, as by small sub-steps") {
  physics::integrate::NewtonReport capped, fine, uncapped;
  // without the cap, the guess's energy is infinite: refused
  CHECK_THROWS_AS((void)spun_step(std::numeric_limits<double>::infinity(), uncapped), physics::integrate::NewtonError);
  const std::vector<double> a = spun_step(default_max_trial_turn, capped);
  const std::vector<double> b = spun_step(0.05, fine);
  MESSAGE("spun joint: guess fraction " << capped.guess_fraction << " in " << capped.iterations << " iterations ("
                                        << capped.term_step_limits << " capped); at 0.05 rad per trial " << fine.guess_fraction
                                        << " in " << fine.iterations << " (" << fine.term_step_limits << "); theta "
                                        << a.back() << " and " << b.back());
  CHECK(capped.guess_fraction == 0.25);
  CHECK(fine.guess_fraction == 1.0 / 64);
  CHECK(std::abs(a.back()) > 0.1);  // the spin carried the rod on
  double largest = 0;
  for (std::size_t k = 0; k < a.size(); ++k) largest = std::max(largest, std::abs(a[k] - b[k]));
  CHECK(largest < 1e-9);
}

// A horizontal cantilever of two rods sharing node 5 (rod A: nodes 0..5, clamped at 0, 1 and
// θ^0; rod B: nodes 5..10), joined at node 5 with stiffness k (none: a free hinge), or one
// unsplit rod; settled under gravity by heavily damped Newton steps. Returns the tip height and
// (joined) the joint's bend angle.
struct CantileverResult {
  double tip = 0, joint_bend = 0;
};
CantileverResult settled_cantilever(bool split, PointStiffness k) {
  physics::System sys;
  const double L = 0.5, r = 0.005, rho = 1000;
  const auto sec = physics::rods::Section::circular(1e8, 0.3, r);
  const double m = rho * pi * r * r * L / 10;
  std::vector<Index> ids;
  for (int i = 0; i <= 10; ++i) ids.push_back(sys.nodes().add(Vec3(L * i / 10, 0, 0), Vec3::Zero(), m));
  sys.nodes().fix(ids[0]);
  sys.nodes().fix(ids[1]);
  auto& rods = sys.add<physics::rods::Rods>();
  if (split) {
    (void)rods.add_rod(std::vector<Index>(ids.begin(), ids.begin() + 6), sys.nodes().x(), false, sec);
    (void)rods.add_rod(std::vector<Index>(ids.begin() + 5, ids.end()), sys.nodes().x(), false, sec);
  } else {
    (void)rods.add_rod(ids, sys.nodes().x(), false, sec);
  }
  rods.rod(0).fix_theta(0);
  rods.use_angle_dofs(sys.angles(), rho * pi * std::pow(r, 4) / 2);
  PointConnections* joint = nullptr;
  if (split) {
    joint = &sys.add<PointConnections>(&rods);
    (void)joint->add("joint", RodEdgeRef{0, 4}, RodEdgeRef{1, 0}, k, sys.state());
  }
  sys.add<physics::Gravity>(Vec3(0, 0, -9.81));
  sys.add<physics::MassDamping>(50.0);
  physics::integrate::NewtonEuler newton;
  for (int s = 0; s < 300; ++s) (void)newton.step(sys, 0.02);
  CantileverResult out;
  out.tip = sys.nodes().position(ids.back()).z();
  if (joint) out.joint_bend = joint->evaluate(0, sys.state()).bend_angle;
  return out;
}


TEST_CASE("point connections term: a split cantilever rejoined with k_b = EI/D bends like the rod; the stiff option holds the joint rigid") {
  const auto sec = physics::rods::Section::circular(1e8, 0.3, 0.005);
  const double D = 0.05;  // edge length = Voronoi length of an interior vertex
  const CantileverResult whole = settled_cantilever(false, {});
  const CantileverResult matched = settled_cantilever(true, {sec.GJ / D, sec.EI1 / D});
  const CantileverResult rigid = settled_cantilever(true, rigid_stiffness(sec, D, 1e3));
  MESSAGE("cantilever tip: unsplit " << whole.tip << " m, joined with EI/D " << matched.tip << " m (joint bend "
                                     << matched.joint_bend << " rad), rigid " << rigid.tip << " m (joint bend " << rigid.joint_bend
                                     << " rad)");
  CHECK(whole.tip < -0.005);  // a real deflection
  CHECK(matched.tip == doctest::Approx(whole.tip).epsilon(1e-3));
  CHECK(rigid.joint_bend < 2e-3 * matched.joint_bend);
  CHECK(rigid.tip > whole.tip);  // stiffer than the rod
}

TEST_CASE("point connections term: compaction renumbers the connection's own node ids, not only its DOFs") {
  RodInShell s(TwistUpdate::incremental_ii);
  const std::vector<Index> old_to_new{0, 3, 5, 6};  // as if nodes had been removed before each
  s.joint->remap_nodes(old_to_new);
  const PointConnection& c = s.joint->connection(0);
  CHECK(c.joint() == 3);
  CHECK((c.position_nodes() == std::vector<Index>{0, 3, 3, 5, 6}));
}

TEST_CASE("point connections term: a connection whose node is removed goes with it, the table compacts") {
  RodInShell s(TwistUpdate::incremental_ii);
  CHECK(s.joint->remove_dangling(s.sys.nodes()) == 0);  // nothing removed: kept
  s.sys.nodes().remove(3);                               // a corner of the triangle side
  CHECK_THROWS_WITH_AS(s.joint->check_nodes(s.sys.nodes()), doctest::Contains("point connection 'rod in shell' refers to node 3"),
                       physics::InputError);  // without the rule, compaction refuses it by name
  CHECK(s.joint->remove_dangling(s.sys.nodes()) == 1);
  CHECK(s.joint->size() == 0);
}

TEST_CASE("point connections term: a rod side needs the rods' twist as angle DOFs") {
  physics::System sys;
  const Index a = sys.nodes().add(Vec3(0, 0, 0), Vec3::Zero(), 1.0);
  const Index b = sys.nodes().add(Vec3(1, 0, 0), Vec3::Zero(), 1.0);
  const Index c = sys.nodes().add(Vec3(-1, 1, 0), Vec3::Zero(), 1.0);
  const Index d = sys.nodes().add(Vec3(-1, -1, 0), Vec3::Zero(), 1.0);
  auto& rods = sys.add<physics::rods::Rods>();
  (void)rods.add_rod(std::vector<Index>{a, b}, sys.nodes().x(), false, physics::rods::Section::circular(1e6, 0.3, 0.01));
  auto& joints = sys.add<PointConnections>(&rods);
  CHECK_THROWS_WITH_AS((void)joints.add("tip", RodEdgeRef{0, 0}, TriangleSide{{a, c, d}, std::nullopt}, {1, 1}, sys.state()),
                       doctest::Contains("'tip'"), physics::InputError);
  rods.use_angle_dofs(sys.angles(), 0.0);
  CHECK_THROWS_WITH_AS((void)joints.add("far", RodEdgeRef{0, 3}, TriangleSide{{a, c, d}, std::nullopt}, {1, 1}, sys.state()),
                       doctest::Contains("out of range"), physics::InputError);
  CHECK(joints.add("tip", RodEdgeRef{0, 0}, TriangleSide{{a, c, d}, std::nullopt}, {1, 1}, sys.state()) == 0);
  CHECK_THROWS_AS((void)rigid_stiffness(physics::rods::Section::circular(1e6, 0.3, 0.01), 0.0), physics::InputError);
}

}  // namespace point_term_test

}  // namespace test_point_term
