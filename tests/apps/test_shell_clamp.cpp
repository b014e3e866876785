// Clamping a shell on an edge from a scene's held nodes (build_continuum's `held`): a strip
// held by its first two columns of nodes has the triangles between them as clamps of Morley
// and patch bending, so the free strip is clamped exactly on the inner held column. Its static tip under
// its weight then matches Euler–Bernoulli for the free length; without the clamp flags the
// held triangles bend like any other and the clamp acts about half a cell further out.
#include <doctest/doctest.h>

#include <cmath>
#include <memory>
#include <string>

#include "sewn/apps/cell_models.hpp"
#include "sewn/apps/continuum.hpp"
#include "sewn/io/cleanup.hpp"
#include "sewn/physics/integrate/newton_euler.hpp"

namespace test_shell_clamp {
namespace {

using sewn::physics::Index;

constexpr double young = 2e11, rho = 1000.0, thickness = 0.01, cell = 0.1, width = 0.1, free_length = 1.0;

struct Result {
  double tip = 0.0;
  Index elements = 0;
};

// A strip of 11 × 1 cells of 0.1 m (x from 0 to 1.1 m), the columns x = 0 and x = 0.1 held,
// solved statically under gravity with `bending`; clamp flags from the held nodes if `flags`.
Result solve(const std::string& bending, bool flags) {
  sewn::GridSpec g;
  g.spacing = {cell, width, 1.0};
  const sewn::IndexedMesh mesh = sewn::tri_grid(11, 1, g);
  const std::vector<sewn::physics::MaterialParams> materials{{young, 0.0, rho, thickness, 1e-4, sewn::physics::ElongatedPolicy::refuse}};
  sewn::physics::MssOptions mo;
  mo.damping = sewn::physics::DampingModel::none;
  sewn::physics::MssModel<3> model(mesh, materials, std::vector<std::uint32_t>{}, mo);
  sewn::app::Scene s;
  s.file = "clamp.json";
  s.model = "shell";
  s.integrator = "newton";
  s.bending = bending;
  s.damping = "none";
  std::vector<std::uint8_t> held(model.nodes().size(), 0);
  for (Index i = 0; i < model.nodes().size(); ++i) held[i] = model.rest_position(i).x() <= cell + 1e-9;
  const auto parts = sewn::app::build_continuum(s, materials, mesh, sewn::app::cell_models(mesh, sewn::io::embedded_cells(mesh), s, "m"),
                                                std::vector<int>(mesh.num_cells(), -1), model,
                                                flags ? std::span<const std::uint8_t>(held) : std::span<const std::uint8_t>());
  REQUIRE((bending != "morley" || parts.morley.term != nullptr));
  for (Index i = 0; i < model.nodes().size(); ++i)
    if (held[i] != 0) model.nodes().fix(i);
  sewn::physics::integrate::NewtonEulerOptions opt;
  opt.solver = sewn::physics::integrate::LinearSolver::ldlt;
  const double h = 1e3;  // quasi-static: inertia M/h² negligible
  opt.velocity_tolerance = 1e-13 / h;
  sewn::physics::integrate::NewtonEuler newton(opt);
  (void)newton.step(model.system(), h);
  Result r;
  int tips = 0;
  for (Index i = 0; i < model.nodes().size(); ++i)
    if (std::abs(model.rest_position(i).x() - (cell + free_length)) < 1e-9) {
      r.tip -= model.nodes().position(i).z();
      ++tips;
    }
  r.tip /= tips;
  if (bending == "morley") {
    r.elements = parts.morley.term->size();
  } else {
    const auto& p = parts.patches;
    r.elements = (p.one ? p.one->size() : 0) + (p.two ? p.two->size() : 0) + (p.three ? p.three->size() : 0);
  }
  return r;
}

TEST_CASE("shell scenes: triangles held on every node clamp Morley and patch bending exactly on the inner held row") {
  const double q = rho * 9.81 * thickness * width, EI = young * width * thickness * thickness * thickness / 12;
  const double exact = q * std::pow(free_length, 4) / (8 * EI);
  for (const std::string bending : {"morley", "patch"}) {
    CAPTURE(bending);
    const Result clamped = solve(bending, true), loose = solve(bending, false);
    CHECK(clamped.elements == 20);  // the two held triangles bend nothing
    CHECK(loose.elements == 22);
    const double e_clamped = (clamped.tip - exact) / exact, e_loose = (loose.tip - exact) / exact;
    CAPTURE(e_clamped);
    CAPTURE(e_loose);
    // either model's error on 10 cells of one row is 1-1.5 % (test_elastic_morley, test_elastic_shells);
    // a clamp half a cell out, 0.05 m on 1 m, lengthens the beam's L⁴ by ~20 %
    CHECK(std::abs(e_clamped) < 0.03);
    CHECK(e_loose > 0.1);
  }
}

}  // namespace
}  // namespace test_shell_clamp
