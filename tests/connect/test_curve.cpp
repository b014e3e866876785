// Curve connections (curve.hpp), one edge at a time: gradients and Hessians against central
// differences for every pair of sides (rod, face, hinge) and every twist update, at random
// configurations and after turns past π; the closed form of a pure turn about the edge; the
// energy of a twisted curve independent of how many edges it is cut into, and of stretching;
// rigid motions; the orientation rule; the errors of bad input, naming the connection.

#include <cmath>
#include <functional>
#include <numbers>
#include <random>
#include <string>
#include <vector>

#include <Eigen/Geometry>
#include <doctest/doctest.h>

#include "sewn/connect/curve.hpp"
#include "sewn/physics/errors.hpp"

namespace test_curve {
namespace {

using sewn::connect::EdgeConnection;
using sewn::connect::EdgeEval;
using sewn::connect::EdgeSide;
using sewn::connect::FaceSide;
using sewn::connect::HingeSide;
using sewn::connect::RodEdgeSide;
using sewn::connect::TwistUpdate;
using sewn::connect::Vec3;
using Index = sewn::physics::Index;

constexpr double pi = std::numbers::pi;
constexpr double k_line = 2.5;  // N/rad

// Edge (0, 1) from the origin along x (length 0.4); a side is a rod edge (0 → 1, θ = 0.3), a
// face with apex 2 (or 4 for the second side) or a hinge with apices (2, 3) (or (4, 5)).
enum class Kind { rod, face, hinge };

EdgeSide make_side(Kind k, int which) {
  const Index base = which == 0 ? 2 : 4;
  switch (k) {
    case Kind::rod:
      return RodEdgeSide{0, 1, Vec3(1, 0, 0), Vec3(0, 1, 0)};
    case Kind::face:
      return FaceSide{base};
    case Kind::hinge:
      break;
  }
  return HingeSide{base, Index(base + 1)};
}

// Side `which`'s rest DOFs beyond the edge: θ, or apices around the edge at angle `phase`.
void append_rest(std::vector<double>& q, Kind k, double phase) {
  auto apex = [&](double angle, double along) {
    q.insert(q.end(), {along, 0.3 * std::cos(angle), 0.3 * std::sin(angle)});
  };
  if (k == Kind::rod) q.push_back(0.3);
  if (k == Kind::face) apex(phase, 0.15);
  if (k == Kind::hinge) {
    apex(phase + 1.2, 0.1);
    apex(phase - 1.4, 0.25);  // left and right of the edge: consistently oriented faces
  }
}

Eigen::VectorXd rest_state(Kind m, Kind n) {
  std::vector<double> q{0, 0, 0, 0.4, 0, 0};
  append_rest(q, m, 0.5);
  append_rest(q, n, 2.0);
  return Eigen::Map<Eigen::VectorXd>(q.data(), static_cast<Eigen::Index>(q.size()));
}

// Turns side n about the edge's line (through node 0) by φ: apices rotated, a rod's θ += φ.
Eigen::VectorXd turn_second(Eigen::VectorXd q, Kind m, Kind n, double phi) {
  const Eigen::Index at = 6 + (m == Kind::rod ? 1 : m == Kind::face ? 3 : 6);
  const Vec3 a = q.segment<3>(0), axis = (q.segment<3>(3) - a).normalized();
  const Eigen::Matrix3d R = Eigen::AngleAxisd(phi, axis).toRotationMatrix();
  if (n == Kind::rod) {
    q[at] += phi;
  } else {
    for (Eigen::Index p = at; p < q.size(); p += 3) q.segment<3>(p) = a + R * (Vec3(q.segment<3>(p)) - a);
  }
  return q;
}

// Largest |gradient − central difference of the energy| and |Hessian − central difference of
// the gradient|, each relative to the largest entry.
struct FdError {
  double gradient = 0, hessian = 0, asymmetry = 0;
};
FdError fd_error(const EdgeConnection& c, const Eigen::VectorXd& q, TwistUpdate u) {
  Eigen::MatrixXd H;
  const EdgeEval e = c.evaluate(q, u, true, &H);
  const double eps = 1e-6;
  Eigen::VectorXd g_fd(q.size());
  Eigen::MatrixXd H_fd(q.size(), q.size());
  for (Eigen::Index k = 0; k < q.size(); ++k) {
    Eigen::VectorXd qp = q, qm = q;
    qp[k] += eps;
    qm[k] -= eps;
    g_fd[k] = (c.evaluate(qp, u, false).energy - c.evaluate(qm, u, false).energy) / (2 * eps);
    H_fd.col(k) = (c.evaluate(qp, u, true).gradient - c.evaluate(qm, u, true).gradient) / (2 * eps);
  }
  FdError out;
  out.gradient = (e.gradient - g_fd).cwiseAbs().maxCoeff() / std::max(1e-300, g_fd.cwiseAbs().maxCoeff());
  out.hessian = (H - H_fd).cwiseAbs().maxCoeff() / std::max(1e-300, H_fd.cwiseAbs().maxCoeff());
  out.asymmetry = (H - H.transpose()).cwiseAbs().maxCoeff() / std::max(1e-300, H.cwiseAbs().maxCoeff());
  // The gradient asked alone equals the one that comes with the Hessian.
  CHECK((c.evaluate(q, u, true).gradient - e.gradient).cwiseAbs().maxCoeff() <= 1e-12 * e.gradient.cwiseAbs().maxCoeff());
  return out;
}

std::string kind_name(Kind k) { return k == Kind::rod ? "rod" : k == Kind::face ? "face" : "hinge"; }

TEST_CASE("curve connection: gradient and Hessian against central differences, every pair of sides and update") {
  std::mt19937 rng(7);
  std::normal_distribution<double> noise(0, 0.03);
  const std::vector<std::pair<Kind, Kind>> pairs{{Kind::rod, Kind::face},  {Kind::face, Kind::rod},   {Kind::face, Kind::face},
                                                 {Kind::hinge, Kind::face}, {Kind::rod, Kind::hinge}, {Kind::hinge, Kind::hinge},
                                                 {Kind::face, Kind::hinge}};
  for (const auto& kinds : pairs) {
    const Kind m = kinds.first, n = kinds.second;  // named: clang 14 cannot capture bindings (INFO)
    for (TwistUpdate u : {TwistUpdate::direct, TwistUpdate::incremental_i, TwistUpdate::incremental_ii}) {
      const Eigen::VectorXd q0 = rest_state(m, n);
      EdgeConnection c("fd", 0, 1, make_side(m, 0), make_side(n, 1), k_line, q0);
      double worst_g = 0, worst_h = 0, worst_sym = 0;
      for (int trial = 0; trial < 4; ++trial) {
        Eigen::VectorXd q = turn_second(q0, m, n, 0.4 * (trial - 1.5));
        for (double& v : q) v += noise(rng);
        const FdError err = fd_error(c, q, u);
        worst_g = std::max(worst_g, err.gradient);
        worst_h = std::max(worst_h, err.hessian);
        worst_sym = std::max(worst_sym, err.asymmetry);
      }
      INFO(kind_name(m) << "-" << kind_name(n) << " update " << static_cast<int>(u) << ": gradient " << worst_g << ", Hessian "
                        << worst_h);
      CHECK(worst_g < 1e-7);
      CHECK(worst_h < 1e-6);
      CHECK(worst_sym < 1e-12);
    }
  }
}

TEST_CASE("curve connection: the reduced derivatives equal the whole stencil's AD, rod sides either way round") {
  // EdgeDerivatives::reduced differentiates δ in the positions relative to x_a and takes a rod's
  // θ exactly; the reference differentiates E in every DOF. Every pair of sides (rod-rod too),
  // a rod side running b → a as well as a → b, every update, after accepted turns.
  std::mt19937 rng(11);
  std::normal_distribution<double> noise(0, 0.05);
  auto side = [](Kind k, int which, bool reversed) -> EdgeSide {
    if (k == Kind::rod && reversed) return RodEdgeSide{1, 0, Vec3(-1, 0, 0), Vec3(0, 0, 1)};
    return make_side(k, which);
  };
  const std::vector<Kind> kinds{Kind::rod, Kind::face, Kind::hinge};
  double worst_g = 0, worst_h = 0;
  int cases = 0;
  for (const Kind m : kinds)
    for (const Kind n : kinds)
      for (const bool reversed_m : {false, true})
        for (const bool reversed_n : {false, true}) {
          if ((reversed_m && m != Kind::rod) || (reversed_n && n != Kind::rod)) continue;
          for (TwistUpdate u : {TwistUpdate::direct, TwistUpdate::incremental_i, TwistUpdate::incremental_ii}) {
            const Eigen::VectorXd q0 = rest_state(m, n);
            EdgeConnection c("reduced", 0, 1, side(m, 0, reversed_m), side(n, 1, reversed_n), k_line, q0);
            for (int turn = 1; turn <= 6; ++turn) c.accept(turn_second(q0, m, n, 0.5 * turn), u);  // accepted δ ≈ 3 rad
            for (int trial = 0; trial < 3; ++trial) {
              Eigen::VectorXd q = turn_second(q0, m, n, 3.0 + 0.3 * trial);
              for (double& v : q) v += noise(rng);
              Eigen::MatrixXd H, H_ref;
              const EdgeEval e = c.evaluate(q, u, true, &H);
              const EdgeEval ref = c.evaluate(q, u, true, &H_ref, sewn::connect::EdgeDerivatives::whole_stencil);
              const EdgeEval grad_only = c.evaluate(q, u, true);
              REQUIRE(e.energy == ref.energy);
              if (u != TwistUpdate::direct)  // past π (a reversed rod n turns δ the other way): followed
                REQUIRE(std::abs(std::abs(e.twist - c.rest_twist()) - 3.0 - 0.3 * trial) < 0.6);
              const double gs = ref.gradient.cwiseAbs().maxCoeff(), hs = H_ref.cwiseAbs().maxCoeff();
              worst_g = std::max(worst_g, (e.gradient - ref.gradient).cwiseAbs().maxCoeff() / gs);
              worst_g = std::max(worst_g, (grad_only.gradient - ref.gradient).cwiseAbs().maxCoeff() / gs);
              worst_h = std::max(worst_h, (H - H_ref).cwiseAbs().maxCoeff() / hs);
              CHECK((H - H.transpose()).cwiseAbs().maxCoeff() <= 1e-15 * hs);
              ++cases;
            }
          }
        }
  INFO("reduced against whole-stencil AD over " << cases << " states: gradient " << worst_g << ", Hessian " << worst_h);
  CHECK(cases == 3 * 3 * 16);
  CHECK(worst_g < 1e-12);
  CHECK(worst_h < 1e-12);
}

TEST_CASE("curve connection: incremental angles past pi and 3 pi, derivatives exact there; the direct one wraps") {
  for (const auto& kinds : {std::pair{Kind::rod, Kind::face}, std::pair{Kind::hinge, Kind::face}}) {
    const Kind m = kinds.first, n = kinds.second;  // named: clang 14 cannot capture bindings (INFO)
    const Eigen::VectorXd q0 = rest_state(m, n);
    EdgeConnection inc_i("i", 0, 1, make_side(m, 0), make_side(n, 1), k_line, q0);
    EdgeConnection inc_ii("ii", 0, 1, make_side(m, 0), make_side(n, 1), k_line, q0);
    const EdgeConnection direct("direct", 0, 1, make_side(m, 0), make_side(n, 1), k_line, q0);
    const double step = 0.3;
    double worst_i = 0, worst_ii = 0, worst_direct = 0;
    for (int k = 1; k <= 40; ++k) {  // 12 rad: past π, 3π
      const Eigen::VectorXd q = turn_second(q0, m, n, step * k);
      const double expected = inc_ii.rest_twist() + step * k;
      worst_i = std::max(worst_i, std::abs(inc_i.evaluate(q, TwistUpdate::incremental_i, false).twist - expected));
      worst_ii = std::max(worst_ii, std::abs(inc_ii.evaluate(q, TwistUpdate::incremental_ii, false).twist - expected));
      worst_direct = std::max(worst_direct, std::abs(direct.evaluate(q, TwistUpdate::direct, false).twist - expected));
      inc_i.accept(q, TwistUpdate::incremental_i);
      inc_ii.accept(q, TwistUpdate::incremental_ii);
    }
    CHECK(worst_i < 1e-9);
    CHECK(worst_ii < 1e-9);
    CHECK(worst_direct > pi);
    // After the turn: an increment of π − 0.05 is still followed, and differentiated exactly.
    const Eigen::VectorXd q = turn_second(q0, m, n, step * 40 + pi - 0.05);
    CHECK(inc_ii.evaluate(q, TwistUpdate::incremental_ii, false).twist ==
          doctest::Approx(inc_ii.rest_twist() + step * 40 + pi - 0.05).epsilon(1e-12));
    const FdError err = fd_error(inc_ii, q, TwistUpdate::incremental_ii);
    CHECK(err.gradient < 1e-7);
    CHECK(err.hessian < 1e-6);
  }
}

TEST_CASE("curve connection: a pure turn about the edge gives E = k l (phi)^2 / 2 and dE/dtheta = k l phi") {
  const Eigen::VectorXd q0 = rest_state(Kind::face, Kind::rod);
  const EdgeConnection c("turn", 0, 1, make_side(Kind::face, 0), make_side(Kind::rod, 1), k_line, q0);
  CHECK(c.rest_length() == doctest::Approx(0.4));
  CHECK(c.evaluate(q0, TwistUpdate::incremental_ii, false).energy == doctest::Approx(0.0).epsilon(1e-15));
  for (double phi : {-1.0, 0.2, 1.3}) {
    Eigen::VectorXd q = q0;
    q[9] += phi;  // the rod's θ
    const EdgeEval e = c.evaluate(q, TwistUpdate::incremental_ii, true);
    CHECK(e.energy == doctest::Approx(0.5 * k_line * 0.4 * phi * phi).epsilon(1e-12));
    CHECK(e.gradient[9] == doctest::Approx(k_line * 0.4 * phi).epsilon(1e-12));
  }
}

TEST_CASE("curve connection: a twisted curve's energy does not depend on how many edges it has, nor on stretching") {
  // A rod along a shell's boundary (length 1, triangles hanging off every edge), the rod turned
  // by φ on every edge: E = ½ k L φ² whatever the number of edges, and the same once stretched.
  const double phi = 0.7;
  for (int edges : {1, 4, 16}) {
    double energy = 0, stretched = 0;
    for (int i = 0; i < edges; ++i) {
      const double x0 = double(i) / edges, x1 = double(i + 1) / edges;
      Eigen::VectorXd q(10);
      q << x0, 0, 0, x1, 0, 0, 0.0, 0.5 * (x0 + x1), 0, -0.2;  // rod θ, then the apex below
      const EdgeConnection c("segment " + std::to_string(i), 0, 1, RodEdgeSide{0, 1, Vec3(1, 0, 0), Vec3(0, 1, 0)}, FaceSide{2},
                             k_line, q);
      q[6] += phi;
      energy += c.evaluate(q, TwistUpdate::incremental_ii, false).energy;
      q.head<6>() *= 1.3;  // stretched along x by 30 %
      stretched += c.evaluate(q, TwistUpdate::incremental_ii, false).energy;
    }
    CHECK(energy == doctest::Approx(0.5 * k_line * 1.0 * phi * phi).epsilon(1e-12));
    CHECK(stretched == doctest::Approx(energy).epsilon(1e-12));
  }
}

TEST_CASE("curve connection: rigid motions give zero energy and force; translations sum the forces to zero") {
  std::mt19937 rng(3);
  std::normal_distribution<double> noise(0, 0.05);
  for (const auto& kinds : {std::pair{Kind::face, Kind::face}, std::pair{Kind::hinge, Kind::face}, std::pair{Kind::hinge, Kind::hinge}}) {
    const Kind m = kinds.first, n = kinds.second;  // named: clang 14 cannot capture bindings (INFO)
    const Eigen::VectorXd q0 = rest_state(m, n);
    const EdgeConnection c("rigid", 0, 1, make_side(m, 0), make_side(n, 1), k_line, q0);
    const Eigen::Matrix3d R = Eigen::AngleAxisd(2.1, Vec3(0.3, -1, 0.5).normalized()).toRotationMatrix();
    Eigen::VectorXd q = q0;
    for (Eigen::Index p = 0; p < q.size(); p += 3) q.segment<3>(p) = R * Vec3(q0.segment<3>(p)) + Vec3(0.2, 1, -3);
    const EdgeEval e = c.evaluate(q, TwistUpdate::incremental_ii, true);
    CHECK(std::abs(e.energy) < 1e-20);
    CHECK(e.gradient.cwiseAbs().maxCoeff() < 1e-12);
    // A strained state: the position forces sum to zero (the energy is translation invariant).
    Eigen::VectorXd s = turn_second(q0, m, n, 0.5);
    for (double& v : s) v += noise(rng);
    const EdgeEval es = c.evaluate(s, TwistUpdate::incremental_ii, true);
    Vec3 total = Vec3::Zero();
    for (Eigen::Index p = 0; p < s.size(); p += 3) total += es.gradient.segment<3>(p);
    CHECK(es.gradient.norm() > 1e-3);
    CHECK(total.norm() < 1e-12 * es.gradient.norm());
  }
  // A rod side: the same rest state turned with its frame has the same rest angle.
  const Eigen::VectorXd q0 = rest_state(Kind::rod, Kind::face);
  const EdgeConnection c("rod", 0, 1, make_side(Kind::rod, 0), make_side(Kind::face, 1), k_line, q0);
  const Eigen::Matrix3d R = Eigen::AngleAxisd(-1.1, Vec3(1, 2, 3).normalized()).toRotationMatrix();
  Eigen::VectorXd q = q0;
  for (Eigen::Index p : {0, 3, 7}) q.segment<3>(p) = R * Vec3(q0.segment<3>(p));
  const EdgeConnection turned("rod turned", 0, 1, RodEdgeSide{0, 1, R * Vec3(1, 0, 0), R * Vec3(0, 1, 0)}, FaceSide{4}, k_line, q);
  CHECK(turned.rest_twist() == doctest::Approx(c.rest_twist()).epsilon(1e-12));
}

TEST_CASE("curve connection: the orientation rule keeps the rest angle within pi/2") {
  // Two faces on opposite sides of the edge, normals antiparallel at rest: the second is negated.
  Eigen::VectorXd q(12);
  q << 0, 0, 0, 1, 0, 0, 0.5, 0.5, 0, 0.5, -0.5, 0;
  const EdgeConnection c("flat", 0, 1, FaceSide{2}, FaceSide{3}, k_line, q);
  CHECK(c.second_sign() == -1.0);
  CHECK(std::abs(c.rest_twist()) < 1e-12);
  q << 0, 0, 0, 1, 0, 0, 0.5, 0.5, 0, 0.5, 0.3, 0.4;  // a fold of 53° between the two faces
  const EdgeConnection d("fold", 0, 1, FaceSide{2}, FaceSide{3}, k_line, q);
  CHECK(d.second_sign() == 1.0);
  CHECK(std::abs(d.rest_twist()) == doctest::Approx(std::atan2(0.4, 0.3)));
}

void check_error(const std::function<void()>& build, const std::string& part) {
  try {
    build();
    FAIL("no error for " << part);
  } catch (const sewn::physics::InputError& e) {
    const std::string what = e.what();
    INFO(what);
    CHECK(what.find("curve connection 'bad'") != std::string::npos);
    CHECK(what.find(part) != std::string::npos);
  }
}

TEST_CASE("curve connection: bad input is refused with the connection's name") {
  const Eigen::VectorXd q = rest_state(Kind::face, Kind::face);
  const EdgeSide f2 = FaceSide{2}, f4 = FaceSide{4};
  check_error([&] { EdgeConnection("bad", 0, 0, f2, f4, k_line, q); }, "both 0");
  check_error([&] { EdgeConnection("bad", 0, 1, FaceSide{1}, f4, k_line, q); }, "appears twice");
  check_error([&] { EdgeConnection("bad", 0, 1, f2, f4, -1.0, q); }, "stiffness");
  check_error([&] { EdgeConnection("bad", 0, 1, f2, f4, k_line, q.head(9)); }, "9 entries");
  Eigen::VectorXd nan = q;
  nan[7] = std::nan("");
  check_error([&] { EdgeConnection("bad", 0, 1, f2, f4, k_line, nan); }, "not finite");
  Eigen::VectorXd zero = q;
  zero.segment<3>(3) = zero.segment<3>(0);
  check_error([&] { EdgeConnection("bad", 0, 1, f2, f4, k_line, zero); }, "zero length");
  Eigen::VectorXd flat = q;
  flat.segment<3>(6) = Vec3(0.7, 0, 0);  // the apex on the edge's line: no normal
  check_error([&] { EdgeConnection("bad", 0, 1, f2, f4, k_line, flat); }, "zero-area");
  const Eigen::VectorXd qr = rest_state(Kind::rod, Kind::face);
  check_error([&] { EdgeConnection("bad", 0, 1, RodEdgeSide{0, 2, Vec3(1, 0, 0), Vec3(0, 1, 0)}, f4, k_line, qr); },
              "is not the shared edge");
  check_error([&] { EdgeConnection("bad", 0, 1, RodEdgeSide{0, 1, Vec3(1, 0, 0), Vec3(1, 0, 0)}, f4, k_line, qr); },
              "orthonormal");
  // A hinge folded flat onto itself: its two normals cancel.
  Eigen::VectorXd qh(15);
  qh << 0, 0, 0, 1, 0, 0, 0.5, 0.5, 0, 0.5, 0.5, 1e-5, 0.3, 0, 0.4;
  check_error([&] { EdgeConnection("bad", 0, 1, HingeSide{2, 3}, f4, k_line, qh); }, "folded flat");
  // A configuration of the wrong size later names the connection too.
  const EdgeConnection good("bad", 0, 1, f2, f4, k_line, q);
  check_error([&] { (void)good.evaluate(q.head(6), TwistUpdate::incremental_ii, false); }, "6 entries");
}

}  // namespace
}  // namespace test_curve
