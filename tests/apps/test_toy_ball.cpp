// The toy ball scene (scenes/s04_toy_ball.json) shows what the 2019 paper's Fig. 12 shows: a
// ball standing and wobbling on its spring. The spring's design (docs/paper_scenes.md, "The toy
// ball's spring") gives a lowest height for the ball from the closed-form spring and column
// formulas; the run, the scene's own integrator settings for its whole second, must stay above it.
#include <doctest/doctest.h>

#include <algorithm>
#include <cmath>
#include <numbers>
#include <set>
#include <string>

#include "../../apps/src/run_build.hpp"
#include "scene_jacobian_check.hpp"
#include "sewn/apps/paper_shapes.hpp"

namespace test_toy_ball {
namespace {

constexpr double pi = std::numbers::pi;
constexpr double g = 9.81;

// The scene's design values (scenes/s04_toy_ball.json, `sewn make-mesh toy_ball`).
struct Design {
  double young = 3e9, poisson = 0.35, wire_density = 1200;  // plastic wire
  double wire_radius = 1.2e-3, coil_diameter = 0.04, turns = 4, length = 0.08;
  double ball_density = 100, ball_volume = 226.0 / 6 * 1e-6;  // foam; 226 tets of (1 cm)³ / 6
  double ball_radius = 0.02;                                  // its centre's height above the spring's top
  double knock = 0.5;                                         // m/s, sideways
};

// The lowest the ball's lowest node can get, from the formulas of docs/paper_scenes.md: the
// spring's top drops by twice its static sag (gravity applied at once to the unloaded spring),
// by the shortening 0.6 A²/L of a cantilever swaying by A = v/ω, and a node at distance `rho`
// from the axis on the ball's flat underside by rho · 1.5 A/L more (the cantilever's end slope).
double lowest_height(const Design& d, double rho) {
  const double wire = 2 * d.wire_radius, D = d.coil_diameter, L = d.length, n = d.turns;
  const double shear = d.young / (2 * (1 + d.poisson));
  const double k = shear * std::pow(wire, 4) / (8 * D * D * D * n);                              // axial, N/m
  const double B = L * d.young * std::pow(wire, 4) / (32 * D * n * (2 + d.poisson));            // column, N·m²
  const double spring_weight = d.wire_density * n * pi * D * pi * wire * wire / 4 * g;
  const double ball_weight = d.ball_density * d.ball_volume * g;
  const double sag = (ball_weight + spring_weight / 2) / k;
  // Buckling of the clamped column carrying its load on a rigid arm a (the ball's centre):
  // kL tan kL = L/a, solved by bisection on (0, π/2).
  double lo = 0, hi = pi / 2;
  for (int i = 0; i < 100; ++i) {
    const double mid = (lo + hi) / 2;
    (mid * std::tan(mid) < L / d.ball_radius ? lo : hi) = mid;
  }
  const double critical = lo * lo * B / (L * L);
  const double load = ball_weight + 0.315 * spring_weight;  // a distributed weight's equivalent end load
  REQUIRE(load < critical / 2);                             // the design stands, with a margin
  const double lateral = 3 * B / (L * L * L) * (1 - load / critical);
  const double mass = (ball_weight + 0.24 * spring_weight) / g;  // Rayleigh's end mass of a cantilever
  const double sway = d.knock / std::sqrt(lateral / mass);
  return L - 2 * sag - 0.6 * sway * sway / L - rho * 1.5 * sway / L;
}

}  // namespace

TEST_CASE("toy ball: the ball stands on its spring for the whole second, above the computed lowest height") {
  const Design d;
  const sewn::app::Scene scene = sewn::app::load_scene(std::string(SEWN_SOURCE_DIR) + "/scenes/s04_toy_ball.json");
  const auto shape = sewn::app::make_paper_shape("toy_ball");
  std::set<std::uint32_t> ball;
  for (std::uint32_t c = 0; c < shape.mesh.num_cells(); ++c)
    if (shape.mesh.tags[c] == 2)
      for (const std::uint32_t p : shape.mesh.cell(c)) ball.insert(p);
  REQUIRE(ball.size() > 4);
  // The underside's reach from the axis, and the design's length: where the spring meets the ball.
  double bottom = 1e9, rho = 0;
  for (const std::uint32_t p : ball) bottom = std::min(bottom, shape.mesh.points[p][2]);
  for (const std::uint32_t p : ball)
    if (shape.mesh.points[p][2] < bottom + 1e-9) rho = std::max(rho, std::hypot(shape.mesh.points[p][0], shape.mesh.points[p][1]));
  CHECK(bottom == doctest::Approx(d.length));
  const double bound = lowest_height(d, rho);
  INFO("computed lowest height " << bound << " m (underside reach " << rho << " m)");

  sewn::app::RunSummary sum;
  auto b = sewn::app::detail::build_bodies(scene, true, sum);
  sewn::physics::System& sys = b.model->system();
  const auto x0 = sys.nodes().x();
  for (const std::uint32_t p : ball)
    for (int k = 0; k < 3; ++k) REQUIRE(x0[3 * p + k] == shape.mesh.points[p][k]);  // nodes are the mesh's points
  sewn::physics::integrate::NewtonEuler newton(sewn::app::test::scene_newton_options(scene));
  const int steps = static_cast<int>(std::lround(scene.duration / scene.step));
  double lowest = 1e9;
  for (int s = 0; s < steps; ++s) {
    (void)newton.step(sys, scene.step);
    const auto x = sys.nodes().x();
    for (const std::uint32_t p : ball) lowest = std::min(lowest, x[3 * p + 2]);
  }
  INFO("lowest height of the ball's nodes over the run " << lowest << " m");
  CHECK(lowest > bound);
  CHECK(lowest < d.length - 1e-3);  // the spring does carry the ball's weight (its static sag is 2.8 mm)
}

}  // namespace test_toy_ball
