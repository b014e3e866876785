// Issue 17, blow-up detection: a semi-implicit run above its stable step is stopped within
// 10 steps of the divergence's start, before any position, velocity or energy reaches 1e12,
// with the step, the node and a smaller step in the message.
#include <doctest/doctest.h>

#include <algorithm>
#include <cmath>
#include <memory>
#include <string>

#include "sewn/physics/integrators.hpp"
#include "sewn/physics/mss_model.hpp"

namespace test_blowup {

using namespace sewn;
using namespace sewn::physics;
using Eigen::Vector3d;

namespace {

// The 1 m cantilever of bench/results/mss.md, coarsely meshed, clamped at x = 0, undamped so
// that nothing but the scheme decides stability.
std::unique_ptr<MssModel<3>> cantilever() {
  MssOptions opt;
  opt.damping = DampingModel::none;
  auto m = std::make_unique<MssModel<3>>(hex_grid(20, 2, 2, {{0.05, 0.05, 0.05}, {}}), std::vector<MaterialParams>{{100e6, 0.3, 1000}},
                                         std::vector<std::uint32_t>{}, opt);
  for (Index i = 0; i < m->nodes().size(); ++i)
    if (m->rest_position(i).x() <= 1e-12) m->nodes().fix(i);
  return m;
}

double largest_value(const System& sys) {
  const auto& n = sys.nodes();
  double v = 0;
  for (double x : n.x()) v = std::max(v, std::abs(x));
  for (double x : n.v()) v = std::max(v, std::abs(x));
  return v;
}

struct Reference {
  int start = -1;           // first step whose energy exceeds twice its budget
  double at_start = 0;      // energy then
};

// Steps without any energy check and records, every step, kinetic + elastic energy against the
// budget the initial energy and the work of gravity allow: the divergence's start as the test
// sees it, independently of the detector.
Reference reference_run(double h, int steps) {
  const auto m = cantilever();
  System& sys = m->system();
  SymplecticEulerOptions o;
  o.enforce_stable_step = false;
  o.health.energy_check_interval = 0;
  SymplecticEuler se(o);
  const double e0 = sys.kinetic_energy() + sys.potential_energy(EnergyKind::internal);
  const double g0 = sys.potential_energy(EnergyKind::external);
  const double floor = 1e-6 * sys.energy_scale();
  Reference r;
  for (int n = 1; n <= steps; ++n) {
    try {
      (void)se.step(sys, h);
    } catch (const BlowupError&) {
      break;  // non-finite: the start has been seen long before
    }
    const double e = sys.kinetic_energy() + sys.potential_energy(EnergyKind::internal);
    const double budget = e0 + std::max(0.0, g0 - sys.potential_energy(EnergyKind::external));
    if (e > 2 * budget + floor) {
      r.start = n;
      r.at_start = e;
      break;
    }
  }
  return r;
}

}  // namespace

TEST_CASE("a semi-implicit divergence is caught within 10 steps, before any value reaches 1e12") {
  const double bound = [] {
    return cantilever()->system().stable_step().h_max;
  }();
  // The Gershgorin bound is ~1.3x below the true limit: 1.6x is just unstable, 100x the
  // issue's "step 100x the explicit limit".
  for (double factor : {1.6, 3.0, 10.0, 100.0}) {
    CAPTURE(factor);
    const double h = factor * bound;
    const Reference ref = reference_run(h, 20000);
    REQUIRE(ref.start > 0);
    const auto model = cantilever();
    MssModel<3>& m = *model;
    SymplecticEulerOptions o;
    o.enforce_stable_step = false;  // the user's `allow_unstable`
    SymplecticEuler se(o);
    int caught = -1;
    std::string what;
    double suggested = 0;
    Index node = invalid_index;
    for (int n = 1; n <= ref.start + 1000 && caught < 0; ++n) {
      try {
        (void)se.step(m.system(), h);
      } catch (const BlowupError& e) {
        caught = n;
        what = e.what();
        suggested = e.suggested_step();
        node = e.node();
        CHECK(e.step() == static_cast<std::uint64_t>(n));
      }
    }
    MESSAGE("h = " << factor << " x bound: divergence starts at step " << ref.start << ", caught at step " << caught
                   << ", largest |x| or |v| then " << largest_value(m.system()));
    REQUIRE(caught > 0);
    CHECK(caught - ref.start <= 10);
    CHECK(largest_value(m.system()) < 1e12);
    CHECK(m.system().kinetic_energy() + m.system().potential_energy() < 1e12);
    CHECK(what.find("step " + std::to_string(caught)) != std::string::npos);
    CHECK(what.find("node " + std::to_string(node)) != std::string::npos);
    CHECK(what.find("suggested step") != std::string::npos);
    // the suggestion is below the bound, hence a step the scheme accepts
    CHECK(suggested < bound);
    CHECK(suggested > 0);
  }
}

TEST_CASE("a stable semi-implicit run just below its bound is not stopped") {
  // Just below the bound the plain energy swings but stays bounded: no check may fire.
  const auto model = cantilever();
  MssModel<3>& m = *model;
  SymplecticEuler se;
  const double h = 0.99 * m.system().stable_step().h_max;
  for (int n = 0; n < 5000; ++n) REQUIRE_NOTHROW((void)se.step(m.system(), h));
}

}  // namespace test_blowup
