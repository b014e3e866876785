// CurveConnections as a force term: the assembled forces, θ torques and Jacobian of a rod laid
// along a shell's boundary edge and across an interior (hinge) edge, against finite
// differences; the curve version of the paper's Fig. 10 release (a rod turned 3.5π inside the
// edge of a held triangle, which, released, turns about the edge by the whole tracked angle,
// where the direct angle fails); the guard; renumbering after compaction.

#include <cmath>
#include <limits>
#include <numbers>
#include <random>
#include <vector>

#include <Eigen/Dense>
#include <doctest/doctest.h>

#include "spun_step.hpp"
#include "sewn/connect/curve_term.hpp"
#include "sewn/physics/basic_terms.hpp"
#include "sewn/physics/shells/shell_terms.hpp"
#include "sewn/physics/integrate/newton_euler.hpp"
#include "sewn/physics/springs.hpp"
#include "sewn/physics/system.hpp"

namespace test_curve_term {
namespace {

using sewn::connect::CurveConnections;
using sewn::connect::FaceSide;
using sewn::connect::HingeSide;
using sewn::connect::RodEdgeRef;
using sewn::connect::TwistUpdate;
using sewn::connect::Vec3;
using sewn::physics::Index;
namespace physics = sewn::physics;

constexpr double pi = std::numbers::pi;

// A rod along x (nodes 0, 1, 2, ends fixed); a triangle (0, 1, 3) hanging below its first edge
// and a flat strip through its second edge, (1, 2, 4) above and (2, 1, 5) below; springs hold
// the shell's shape, so without the connection the shell swings freely about the rod.
struct RodAlongShell {
  physics::System sys;
  physics::rods::Rods* rods = nullptr;
  CurveConnections* curve = nullptr;
  explicit RodAlongShell(TwistUpdate update, bool with_strip = true) {
    auto& nodes = sys.nodes();
    for (const Vec3& p : {Vec3(0, 0, 0), Vec3(0.1, 0, 0), Vec3(0.2, 0, 0), Vec3(0.05, 0, -0.1), Vec3(0.15, 0, 0.1),
                          Vec3(0.15, 0, -0.1)})
      (void)nodes.add(p, Vec3::Zero(), 0.01);
    nodes.fix(0);
    nodes.fix(1);
    nodes.fix(2);
    rods = &sys.add<physics::rods::Rods>();
    const std::vector<Index> ids{0, 1, 2};
    (void)rods->add_rod(ids, nodes.x(), false, physics::rods::Section::circular(1e7, 0.3, 0.005));
    rods->use_angle_dofs(sys.angles(), 1e-7);
    auto& springs = sys.add<physics::Springs>();
    const std::vector<std::pair<Index, Index>> bars{{0, 3}, {1, 3}, {1, 4}, {2, 4}, {1, 5}, {2, 5}};
    for (auto [p, q] : bars) (void)springs.add(p, q, 100.0, (nodes.position(p) - nodes.position(q)).norm());
    curve = &sys.add<CurveConnections>(rods, update);
    (void)curve->add("sleeve 0", 0, 1, RodEdgeRef{0, 0}, FaceSide{3}, 1e-2, sys.state());
    if (with_strip) (void)curve->add("sleeve 1", 1, 2, RodEdgeRef{0, 1}, HingeSide{4, 5}, 1e-2, sys.state());
  }
  // The triangle's turn about +x: the angle of its apex (node 3) in the yz plane.
  [[nodiscard]] double triangle_angle() const {
    const Vec3 p = sys.nodes().position(3);
    return std::atan2(p.z(), p.y());
  }
};

double unwrap_to(double raw, double previous) { return raw + 2 * pi * std::round((previous - raw) / (2 * pi)); }

TEST_CASE("curve connections term: forces, torques and Jacobian against finite differences") {
  RodAlongShell s(TwistUpdate::incremental_ii);
  std::mt19937 rng(4);
  std::normal_distribution<double> noise(0, 0.01);
  for (double& x : s.sys.nodes().x()) x += noise(rng);
  s.sys.angles().values()[0] += 0.6;
  s.sys.angles().values()[1] -= 0.4;
  const std::size_t n3 = 3 * std::size_t{s.sys.nodes().size()}, na = 2, total = n3 + 3;
  std::vector<double> q(total, 0.0), zero(total, 0.0);
  std::copy(s.sys.nodes().x().begin(), s.sys.nodes().x().end(), q.begin());
  q[n3] = s.sys.angles().values()[0];
  q[n3 + 1] = s.sys.angles().values()[1];
  auto view = [&](const std::vector<double>& qq) {
    return physics::StateView{std::span<const double>(qq).first(n3), std::span<const double>(zero).first(n3),
                              s.sys.nodes().masses(), std::span<const double>(qq).subspan(n3, na),
                              std::span<const double>(zero).subspan(n3, na)};
  };
  auto force = [&](const std::vector<double>& qq) {
    std::vector<double> f(total, 0.0);
    s.curve->add_forces(view(qq), f);
    return f;
  };
  const std::vector<double> f0 = force(q);
  physics::BlockMatrix& A = s.sys.matrix();
  A.set_zero();
  physics::JacobianRequest req;
  req.matrix = &A;
  req.cx = 1.0;
  s.curve->add_jacobians(view(q), req);
  const Eigen::MatrixXd J(A.to_sparse());
  const double eps = 1e-6;
  double worst_f = 0, worst_j = 0, scale_f = 0, scale_j = 0;
  for (std::size_t k = 0; k < n3 + na; ++k) {
    std::vector<double> qp = q, qm = q;
    qp[k] += eps;
    qm[k] -= eps;
    const double fd = -(s.curve->potential_energy(view(qp)) - s.curve->potential_energy(view(qm))) / (2 * eps);
    worst_f = std::max(worst_f, std::abs(fd - f0[k]));
    scale_f = std::max(scale_f, std::abs(f0[k]));
    const std::vector<double> fp = force(qp), fm = force(qm);
    for (std::size_t r = 0; r < n3 + na; ++r) {
      const double d = (fp[r] - fm[r]) / (2 * eps);
      worst_j = std::max(worst_j, std::abs(d - J(static_cast<Eigen::Index>(r), static_cast<Eigen::Index>(k))));
      scale_j = std::max(scale_j, std::abs(d));
    }
  }
  MESSAGE("rod along shell: |f - fd| " << worst_f << " of " << scale_f << ", |J - fd| " << worst_j << " of " << scale_j);
  CHECK(std::abs(f0[n3]) > 1e-4);  // the torques on both θ
  CHECK(std::abs(f0[n3 + 1]) > 1e-4);
  CHECK(worst_f < 1e-6 * scale_f);
  CHECK(worst_j < 1e-5 * scale_j);
}

// Turns the rod's first edge 3.5π with the triangle held, releases the triangle, lets it settle;
// returns the triangle's tracked turn about +x.
double released_turn(TwistUpdate update, double* largest_step_turn = nullptr) {
  RodAlongShell s(update, false);
  s.sys.nodes().fix(3);
  s.sys.add<physics::MassDamping>(3.0);
  physics::integrate::NewtonEuler newton;
  const double h = 0.01;
  s.sys.angles().set_fixed(0, true);
  s.sys.angles().set_fixed(1, true);
  s.sys.angles().rates()[0] = 0.35 * pi / h;
  for (int k = 0; k < 10; ++k) (void)newton.step(s.sys, h);
  CHECK(s.sys.angles().values()[0] == doctest::Approx(3.5 * pi));
  s.sys.angles().rates()[0] = 0.0;
  s.sys.nodes().unfix(3);
  double turn = s.triangle_angle(), largest = 0;
  const double start = turn;
  for (int k = 0; k < 1000; ++k) {
    (void)newton.step(s.sys, h);
    const double next = unwrap_to(s.triangle_angle(), turn);
    largest = std::max(largest, std::abs(next - turn));
    turn = next;
  }
  if (largest_step_turn) *largest_step_turn = largest;
  return turn - start;
}

TEST_CASE("curve connections term: Fig. 10 along an edge, the released shell turns by the tracked angle") {
  double largest = 0;
  const double incremental = released_turn(TwistUpdate::incremental_ii, &largest);
  const double incremental_i = released_turn(TwistUpdate::incremental_i);
  const double direct = released_turn(TwistUpdate::direct);
  MESSAGE("released triangle turned " << incremental / pi << " pi (update II), " << incremental_i / pi << " pi (I), "
                                      << direct / pi << " pi (direct); largest turn per step " << largest << " rad");
  CHECK(incremental == doctest::Approx(3.5 * pi).epsilon(1e-3));
  CHECK(incremental_i == doctest::Approx(incremental).epsilon(1e-6));
  CHECK(std::abs(direct - incremental) > pi);
  CHECK(largest < 1.0);
}

TEST_CASE("curve connections term: guard, renumbering, errors naming the connection") {
  RodAlongShell s(TwistUpdate::incremental_ii);
  CHECK(std::isfinite(s.sys.potential_energy()));
  s.sys.angles().values()[0] += 3.0;  // past max_twist_increment since the accepted state
  CHECK(std::isinf(s.sys.potential_energy()));
  s.sys.angles().values()[0] -= 3.0;
  // The triangle's apex moved onto the edge's line: no normal, infinite energy.
  const Vec3 apex = s.sys.nodes().position(3);
  s.sys.nodes().set_position(3, Vec3(0.05, 0, 0));
  CHECK(s.curve->evaluate(0, s.sys.state()).degenerate);
  CHECK(std::isinf(s.sys.potential_energy()));
  s.sys.nodes().set_position(3, apex);
  // Compaction renumbers the connection's own node ids too (errors name current nodes).
  std::vector<Index> old_to_new{0, 1, 2, 4, 5, 6};
  s.curve->remap_nodes(old_to_new);
  CHECK((s.curve->connection(0).stencil_nodes() == std::vector<Index>{0, 1, 4}));
  CHECK((s.curve->connection(1).stencil_nodes() == std::vector<Index>{1, 2, 5, 6}));
  // Errors.
  RodAlongShell t(TwistUpdate::incremental_ii, false);
  CHECK_THROWS_WITH_AS((void)t.curve->add("far", 0, 1, RodEdgeRef{0, 0}, FaceSide{17}, 1.0, t.sys.state()),
                       doctest::Contains("curve connection 'far': node 17 is out of range"), physics::InputError);
  CHECK_THROWS_WITH_AS((void)t.curve->add("off", 0, 1, RodEdgeRef{0, 1}, FaceSide{3}, 1.0, t.sys.state()),
                       doctest::Contains("curve connection 'off'"), physics::InputError);
  CHECK_THROWS_WITH_AS((void)t.curve->add("norod", 0, 1, RodEdgeRef{3, 0}, FaceSide{3}, 1.0, t.sys.state()),
                       doctest::Contains("curve connection 'norod': rod 3 edge 0 is out of range"), physics::InputError);
}

TEST_CASE("curve connections term: a trial's twist is capped; a rigid rotation about the edge is not") {
  RodAlongShell s(TwistUpdate::incremental_ii);
  const physics::StateView at = s.sys.state();
  // dq: the shell's free nodes turned rigidly by `turn` about the rod's axis (x), rod edge 0's θ
  // by `turn` + `twist`, edge 1's by `turn`: the joints' twists move by `twist` only.
  auto fraction = [&](double turn, double twist) {
    const Eigen::Matrix3d R = Eigen::AngleAxisd(turn, Vec3::UnitX()).toRotationMatrix();
    std::vector<double> dx(at.x.size(), 0.0), zero(at.x.size(), 0.0), dtheta{turn + twist, turn}, zero_theta(2, 0.0);
    for (Index i = 3; i < s.sys.nodes().size(); ++i) {
      const Vec3 p = s.sys.nodes().position(i), d = R * p - p;
      for (int a = 0; a < 3; ++a) dx[3 * std::size_t{i} + static_cast<std::size_t>(a)] = d[a];
    }
    return s.curve->step_fraction(at, {dx, zero, at.mass, dtheta, zero_theta});
  };
  CHECK(fraction(1.5, 0.0) == 1.0);   // both sides turn together: no joint turns
  CHECK(fraction(0.0, 3.0) == 0.25);  // 3 rad of twist halved until 3α ≤ π/4
  CHECK(fraction(0.0, -0.5) == 1.0);
  s.curve->set_max_trial_turn(std::numeric_limits<double>::infinity());
  CHECK(fraction(0.0, 3.0) == 1.0);
  CHECK_THROWS_WITH_AS(s.curve->set_max_trial_turn(-1.0), doctest::Contains("max_trial_turn"), physics::InputError);
}

// One step of RodAlongShell (the shell free) whose rod edge 0 spins at 3 rad per step, its θ
// free: the initial guess θ_n + 3 rad lies past the jump guard. Returns the state after the
// step (x, then both θ).
std::vector<double> spun_step(double max_turn, physics::integrate::NewtonReport& rep) {
  RodAlongShell s(TwistUpdate::incremental_ii);
  s.curve->set_max_trial_turn(max_turn);
  std::vector<double> q = sewn::connect::test::spun_step(s.sys, 0, 3.0, rep);
  CHECK(std::isfinite(s.sys.potential_energy()));
  return q;
}

TEST_CASE("curve connections term: a joint driven past its guard by the initial guess converges, as by small sub-steps") {
  physics::integrate::NewtonReport capped, fine, uncapped;
  // without the cap, the guess's energy is infinite: refused
  CHECK_THROWS_AS((void)spun_step(std::numeric_limits<double>::infinity(), uncapped), physics::integrate::NewtonError);
  const std::vector<double> a = spun_step(sewn::connect::default_max_trial_turn, capped);
  const std::vector<double> b = spun_step(0.05, fine);
  MESSAGE("spun curve joint: guess fraction " << capped.guess_fraction << " in " << capped.iterations << " iterations ("
                                              << capped.term_step_limits << " capped); at 0.05 rad per trial "
                                              << fine.guess_fraction << " in " << fine.iterations << " (" << fine.term_step_limits
                                              << "); theta " << a[a.size() - 2] << " and " << b[b.size() - 2]);
  CHECK(capped.guess_fraction == 0.25);
  CHECK(fine.guess_fraction == 1.0 / 64);
  CHECK(std::abs(a[a.size() - 2]) > 0.1);  // the spin carried the rod on
  double largest = 0;
  for (std::size_t k = 0; k < a.size(); ++k) largest = std::max(largest, std::abs(a[k] - b[k]));
  CHECK(largest < 1e-9);
}

// A cantilever plate (0.2 × 0.05 m, 8 × 2 cells of two triangles, E = 1 GPa, h = 2 mm, clamped
// along its first two columns of nodes) settled under gravity: whole (hinges everywhere), or
// split along x = 0.1 (no hinge across that line: the halves share its nodes only) and rejoined
// by a curve connection of k per unit length along each of its edges (k = 0: a free hinge).
// Returns the mean height of the free end.
double plate_tip(bool split, double k) {
  constexpr int nx = 8, ny = 2;
  const double dx = 0.025, E = 1e9, nu = 0.3, h = 2e-3, rho = 1000;
  physics::System sys;
  auto id = [](int i, int j) { return static_cast<Index>(i + (nx + 1) * j); };
  const double node_mass = rho * h * (nx * dx) * (ny * dx) / ((nx + 1) * (ny + 1));
  for (int j = 0; j <= ny; ++j)
    for (int i = 0; i <= nx; ++i) (void)sys.nodes().add(Vec3(i * dx, j * dx, 0), Vec3::Zero(), node_mass);
  for (int j = 0; j <= ny; ++j) {
    sys.nodes().fix(id(0, j));
    sys.nodes().fix(id(1, j));
  }
  std::vector<std::array<Index, 3>> left, right;
  for (int j = 0; j < ny; ++j)
    for (int i = 0; i < nx; ++i) {
      auto& half = (split && i >= nx / 2) ? right : left;
      half.push_back({id(i, j), id(i + 1, j), id(i + 1, j + 1)});
      half.push_back({id(i, j), id(i + 1, j + 1), id(i, j + 1)});
    }
  auto& membranes = sys.add<physics::shells::Membranes>();
  const std::vector<double> rest(sys.nodes().x().begin(), sys.nodes().x().end());
  for (const auto* half : {&left, &right})
    for (const auto& t : *half) {
      physics::shells::TriPositions X;
      for (int c = 0; c < 3; ++c) X.col(c) = sys.nodes().position(t[static_cast<std::size_t>(c)]);
      (void)membranes.add(t, X, E, nu, h);
    }
  auto& hinges = sys.add<physics::shells::Hinges>();
  const double k_b = physics::shells::hinge_stiffness(E, nu, h);
  (void)hinges.add_interior_edges(left, rest, k_b);
  if (split) (void)hinges.add_interior_edges(right, rest, k_b);
  if (split && k > 0) {
    auto& curve = sys.add<CurveConnections>(nullptr);
    for (int j = 0; j < ny; ++j)  // the left triangle (apex behind the line) and the right one (apex ahead)
      (void)curve.add("split " + std::to_string(j), id(nx / 2, j), id(nx / 2, j + 1), FaceSide{id(nx / 2 - 1, j)},
                      FaceSide{id(nx / 2 + 1, j + 1)}, k, sys.state());
  }
  sys.add<physics::Gravity>(Vec3(0, 0, -9.81));
  sys.add<physics::MassDamping>(50.0);
  physics::integrate::NewtonEuler newton;
  for (int s = 0; s < 300; ++s) (void)newton.step(sys, 0.01);
  double tip = 0;
  for (int j = 0; j <= ny; ++j) tip += sys.nodes().position(id(nx, j)).z() / (ny + 1);
  return tip;
}

TEST_CASE("curve connections term: a plate split along a line and rejoined by a stiff curve connection bends like the whole plate") {
  const double D = 1e9 * 8e-9 / (12 * (1 - 0.09));  // E h³ / 12(1 − ν²)
  const double whole = plate_tip(false, 0), hinged = plate_tip(true, 0), stiff = plate_tip(true, 1e3 * D / 0.025);
  MESSAGE("plate tip: whole " << whole << " m, split with a free hinge " << hinged << " m, rejoined stiffly " << stiff << " m");
  CHECK(whole < -1e-3);                                     // a real deflection
  CHECK(hinged < 5 * whole);                                // the free hinge lets the far half fall
  CHECK(stiff == doctest::Approx(whole).epsilon(0.1));      // the joint carries the moment
  CHECK(stiff > whole);                                     // and is stiffer than the plate it replaces
}

TEST_CASE("curve connections term: removing nodes in random order removes exactly the connections they held") {
  // A line of 8 edges (nodes 0..8 along x), each with a face above (apex 9 + i) and below
  // (apex 17 + i): one connection per edge. Nodes removed one by one at random, the rule
  // applied, the table compacted: what remains is exactly the connections whose four nodes all
  // survive, renumbered, with finite energy; never one left referring to a removed node.
  for (unsigned seed = 1; seed <= 20; ++seed) {
    physics::System sys;
    for (int i = 0; i <= 8; ++i) (void)sys.nodes().add(Vec3(0.1 * i, 0, 0), Vec3::Zero(), 1.0);
    for (int i = 0; i < 8; ++i) (void)sys.nodes().add(Vec3(0.1 * i + 0.05, 0.05, 0.02), Vec3::Zero(), 1.0);
    for (int i = 0; i < 8; ++i) (void)sys.nodes().add(Vec3(0.1 * i + 0.05, -0.05, 0.01), Vec3::Zero(), 1.0);
    auto& curve = sys.add<CurveConnections>(nullptr);
    for (int i = 0; i < 8; ++i)
      (void)curve.add("edge " + std::to_string(i), Index(i), Index(i + 1), FaceSide{Index(9 + i)}, FaceSide{Index(17 + i)}, 1.0,
                      sys.state());
    std::vector<Index> original(25);  // original id of each current node
    for (Index k = 0; k < 25; ++k) original[k] = k;
    std::vector<bool> gone(25, false);
    std::mt19937 rng(seed);
    for (int round = 0; round < 6; ++round) {
      const Index victim = std::uniform_int_distribution<Index>(0, sys.nodes().size() - 1)(rng);
      gone[original[victim]] = true;
      sys.nodes().remove(victim);
      (void)curve.remove_dangling(sys.nodes());
      const std::vector<Index> map = sys.compact_nodes();
      std::vector<Index> next(sys.nodes().size());
      for (Index k = 0; k < map.size(); ++k)
        if (map[k] != physics::invalid_index) next[map[k]] = original[k];
      original = next;
      std::vector<std::string> expected, kept;
      for (int i = 0; i < 8; ++i)
        if (!gone[i] && !gone[i + 1] && !gone[9 + i] && !gone[17 + i]) expected.push_back("edge " + std::to_string(i));
      for (Index c = 0; c < curve.size(); ++c) {
        kept.push_back(curve.connection(c).name());
        const int i = std::stoi(curve.connection(c).name().substr(5));
        const std::vector<Index> want{Index(i), Index(i + 1), Index(9 + i), Index(17 + i)};
        std::vector<Index> now;
        for (Index v : curve.connection(c).stencil_nodes()) now.push_back(original[v]);
        CHECK(now == want);  // renumbered onto the same nodes
      }
      CHECK(kept == expected);
      CHECK(std::isfinite(curve.potential_energy(sys.state())));
    }
  }
}

}  // namespace
}  // namespace test_curve_term
