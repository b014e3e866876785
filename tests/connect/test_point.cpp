// Point connections: gradients against finite differences (also at twist increments near π
// and nearly antiparallel axes), invariance under rigid motions, the 2019 paper's Fig. 10
// (the incremental twist passes π and 3π linearly; the direct one wraps), and bad input.

#include <chrono>
#include <cmath>
#include <numbers>
#include <random>
#include <string>

#include <doctest/doctest.h>
#include <Eigen/Geometry>

#include "point_fd.hpp"
#include "sewn/connect/point.hpp"
#include "sewn/physics/rods/stencils.hpp"

namespace test_point {

using namespace sewn;
using namespace sewn::connect;
using Eigen::VectorXd;

namespace {

constexpr double pi = std::numbers::pi;

// A shell triangle (nodes 0, 1, 2; joint 0) opening towards −x, and a rod edge (0 → 3)
// leaving the joint along +x tilted by `tilt` about z: the first side is the triangle.
struct RodInTriangle {
  TriangleSide tri{{0, 1, 2}, std::nullopt};
  RodEdgeSide rod;
  VectorXd q = VectorXd(16);
  explicit RodInTriangle(double tilt = 0.0, double theta = 0.3) {
    const Vec3 tip(std::cos(tilt), std::sin(tilt), 0);
    rod.from = 0;
    rod.to = 3;
    rod.tangent = tip;
    rod.director = Vec3(0, 0, 1);
    q << 0, 0, 0, -1, 0.5, 0, -1, -0.5, 0, 0, 0, 0, tip[0], tip[1], tip[2], theta;
  }
};

// Two rod edges 4 → 0 and 0 → 5 meeting at node 0 with a small kink.
struct TwoRods {
  RodEdgeSide a, b;
  VectorXd q = VectorXd(14);
  TwoRods() {
    const Vec3 xa(-1, 0.1, 0), x0(0, 0, 0), xb(1, 0, 0.1);
    a.from = 4;
    a.to = 0;
    a.tangent = (x0 - xa).normalized();
    a.director = physics::rods::any_perpendicular(a.tangent);
    b.from = 0;
    b.to = 5;
    b.tangent = (xb - x0).normalized();
    b.director = physics::rods::any_perpendicular(b.tangent);
    q << xa[0], xa[1], xa[2], 0, 0, 0, -0.2, 0, 0, 0, xb[0], xb[1], xb[2], 0.4;
  }
};

void check_gradient(const PointConnection& c, const VectorXd& q, TwistUpdate u) {
  const PointEval e = c.evaluate(q, u, true);
  REQUIRE(e.gradient.size() == q.size());
  const VectorXd fd = sewn::connect::test::finite_gradient(c, q, u, 1e-6);
  INFO("analytic " << e.gradient.transpose() << "\nfinite   " << fd.transpose());
  CHECK(e.energy > 0);
  CHECK((e.gradient - fd).norm() <= 1e-6 * std::max(1.0, fd.norm()));
}

// The Hessian against central differences of the (exact, AD) gradient, and its symmetry.
void check_hessian(const PointConnection& c, const VectorXd& q, TwistUpdate u) {
  Eigen::MatrixXd H;
  const PointEval e = c.evaluate(q, u, true, &H);
  REQUIRE(H.rows() == q.size());
  REQUIRE(H.cols() == q.size());
  CHECK((e.gradient - c.evaluate(q, u, true).gradient).norm() <= 1e-12 * std::max(1.0, e.gradient.norm()));
  Eigen::MatrixXd fd(q.size(), q.size());
  const double h = 1e-6;
  for (Eigen::Index i = 0; i < q.size(); ++i) {
    VectorXd qp = q, qm = q;
    qp[i] += h;
    qm[i] -= h;
    fd.col(i) = (c.evaluate(qp, u, true).gradient - c.evaluate(qm, u, true).gradient) / (2 * h);
  }
  INFO("analytic\n" << H << "\nfinite\n" << fd);
  CHECK((H - H.transpose()).norm() <= 1e-10 * std::max(1.0, H.norm()));
  // The chained Hessian (the default) equals the whole-stencil AD one.
  Eigen::MatrixXd nested;
  (void)c.evaluate(q, u, true, &nested, HessianMethod::nested_ad);
  CHECK((H - nested).norm() <= 1e-10 * std::max(1.0, nested.norm()));
  CHECK((H - fd).norm() <= 1e-5 * std::max(1.0, fd.norm()));
}

VectorXd perturbed(const VectorXd& q, std::mt19937& rng, double size) {
  std::uniform_real_distribution<double> u(-size, size);
  VectorXd out = q;
  for (Eigen::Index i = 0; i < q.size(); ++i) out[i] += u(rng);
  return out;
}

// Applies the rotation R about the origin to the position blocks at `blocks`; each rod side
// (stencil offset, frame history) gets the θ that turns its material frame with R too (a
// rigid motion of the body, frame included).
VectorXd rotated(const VectorXd& q, const Eigen::Matrix3d& R, const std::vector<int>& blocks,
                 const std::vector<std::pair<int, RodEdgeSide>>& rods) {
  VectorXd out = q;
  for (int b : blocks) out.segment<3>(b) = R * q.segment<3>(b);
  for (const auto& [off, side] : rods) {
    const Vec3 t = (q.segment<3>(off + 3) - q.segment<3>(off)).normalized();
    const Vec3 a1 = physics::rods::parallel_transport(side.tangent, t, side.director);
    const double th = q[off + 6];
    const Vec3 m1 = std::cos(th) * a1 + std::sin(th) * t.cross(a1);
    const Vec3 t2 = R * t;
    const Vec3 a1r = physics::rods::parallel_transport(side.tangent, t2, side.director);
    out[off + 6] = physics::rods::signed_angle(a1r, R * m1, t2);
  }
  return out;
}

}  // namespace

TEST_CASE("point connection: rest state has zero energy and the orientation rule holds") {
  RodInTriangle s;
  PointConnection c("rt", s.tri, s.rod, {2.0, 3.0}, s.q);
  const PointEval e = c.evaluate(s.q, TwistUpdate::incremental_ii, true);
  CHECK(e.energy < 1e-24);
  CHECK(e.gradient.norm() < 1e-12);
  CHECK(c.second_axis_sign() == 1.0);  // straight continuation: axes already agree
  CHECK(c.joint() == 0);
  CHECK(c.position_nodes() == std::vector<Index>{0, 1, 2, 0, 3});

  // A rod folded back over the triangle: the rule flips its axis so m̄3·n̄3 ≥ 0.
  RodInTriangle f(pi - 0.3);
  PointConnection cf("folded", f.tri, f.rod, {2.0, 3.0}, f.q);
  CHECK(cf.second_axis_sign() == -1.0);
  CHECK_FALSE(cf.evaluate(f.q, TwistUpdate::direct, false).singular());
}

TEST_CASE("point connection: gradients and Hessians match finite differences (rod-triangle, rod-rod, triangle-triangle)") {
  std::mt19937 rng(16);
  for (TwistUpdate u : {TwistUpdate::direct, TwistUpdate::incremental_i, TwistUpdate::incremental_ii}) {
    CAPTURE(static_cast<int>(u));
    RodInTriangle s(0.2);
    PointConnection rt("rt", s.tri, s.rod, {2.0, 3.0}, s.q);
    TwoRods r;
    PointConnection rr("rr", r.a, r.b, {1.5, 0.7}, r.q);
    VectorXd qt(18);
    qt << 0, 0, 0, -1, 0.5, 0, -1, -0.5, 0.1, 0, 0, 0, 1, 0.4, 0.2, 1, -0.6, -0.1;
    PointConnection tt("tt", TriangleSide{{0, 1, 2}, std::nullopt}, TriangleSide{{3, 0, 4}, std::nullopt}, {1.0, 2.0},
                       qt);
    for (int trial = 0; trial < 5; ++trial) {
      const VectorXd a = perturbed(s.q, rng, 0.15), b = perturbed(r.q, rng, 0.15), t = perturbed(qt, rng, 0.15);
      check_gradient(rt, a, u);
      check_gradient(rr, b, u);
      check_gradient(tt, t, u);
      check_hessian(rt, a, u);
      check_hessian(rr, b, u);
      check_hessian(tt, t, u);
    }
  }
}

TEST_CASE("point connection: the twist energy alone is ½k_t(δ−δ̄)² of the rod's turn") {
  RodInTriangle s;
  PointConnection c("rt", s.tri, s.rod, {2.0, 0.0}, s.q);
  VectorXd q = s.q;
  q[15] += 0.5;  // the rod turns about its own axis: δ grows by the same angle, no bending
  const PointEval e = c.evaluate(q, TwistUpdate::incremental_ii, true);
  CHECK(e.twist - c.rest_twist() == doctest::Approx(0.5).epsilon(1e-12));
  CHECK(e.bend_angle < 1e-12);
  CHECK(e.energy == doctest::Approx(0.5 * 2.0 * 0.25).epsilon(1e-12));
  CHECK(e.gradient[15] == doctest::Approx(2.0 * 0.5).epsilon(1e-12));
}

TEST_CASE("point connection: bending energy is ½k_b ω² of the axis' tilt, and FD-exact at ω → 0") {
  RodInTriangle s;
  PointConnection c("rt", s.tri, s.rod, {0.0, 3.0}, s.q);
  RodInTriangle tilted(0.25);
  VectorXd q = s.q;
  q.segment<3>(12) = tilted.q.segment<3>(12);
  const PointEval e = c.evaluate(q, TwistUpdate::incremental_ii, false);
  CHECK(e.bend_angle == doctest::Approx(0.25).epsilon(1e-12));
  CHECK(e.energy == doctest::Approx(0.5 * 3.0 * 0.25 * 0.25).epsilon(1e-12));
  // Tiny tilt (ω ~ 1e-9, the guarded branch): finite gradient equal to its finite difference.
  VectorXd q0 = s.q;
  q0[13] = 1e-9;
  Eigen::MatrixXd h0;
  const PointEval e0 = c.evaluate(q0, TwistUpdate::incremental_ii, true, &h0);
  CHECK(e0.gradient.allFinite());
  CHECK(h0.allFinite());
  q0[13] = 1e-4;  // the regular branch, just above
  check_gradient(c, q0, TwistUpdate::incremental_ii);
}

TEST_CASE("point connection: gradients near the singular configurations") {
  for (TwistUpdate u : {TwistUpdate::incremental_i, TwistUpdate::incremental_ii}) {
    CAPTURE(static_cast<int>(u));
    // Accepted twist far from rest, then a step whose increment is just under π.
    RodInTriangle s(0.1);
    PointConnection c("near-pi", s.tri, s.rod, {2.0, 1.0}, s.q);
    VectorXd q = s.q;
    for (int k = 1; k <= 10; ++k) {
      q[15] = s.q[15] + 0.6 * k;
      c.accept(q, u);
    }
    q[15] += pi - 0.05;
    const PointEval e = c.evaluate(q, u, false);
    CHECK(e.twist - c.rest_twist() == doctest::Approx(6.0 + pi - 0.05).epsilon(1e-9));
    check_gradient(c, q, u);
    check_hessian(c, q, u);
    q[15] += 2 * pi - 0.1;  // increment now 3π − 0.15 ≡ π − 0.15 — the other side: aliased by design
    CHECK(std::abs(c.evaluate(q, u, false).twist - c.rest_twist() - (6.0 + 3 * pi - 0.15)) > 1.0);
  }
  // Bending through nearly π is flagged.
  RodInTriangle b;
  PointConnection cb("bend-pi", b.tri, b.rod, {2.0, 1.0}, b.q);
  VectorXd q = b.q;
  q.segment<3>(12) = Vec3(-1, 0.001, 0).normalized();
  CHECK(cb.evaluate(q, TwistUpdate::incremental_ii, false).bend_near_pi);
}

TEST_CASE("orientation rule: a joint bent or folded at rest meets the transport's singularity only at a bend of pi") {
  // Rods leaving the triangle 62° off its axis (the toy ball's spring foot on its platform),
  // nearly perpendicular to it, and folded back over it (the rule flips that one's axis).
  for (double tilt : {1.08, pi / 2 - 0.1, pi - 0.3}) {
    CAPTURE(tilt);
    RodInTriangle s(tilt);
    PointConnection c("bent", s.tri, s.rod, {2.0, 3.0}, s.q);
    CHECK(c.second_axis_sign() == (tilt < pi / 2 ? 1.0 : -1.0));
    const PointEval e0 = c.evaluate(s.q, TwistUpdate::incremental_ii, true);
    CHECK(e0.energy < 1e-20);
    CHECK(e0.gradient.norm() < 1e-9);
    // Bent on in its plane by ω (away from the triangle's axis, or, folded, towards it).
    const double away = tilt < pi / 2 ? 1.0 : -1.0;
    auto bent = [&](double w) {
      VectorXd q = s.q;
      q.segment<3>(12) = Vec3(std::cos(tilt + away * w), std::sin(tilt + away * w), 0);
      return q;
    };
    // Where the axes themselves are antiparallel (the transport from the side's own m3 would be
    // singular there): an ordinary state now, ω short of π by the rest tilt.
    const double w_old = tilt < pi / 2 ? pi - tilt : tilt;
    const PointEval e = c.evaluate(bent(w_old), TwistUpdate::incremental_ii, false);
    CHECK_FALSE(e.singular());
    CHECK(e.bend_angle == doctest::Approx(w_old).epsilon(1e-12));
    CHECK(std::isfinite(e.energy));
    for (TwistUpdate u : {TwistUpdate::incremental_i, TwistUpdate::incremental_ii}) {
      VectorXd q = bent(w_old);
      q[15] += 0.4;  // twisted too
      check_gradient(c, q, u);
      check_hessian(c, q, u);
    }
    // Bent from rest until 1 + cos ω = gap: the guard's flag, and finite differences short of it.
    for (double gap : {1e-2, 1e-4}) {
      const VectorXd q = bent(std::acos(gap - 1));
      const PointEval g = c.evaluate(q, TwistUpdate::incremental_ii, false);
      if (gap > antiparallel_margin) {
        CHECK_FALSE(g.near_antiparallel);
        check_gradient(c, q, TwistUpdate::incremental_ii);
        check_gradient(c, q, TwistUpdate::incremental_i);
        check_hessian(c, q, TwistUpdate::incremental_ii);
      } else {
        CHECK(g.near_antiparallel);
      }
    }
  }
}

TEST_CASE("point connection: a rigid motion of the connected pair changes neither energy nor force") {
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> ang(-pi, pi);
  for (double tilt : {0.2, 1.08, pi - 0.3}) {  // nearly straight, bent (turned twist frame), folded (flipped)
    CAPTURE(tilt);
    RodInTriangle s(tilt);
    PointConnection rt("rt", s.tri, s.rod, {2.0, 3.0}, s.q);
    TwoRods r;
    PointConnection rr("rr", r.a, r.b, {1.5, 0.7}, r.q);
    const std::vector<int> rt_blocks{0, 3, 6, 9, 12};
    for (int trial = 0; trial < 5; ++trial) {
      const Eigen::Matrix3d R =
          Eigen::AngleAxisd(ang(rng), Vec3(ang(rng), ang(rng), ang(rng)).normalized()).toRotationMatrix();
      // At rest, rotated: zero energy, zero force.
      const VectorXd q_rt = rotated(s.q, R, rt_blocks, {{9, s.rod}});
      const PointEval e0 = rt.evaluate(q_rt, TwistUpdate::incremental_ii, true);
      CHECK(e0.energy < 1e-20);
      CHECK(e0.gradient.norm() < 1e-9);
      const VectorXd q_rr = rotated(r.q, R, {0, 3, 7, 10}, {{0, r.a}, {7, r.b}});
      CHECK(rr.evaluate(q_rr, TwistUpdate::incremental_ii, false).energy < 1e-20);
      // Strained, rotated: the same energy; the forces sum to zero (translation invariance).
      VectorXd qs = s.q;
      qs.segment<3>(12) += Vec3(0.05, 0.2, -0.1);
      qs[15] += 0.7;
      const PointEval e1 = rt.evaluate(qs, TwistUpdate::incremental_ii, true);
      const PointEval e2 = rt.evaluate(rotated(qs, R, rt_blocks, {{9, s.rod}}), TwistUpdate::incremental_ii, true);
      CHECK(e1.energy > 0.1);
      CHECK(e2.energy == doctest::Approx(e1.energy).epsilon(1e-10));
      Vec3 net = Vec3::Zero();
      for (int blk : {0, 3, 6, 9, 12}) net += e2.gradient.segment<3>(blk);
      CHECK(net.norm() < 1e-10 * e2.gradient.norm());
    }
  }
}

TEST_CASE("Fig. 10: a rod turned in a held shell triangle — the incremental angle passes pi and 3pi linearly") {
  const double omega = 0.3;  // rad per step
  const int steps = 50;      // 15 rad: past π, 3π and 4π
  for (double tilt : {0.0, 0.2}) {
    CAPTURE(tilt);
    RodInTriangle s(tilt);
    PointConnection c_i("fig10-I", s.tri, s.rod, {1.0, 1.0}, s.q);
    PointConnection c_ii("fig10-II", s.tri, s.rod, {1.0, 1.0}, s.q);
    const PointConnection c_direct("fig10-direct", s.tri, s.rod, {1.0, 1.0}, s.q);
    double err_i = 0, err_ii = 0, err_direct = 0, bend_drift = 0;
    const double bend0 = c_i.evaluate(s.q, TwistUpdate::direct, false).bend_angle;
    VectorXd q = s.q;
    for (int k = 1; k <= steps; ++k) {
      q[15] = s.q[15] + omega * k;  // the rod's material frame turns kinematically
      const double expected = c_i.rest_twist() + omega * k;
      err_i = std::max(err_i, std::abs(c_i.evaluate(q, TwistUpdate::incremental_i, false).twist - expected));
      err_ii = std::max(err_ii, std::abs(c_ii.evaluate(q, TwistUpdate::incremental_ii, false).twist - expected));
      const PointEval d = c_direct.evaluate(q, TwistUpdate::direct, false);
      err_direct = std::max(err_direct, std::abs(d.twist - expected));
      bend_drift = std::max(bend_drift, std::abs(d.bend_angle - bend0));
      c_i.accept(q, TwistUpdate::incremental_i);
      c_ii.accept(q, TwistUpdate::incremental_ii);
    }
    CHECK(c_ii.accepted_twist() - c_ii.rest_twist() > 3 * pi);
    CHECK(err_i < 1e-9);
    CHECK(err_ii < 1e-9);
    CHECK(err_direct > pi);  // the same check fails for the direct angle: it wraps
    CHECK(bend_drift < 1e-12);
  }
  // The other way round: the triangle turned about the rod's axis, the rod held.
  RodInTriangle s;
  PointConnection c("fig10-shell", s.tri, s.rod, {1.0, 1.0}, s.q);
  double err = 0;
  for (int k = 1; k <= steps; ++k) {
    const Eigen::Matrix3d R = Eigen::AngleAxisd(omega * k, Vec3::UnitX()).toRotationMatrix();
    VectorXd q = s.q;
    for (int blk : {3, 6}) q.segment<3>(blk) = R * s.q.segment<3>(blk);
    err = std::max(err, std::abs(c.evaluate(q, TwistUpdate::incremental_ii, false).twist -
                                 (c.rest_twist() - omega * k)));
    c.accept(q, TwistUpdate::incremental_ii);
  }
  CHECK(err < 1e-9);
}

TEST_CASE("point connection: bad input names the connection") {
  RodInTriangle s;
  auto throws_with = [](auto&& make, const std::string& needle) {
    try {
      make();
      FAIL("no error for " << needle);
    } catch (const physics::InputError& e) {
      const std::string what = e.what();
      INFO(what);
      CHECK(what.find("'joint-7'") != std::string::npos);
      CHECK(what.find(needle) != std::string::npos);
    }
  };
  RodEdgeSide far = s.rod;
  far.from = 8;
  far.to = 9;
  throws_with([&] { PointConnection("joint-7", s.tri, far, {1, 1}, s.q); }, "share no node");
  VectorXd flat = s.q;
  flat.segment<3>(6) = Vec3(-2, 1.0, 0);  // collinear with the joint and node 1
  throws_with([&] { PointConnection("joint-7", s.tri, s.rod, {1, 1}, flat); }, "zero area");
  RodEdgeSide along = s.rod;
  along.to = 1;
  throws_with([&] { PointConnection("joint-7", s.tri, along, {1, 1}, s.q); }, "more than one node");
  throws_with([&] { PointConnection("joint-7", s.tri, s.rod, {1, 1}, s.q.head(10)); }, "entries");
  throws_with([&] { PointConnection("joint-7", s.tri, s.rod, {-1, 1}, s.q); }, "stiffnesses");
  TriangleSide outside = s.tri;
  outside.rest_axis = Vec3(1, 0, 0);  // points away from the corner
  throws_with([&] { PointConnection("joint-7", outside, s.rod, {1, 1}, s.q); }, "outside");
  PointConnection ok("joint-7", s.tri, s.rod, {1, 1}, s.q);
  throws_with([&] { (void)ok.evaluate(s.q.head(15), TwistUpdate::direct, false); }, "entries");
  VectorXd nan = s.q;
  nan[4] = std::nan("");
  throws_with([&] { (void)ok.evaluate(nan, TwistUpdate::incremental_ii, true); }, "not finite");
  throws_with([&] { PointConnection("joint-7", s.tri, s.rod, {1, 1}, nan); }, "not finite");
}

TEST_CASE("point connection: accept() keeps a rod side's frame in step with Rod::update_frames") {
  // A rod (vertices 0, 1, 2) leaving a held triangle (0, 10, 11) at vertex 0, swung about a
  // tilted axis through the joint for 20 steps with θ held; after each accepted step the
  // connection's twist must equal the one built from the rod's own material frame.
  using physics::rods::Points;
  const auto sec = physics::rods::Section::circular(1e7, 0.3, 0.01);
  Points rest(3, 3);
  rest << 0, 0.4, 0.8, 0, 0.05, 0, 0, 0, 0.03;
  physics::rods::Rod rod(rest, false, sec);
  rod.set_theta(0, 0.4);
  const TriangleSide tri{{0, 10, 11}, std::nullopt};
  auto stencil = [&](const Points& x) {
    VectorXd q(16);
    q << 0, 0, 0, -1, 0.5, 0, -1, -0.5, 0, 0, 0, 0, 0, 0, 0, rod.theta()[0];
    q.segment<3>(9) = x.col(0);
    q.segment<3>(12) = x.col(1);
    return q;
  };
  PointConnection c("swing", tri, rod_edge_side(rod, rest, 0), {1.0, 1.0}, stencil(rest));
  const Eigen::Matrix3d step = Eigen::AngleAxisd(0.1, Vec3(0.3, 1, 0.5).normalized()).toRotationMatrix();
  Points x = rest;
  double worst = 0;
  for (int k = 0; k < 20; ++k) {
    x = step * x;
    const VectorXd q = stencil(x);
    const double raw = c.evaluate(q, TwistUpdate::direct, false).twist_raw;
    // The triangle's frame (axis into the joint, normal) turned onto the rod's rest tangent:
    // the frame the twist is measured from (the orientation rule).
    const Vec3 m3(1, 0, 0), m1(0, 0, 1), t0 = (rest.col(1) - rest.col(0)).normalized();
    const Vec3 n3 = (x.col(1) - x.col(0)).normalized();
    const Vec3 n1 = rod.material_directors(x, 0).first;
    const Vec3 m1t = physics::rods::parallel_transport(m3, t0, m1);
    const double expected = physics::rods::signed_angle(physics::rods::parallel_transport(t0, n3, m1t), n1, n3);
    worst = std::max(worst, std::abs(std::remainder(raw - expected, 2 * pi)));
    c.accept(q, TwistUpdate::incremental_ii);
    rod.update_frames(x);
  }
  CHECK(worst < 1e-10);
}

TEST_CASE("point connection: cost of the chained and the nested-AD Hessian (report only)") {
  RodInTriangle s;
  PointConnection c("rt", s.tri, s.rod, {2.0, 3.0}, s.q);
  std::mt19937 rng(3);
  const VectorXd q = perturbed(s.q, rng, 0.1);
  auto fastest_us = [&](HessianMethod m) {
    double best = 1e300;
    Eigen::MatrixXd H;
    for (int batch = 0; batch < 5; ++batch) {
      const auto t0 = std::chrono::steady_clock::now();
      for (int k = 0; k < 20; ++k) (void)c.evaluate(q, TwistUpdate::incremental_ii, true, &H, m);
      best = std::min(best, std::chrono::duration<double, std::micro>(std::chrono::steady_clock::now() - t0).count() / 20);
    }
    return best;
  };
  const double nested = fastest_us(HessianMethod::nested_ad), chained = fastest_us(HessianMethod::chained);
  MESSAGE("rod-triangle Hessian, fastest of 5 batches of 20: nested AD " << nested << " us, chained " << chained << " us ("
                                                                          << nested / chained << "x)");
  CHECK(chained > 0);
}

}  // namespace test_point
