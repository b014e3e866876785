// Point connections with a solid's tetrahedron as a side (solid option i, point.hpp TetSide):
// gradients and Hessians against central differences (and chained = whole-stencil AD) for
// rod–tet, tet–rod, triangle–tet and tet–tet in every update; rigid motions; a pure twist's
// closed form; the frame following the tet's deformation; bad input; the force term's stencil.

#include <cmath>
#include <numbers>
#include <random>
#include <string>
#include <vector>

#include <Eigen/Geometry>
#include <doctest/doctest.h>

#include "sewn/connect/point_term.hpp"
#include "sewn/physics/system.hpp"

namespace test_point_solid {
namespace {

using Eigen::VectorXd;
using sewn::connect::HessianMethod;
using sewn::connect::PointConnection;
using sewn::connect::PointEval;
using sewn::connect::RodEdgeSide;
using sewn::connect::Side;
using sewn::connect::TetSide;
using sewn::connect::TriangleSide;
using sewn::connect::TwistUpdate;
using sewn::connect::Vec3;
using Index = sewn::physics::Index;

// A tet (0, 1, 2, 3) below its surface node 0 (outward normal +z); a rod edge 0 → 4 standing on
// it; a triangle (0, 5, 6) leaning off it; a second tet (0, 7, 8, 9) above, touching at node 0.
const Vec3 X[10] = {Vec3(0, 0, 0),        Vec3(0.5, 0.1, -0.6),  Vec3(-0.4, 0.4, -0.5), Vec3(-0.1, -0.5, -0.7),
                    Vec3(0.1, 0.05, 1.0), Vec3(0.6, -0.2, 0.5),  Vec3(0.5, 0.4, 0.6),   Vec3(0.4, 0.1, 0.7),
                    Vec3(-0.5, 0.3, 0.6), Vec3(0.0, -0.5, 0.8)};

enum class Kind { tet, rod, triangle, upper_tet };

Side make_side(Kind k) {
  switch (k) {
    case Kind::tet:
      return TetSide{{0, 1, 2, 3}, Vec3(0, 0, 1)};
    case Kind::upper_tet:
      return TetSide{{7, 0, 8, 9}, Vec3(0, 0, -1)};  // joint not first: the side reorders
    case Kind::rod: {
      const Vec3 t = (X[4] - X[0]).normalized();
      return RodEdgeSide{0, 4, t, sewn::physics::rods::any_perpendicular(t)};
    }
    case Kind::triangle:
      break;
  }
  return TriangleSide{{0, 5, 6}, std::nullopt};
}

// The rest stencil in the connection's order (its position_nodes(); a rod's θ = 0.2 after its two).
VectorXd rest_q(const Side& m, const Side& n) {
  const auto nodes = sewn::connect::stencil_layout("rest", m, n);
  std::vector<double> q;
  std::size_t p = 0;
  for (const Side* s : {&m, &n}) {
    const int count = std::holds_alternative<RodEdgeSide>(*s) ? 2 : std::holds_alternative<TriangleSide>(*s) ? 3 : 4;
    for (int v = 0; v < count; ++v, ++p) q.insert(q.end(), {X[nodes[p]].x(), X[nodes[p]].y(), X[nodes[p]].z()});
    if (std::holds_alternative<RodEdgeSide>(*s)) q.push_back(0.2);
  }
  return Eigen::Map<VectorXd>(q.data(), static_cast<Eigen::Index>(q.size()));
}

struct FdError {
  double gradient = 0, hessian = 0, chained_vs_whole = 0;
};
FdError fd_error(const PointConnection& c, const VectorXd& q, TwistUpdate u) {
  Eigen::MatrixXd H, whole;
  const PointEval e = c.evaluate(q, u, true, &H);
  (void)c.evaluate(q, u, true, &whole, HessianMethod::nested_ad);
  const double h = 1e-6;
  VectorXd g(q.size());
  Eigen::MatrixXd Hfd(q.size(), q.size());
  for (Eigen::Index i = 0; i < q.size(); ++i) {
    VectorXd qp = q, qm = q;
    qp[i] += h;
    qm[i] -= h;
    g[i] = (c.evaluate(qp, u, false).energy - c.evaluate(qm, u, false).energy) / (2 * h);
    Hfd.col(i) = (c.evaluate(qp, u, true).gradient - c.evaluate(qm, u, true).gradient) / (2 * h);
  }
  FdError out;
  out.gradient = (e.gradient - g).cwiseAbs().maxCoeff() / g.cwiseAbs().maxCoeff();
  out.hessian = (H - Hfd).cwiseAbs().maxCoeff() / Hfd.cwiseAbs().maxCoeff();
  out.chained_vs_whole = (H - whole).cwiseAbs().maxCoeff() / whole.cwiseAbs().maxCoeff();
  CHECK((c.evaluate(q, u, true).gradient - e.gradient).cwiseAbs().maxCoeff() <= 1e-12 * e.gradient.cwiseAbs().maxCoeff());
  return out;
}

std::string kind_name(Kind k) {
  return k == Kind::tet ? "tet" : k == Kind::rod ? "rod" : k == Kind::triangle ? "triangle" : "upper tet";
}

TEST_CASE("point connection, solid side: rest state, orientation, derivatives against differences") {
  std::mt19937 rng(11);
  std::uniform_real_distribution<double> noise(-0.08, 0.08);
  const std::vector<std::pair<Kind, Kind>> pairs{
      {Kind::rod, Kind::tet}, {Kind::tet, Kind::rod}, {Kind::triangle, Kind::tet}, {Kind::tet, Kind::upper_tet}};
  for (const auto& kinds : pairs) {
    const Kind m = kinds.first, n = kinds.second;  // named: clang 14 cannot capture bindings (INFO)
    const Side sm = make_side(m), sn = make_side(n);
    const VectorXd q0 = rest_q(sm, sn);
    const PointConnection c("solid", sm, sn, {2.0, 3.0}, q0);
    INFO(kind_name(m) << "-" << kind_name(n));
    const PointEval rest = c.evaluate(q0, TwistUpdate::incremental_ii, true);
    CHECK(rest.energy < 1e-24);
    CHECK(rest.gradient.cwiseAbs().maxCoeff() < 1e-12);
    CHECK(c.num_dofs() == q0.size());
    // Every pair here continues across the joint (a rod standing on the surface, a triangle
    // leaning off it, a tet on top): the axes agree as built, no flip — a tet's axis is −rest_axis
    // (into its body) as the second side, a rod's its tangent (out of the joint).
    CHECK(c.second_axis_sign() == (std::holds_alternative<TetSide>(sn) ? -1.0 : 1.0));
    for (TwistUpdate u : {TwistUpdate::direct, TwistUpdate::incremental_i, TwistUpdate::incremental_ii}) {
      double worst_g = 0, worst_h = 0, worst_c = 0;
      for (int trial = 0; trial < 3; ++trial) {
        VectorXd q = q0;
        for (double& v : q) v += noise(rng);
        const FdError err = fd_error(c, q, u);
        worst_g = std::max(worst_g, err.gradient);
        worst_h = std::max(worst_h, err.hessian);
        worst_c = std::max(worst_c, err.chained_vs_whole);
      }
      INFO("update " << static_cast<int>(u) << ": gradient " << worst_g << ", Hessian " << worst_h << ", chained vs whole "
                     << worst_c);
      CHECK(worst_g < 1e-7);
      CHECK(worst_h < 1e-6);
      CHECK(worst_c < 1e-10);
    }
  }
}

TEST_CASE("point connection, solid side: rigid motions cost nothing, a twist of the rod costs k_t phi^2 / 2") {
  for (const auto& kinds : {std::pair{Kind::tet, Kind::upper_tet}, std::pair{Kind::triangle, Kind::tet}}) {
    const Kind m = kinds.first, n = kinds.second;  // named: clang 14 cannot capture bindings (INFO)
    const Side sm = make_side(m), sn = make_side(n);
    const VectorXd q0 = rest_q(sm, sn);
    const PointConnection c("rigid", sm, sn, {2.0, 3.0}, q0);
    const Eigen::Matrix3d R = Eigen::AngleAxisd(2.4, Vec3(-0.3, 1, 0.6).normalized()).toRotationMatrix();
    VectorXd q = q0;
    for (Eigen::Index p = 0; p < q.size(); p += 3) q.segment<3>(p) = R * Vec3(q0.segment<3>(p)) + Vec3(1, -2, 0.5);
    const PointEval e = c.evaluate(q, TwistUpdate::incremental_ii, true);
    CHECK(e.energy < 1e-22);
    CHECK(e.gradient.cwiseAbs().maxCoeff() < 1e-10);
  }
  // The rod turned about its own axis by φ: pure twist, no bend.
  const Side sm = make_side(Kind::tet), sn = make_side(Kind::rod);
  VectorXd q = rest_q(sm, sn);
  const PointConnection c("twist", sm, sn, {2.0, 3.0}, q);
  q[q.size() - 1] += 0.7;
  const PointEval e = c.evaluate(q, TwistUpdate::incremental_ii, false);
  CHECK(e.energy == doctest::Approx(0.5 * 2.0 * 0.7 * 0.7).epsilon(1e-12));
  CHECK(e.bend_angle < 1e-12);
  // A rod standing straight up on the tet, the tet sheared sideways (its top node kept, x += 0.3 z
  // below): the solid's axis tilts with F by atan(0.3), so the joint bends that much though no
  // node of the rod moved.
  VectorXd s(19);
  s << X[0].x(), X[0].y(), X[0].z(), X[1].x(), X[1].y(), X[1].z(), X[2].x(), X[2].y(), X[2].z(), X[3].x(), X[3].y(), X[3].z(), 0,
      0, 0, 0, 0, 1, 0;
  const PointConnection up("up", sm, RodEdgeSide{0, 4, Vec3(0, 0, 1), Vec3(1, 0, 0)}, {2.0, 3.0}, s);
  CHECK(up.evaluate(s, TwistUpdate::incremental_ii, false).energy < 1e-24);
  for (int v = 1; v < 4; ++v) s[3 * v] += 0.3 * s[3 * v + 2];
  CHECK(up.evaluate(s, TwistUpdate::incremental_ii, false).bend_angle == doctest::Approx(std::atan(0.3)).epsilon(1e-9));
}

TEST_CASE("point connection, solid side: bad input names the connection") {
  const Side rod = make_side(Kind::rod);
  VectorXd q = rest_q(make_side(Kind::tet), rod);
  VectorXd flat = q;
  flat.segment<3>(9) = 0.5 * (flat.segment<3>(3) + flat.segment<3>(6));  // node 3 between 1 and 2: no volume
  CHECK_THROWS_WITH_AS(PointConnection("flat", make_side(Kind::tet), rod, {1, 1}, flat),
                       doctest::Contains("point connection 'flat': tetrahedron (0, 1, 2, 3) has zero volume at rest"),
                       sewn::physics::InputError);
  CHECK_THROWS_WITH_AS(PointConnection("axis", TetSide{{0, 1, 2, 3}, Vec3::Zero()}, rod, {1, 1}, q),
                       doctest::Contains("point connection 'axis': tetrahedron (0, 1, 2, 3): rest axis is zero"),
                       sewn::physics::InputError);
  CHECK_THROWS_WITH_AS(PointConnection("edge", make_side(Kind::tet), TetSide{{0, 1, 8, 9}, Vec3(0, 0, 1)}, {1, 1}, q),
                       doctest::Contains("share more than one node"), sewn::physics::InputError);
}

TEST_CASE("point connections term: a tet side's twelve position DOFs in the stencil") {
  sewn::physics::System sys;
  for (const Vec3& p : X) (void)sys.nodes().add(p, Vec3::Zero(), 0.1);
  auto& term = sys.add<sewn::connect::PointConnections>(nullptr);
  (void)term.add("tet-tet", TetSide{{0, 1, 2, 3}, Vec3(0, 0, 1)}, TetSide{{7, 0, 8, 9}, Vec3(0, 0, -1)}, {2.0, 3.0}, sys.state());
  std::mt19937 rng(2);
  std::uniform_real_distribution<double> noise(-0.05, 0.05);
  for (double& x : sys.nodes().x()) x += noise(rng);
  std::vector<double> f(3 * 10, 0.0);
  term.add_forces(sys.state(), f);
  const double h = 1e-6;
  double worst = 0, scale = 0;
  for (std::size_t k = 0; k < f.size(); ++k) {
    const double x = sys.nodes().x()[k];
    sys.nodes().x()[k] = x + h;
    const double ep = term.potential_energy(sys.state());
    sys.nodes().x()[k] = x - h;
    const double em = term.potential_energy(sys.state());
    sys.nodes().x()[k] = x;
    worst = std::max(worst, std::abs(-(ep - em) / (2 * h) - f[k]));
    scale = std::max(scale, std::abs(f[k]));
  }
  CHECK(scale > 1e-3);
  CHECK(worst < 1e-6 * scale);
  CHECK(f[3 * 4] == 0.0);  // node 4 is in no stencil
}

}  // namespace
}  // namespace test_point_solid
