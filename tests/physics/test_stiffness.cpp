// Stiffness and mass formulas: the PHYSICS_NOTES §1.2 table, the negative-stiffness
// thresholds, the defining uniaxial property of Baudet's edge fit on non-cubic boxes, van
// Gelder's regular tet and equilateral triangle, lumped masses, and input checks.
#include <doctest/doctest.h>

#include <cmath>

#include "sewn/physics/physics.hpp"

namespace test_stiffness {

using namespace sewn::physics;
using doctest::Approx;
using Eigen::Vector3d;

TEST_CASE("Baudet values of the unit cube and unit square (PHYSICS_NOTES §1.2 table)") {
  const BoxStiffness cube = baudet_box(1.0, 0.3, 1, 1, 1);
  for (double e : cube.edge) CHECK(e == Approx(0.21154).epsilon(1e-4));
  CHECK(cube.diagonal == Approx(0.28846).epsilon(1e-4));
  // Closed forms (1+4ν)/(8(1+ν)) E a and 3/(8(1+ν)) E a, with E and a scaling linearly.
  const BoxStiffness big = baudet_box(2e8, 0.3, 0.0125, 0.0125, 0.0125);
  CHECK(big.edge[0] == Approx((1 + 4 * 0.3) / (8 * 1.3) * 2e8 * 0.0125).epsilon(1e-12));
  CHECK(big.diagonal == Approx(3 / (8 * 1.3) * 2e8 * 0.0125).epsilon(1e-12));
  const RectangleStiffness sq = baudet_rectangle(1.0, 0.3, 1, 1);
  CHECK(sq.edge[0] == Approx(0.36538).epsilon(1e-4));
  CHECK(sq.edge[1] == Approx(0.36538).epsilon(1e-4));
  CHECK(sq.diagonal == Approx(0.38462).epsilon(1e-4));
  // At the Cauchy ratio ν = 1/4 (3D): k = μa/2 and k_d = 3λa/4.
  const double nu = 0.25, mu = 1 / (2 * (1 + nu)), lambda = nu / ((1 + nu) * (1 - 2 * nu));
  const BoxStiffness cauchy = baudet_box(1.0, nu, 1, 1, 1);
  CHECK(cauchy.edge[0] == Approx(mu / 2).epsilon(1e-12));
  CHECK(cauchy.diagonal == Approx(3 * lambda / 4).epsilon(1e-12));
}

TEST_CASE("negative Baudet edge stiffness: thresholds, report, fallbacks") {
  CHECK(baudet_box_max_aspect(0.3) == Approx(1.543).epsilon(3e-4));
  CHECK(baudet_rectangle_max_aspect(0.3) == Approx(std::sqrt(2 + 3 * 0.3)).epsilon(1e-14));
  CHECK(baudet_rectangle_max_aspect(0.3) == Approx(1.703).epsilon(3e-4));
  // The sign changes exactly there (i/j = i/k for the box).
  for (double nu : {0.0, 0.25, 0.3, 0.45}) {
    const double rb = baudet_box_max_aspect(nu), rr = baudet_rectangle_max_aspect(nu);
    CHECK(baudet_box_edge(1, nu, rb * (1 - 1e-9), 1, 1) > 0);
    CHECK(baudet_box_edge(1, nu, rb * (1 + 1e-9), 1, 1) < 0);
    CHECK(baudet_rectangle_edge(1, nu, rr * (1 - 1e-9), 1) > 0);
    CHECK(baudet_rectangle_edge(1, nu, rr * (1 + 1e-9), 1) < 0);
  }
  // Shortening an edge never makes it negative.
  CHECK(baudet_box_edge(1, 0.3, 0.1, 1, 1) > 0);
  const BoxStiffness elongated = baudet_box(1.0, 0.3, 1.6, 1, 1);
  CHECK_FALSE(elongated.valid());
  CHECK(elongated.edge[0] < 0);
  CHECK(elongated.edge[1] > 0);
  CHECK(elongated.diagonal > 0);
  CHECK(describe(elongated).find("along x = -") != std::string::npos);
  const BoxStiffness clamped = clamp_edges(elongated, 0.0);
  CHECK(clamped.edge[0] == 0.0);
  CHECK(clamped.edge[1] == elongated.edge[1]);
  const BoxStiffness floored = clamp_edges(elongated, 0.05);
  CHECK(floored.edge[0] == 0.05);
  CHECK(floored.valid());
  const BoxStiffness cube_eq = baudet_box_cube_equivalent(1.0, 0.3, 1.6, 1, 1);
  CHECK(cube_eq.valid());
  CHECK(cube_eq.edge[0] == Approx(baudet_box(1.0, 0.3, 1, 1, 1).edge[0] * std::cbrt(1.6)));
  CHECK_FALSE(baudet_rectangle(1.0, 0.3, 2.0, 1.0).valid());
  CHECK(baudet_rectangle_square_equivalent(1.0, 0.3, 2.0, 1.0).valid());
  CHECK_THROWS_AS((void)clamp_edges(elongated, -1.0), InputError);
}

// The edge values are fitted so that a box stretched by ε along one axis, with the Poisson
// contraction -νε imposed on the others, pulls on its face with E ε A (PHYSICS_NOTES §1.2).
// This checks the printed non-cubic formulas (all three edge orientations) physically.
TEST_CASE("Baudet box: uniaxial force with imposed Poisson contraction is E ε A, for non-cubic boxes") {
  for (double nu : {0.25, 0.3}) {
    const double L[3] = {0.02, 0.013, 0.017}, E = 3e7, eps = 1e-7;
    const BoxStiffness ks = baudet_box(E, nu, L[0], L[1], L[2]);
    REQUIRE(ks.valid());
    for (int axis = 0; axis < 3; ++axis) {
      System sys;
      Eigen::Vector3d strain = Eigen::Vector3d::Constant(-nu * eps);
      strain[axis] = eps;
      for (int c = 0; c < 8; ++c) {
        const Vector3d p((c & 1) * L[0], ((c >> 1) & 1) * L[1], ((c >> 2) & 1) * L[2]);
        sys.nodes().add(p + strain.cwiseProduct(p), Vector3d::Zero(), 1.0);
      }
      Springs& sp = sys.add<Springs>();
      for (int c = 0; c < 8; ++c)
        for (int a = 0; a < 3; ++a)
          if (((c >> a) & 1) == 0) sp.add(c, c | (1 << a), ks.edge[a], L[a]);
      const double D = std::sqrt(L[0] * L[0] + L[1] * L[1] + L[2] * L[2]);
      for (int c = 0; c < 4; ++c) sp.add(c, 7 - c, ks.diagonal, D, SpringKind::diagonal);
      sys.compute_forces();
      double pull = 0;
      for (int c = 0; c < 8; ++c)
        if ((c >> axis) & 1) pull += sys.nodes().force(c)[axis];
      const double area = L[0] * L[1] * L[2] / L[axis];
      CHECK(-pull == Approx(E * eps * area).epsilon(1e-5));
    }
  }
}

TEST_CASE("van Gelder stiffness: regular tetrahedron and equilateral triangle") {
  const double E = 2.5e6, l = 0.03;
  const Vector3d p0(0, 0, 0), p1(l, 0, 0), p2(l / 2, l * std::sqrt(3.0) / 2, 0);
  const Vector3d p3(l / 2, l * std::sqrt(3.0) / 6, l * std::sqrt(2.0 / 3.0));
  for (double k : van_gelder_tet(E, p0, p1, p2, p3)) CHECK(k == Approx(E * l / (6 * std::sqrt(2.0))).epsilon(1e-12));
  CHECK(van_gelder_tet_edge(1.0, std::pow(1.0, 3) / (6 * std::sqrt(2.0)), 1.0) == Approx(0.1179).epsilon(1e-3));
  // Equilateral triangle: √3/4 E, the value Lloyd et al. derive for ν = 1/3.
  for (double k : van_gelder_triangle(E, p0, p1, p2)) CHECK(k == Approx(std::sqrt(3.0) / 4 * E).epsilon(1e-12));
  CHECK_THROWS_WITH_AS((void)van_gelder_tet(E, p0, p1, p2, (p0 + p1) / 2), doctest::Contains("degenerate"), InputError);
  CHECK_THROWS_AS((void)van_gelder_triangle(E, p0, p1, 2 * p1), InputError);
}

TEST_CASE("lumped masses: the 5-tetrahedron cube gives corner masses ρV/24 and 5ρV/24") {
  const double rho = 1000, a = 0.1, V = a * a * a;
  Vector3d c[8];
  for (int i = 0; i < 8; ++i) c[i] = Vector3d((i & 1) * a, ((i >> 1) & 1) * a, ((i >> 2) & 1) * a);
  // Central tet on corners 0, 3, 5, 6; each other corner cuts off one corner tet.
  const int tets[5][4] = {{0, 3, 5, 6}, {1, 0, 3, 5}, {2, 0, 3, 6}, {4, 0, 5, 6}, {7, 3, 5, 6}};
  double m[8] = {};
  for (const auto& t : tets) {
    const double vol = tet_volume(c[t[0]], c[t[1]], c[t[2]], c[t[3]]);
    for (int v : t) m[v] += lumped_corner_mass(rho, vol, 4);
  }
  for (int i : {1, 2, 4, 7}) CHECK(m[i] == Approx(rho * V / 24).epsilon(1e-12));
  for (int i : {0, 3, 5, 6}) CHECK(m[i] == Approx(5 * rho * V / 24).epsilon(1e-12));
  CHECK(lumped_corner_mass(rho, V, 8) == Approx(rho * V / 8));
  CHECK_THROWS_AS((void)lumped_corner_mass(-1, V, 8), InputError);
  CHECK_THROWS_AS((void)lumped_corner_mass(rho, V, 0), InputError);
}

TEST_CASE("stiffness formulas refuse bad material and geometry, naming the value") {
  CHECK_THROWS_WITH_AS((void)baudet_box(1, 0.5, 1, 1, 1), doctest::Contains("Poisson ratio"), InputError);
  CHECK_THROWS_WITH_AS((void)baudet_box(0, 0.3, 1, 1, 1), doctest::Contains("Young's modulus"), InputError);
  CHECK_THROWS_AS((void)baudet_box(1, -1.0, 1, 1, 1), InputError);
  CHECK_THROWS_WITH_AS((void)baudet_box_edge(1, 0.3, -1, 1, 1), doctest::Contains("edge length i"), InputError);
  CHECK_THROWS_AS((void)baudet_rectangle(1, 0.3, 1, std::nan("")), InputError);
  CHECK_THROWS_AS((void)baudet_rectangle_diagonal(-5, 0.3, 1, 1), InputError);
  CHECK_THROWS_AS((void)van_gelder_tet_edge(1, 0, 1), InputError);
  CHECK_THROWS_AS((void)baudet_box_max_aspect(0.7), InputError);
}

}  // namespace test_stiffness
