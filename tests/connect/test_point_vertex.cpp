// Point connections at a shell's interior vertex (VertexSide, PHYSICS_NOTES §3.5): the frame is
// the one-ring's angle-weighted normal, so a rod standing on the shell along it starts with its
// axis parallel to the shell's (a corner bisector lies in the surface, a right angle away).
// Gradients and Hessians against central differences (also with nearly antiparallel axes),
// rigid motions, the twist and bend closed forms, and bad input.

#include <cmath>
#include <functional>
#include <numbers>
#include <random>
#include <string>

#include <doctest/doctest.h>
#include <Eigen/Geometry>

#include "point_fd.hpp"
#include "sewn/connect/point.hpp"
#include "sewn/physics/rods/stencils.hpp"

namespace test_point_vertex {
namespace {

using Eigen::VectorXd;
using sewn::connect::PointConnection;
using sewn::connect::PointEval;
using sewn::connect::RodEdgeSide;
using sewn::connect::TwistUpdate;
using sewn::connect::Vec3;
using sewn::connect::VertexSide;

constexpr double pi = std::numbers::pi;
constexpr int ring = 6;

// Joint 0 at the origin, a one-ring of 6 nodes (1..6) around it, slightly wavy (not planar), and
// a rod edge 0 → 7 leaving the joint along the direction `rod` (unit). Stencil: the vertex side
// (21), then the rod side (x0, x7, θ: 7), or the reverse with `rod_first`.
struct RodOnVertex {
  VertexSide vertex{0, {1, 2, 3, 4, 5, 6}};
  RodEdgeSide rod;
  Eigen::Matrix<double, 3, ring> ring_x;
  Vec3 tip;
  double theta = 0.3;
  bool rod_first = false;
  explicit RodOnVertex(const Vec3& dir = Vec3(0, 0, 1), bool rod_first_ = false) : tip(dir), rod_first(rod_first_) {
    for (int i = 0; i < ring; ++i) {
      const double a = 2 * pi * i / ring + 0.1 * std::sin(3.0 * i);
      ring_x.col(i) = Vec3((1 + 0.1 * i) * std::cos(a), (1 + 0.1 * i) * std::sin(a), 0.08 * std::cos(2.0 * i));
    }
    rod.from = 0;
    rod.to = 7;
    rod.tangent = tip.normalized();
    rod.director = sewn::physics::rods::any_perpendicular(rod.tangent);
  }
  [[nodiscard]] int vertex_at() const { return rod_first ? 7 : 0; }
  [[nodiscard]] int rod_at() const { return rod_first ? 0 : 3 * (ring + 1); }
  [[nodiscard]] VectorXd q() const {
    VectorXd out(3 * (ring + 1) + 7);
    out.segment<3>(vertex_at()).setZero();
    for (int i = 0; i < ring; ++i) out.segment<3>(vertex_at() + 3 * (i + 1)) = ring_x.col(i);
    out.segment<3>(rod_at()).setZero();
    out.segment<3>(rod_at() + 3) = tip;
    out[rod_at() + 6] = theta;
    return out;
  }
  [[nodiscard]] PointConnection connection(const std::string& name, double kt = 2.0, double kb = 3.0) const {
    return rod_first ? PointConnection(name, rod, vertex, {kt, kb}, q()) : PointConnection(name, vertex, rod, {kt, kb}, q());
  }
};

// Gradient against differences of the energy, Hessian against differences of the gradient.
void check_derivatives(const PointConnection& c, const VectorXd& q, TwistUpdate u) {
  Eigen::MatrixXd H;
  const PointEval e = c.evaluate(q, u, true, &H);
  REQUIRE(e.gradient.size() == q.size());
  REQUIRE(H.rows() == q.size());
  const VectorXd fd = sewn::connect::test::finite_gradient(c, q, u, 1e-6);
  INFO("analytic " << e.gradient.transpose() << "\nfinite   " << fd.transpose());
  CHECK((e.gradient - fd).norm() <= 1e-6 * std::max(1.0, fd.norm()));
  CHECK((c.evaluate(q, u, true).gradient - e.gradient).norm() <= 1e-12 * std::max(1.0, e.gradient.norm()));
  Eigen::MatrixXd fdh(q.size(), q.size());
  const double h = 1e-6;
  for (Eigen::Index i = 0; i < q.size(); ++i) {
    VectorXd qp = q, qm = q;
    qp[i] += h;
    qm[i] -= h;
    fdh.col(i) = (c.evaluate(qp, u, true).gradient - c.evaluate(qm, u, true).gradient) / (2 * h);
  }
  CHECK((H - H.transpose()).norm() <= 1e-10 * std::max(1.0, H.norm()));
  CHECK((H - fdh).norm() <= 1e-5 * std::max(1.0, fdh.norm()));
}

VectorXd perturbed(const VectorXd& q, std::mt19937& rng, double size) {
  std::uniform_real_distribution<double> u(-size, size);
  VectorXd out = q;
  for (Eigen::Index i = 0; i < q.size(); ++i) out[i] += u(rng);
  return out;
}

std::string reason(const std::function<void()>& f) {
  try {
    f();
  } catch (const sewn::physics::InputError& e) {
    return e.what();
  }
  return "accepted";
}

}  // namespace

TEST_CASE("vertex side: the frame is the one-ring's angle-weighted normal; a rod along it is a straight joint") {
  // A flat, regular ring: the normal is +z exactly, m1 the first edge's direction.
  RodOnVertex s;
  for (int i = 0; i < ring; ++i) s.ring_x.col(i) = Vec3(std::cos(2 * pi * i / ring), std::sin(2 * pi * i / ring), 0);
  const PointConnection c = s.connection("flat");
  const auto f = c.frames(s.q());
  CHECK((f[0] - Vec3(1, 0, 0)).norm() < 1e-14);
  CHECK(std::abs(std::abs(f[1].z()) - 1) < 1e-14);
  CHECK(f[1].dot(f[3]) == doctest::Approx(1.0).epsilon(1e-14));  // the rod continues the normal: far from n3 = −m3
  const PointEval e = c.evaluate(s.q(), TwistUpdate::incremental_ii, true);
  CHECK(e.energy == 0.0);
  CHECK(e.bend_angle < 1e-12);
  CHECK(e.gradient.norm() < 1e-12);
  // Tilting the rod by φ from the normal costs ½k_bφ²; turning it by ψ, ½k_tψ².
  for (double phi : {0.3, 1.2, 2.5}) {
    VectorXd q = s.q();
    q.segment<3>(3 * (ring + 1) + 3) = Vec3(std::sin(phi), 0, std::cos(phi));
    CHECK(c.evaluate(q, TwistUpdate::incremental_ii, false).bend_angle == doctest::Approx(phi).epsilon(1e-12));
  }
  VectorXd q = s.q();
  q[3 * (ring + 1) + 6] += 0.7;
  CHECK(c.evaluate(q, TwistUpdate::incremental_ii, false).energy == doctest::Approx(0.5 * 2.0 * 0.49).epsilon(1e-12));
}

TEST_CASE("vertex side: gradients and Hessians match central differences (vertex-rod, rod-vertex, all updates)") {
  std::mt19937 rng(11);
  for (bool rod_first : {false, true}) {
    const RodOnVertex s(Vec3(0.2, -0.1, 1).normalized(), rod_first);
    const PointConnection c = s.connection("vertex-rod");
    for (TwistUpdate u : {TwistUpdate::direct, TwistUpdate::incremental_i, TwistUpdate::incremental_ii}) {
      for (int trial = 0; trial < 3; ++trial) {
        CAPTURE(rod_first);
        CAPTURE(static_cast<int>(u));
        CAPTURE(trial);
        VectorXd q = perturbed(s.q(), rng, 0.1);
        q[s.rod_at() + 6] += 0.8;
        check_derivatives(c, q, u);
      }
    }
  }
}

TEST_CASE("vertex side: derivatives with nearly antiparallel axes, the guard's flag closer still") {
  // The rod folded back towards the shell through the plane of x and z until 1 + m3·n3 = gap.
  const RodOnVertex s;
  const PointConnection c = s.connection("folded");
  const Vec3 m3 = c.frames(s.q())[1];
  for (double gap : {1e-2, 1e-4}) {
    CAPTURE(gap);
    const double a = std::acos(gap - 1);  // angle between the rod and m3
    VectorXd q = s.q();
    const Vec3 side = m3.cross(Vec3(0, 1, 0)).normalized();
    // the rod's axis n3 is ±its tangent, with the sign that made it m3's at rest
    const double sign = s.rod.tangent.dot(m3) > 0 ? 1.0 : -1.0;
    q.segment<3>(s.rod_at() + 3) = sign * (std::cos(a) * m3 + std::sin(a) * side);
    const PointEval e = c.evaluate(q, TwistUpdate::incremental_ii, false);
    const auto f = c.frames(q);
    CHECK(1 + f[1].dot(f[3]) == doctest::Approx(gap).epsilon(1e-9));
    if (gap > sewn::connect::antiparallel_margin) {
      CHECK_FALSE(e.near_antiparallel);
      check_derivatives(c, q, TwistUpdate::incremental_ii);
      check_derivatives(c, q, TwistUpdate::incremental_i);
    } else {
      CHECK(e.near_antiparallel);
    }
  }
}

TEST_CASE("vertex side: a rigid motion changes neither energy nor force") {
  std::mt19937 rng(5);
  std::uniform_real_distribution<double> ang(-pi, pi);
  const RodOnVertex s(Vec3(0.3, 0.1, 1).normalized());
  const PointConnection c = s.connection("rigid");
  VectorXd strained = s.q();
  for (int i = 1; i <= ring; ++i) strained.segment<3>(3 * i) += Vec3(0.02 * i, -0.03, 0.05 * std::sin(i));
  strained.segment<3>(3 * (ring + 1) + 3) += Vec3(0.2, -0.1, 0.05);
  const double e0 = c.evaluate(strained, TwistUpdate::direct, false).energy;
  CHECK(e0 > 1e-3);
  for (int trial = 0; trial < 4; ++trial) {
    const Eigen::Matrix3d R = Eigen::AngleAxisd(ang(rng), Vec3(ang(rng), ang(rng), ang(rng)).normalized()).toRotationMatrix();
    // Every position rotated; the rod's θ re-measured so that its material frame turns with R.
    VectorXd q = strained;
    for (int b = 0; b < ring + 1; ++b) q.segment<3>(3 * b) = R * strained.segment<3>(3 * b);
    const int r = s.rod_at();
    q.segment<3>(r) = R * strained.segment<3>(r);
    q.segment<3>(r + 3) = R * strained.segment<3>(r + 3);
    const Vec3 t = (strained.segment<3>(r + 3) - strained.segment<3>(r)).normalized();
    const Vec3 a1 = sewn::physics::rods::parallel_transport(s.rod.tangent, t, s.rod.director);
    const Vec3 m1 = std::cos(strained[r + 6]) * a1 + std::sin(strained[r + 6]) * t.cross(a1);
    const Vec3 t2 = R * t;
    q[r + 6] = sewn::physics::rods::signed_angle(sewn::physics::rods::parallel_transport(s.rod.tangent, t2, s.rod.director), R * m1, t2);
    const PointEval e = c.evaluate(q, TwistUpdate::direct, true);
    CHECK(e.energy == doctest::Approx(e0).epsilon(1e-10));
    Vec3 net = Vec3::Zero();
    for (int b = 0; b < ring + 1; ++b) net += e.gradient.segment<3>(3 * b);
    net += e.gradient.segment<3>(r) + e.gradient.segment<3>(r + 3);
    CHECK(net.norm() < 1e-10 * e.gradient.norm());
  }
}

TEST_CASE("vertex side: bad input names the connection and the reason") {
  RodOnVertex s;
  const auto with_ring = [&](const std::vector<Vec3>& pts, std::vector<sewn::physics::Index> ids) {
    RodOnVertex t = s;
    t.vertex.ring = std::move(ids);
    VectorXd q(3 * (pts.size() + 1) + 7);
    q.head<3>().setZero();
    for (std::size_t i = 0; i < pts.size(); ++i) q.segment<3>(3 * static_cast<Eigen::Index>(i + 1)) = pts[i];
    q.segment<7>(3 * static_cast<Eigen::Index>(pts.size() + 1)) << 0, 0, 0, 0, 0, 1, 0;
    return reason([&] { (void)PointConnection("joint 9", t.vertex, t.rod, {1, 1}, q); });
  };
  CHECK(with_ring({{1, 0, 0}, {0, 1, 0}}, {1, 2}) ==
        "point connection 'joint 9': shell vertex 0 (one-ring of 2): a one-ring needs at least 3 nodes");
  CHECK(with_ring({{1, 0, 0}, {2, 0, 0}, {0, 1, 0}}, {1, 2, 3}) ==
        "point connection 'joint 9': shell vertex 0 (one-ring of 3): its triangle (0, 1, 2) has zero area at rest");
  CHECK(with_ring({{1, 0, 0}, {0, 1, 0}, {2, 0, 0}, {0, 2, 0}}, {1, 2, 3, 4}) ==
        "point connection 'joint 9': shell vertex 0 (one-ring of 4): its one-ring's normals cancel at rest: no vertex normal");
  // The rod meets the side at a ring node, not at its joint.
  RodOnVertex t = s;
  t.rod.from = 3;
  VectorXd q = s.q();
  q.segment<3>(3 * (ring + 1)) = s.ring_x.col(2);
  CHECK(reason([&] { (void)PointConnection("joint 9", t.vertex, t.rod, {1, 1}, q); }) ==
        "point connection 'joint 9': shell vertex 0 (one-ring of 6) meets rod edge (3, 7) at ring node 3, not at its joint");
}

}  // namespace test_point_vertex
