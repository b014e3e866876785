// The paper scenes' exact Jacobians term by term (scene_jacobian_check.hpp): each term's
// (∂F/∂q)·p against central differences of its own forces along p, at states a run visits.
// Newton on the exact Hessian converges quadratically only if every term's matches its gradient.
#include <doctest/doctest.h>

#include <algorithm>
#include <cmath>
#include <random>
#include <string>

#include "scene_jacobian_check.hpp"

namespace test_scene_jacobians {
namespace {

using sewn::app::test::term_jacobian_errors;

// The scene's bodies stepped `steps` times by its own integrator settings, motion included.
sewn::app::detail::Bodies stepped(const std::string& name, int steps) {
  const sewn::app::Scene scene = sewn::app::load_scene(std::string(SEWN_SOURCE_DIR) + "/scenes/s04_" + name + ".json");
  sewn::app::RunSummary sum;
  auto b = sewn::app::detail::build_bodies(scene, true, sum);
  sewn::physics::integrate::NewtonEuler newton(sewn::app::test::scene_newton_options(scene));
  for (int s = 0; s < steps; ++s) {
    if (!b.motion.empty()) b.motion.drive(b.model->nodes(), s * scene.step, scene.step);
    (void)newton.step(b.model->system(), scene.step);
  }
  return b;
}

void check_terms(const std::string& name, int steps, bool perturbed) {
  auto b = stepped(name, steps);
  sewn::physics::System& sys = b.model->system();
  std::mt19937 rng(7);
  // Away from the accepted state too, where the terms' frozen history (rods' reference frames,
  // connections' accepted twist) no longer matches the configuration: the iterates Newton visits.
  const auto shift = sewn::app::test::random_direction(sys, rng, 3e-3, 0.2);
  if (perturbed) {
    auto x = sys.nodes().x();
    const std::size_t n3 = x.size();
    for (std::size_t k = 0; k < n3; ++k) x[k] += shift[k];
    for (std::size_t a = 0; a < sys.angles().size(); ++a) sys.angles().values()[a] += shift[n3 + a];
  }
  for (int trial = 0; trial < 3; ++trial) {
    const auto p = sewn::app::test::random_direction(sys, rng, 1e-3, 1e-2);
    for (const auto& e : term_jacobian_errors(sys, p, 1e-4)) {
      const std::string where = perturbed ? " steps and a random displacement, " : " steps, ";
      INFO(name << " after " << steps << where << e.term << ": |Jp - dF|inf " << e.error << " of " << e.scale << " at dof "
                   << e.worst);
      CHECK(e.error <= 1e-6 * e.scale + 1e-12);
    }
  }
}

}  // namespace

TEST_CASE("paper scenes: every term's exact Jacobian is the derivative of its forces (frisbee)") {
  check_terms("frisbee", 5, false);
  check_terms("frisbee", 5, true);
}

TEST_CASE("paper scenes: every term's exact Jacobian is the derivative of its forces (toy ball, joints on)") {
  check_terms("toy_ball", 5, false);
  check_terms("toy_ball", 5, true);
}

TEST_CASE("toy ball with its joints on: a second of steps converged, the spring's foot framed by the platform's vertex normal") {
  // NewtonEuler::step throws when a step does not converge within the scene's limit, so every
  // step below reached the scene's tolerance. Before the vertex frame (the platform centre's
  // side was an in-plane corner bisector) step 20 met the joint's antiparallel guard.
  const sewn::app::Scene scene = sewn::app::load_scene(std::string(SEWN_SOURCE_DIR) + "/scenes/s04_toy_ball.json");
  REQUIRE(scene.connections.enabled);
  sewn::app::RunSummary sum;
  auto b = sewn::app::detail::build_bodies(scene, true, sum);
  REQUIRE(b.joints.points != nullptr);
  const auto& points = *b.joints.points;
  REQUIRE(points.size() == 2);
  // the rod–shell joint is at an interior vertex: its stencil holds the one-ring (more than a
  // triangle's three nodes plus the rod edge's two)
  int vertex_joint = -1;
  for (sewn::physics::Index c = 0; c < points.size(); ++c)
    if (points.connection(c).position_nodes().size() > 5) vertex_joint = static_cast<int>(c);
  REQUIRE(vertex_joint >= 0);
  sewn::physics::integrate::NewtonEuler newton(sewn::app::test::scene_newton_options(scene));
  sewn::physics::System& sys = b.model->system();
  int iterations = 0;
  double closest = 2;  // smallest 1 + m3·n3 of that joint over the run (2: parallel, 0: antiparallel)
  const int steps = 30;
  for (int s = 0; s < steps; ++s) {
    iterations += newton.step(sys, scene.step).iterations;
    const auto f = points.frames(static_cast<sewn::physics::Index>(vertex_joint), sys.state());
    closest = std::min(closest, 1 + f[1].dot(f[3]));
    REQUIRE(std::isfinite(sys.potential_energy()));
  }
  MESSAGE("toy ball with joints: " << iterations << " Newton iterations in " << steps << " steps; the foot joint's axes at most "
                                   << std::acos(closest - 1) << " rad apart (1 + m3.n3 >= " << closest << ")");
  // The spring leaves the platform along its normal and bends, but its foot never folds back
  // past a right angle onto the platform.
  CHECK(closest > 1.0);
}

}  // namespace test_scene_jacobians
