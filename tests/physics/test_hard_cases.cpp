// The hard cases, on the map-based model: the 2013 paper's own setting, a spinning
// beam, a 10⁶ stiffness contrast, and a cantilever's convergence under mesh refinement.
#include <doctest/doctest.h>

#include <cmath>
#include <string>

#include <Eigen/Geometry>

#include "helpers.hpp"
#include "sewn/physics/integrators.hpp"
#include "sewn/physics/mss_model.hpp"

namespace test_hard_cases {

using namespace sewn;
using namespace sewn::physics;
using Eigen::Vector3d;

namespace {

using sewn::physics::test::paper_material;

// Fixes every node whose rest x is at most x_max (a clamped end).
template <int D>
void clamp_below_x(MssModel<D>& m, double x_max) {
  for (Index i = 0; i < m.nodes().size(); ++i)
    if (m.rest_position(i).x() <= x_max) m.nodes().fix(i);
}

double max_strain(const Springs& s, const NodeTable& n) {
  double worst = 0;
  for (Index i = 0; i < s.size(); ++i) {
    if (!s.is_alive(i)) continue;
    const double d = (n.position(s.node_j(i)) - n.position(s.node_i(i))).norm();
    worst = std::max(worst, std::abs(d / s.rest_length(i) - 1));
  }
  return worst;
}

// Static tip deflection of a 1 m cantilever (b = h = 0.1 m) meshed with 10N x N x N cubes:
// linearly implicit steps with a huge h are Newton steps on the static problem (the mass and
// damping terms vanish as h grows), so a few reach equilibrium. Returns the mean z-displacement
// of the x = L particles, in metres.
double cantilever_tip(std::uint32_t N, double nu) {
  const double a = 0.1 / N;
  MaterialParams mat{100e6, nu, 1000};
  MssOptions opt;
  opt.gravity = Vector3d(0, 0, -9.81);
  opt.damping = DampingModel::none;
  MssModel<3> m(hex_grid(10 * N, N, N, {{a, a, a}, {}}), {mat}, {}, opt);
  clamp_below_x(m, 1e-12);
  ImplicitEulerOptions io;
  io.cg_tolerance = 1e-12;
  io.cg_max_iterations = 100000;
  io.health.energy_check_interval = 0;  // Newton steps, not a trajectory
  LinearlyImplicitEuler euler(io);
  for (int k = 0; k < 3; ++k) {  // the third changes the tip by ~2e-5 relative
    (void)euler.step(m.system(), 1e3);
    for (Index i = 0; i < m.nodes().size(); ++i) m.nodes().set_velocity(i, Vector3d::Zero());
  }
  double tip = 0;
  int count = 0;
  for (Index i = 0; i < m.nodes().size(); ++i)
    if (std::abs(m.rest_position(i).x() - 1.0) < 1e-9) {
      tip += m.nodes().position(i).z() - m.rest_position(i).z();
      ++count;
    }
  return -tip / count;
}

}  // namespace

TEST_CASE("the paper's own setting: a 10 cm cube, E = 100 MPa, h = 1 ms") {
  MssOptions opt;  // gravity and the paper's per-spring viscosity
  MssModel<3> m(hex_grid(1, 1, 1, {{0.1, 0.1, 0.1}, {}}), {paper_material}, {}, opt);
  for (Index i = 0; i < 8; ++i)
    if (m.rest_position(i).z() == 0) m.nodes().fix(i);  // the bottom face rests on the ground
  SUBCASE("semi-implicit Euler is refused, with the stable-step bound in the message") {
    SymplecticEuler euler;
    try {
      (void)euler.step(m.system(), 1e-3);
      FAIL("a step 1 ms far above the explicit limit was accepted");
    } catch (const StabilityError& e) {
      CHECK(e.bound() < 1e-3);
      CHECK(e.bound() > 0);
      // the message states the bound (as printed) so the user can choose a step
      char bound[32];
      std::snprintf(bound, sizeof bound, "%.3g", e.bound());
      CAPTURE(e.what());
      CHECK(std::string(e.what()).find(std::string(bound).substr(0, 3)) != std::string::npos);
    }
  }
  SUBCASE("10 000 implicit steps stay bounded") {
    // The block settles within a few hundred steps (static sag ~ρgL²/E, under a micrometre).
    // A lone hexahedron has zero-stiffness mechanisms (PHYSICS_NOTES §1.2); one of them, the
    // top face twisting about z, lowers the top at second order, so gravity makes it grow from
    // round-off after ~2 s: a genuine buckling of the model that nonlinearity caps. "Bounded"
    // is therefore checked physically: no particle leaves a 1 mm neighbourhood of its start
    // (1% of the side) and the kinetic energy never exceeds the work gravity has done.
    LinearlyImplicitEuler euler;
    const Eigen::Matrix3Xd x0 = m.nodes().positions();
    int max_iterations = 0;
    double worst = 0, settled = 0;
    for (int s = 1; s <= 10000; ++s) {
      max_iterations = std::max(max_iterations, euler.step(m.system(), 1e-3).cg_iterations);
      const Eigen::Matrix3Xd u = m.nodes().positions() - x0;
      double work = 0;
      for (Index i = 0; i < 8; ++i) work += m.nodes().mass(i) * 9.81 * -u(2, i);
      REQUIRE(m.system().kinetic_energy() <= work + 1e-30);
      worst = std::max(worst, u.cwiseAbs().maxCoeff());
      if (s == 1000) settled = m.system().kinetic_energy();
    }
    CHECK(worst < 1e-3);
    CHECK(settled < 1e-20);  // at rest after 1 s, before the mechanism has grown out of round-off
    CHECK(m.nodes().positions().allFinite());
    MESSAGE("paper cube, 10000 implicit steps: largest displacement " << worst << " m, kinetic energy at 1 s " << settled
                                                                       << " J, at most " << max_iterations << " CG iterations");
  }
}

TEST_CASE("a beam spun at 20 rad/s for 2 s stays bounded, then returns to its rest lengths") {
  MssOptions opt;
  opt.gravity.setZero();
  opt.damping = DampingModel::none;
  MaterialParams rubber{1e6, 0.3, 1000};
  MssModel<3> m(hex_grid(10, 2, 2, {{0.02, 0.02, 0.02}, {-0.1, -0.02, -0.02}}), {rubber}, {}, opt);
  const double omega = 20;
  for (Index i = 0; i < m.nodes().size(); ++i) {
    const Vector3d r = m.rest_position(i);
    m.nodes().set_velocity(i, Vector3d(0, 0, omega).cross(r));
  }
  const double e0 = m.system().kinetic_energy();
  LinearlyImplicitEuler euler;
  double worst = 0;
  const double h = 1e-3;
  for (int s = 0; s < 2000; ++s) {
    (void)euler.step(m.system(), h);
    worst = std::max(worst, max_strain(m.springs(), m.nodes()));
    // Implicit Euler dissipates, except that its linear position update x + h·v of a rigid
    // rotation stretches every radius by √(1 + (hω)²): the energy may exceed E₀ by that much.
    REQUIRE(m.system().kinetic_energy() + m.system().potential_energy() <= e0 * (1 + h * h * omega * omega));
  }
  // centrifugal stretch of a spinning 20 cm rubber bar: ρω²L²/(8E) ≈ 2e-3; bounded means a few %
  CHECK(worst < 0.05);
  MESSAGE("spinning beam: worst spring strain " << worst << ", kinetic energy " << e0 << " -> " << m.system().kinetic_energy());
  // Damp it out: an unloaded body comes to rest with its springs back at their rest lengths.
  // The lattice's zero-stiffness mechanisms relax only algebraically under mass damping, so
  // "back" is measured against the strain the spin produced.
  m.system().add<MassDamping>(50.0);
  int steps = 0;
  for (; steps < 20000 && m.system().kinetic_energy() > 1e-10 * e0; ++steps) (void)euler.step(m.system(), 1e-3);
  CHECK(m.system().kinetic_energy() <= 1e-10 * e0);
  const double residual = max_strain(m.springs(), m.nodes());
  MESSAGE("at rest after " << steps << " damped steps: residual strain " << residual);
  CHECK(residual < 1e-3 * worst);
}

TEST_CASE("a stiffness contrast of 10^6 inside one object converges") {
  // a clamped bar: soft half (1 kPa... 1 GPa) joined to a stiff half, per-element material
  const IndexedMesh mesh = hex_grid(10, 2, 2, {{0.05, 0.05, 0.05}, {}});
  std::vector<std::uint32_t> material_of_cell(mesh.num_cells());
  for (std::uint32_t c = 0; c < mesh.num_cells(); ++c) material_of_cell[c] = (c % 10) < 5 ? 0 : 1;
  MssModel<3> m(mesh, {{1e3, 0.3, 1000}, {1e9, 0.3, 1000}}, material_of_cell);
  clamp_below_x(m, 1e-12);
  LinearlyImplicitEuler euler;
  euler.options().solver = solve::Backend::jacobi;
  int most = 0;
  for (int s = 0; s < 200; ++s) {
    const StepReport r = euler.step(m.system(), 1e-3);
    CHECK(r.cg_converged);
    most = std::max(most, r.cg_iterations);
  }
  CHECK(most > 0);
  CHECK(m.nodes().positions().allFinite());
  MESSAGE("stiffness contrast 1e6: at most " << most << " CG iterations per implicit step (block-Jacobi, tolerance 1e-6)");
}

TEST_CASE("a cantilever's static deflection converges as the mesh is refined") {
  // PHYSICS_NOTES §4: at ν = 1/4 the Baudet lattice is exact in the continuum limit, so it
  // converges to beam theory. The test measures the order of convergence from three
  // resolutions (N = 1 is too coarse to be in the asymptotic range) and extrapolates.
  const double d2 = cantilever_tip(2, 0.25), d4 = cantilever_tip(4, 0.25), d8 = cantilever_tip(8, 0.25);
  MESSAGE("cantilever tip deflection (nu = 0.25): N=2 " << d2 * 1e3 << " mm, N=4 " << d4 * 1e3 << " mm, N=8 " << d8 * 1e3 << " mm");
  CHECK(d2 < d4);
  CHECK(d4 < d8);  // the coarse lattice is too stiff and softens monotonically
  const double order = std::log2((d4 - d2) / (d8 - d4));
  MESSAGE("observed order of convergence: " << order);
  CHECK(order > 1.0);
  // Euler-Bernoulli plus Timoshenko shear, qL⁴/(8EI) + qL²/(2κGA) with κ = 5/6: 14.86 mm
  const double E = 100e6, nu = 0.25, q = 1000 * 9.81 * 0.01, I = 0.1 * 0.1 * 0.1 * 0.1 / 12, G = E / (2 * (1 + nu));
  const double beam = q / (8 * E * I) + q / (2 * (5.0 / 6.0) * G * 0.01);
  const double limit = d8 + (d8 - d4) / (std::pow(2.0, order) - 1);
  MESSAGE("Richardson limit " << limit * 1e3 << " mm, beam theory " << beam * 1e3 << " mm");
  // extrapolating from N = 2..8, where the order is still rising towards 2, is good to about 1%
  CHECK(limit == doctest::Approx(beam).epsilon(0.02));
}

TEST_CASE("at nu = 0.3 the mass-spring cantilever converges, but not to the continuum answer") {
  // The lattice represents ν = 1/4 only: at ν = 0.3 its bending modulus is E_100 ≈ E/1.048
  // (PHYSICS_NOTES §4), so it converges to ≈ 14.19 mm, 4-5 % short of Timoshenko's 14.868 mm,
  // and no refinement closes that gap (bench/results/elastic.md puts it beside the tets).
  const double d2 = cantilever_tip(2, 0.3), d4 = cantilever_tip(4, 0.3), d8 = cantilever_tip(8, 0.3);
  MESSAGE("cantilever tip deflection (nu = 0.3): N=2 " << d2 * 1e3 << " mm, N=4 " << d4 * 1e3 << " mm, N=8 " << d8 * 1e3 << " mm");
  CHECK(d2 < d4);
  CHECK(d4 < d8);
  const double order = std::log2((d4 - d2) / (d8 - d4));
  CHECK(order > 1.0);
  const double E = 100e6, nu = 0.3, q = 1000 * 9.81 * 0.01, I = 0.1 * 0.1 * 0.1 * 0.1 / 12, G = E / (2 * (1 + nu));
  const double beam = q / (8 * E * I) + q / (2 * (5.0 / 6.0) * G * 0.01);
  const double limit = d8 + (d8 - d4) / (std::pow(2.0, order) - 1);
  MESSAGE("Richardson limit " << limit * 1e3 << " mm, Timoshenko " << beam * 1e3 << " mm: misses by "
                              << 100 * (beam - limit) / beam << " %");
  CHECK(limit == doctest::Approx(beam / 1.048).epsilon(0.02));
  CHECK((beam - limit) / beam > 0.03);
}

}  // namespace test_hard_cases
