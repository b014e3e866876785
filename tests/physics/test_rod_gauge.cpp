// The twist solve of a rod whose energy does not change when all its material angles turn
// together (round section, straight at rest) and that holds no angle: the θ block is then
// singular along (1, ..., 1). Rod::solve_twist must converge there, leave the angles' mean
// where it was (no drift along the free direction), and find the same twist as a rod with one
// angle held.
#include <cmath>
#include <random>
#include <vector>

#include <Eigen/Geometry>
#include <doctest/doctest.h>

#include "sewn/physics/rods/rod.hpp"

namespace test_rod_gauge {
namespace {

using sewn::physics::rods::Points;
using sewn::physics::rods::Rod;
using sewn::physics::rods::Section;
using sewn::physics::rods::Vec3;

Points straight(int n, double L) {
  Points x(3, n);
  for (int i = 0; i < n; ++i) x.col(i) = Vec3(L * i / (n - 1), 0, 0);
  return x;
}

// The rod bent and twisted out of its rest line: each vertex moved by up to `amount`.
Points deformed(const Points& rest, std::mt19937& rng, double amount) {
  std::uniform_real_distribution<double> u(-amount, amount);
  Points x = rest;
  for (int i = 0; i < x.cols(); ++i) x.col(i) += Vec3(u(rng), u(rng), u(rng));
  return x;
}

double mean(std::span<const double> v) {
  double s = 0;
  for (double t : v) s += t;
  return s / static_cast<double>(v.size());
}

TEST_CASE("rod twist solve with no held angle: converges, no drift of the mean angle, the held rod's answer") {
  const Section sec = Section::circular(1e9, 0.3, 0.002);
  const Points rest = straight(14, 1.0);
  for (std::uint32_t seed = 1; seed <= 5; ++seed) {
    CAPTURE(seed);
    std::mt19937 rng(seed);
    Rod free_rod(rest, false, sec), held(rest, false, sec);
    held.fix_theta(0);
    const int m = free_rod.num_edges();
    // a sequence of states as a run would visit them, the frames following each
    Points x = rest;
    for (int k = 0; k < 8; ++k) {
      x = deformed(x, rng, 0.01);
      const double mean_before = mean(free_rod.theta());
      int iterations = 0;
      CHECK_NOTHROW(iterations = free_rod.solve_twist(x));
      CHECK(iterations < 20);
      (void)held.solve_twist(x);
      // the free direction is left alone: the angles' mean stays where it was
      CHECK(std::abs(mean(free_rod.theta()) - mean_before) < 1e-12);
      // ∂E/∂θ = 0 on every edge (against the torque scale GJ/l̄)
      Eigen::VectorXd g;
      const double E = free_rod.evaluate(x, g, nullptr);
      const double torque_scale = sec.GJ / free_rod.rest_length(0);
      CHECK(g.tail(m).lpNorm<Eigen::Infinity>() < 1e-9 * torque_scale);
      // the same minimum as with θ⁰ held: the same energy and the same angle differences
      CHECK(std::abs(E - held.energy(x)) <= 1e-12 * std::max(E, 1e-300) + 1e-18);
      for (int j = 1; j < m; ++j) {
        const double d_free = free_rod.theta()[static_cast<std::size_t>(j)] - free_rod.theta()[0];
        const double d_held = held.theta()[static_cast<std::size_t>(j)] - held.theta()[0];
        CHECK(std::abs(d_free - d_held) < 1e-9);
      }
      free_rod.update_frames(x);
      held.update_frames(x);
    }
  }
}

TEST_CASE("rod twist solve with no held angle: a bent-at-rest or elliptic rod keeps its full solve") {
  // neither has the free direction: their θ block is definite, and the solve moves the mean
  // angle when the minimum asks for it
  std::mt19937 rng(11);
  Points bent = straight(10, 1.0);
  for (int i = 0; i < bent.cols(); ++i) bent(1, i) = 0.2 * std::sin(3.0 * i / 9.0);
  for (const auto& [rest, sec] : {std::pair{bent, Section::circular(1e9, 0.3, 0.002)},
                                  std::pair{straight(10, 1.0), Section::elliptic(1e9, 0.3, 0.003, 0.001)}}) {
    Rod rod(rest, false, sec);
    const Points x = deformed(rest, rng, 0.02);
    CHECK_NOTHROW((void)rod.solve_twist(x));
    Eigen::VectorXd g;
    (void)rod.evaluate(x, g, nullptr);
    CHECK(g.tail(rod.num_edges()).lpNorm<Eigen::Infinity>() < 1e-9 * sec.GJ / rod.rest_length(0));
  }
}

}  // namespace
}  // namespace test_rod_gauge
