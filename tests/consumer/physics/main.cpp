// The mass-spring model taken without cutting or io: a beam clamped at x = 0 stepped under
// gravity with the linearly implicit scheme; its free end must sag and every CG converge.
#include <cstdio>

#include "sewn/physics/integrators.hpp"
#include "sewn/physics/mss_model.hpp"

int main() {
  sewn::physics::MssModel<3> beam(sewn::hex_grid(4, 1, 1, {{0.1, 0.1, 0.1}, {}}), {{1e6, 0.3, 1000}}, {});
  auto& nodes = beam.nodes();
  sewn::physics::Index tip = 0;
  for (sewn::physics::Index i = 0; i < nodes.size(); ++i) {
    if (nodes.position(i).x() < 1e-9) nodes.fix(i);
    if (nodes.position(i).x() > nodes.position(tip).x()) tip = i;
  }
  sewn::physics::LinearlyImplicitEuler euler;
  bool converged = true;
  for (int s = 0; s < 50; ++s) converged = euler.step(beam.system(), 1e-3).cg_converged && converged;
  const double sag = -nodes.position(tip).z();
  std::printf("consumer_physics: %u nodes, tip sag %.3g mm after 50 steps, CG %s\n", nodes.size(), 1e3 * sag,
              converged ? "converged" : "FAILED");
  return converged && sag > 0 ? 0 : 1;
}
