// The 2019 paper's Fig. 18: a slab half solid (tetrahedra), half shell (its mid-surface),
// joined along the line where the shell meets the solid's end face by a stiff curve
// connection, bends under its weight like the all-solid slab; hinged there (no connection) the
// shell half falls away.
#include <doctest/doctest.h>

#include <cmath>

#include "sewn/apps/fig18_slab_model.hpp"
#include "sewn/physics/integrate/newton_euler.hpp"

namespace test_connection_slab {
namespace {

constexpr double h = 0.01;                 // cell size (m)
constexpr std::uint32_t ny = 4, nz = 2;    // slab 0.04 m wide, 0.02 m thick
constexpr double E = 1e7, rho = 1000, g = 9.81;

// The static tip deflection (mean z displacement of the nodes at x = L) of the slab clamped at
// x = 0 under gravity, `solid` cells of tetrahedra along x from x = 0, then `shell` cells of the
// mid-surface shell: backward Euler steps of 100 s from rest (the inertia term is then 1e-4 of
// the slab's stiffness: Newton on the static problem), until the tip stops moving.
double tip_sag(std::uint32_t solid, std::uint32_t shell, bool connections, bool rigid) {
  sewn::app::Fig18SlabSpec spec;
  spec.solid = solid;
  spec.shell = shell;
  spec.ny = ny;
  spec.nz = nz;
  spec.cell = h;
  spec.young = E;
  spec.density = rho;
  spec.gravity = g;
  spec.connections = connections;
  spec.rigid = rigid;
  const sewn::app::Fig18SlabModel slab = sewn::app::build_fig18_slab_model(spec);
  if (connections) REQUIRE(slab.curve_joints == ny);
  sewn::physics::integrate::NewtonEulerOptions no;
  no.max_iterations = 200;
  sewn::physics::integrate::NewtonEuler newton(no);
  double last = 0;
  for (int step = 0; step < 20; ++step) {
    for (double& v : slab.model->nodes().v()) v = 0;
    (void)newton.step(slab.model->system(), 100.0);
    if (std::abs(slab.sag() - last) < 1e-9) break;
    last = slab.sag();
  }
  return slab.sag();
}

TEST_CASE("Fig. 18: a slab half solid, half shell, joined by a stiff curve connection, bends like the all-solid slab") {
  // 0.2 × 0.04 × 0.02 m, cells of 1 cm, clamped at x = 0; the mixed slab's second half is the
  // shell of the same thickness on the mid-surface, joined along its first edge line
  const double solid = tip_sag(20, 0, false, false);
  const double mixed = tip_sag(10, 10, true, true);
  const double mixed_auto = tip_sag(10, 10, true, false);
  const double hinged = tip_sag(10, 10, false, false);
  // Euler–Bernoulli: q L⁴ / (8 E I), q = ρ g W T, I = W T³/12
  const double W = ny * h, T = nz * h, L = 20 * h;
  const double beam = rho * g * W * T * std::pow(L, 4) / (8 * E * W * T * T * T / 12);
  CAPTURE(solid);
  CAPTURE(mixed);
  CAPTURE(mixed_auto);
  CAPTURE(hinged);
  CAPTURE(beam);
  // The tolerance's reason: linear tetrahedra two layers thick lock in bending (the all-solid
  // slab sags about half the beam's q L⁴/(8EI)), the shell does not; so the mixed slab, whose
  // root half is the same tetrahedra carrying the same load, sags at least as much as the
  // all-solid one, and at most by the outer half's own bending more: a cantilever of L/2 under
  // q, q (L/2)⁴/(8EI) = beam/16, which the locked tetrahedra would not have had at all; 10 %
  // on that share for the shell's coarse hinges and the slab's plate stiffening (1/(1 − ν²)).
  // A joint softer than the slab around it turns and adds to the sag beyond that.
  CHECK(mixed >= solid);
  CHECK(mixed <= solid + 1.1 * beam / 16);
  // hinged, the shell half swings down about the line (≈ its length, 0.1 m)
  CHECK(hinged > 10 * solid);
  // the auto (not rigid) joint is as stiff as one cell of the softer side: it turns a little
  CHECK(mixed_auto >= mixed);
}

}  // namespace
}  // namespace test_connection_slab
