// Discrete elastic rod stencils: gradients and Hessians against central finite differences
// (random, nearly collinear and nearly folded configurations, frames off their reference
// tangents), rigid-motion invariance, transport near its singularity, angle tracking.
#include <chrono>
#include <cmath>
#include <cstdio>
#include <numbers>
#include <random>
#include <string>

#include <Eigen/Eigenvalues>
#include <Eigen/Geometry>
#include <doctest/doctest.h>

#include "sewn/physics/errors.hpp"
#include "sewn/physics/rods/stencils.hpp"

namespace test_rod_stencils {

using namespace sewn::physics;
using namespace sewn::physics::rods;

namespace {

using Q = Eigen::Matrix<double, 11, 1>;

struct Case {
  Q q;
  BendTwistRest rest;
  BendTwistFrames frames;
};

BendTwistEval eval(const Case& c, const Q& q, Want w) {
  return bend_twist(q.segment<3>(0), q.segment<3>(3), q.segment<3>(6), q[9], q[10], c.rest, c.frames, w);
}

// Frames whose reference tangents are the given edges' tangents turned by a small random
// rotation, so the transported frames carry a spin (the general case inside a step).
BendTwistFrames frames_near(const Q& q, std::mt19937& rng, double tilt) {
  std::normal_distribution<double> n(0, 1);
  BendTwistFrames f;
  const Vec3 t0 = (q.segment<3>(3) - q.segment<3>(0)).normalized();
  const Vec3 t1 = (q.segment<3>(6) - q.segment<3>(3)).normalized();
  const Eigen::Matrix3d R0 = Eigen::AngleAxisd(tilt, Vec3(n(rng), n(rng), n(rng)).normalized()).toRotationMatrix();
  const Eigen::Matrix3d R1 = Eigen::AngleAxisd(tilt, Vec3(n(rng), n(rng), n(rng)).normalized()).toRotationMatrix();
  f.tangent0 = R0 * t0;
  f.tangent1 = R1 * t1;
  f.director0 = any_perpendicular(f.tangent0);
  f.director1 = parallel_transport(f.tangent0, f.tangent1, f.director0);
  f.director1 = Eigen::AngleAxisd(n(rng), f.tangent1) * f.director1;  // some reference twist
  return f;
}

// Edges turning by `turn`, frames `tilt` off their reference tangents, θ^i − θ^{i−1} about
// `twist` (the natural strains are random and small: a large twist is a large strain).
Case random_case(std::mt19937& rng, double turn, double tilt, double twist = 0.0) {
  std::normal_distribution<double> n(0, 1);
  std::uniform_real_distribution<double> len(0.5, 1.5);
  Case c;
  const Vec3 x1(n(rng), n(rng), n(rng));
  const Vec3 d0 = Vec3(n(rng), n(rng), n(rng)).normalized();
  const Vec3 axis = any_perpendicular(d0);
  const Vec3 d1 = Eigen::AngleAxisd(turn, Eigen::AngleAxisd(n(rng), d0) * axis) * d0;
  c.q.segment<3>(0) = x1 - len(rng) * d0;
  c.q.segment<3>(3) = x1;
  c.q.segment<3>(6) = x1 + len(rng) * d1;
  c.q[9] = n(rng);
  c.q[10] = c.q[9] + twist + n(rng);
  c.rest = {0.3 * n(rng), 0.2 * n(rng), 0.4 * n(rng), 0.9, 2.0, 1.3, 0.7};
  c.frames = frames_near(c.q, rng, tilt);
  c.frames.reference_twist = eval(c, c.q, Want::energy).reference_twist;
  return c;
}

// Largest |analytic − central difference| relative to the largest analytic entry.
double gradient_error(const Case& c, double h) {
  const BendTwistEval e = eval(c, c.q, Want::gradient);
  double err = 0, scale = 1e-12;
  for (int k = 0; k < 11; ++k) {
    Q qp = c.q, qm = c.q;
    qp[k] += h;
    qm[k] -= h;
    const double fd = (eval(c, qp, Want::energy).energy - eval(c, qm, Want::energy).energy) / (2 * h);
    err = std::max(err, std::abs(fd - e.gradient[k]));
    scale = std::max(scale, std::abs(e.gradient[k]));
  }
  return err / scale;
}

double hessian_error(const Case& c, double h) {
  const BendTwistEval e = eval(c, c.q, Want::hessian);
  Eigen::Matrix<double, 11, 11> fd;
  for (int k = 0; k < 11; ++k) {
    Q qp = c.q, qm = c.q;
    qp[k] += h;
    qm[k] -= h;
    fd.col(k) = (eval(c, qp, Want::gradient).gradient - eval(c, qm, Want::gradient).gradient) / (2 * h);
  }
  return (fd - e.hessian).cwiseAbs().maxCoeff() / std::max(1e-12, e.hessian.cwiseAbs().maxCoeff());
}

}  // namespace

TEST_CASE("rod stencil: bend-twist gradient and Hessian match finite differences") {
  std::mt19937 rng(1234);
  struct Regime {
    const char* name;
    double turn, tilt, twist, h, tol;
  };
  // Turning angles: generic, nearly collinear, nearly folded (t0·t1 = −0.9), a kink near 180°
  // (χ = 1 − cos(φ) ≈ 1.5e-4: the energy scales like 1/χ², so the step is scaled down with it);
  // frames far (1.5 rad) from the current tangents; a twist of 3 rad past the natural one.
  const Regime regimes[] = {{"generic", 0.8, 0.2, 0.0, 1e-6, 1e-6},
                            {"nearly collinear", 1e-5, 0.05, 0.0, 1e-7, 1e-6},
                            {"synced frames", 0.5, 0.0, 0.0, 1e-6, 1e-6},
                            {"nearly folded", std::acos(-0.9), 0.2, 0.0, 1e-6, 1e-6},
                            {"frames far off", 0.8, 1.5, 0.0, 1e-6, 1e-6},
                            {"large twist", 0.8, 0.2, 3.0, 1e-6, 1e-6},
                            {"kink 179 deg", std::numbers::pi * 179.0 / 180.0, 0.1, 0.0, 1e-9, 1e-4}};
  for (const Regime& r : regimes) {
    const std::string regime = r.name;
    CAPTURE(regime);
    double worst = 0;
    for (int trial = 0; trial < 20; ++trial) {
      const Case c = random_case(rng, r.turn, r.tilt, r.twist);
      CHECK(eval(c, c.q, Want::energy).energy > 0);
      CHECK(gradient_error(c, r.h) < r.tol);
      const double herr = hessian_error(c, r.h);
      worst = std::max(worst, herr);
      CHECK(herr < r.tol);
      // Every request returns the same energy and gradient; the Hessian is exactly symmetric.
      const BendTwistEval g = eval(c, c.q, Want::gradient), H = eval(c, c.q, Want::hessian);
      CHECK(H.energy == g.energy);
      CHECK(H.gradient == g.gradient);
      CHECK(H.hessian == H.hessian.transpose());
      // The angle block at a gradient's cost equals the full Hessian's.
      const BendTwistEval a = eval(c, c.q, Want::angle_hessian);
      CHECK(a.gradient == g.gradient);
      CHECK((a.hessian.bottomRightCorner<2, 2>() - H.hessian.bottomRightCorner<2, 2>()).norm() <=
            1e-12 * (1 + H.hessian.bottomRightCorner<2, 2>().norm()));
      CHECK(a.hessian.topLeftCorner<9, 11>().isZero());
    }
    MESSAGE(regime << ": largest relative Hessian error " << worst);
  }
}

TEST_CASE("rod stencil: the Gauss-Newton Hessian is exact at the natural strains and PSD elsewhere") {
  std::mt19937 rng(4321);
  const double turns[] = {0.8, 1e-5, 2.5};  // generic, nearly collinear, strongly bent
  for (double turn : turns) {
    CAPTURE(turn);
    for (int trial = 0; trial < 20; ++trial) {
      Case c = random_case(rng, turn, 0.2);
      const BendTwistEval H = eval(c, c.q, Want::hessian), gn = eval(c, c.q, Want::gauss_newton);
      // Only the Hessian stand-in is new: energy and gradient are the plain pass's, bit for bit.
      const BendTwistEval g = eval(c, c.q, Want::gradient);
      CHECK(gn.energy == g.energy);
      CHECK(gn.gradient == g.gradient);
      CHECK(gn.kappa1 == g.kappa1);
      CHECK(gn.twist == g.twist);
      // PSD by construction; symmetric exactly.
      CHECK(gn.hessian == gn.hessian.transpose());
      const Eigen::SelfAdjointEigenSolver<Eigen::Matrix<double, 11, 11>> eig(gn.hessian);
      CHECK(eig.eigenvalues().minCoeff() >= -1e-12 * gn.hessian.norm());
      // Away from the natural strains the exact Hessian has the curvature terms GN drops: the two
      // differ (the random natural strains are not the current ones).
      CHECK((gn.hessian - H.hessian).norm() > 1e-6 * H.hessian.norm());
      // At the natural strains (κ̄, m̄ := the current ones; distinct stiffnesses, so each strain's
      // gradient is tested on its own) the dropped terms vanish: GN equals the exact Hessian.
      c.rest.kappa1 = H.kappa1;
      c.rest.kappa2 = H.kappa2;
      c.rest.twist = H.twist;
      const BendTwistEval at_rest = eval(c, c.q, Want::hessian), gn_rest = eval(c, c.q, Want::gauss_newton);
      CHECK(gn_rest.energy < 1e-20);
      CHECK((gn_rest.hessian - at_rest.hessian).norm() <= 1e-12 * at_rest.hessian.norm());
    }
  }
}

TEST_CASE("rod stencil: with frames at the current tangents the gradient is PHYSICS_NOTES 3.1's") {
  std::mt19937 rng(7);
  const Case c = random_case(rng, 0.6, 0.0);
  const BendTwistEval e = eval(c, c.q, Want::gradient);
  // Twist gradient alone (EI = 0): ∇_{i−1}m = −κb/(2|e^{i−1}|), ∇_{i+1}m = κb/(2|e^i|).
  Case tw = c;
  tw.rest.EI1 = tw.rest.EI2 = 0;
  const BendTwistEval t = eval(tw, tw.q, Want::gradient);
  const Vec3 e0 = c.q.segment<3>(3) - c.q.segment<3>(0), e1 = c.q.segment<3>(6) - c.q.segment<3>(3);
  const Vec3 kb = 2 * e0.normalized().cross(e1.normalized()) / (1 + e0.normalized().dot(e1.normalized()));
  const double dE_dm = tw.rest.GJ / tw.rest.voronoi * (t.twist - tw.rest.twist);
  CHECK((t.gradient.segment<3>(0) - dE_dm * (-kb / (2 * e0.norm()))).norm() < 1e-12);
  CHECK((t.gradient.segment<3>(6) - dE_dm * (kb / (2 * e1.norm()))).norm() < 1e-12);
  CHECK(t.gradient[10] == doctest::Approx(dE_dm));
  CHECK(e.energy > 0);
}

TEST_CASE("rod stencil: rigid motions give zero force and torque") {
  std::mt19937 rng(99);
  for (int trial = 0; trial < 20; ++trial) {
    const Case c = random_case(rng, 1.0, 0.0);  // frames synced: the state an accepted step leaves
    const BendTwistEval e = eval(c, c.q, Want::gradient);
    Vec3 force = Vec3::Zero(), torque = Vec3::Zero();
    for (int k = 0; k < 3; ++k) {
      force += e.gradient.segment<3>(3 * k);
      torque += c.q.segment<3>(3 * k).cross(e.gradient.segment<3>(3 * k));
    }
    // The material frames turn with the body: an infinitesimal rotation ω turns edge j's
    // frame about t^j by ω·t^j, so the angles' generalised forces join the torque.
    const Vec3 t0 = (c.q.segment<3>(3) - c.q.segment<3>(0)).normalized();
    const Vec3 t1 = (c.q.segment<3>(6) - c.q.segment<3>(3)).normalized();
    torque += e.gradient[9] * t0 + e.gradient[10] * t1;
    const double scale = e.gradient.norm() * (1 + c.q.head<9>().norm());
    CHECK(force.norm() < 1e-12 * scale);
    CHECK(torque.norm() < 1e-12 * scale);

    // A finite rotation and translation of positions and frames together leaves the energy.
    const Eigen::Matrix3d R = Eigen::AngleAxisd(2.5, Vec3(0.3, -0.5, 0.8).normalized()).toRotationMatrix();
    Case moved = c;
    for (int k = 0; k < 3; ++k) moved.q.segment<3>(3 * k) = R * c.q.segment<3>(3 * k) + Vec3(4, -2, 7);
    moved.frames.tangent0 = R * c.frames.tangent0;
    moved.frames.tangent1 = R * c.frames.tangent1;
    moved.frames.director0 = R * c.frames.director0;
    moved.frames.director1 = R * c.frames.director1;
    CHECK(eval(moved, moved.q, Want::energy).energy == doctest::Approx(eval(c, c.q, Want::energy).energy).epsilon(1e-12));
  }
}

TEST_CASE("rod stencil: stretch gradient and Hessian match finite differences") {
  std::mt19937 rng(5);
  std::normal_distribution<double> n(0, 1);
  for (int trial = 0; trial < 20; ++trial) {
    const Vec3 x0(n(rng), n(rng), n(rng)), x1(n(rng), n(rng), n(rng));
    const double EA = 3.0, rest = 0.7 + 0.5 * std::abs(n(rng));
    const StretchEval s = stretch(x0, x1, EA, rest, true);
    Eigen::Matrix<double, 6, 1> q;
    q << x0, x1;
    const double h = 1e-6;
    for (int k = 0; k < 6; ++k) {
      auto qp = q, qm = q;
      qp[k] += h;
      qm[k] -= h;
      const StretchEval sp = stretch(qp.head<3>(), qp.tail<3>(), EA, rest, false);
      const StretchEval sm = stretch(qm.head<3>(), qm.tail<3>(), EA, rest, false);
      CHECK((sp.energy - sm.energy) / (2 * h) == doctest::Approx(s.gradient[k]).epsilon(1e-6));
      CHECK(((sp.gradient - sm.gradient) / (2 * h) - s.hessian.col(k)).norm() < 1e-6 * s.hessian.norm());
    }
  }
}

TEST_CASE("rod geometry: parallel transport, also near opposite tangents") {
  const Vec3 a = Vec3(1, 2, -0.5).normalized();
  const Vec3 u = any_perpendicular(a);
  for (double eps : {0.5, 1e-3, 1e-7, 0.0}) {
    const Vec3 b = (-a + eps * u.cross(a)).normalized();
    const Vec3 v = parallel_transport(a, b, u);
    CAPTURE(eps);
    CHECK(v.allFinite());
    CHECK(v.norm() == doctest::Approx(1.0).epsilon(1e-12));
    CHECK(std::abs(v.dot(b)) < 1e-9);
  }
  // Transport is a rotation: back and forth is the identity, and it keeps angles.
  const Vec3 b = Vec3(-0.2, 0.9, 0.4).normalized();
  const Vec3 w = Vec3(0.3, 0.1, 0.7);
  CHECK((parallel_transport(b, a, parallel_transport(a, b, w)) - w).norm() < 1e-14);
  CHECK((parallel_transport(a, b, a) - b).norm() < 1e-14);
}

TEST_CASE("rod geometry: angles are tracked past pi without jumps") {
  double tracked = 0;
  for (int k = 0; k <= 400; ++k) {
    const double truth = 0.05 * k;  // reaches 20 rad
    const double raw = std::atan2(std::sin(truth), std::cos(truth));
    tracked = unwrap_angle(raw, tracked);
    CHECK(tracked == doctest::Approx(truth).epsilon(1e-12));
  }
}

TEST_CASE("rod sections: circular and elliptic moduli, bad input rejected") {
  const Section c = Section::circular(2e9, 0.25, 0.01);
  const double pi = std::numbers::pi;
  CHECK(c.EA == doctest::Approx(2e9 * pi * 1e-4));
  CHECK(c.EI1 == doctest::Approx(2e9 * pi * 1e-8 / 4));
  CHECK(c.GJ == doctest::Approx(2e9 / 2.5 * pi * 1e-8 / 2));
  const Section e = Section::elliptic(2e9, 0.25, 0.02, 0.01);
  CHECK(e.EI1 / e.EI2 == doctest::Approx(4.0));
  CHECK_THROWS_AS((void)Section::circular(-1, 0.3, 0.01), InputError);
  CHECK_THROWS_AS((void)Section::circular(1e9, 0.5, 0.01), InputError);
  CHECK_THROWS_AS((void)Section::elliptic(1e9, 0.3, 0.01, NAN), InputError);
}

TEST_CASE("rod stencil: cost of the gradient, the exact and the Gauss-Newton Hessians (report only)") {
  // The machine is shared: the fastest of 30 batches is the least disturbed estimate.
  std::mt19937 rng(3);
  const Case c = random_case(rng, 0.7, 0.1);
  using clock = std::chrono::steady_clock;
  double sink = 0, g_us = 1e9, h_us = 1e9, gn_us = 1e9;
  const int reps = 200;
  for (int batch = 0; batch < 30; ++batch) {
    auto t0 = clock::now();
    for (int k = 0; k < reps; ++k) sink += eval(c, c.q, Want::gradient).gradient[k % 11];
    auto t1 = clock::now();
    for (int k = 0; k < reps; ++k) sink += eval(c, c.q, Want::hessian).hessian(k % 11, 3);
    auto t2 = clock::now();
    for (int k = 0; k < reps; ++k) sink += eval(c, c.q, Want::gauss_newton).hessian(k % 11, 3);
    auto t3 = clock::now();
    g_us = std::min(g_us, std::chrono::duration<double, std::micro>(t1 - t0).count() / reps);
    h_us = std::min(h_us, std::chrono::duration<double, std::micro>(t2 - t1).count() / reps);
    gn_us = std::min(gn_us, std::chrono::duration<double, std::micro>(t3 - t2).count() / reps);
  }
  MESSAGE("bend-twist stencil (fastest of 30 batches): gradient " << g_us << " us, gradient+exact Hessian " << h_us
                                                                   << " us, gradient+Gauss-Newton Hessian " << gn_us << " us");
  CHECK(std::isfinite(sink));
}

}  // namespace test_rod_stencils
