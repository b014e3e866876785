// The semi-implicit stable step with T-junctions: the bound is the reduced system's (slave
// masses lumped onto the masters, slave springs seen through W), as the integrator steps it.
// Checked against the largest eigenvalue of that reduced system found by power iteration, by
// running it (bounded energy at 0.9x the bound, blow-up above the true limit), and against the
// uniform grid where there are no T-junctions.
#include <doctest/doctest.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <memory>
#include <random>
#include <vector>

#include "sewn/physics/integrators.hpp"
#include "sewn/refine/coarsen.hpp"
#include "sewn/refine/hierarchy.hpp"
#include "sewn/refine/subdivide.hpp"
#include "support.hpp"

namespace test_stable_step {  // one namespace per file: the unity build compiles several files as one

namespace {

namespace ph = sewn::physics;
namespace rf = sewn::refine;
using Eigen::Vector3d;
using ph::Index;

const ph::MaterialParams material{1e5, 0.3, 100};

ph::MssOptions free_body() {
  ph::MssOptions o;
  o.gravity.setZero();
  o.damping = ph::DampingModel::none;
  return o;
}

// A 2×2×1 block of 0.1 m hexahedra, one refined and one of its children again: border and
// middle T-junctions, some with a master that is itself a T-junction.
std::unique_ptr<ph::MssModel<3>> adaptive_block() {
  auto m = std::make_unique<ph::MssModel<3>>(sewn::hex_grid(2, 2, 1, {{0.1, 0.1, 0.1}, {}}), std::vector{material},
                                             std::vector<std::uint32_t>{}, free_body());
  const rf::RefineReport a = rf::refine_element(*m, 0);
  (void)rf::refine_element(*m, a.children[6]);
  return m;
}

// Positions perturbed by up to 1 % of an element (rest + noise), velocities small; the
// T-junctions put back on their masters.
template <int D>
void perturb(ph::MssModel<D>& m, unsigned seed) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> u(-1, 1);
  for (Index i = 0; i < m.nodes().size(); ++i) {
    if (!m.nodes().is_alive(i)) continue;
    m.nodes().set_position(i, m.rest_position(i) + 1e-4 * Vector3d(u(rng), u(rng), D == 3 ? u(rng) : 0.0));
    m.nodes().set_velocity(i, 1e-3 * Vector3d(u(rng), u(rng), D == 3 ? u(rng) : 0.0));
  }
  m.system().slaves().after_step(m.nodes());
}

// λmax(M_r⁻¹ WᵀKW) of the system the semi-implicit step integrates (K = -∂F/∂x, compression
// clamped as in the bound), by power iteration from a seeded start: a value from below.
double reduced_lambda_max(ph::System& sys) {
  ph::SlaveNodes& s = sys.slaves();
  const auto inv_mass = s.empty() ? sys.nodes().inverse_mass_dof() : s.inverse_mass_dof(sys.nodes());
  const std::vector<double> im(inv_mass.begin(), inv_mass.end());
  const std::size_t n3 = im.size();
  std::vector<double> v(n3), kv(n3);
  std::mt19937 rng(11);
  std::uniform_real_distribution<double> u(-1, 1);
  for (std::size_t k = 0; k < n3; ++k) v[k] = im[k] != 0 ? u(rng) : 0.0;
  double lambda = 0;
  for (int it = 0; it < 3000; ++it) {
    // iterate on y = M_r^{1/2} v so that the operator is symmetric: A = M^{-1/2} K_r M^{-1/2}
    double norm = 0;
    for (double e : v) norm += e * e;
    norm = std::sqrt(norm);
    for (double& e : v) e /= norm;
    std::vector<double> x(n3);
    for (std::size_t k = 0; k < n3; ++k) x[k] = v[k] * std::sqrt(im[k]);
    s.expand(x);
    std::fill(kv.begin(), kv.end(), 0.0);
    ph::JacobianRequest req;
    req.product_in = x;
    req.product_out = kv;
    sys.add_jacobians(req);
    s.reduce(kv);
    double rq = 0;
    for (std::size_t k = 0; k < n3; ++k) {
      kv[k] = -kv[k] * std::sqrt(im[k]);  // K = -∂F/∂x
      rq += v[k] * kv[k];
    }
    lambda = rq;
    v = kv;
  }
  return lambda;
}

// Every slave written in particles that move, weights summing to 1, at its place: what the
// bound folds slave rows with.
void check_expansion(const ph::System& sys) {
  const ph::SlaveExpansion e = sys.slaves().expansion(sys.nodes().size());
  for (const ph::SlaveNode& s : sys.slaves().slaves()) {
    CAPTURE(s.node);
    REQUIRE(e.is_slave(s.node));
    double sum = 0;
    Vector3d x = Vector3d::Zero();
    for (const auto& t : e.of(s.node)) {
      CHECK(!e.is_slave(t.node));
      sum += t.weight;
      x += t.weight * sys.nodes().position(t.node);
    }
    CHECK(std::abs(sum - 1) <= 1e-14);
    CHECK((x - sys.nodes().position(s.node)).norm() <= 1e-14);
  }
}

// Σ ½ m_r v² over the particles the step moves (lumped masses) plus the elastic energy.
double reduced_energy(ph::System& sys) {
  const std::vector<double> m = sys.slaves().lumped_masses(sys.nodes());
  double e = sys.potential_energy();
  for (Index i = 0; i < sys.nodes().size(); ++i) e += 0.5 * m[i] * sys.nodes().velocity(i).squaredNorm();
  return e;
}

// Runs `steps` semi-implicit steps at h without the integrator's own guard; returns the largest
// energy seen over the starting one (infinite once the state is not finite).
double energy_growth(ph::System& sys, double h, int steps) {
  ph::SymplecticEulerOptions o;
  o.enforce_stable_step = false;
  o.health.energy_check_interval = 0;
  o.health.check_finite = false;
  ph::SymplecticEuler euler(o);
  const double e0 = reduced_energy(sys);
  double worst = 1;
  for (int k = 0; k < steps; ++k) {
    (void)euler.step(sys, h);
    const double e = reduced_energy(sys);
    if (!std::isfinite(e)) return std::numeric_limits<double>::infinity();
    worst = std::max(worst, e / e0);
  }
  return worst;
}

}  // namespace

TEST_CASE("stable step: without T-junctions, a uniformly refined model's bound is the fine grid's") {
  auto refined = std::make_unique<ph::MssModel<3>>(sewn::hex_grid(2, 1, 1, {{0.2, 0.2, 0.2}, {}}), std::vector{material},
                                                   std::vector<std::uint32_t>{}, free_body());
  (void)rf::refine_all(*refined);
  (void)rf::refine_all(*refined);
  REQUIRE(refined->system().slaves().empty());
  ph::MssModel<3> direct(sewn::hex_grid(8, 4, 4, {{0.05, 0.05, 0.05}, {}}), {material}, {}, free_body());
  const double a = refined->system().stable_step().h_max, b = direct.system().stable_step().h_max;
  CHECK(std::abs(a - b) <= 1e-12 * b);

  ph::MssModel<2> quads(sewn::quad_grid(2, 2, {{0.2, 0.2, 1}, {}}), {material}, {}, free_body());
  (void)rf::refine_all(quads);
  ph::MssModel<2> fine(sewn::quad_grid(4, 4, {{0.1, 0.1, 1}, {}}), {material}, {}, free_body());
  REQUIRE(quads.system().slaves().empty());
  CHECK(std::abs(quads.system().stable_step().h_max - fine.system().stable_step().h_max) <= 1e-12 * fine.system().stable_step().h_max);
}

TEST_CASE("stable step: with T-junctions the bound is the reduced system's, safe and not set by a slave") {
  auto m = adaptive_block();
  REQUIRE(m->system().slaves().reduces());
  perturb(*m, 3);
  ph::System& sys = m->system();
  check_expansion(sys);
  const ph::StableStep st = sys.stable_step();
  const double lambda = reduced_lambda_max(sys);
  const double h_true = 2 / std::sqrt(lambda);
  CAPTURE(st.h_max);
  CAPTURE(h_true);
  CHECK(st.h_max <= h_true);               // an upper bound on ω, so a safe step
  CHECK(st.h_max >= 0.5 * h_true);         // and not a uselessly small one
  CHECK(!m->system().slaves().slaves().empty());
  for (const auto& s : sys.slaves().slaves()) CHECK(st.stiffness_node != s.node);

  // the unreduced rows (each particle on its own mass, as the paper's treatment steps them)
  // give a smaller bound: a slave's row carries little mass and a coarse side's springs
  sys.slaves().set_treatment(ph::SlaveTreatment::paper_projection);
  const double unreduced = sys.stable_step().h_max;
  sys.slaves().set_treatment(ph::SlaveTreatment::reduction);
  CAPTURE(unreduced);
  CHECK(unreduced < st.h_max);
}

TEST_CASE("stable step: at 0.9x the reduced bound the energy stays bounded, above the true limit it blows up") {
  auto stable = adaptive_block();
  perturb(*stable, 5);
  const double bound = stable->system().stable_step().h_max;
  const double h_true = 2 / std::sqrt(reduced_lambda_max(stable->system()));
  REQUIRE(bound <= h_true);
  // a stable mode of frequency ω under symplectic Euler keeps its energy within a factor
  // (1 + hω/2)/(1 - hω/2) of where it started, 19 at hω = 1.8 (h = 0.9x a bound that is below
  // the true limit 2/ω_max); an unstable one grows without bound
  CHECK(energy_growth(stable->system(), 0.9 * bound, 20000) <= 19);

  auto unstable = adaptive_block();
  perturb(*unstable, 5);
  CHECK(energy_growth(unstable->system(), 1.2 * h_true, 2000) > 1e6);
}

TEST_CASE("stable step: seeded random refine / coarsen sequences keep the reduced bound below the true limit") {
  for (unsigned seed : {1u, 2u, 3u}) {
    CAPTURE(seed);
    ph::MssModel<3> m(sewn::hex_grid(2, 2, 1, {{0.1, 0.1, 0.1}, {}}), {material}, {}, free_body());
    const double mass0 = m.node_mass();
    std::mt19937 rng(seed);
    rf::RefineOptions o;
    o.max_level = 3;
    for (int step = 0; step < 12; ++step) {
      refine_test::random_refine_or_coarsen(m, rng, o);
      refine_test::check_all(m);
      CHECK(std::abs(m.node_mass() - mass0) <= 1e-13 * mass0);
      perturb(m, seed * 100 + static_cast<unsigned>(step));
      check_expansion(m.system());
      const double bound = m.system().stable_step().h_max;
      const double h_true = 2 / std::sqrt(reduced_lambda_max(m.system()));
      CAPTURE(step);
      CHECK(bound <= h_true);
      CHECK(bound >= 0.5 * h_true);
    }
  }
}

}  // namespace test_stable_step
