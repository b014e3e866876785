#include "sewn/connect/point.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <numbers>
#include <sstream>
#include <stdexcept>
#include <type_traits>

#include "history.hpp"
#include "jet.hpp"
#include "vertex_frame.hpp"
#include "sewn/physics/rods/stencils.hpp"

namespace sewn::connect {

namespace {

using detail::signed_angle;
using detail::transport;
using detail::V3;
using detail::value_of;
using detail::vec_at;
using physics::InputError;

constexpr double two_pi = 2 * std::numbers::pi;
// Forward AD over the whole stencil, in as many directions as it needs: 18 (rod or triangle
// sides) or 24 (a tet side); first order (gradients), second (the reference Hessian).
constexpr int max_dofs = 24;  // tet + tet
// The chained Hessian's scalars: a side's frame in 9 (rod, triangle) or 12 (tet) directions,
// the core in 12.
constexpr int side_dofs_max = 12;  // the whole-stencil and per-side jets; a vertex side has its own
using Coef = std::array<double, 6>;

[[noreturn]] void fail(const std::string& name, const std::string& why) {
  throw InputError("point connection '" + name + "': " + why);
}

std::string describe(const Side& s) {
  std::ostringstream o;
  if (const auto* r = std::get_if<RodEdgeSide>(&s)) {
    o << "rod edge (" << r->from << ", " << r->to << ")";
  } else if (const auto* t = std::get_if<TriangleSide>(&s)) {
    o << "triangle (" << t->nodes[0] << ", " << t->nodes[1] << ", " << t->nodes[2] << ")";
  } else if (const auto* v = std::get_if<VertexSide>(&s)) {
    o << "shell vertex " << v->joint << " (one-ring of " << v->ring.size() << ")";
  } else {
    const auto& k = std::get<TetSide>(s);
    o << "tetrahedron (" << k.nodes[0] << ", " << k.nodes[1] << ", " << k.nodes[2] << ", " << k.nodes[3] << ")";
  }
  return o.str();
}

std::vector<Index> side_nodes(const Side& s) {
  if (const auto* r = std::get_if<RodEdgeSide>(&s)) return {r->from, r->to};
  if (const auto* t = std::get_if<TriangleSide>(&s)) return {t->nodes.begin(), t->nodes.end()};
  if (const auto* v = std::get_if<VertexSide>(&s)) {
    std::vector<Index> out{v->joint};
    out.insert(out.end(), v->ring.begin(), v->ring.end());
    return out;
  }
  const auto& k = std::get<TetSide>(s);
  return {k.nodes.begin(), k.nodes.end()};
}

int side_dofs(const Side& s) {
  if (std::holds_alternative<RodEdgeSide>(s)) return 7;
  if (const auto* v = std::get_if<VertexSide>(&s)) return 3 * (static_cast<int>(v->ring.size()) + 1);
  return std::holds_alternative<TriangleSide>(s) ? 9 : 12;
}

// The one node both sides hold; rejects sides that are degenerate or share 0 or 2+ nodes.
Index shared_node(const std::string& name, const Side& m, const Side& n) {
  for (const Side* s : {&m, &n}) {
    const auto v = side_nodes(*s);
    for (std::size_t i = 0; i < v.size(); ++i)
      for (std::size_t j = i + 1; j < v.size(); ++j)
        if (v[i] == v[j]) fail(name, describe(*s) + " repeats node " + std::to_string(v[i]));
  }
  std::vector<Index> common;
  for (Index a : side_nodes(m))
    for (Index b : side_nodes(n))
      if (a == b) common.push_back(a);
  if (common.empty()) fail(name, describe(m) + " and " + describe(n) + " share no node");
  for (const Side* s : {&m, &n})
    if (const auto* v = std::get_if<VertexSide>(s); v && common.size() == 1 && common[0] != v->joint)
      fail(name, describe(*s) + " meets " + describe(s == &m ? n : m) + " at ring node " + std::to_string(common[0]) +
                     ", not at its joint");
  if (common.size() > 1)
    fail(name, describe(m) + " and " + describe(n) +
                   " share more than one node (an edge: that is a curve connection, not a point one)");
  return common[0];
}

// A triangle side with its nodes rotated to start at the joint (orientation kept); a tet's
// joint moved to the front, the others in order.
TriangleSide rotated(TriangleSide t, Index joint) {
  while (t.nodes[0] != joint) t.nodes = {t.nodes[1], t.nodes[2], t.nodes[0]};
  return t;
}
TetSide rotated(TetSide t, Index joint) {
  const auto at = std::find(t.nodes.begin(), t.nodes.end(), joint);
  std::rotate(t.nodes.begin(), at, at + 1);
  return t;
}
// Side s with its nodes starting at the joint.
Side rotated(const Side& s, Index joint) {
  if (const auto* t = std::get_if<TriangleSide>(&s)) return rotated(*t, joint);
  if (const auto* k = std::get_if<TetSide>(&s)) return rotated(*k, joint);
  return s;
}

template <class T>
struct Frame {
  V3<T> m1, m2, m3;
};

// The side's frame from the stencil q, its DOFs from offset `at`, axis sign and triangle coefficients.
template <class T, class Q>
Frame<T> build_frame(const Side& side, const Q& q, int at, double sign, const Coef& coef) {
  using detail::cross;
  using detail::dot;
  using std::cos;
  using std::sin;
  using std::sqrt;
  Frame<T> f;
  if (const auto* v = std::get_if<VertexSide>(&side)) {
    // The one-ring is wider than the jets that come here: its derivatives are chained
    // (vertex_frame_jet), only its values are built here.
    if constexpr (std::is_same_v<T, double>) {
      const auto mv = detail::vertex_frame(q, at, static_cast<int>(v->ring.size()), sign);
      f.m1 = {mv[0].x(), mv[0].y(), mv[0].z()};
      f.m3 = {mv[1].x(), mv[1].y(), mv[1].z()};
    } else {
      throw std::logic_error("point connection: a vertex side's frame has no whole-stencil jet");
    }
  } else if (const auto* r = std::get_if<RodEdgeSide>(&side)) {
    const V3<T> t = detail::normalized(vec_at<T>(q, at + 3) - vec_at<T>(q, at));
    const V3<T> tb = detail::constant<T>(r->tangent.x(), r->tangent.y(), r->tangent.z());
    const V3<T> db = detail::constant<T>(r->director.x(), r->director.y(), r->director.z());
    const V3<T> a1 = transport(tb, t, db);
    const V3<T> a2 = cross(t, a1);
    f.m1 = cos(q[at + 6]) * a1 + sin(q[at + 6]) * a2;
    f.m3 = T(sign) * t;
  } else if (std::holds_alternative<TetSide>(side)) {
    const V3<T> x0 = vec_at<T>(q, at);
    const V3<T> c1 = vec_at<T>(q, at + 3) - x0, c2 = vec_at<T>(q, at + 6) - x0, c3 = vec_at<T>(q, at + 9) - x0;
    const V3<T> a = coef[0] * c1 + coef[1] * c2 + coef[2] * c3;  // F m̄3
    const V3<T> b = coef[3] * c1 + coef[4] * c2 + coef[5] * c3;  // F m̄1
    const V3<T> m3 = detail::normalized(a);
    f.m1 = detail::normalized(b - dot(b, m3) * m3);
    f.m3 = T(sign) * m3;
  } else {
    const V3<T> e1 = vec_at<T>(q, at + 3) - vec_at<T>(q, at);
    const V3<T> e2 = vec_at<T>(q, at + 6) - vec_at<T>(q, at);
    f.m1 = detail::normalized(cross(e1, e2));
    const V3<T> axis = T(coef[0]) * e1 + T(coef[1]) * e2;
    f.m3 = (T(sign) / sqrt(dot(axis, axis))) * axis;
  }
  f.m2 = cross(f.m3, f.m1);
  return f;
}

// A side's frame (m1, m3) as 6 values with their Jacobian and second derivatives over the
// side's DOFs (the first 7 or 9 columns are used).
using SideJet = detail::FrameJet;

template <int N, bool H>
SideJet side_jet_n(const Side& side, const Eigen::VectorXd& q, int at, int dofs, double sign, const Coef& coef) {
  using S = detail::Jet<N, H>;
  std::array<S, side_dofs_max> qa;  // sized for any side, so no path reads past it
  for (int i = 0; i < dofs; ++i) qa[static_cast<std::size_t>(i)] = S::variable(q[at + i], i);
  const Frame<S> f = build_frame<S>(side, qa, 0, sign, coef);
  SideJet jet;
  jet.jacobian = Eigen::MatrixXd::Zero(6, dofs);
  const std::array<const S*, 6> out{&f.m1.x, &f.m1.y, &f.m1.z, &f.m3.x, &f.m3.y, &f.m3.z};
  for (int k = 0; k < 6; ++k) {
    const S& v = *out[static_cast<std::size_t>(k)];
    jet.value[k] = v.v;
    for (int i = 0; i < dofs; ++i) jet.jacobian(k, i) = v.g[static_cast<std::size_t>(i)];
    if constexpr (H) {
      jet.hessian[static_cast<std::size_t>(k)] = Eigen::MatrixXd::Zero(dofs, dofs);
      for (int i = 0; i < dofs; ++i)
        for (int j = 0; j < dofs; ++j) jet.hessian[static_cast<std::size_t>(k)](i, j) = v.hessian(i, j);
    }
  }
  return jet;
}
// In as few directions as the side needs; second derivatives if H.
template <bool H>
SideJet side_jet(const Side& side, const Eigen::VectorXd& q, int at, int dofs, double sign, const Coef& coef) {
  if (const auto* v = std::get_if<VertexSide>(&side)) return detail::vertex_frame_jet(q, at, static_cast<int>(v->ring.size()), sign, H);
  return dofs <= 9 ? side_jet_n<9, H>(side, q, at, dofs, sign, coef) : side_jet_n<12, H>(side, q, at, dofs, sign, coef);
}

// The first side's frame turned by the constant rotation R fixed at rest (m'_j = Σ_i R(i, j) m_i):
// the frame the twist is measured from, whose axis m'3 is where n3 sat at rest (the orientation
// rule, see PointConnection).
template <class T>
Frame<T> turned(const Frame<T>& f, const Eigen::Matrix3d& R) {
  auto column = [&](int j) { return T(R(0, j)) * f.m1 + T(R(1, j)) * f.m2 + T(R(2, j)) * f.m3; };
  return {column(0), column(1), column(2)};
}

template <class T>
struct Core {
  T energy{};
  double twist = 0, twist_raw = 0, bend = 0, one_plus_c = 2;
};

}  // namespace

RodEdgeSide rod_edge_side(const physics::rods::Rod& rod, const physics::rods::Points& x, int edge, Index node_offset) {
  if (edge < 0 || edge >= rod.num_edges())
    throw InputError("rod_edge_side: edge " + std::to_string(edge) + " out of range (the rod has " +
                     std::to_string(rod.num_edges()) + " edges)");
  const int n = rod.num_vertices();
  const int to = (edge + 1) % n;
  RodEdgeSide s;
  s.from = node_offset + static_cast<Index>(edge);
  s.to = node_offset + static_cast<Index>(to);
  s.tangent = (x.col(to) - x.col(edge)).normalized();
  s.director = rod.reference_director(x, edge);
  return s;
}

std::vector<Index> stencil_layout(const std::string& name, const Side& m, const Side& n) {
  const Index joint = shared_node(name, m, n);
  std::vector<Index> out;
  for (const Side* s : {&m, &n}) {
    const auto v = side_nodes(rotated(*s, joint));
    out.insert(out.end(), v.begin(), v.end());
  }
  return out;
}

PointConnection::PointConnection(std::string name, Side m, Side n, PointStiffness k, const Eigen::VectorXd& q_rest)
    : name_(std::move(name)), m_(std::move(m)), n_(std::move(n)), k_(k) {
  if (!std::isfinite(k_.twist) || !std::isfinite(k_.bend) || k_.twist < 0 || k_.bend < 0)
    fail(name_, "stiffnesses must be finite and >= 0 (twist " + std::to_string(k_.twist) + ", bend " +
                    std::to_string(k_.bend) + ")");
  nodes_ = stencil_layout(name_, m_, n_);
  joint_ = shared_node(name_, m_, n_);
  dofs_m_ = side_dofs(m_);
  dofs_n_ = side_dofs(n_);
  if (q_rest.size() != num_dofs())
    fail(name_, "rest configuration has " + std::to_string(q_rest.size()) + " entries, the stencil " +
                    std::to_string(num_dofs()));
  if (!q_rest.allFinite()) fail(name_, "rest configuration is not finite");

  // A tet side: checks, and Dm⁻¹m̄3, Dm⁻¹m̄1 (F m̄ = Ds Dm⁻¹ m̄ at any state).
  auto prepare_tet = [&](const TetSide& k, const Eigen::VectorXd& q, Coef& coef) {
    if (!k.rest_axis.allFinite() || !(k.rest_axis.norm() > 0)) fail(name_, describe(k) + ": rest axis is zero or not finite");
    Eigen::Matrix3d Dm;
    for (int c = 0; c < 3; ++c) Dm.col(c) = q.segment<3>(3 * (c + 1)) - q.segment<3>(0);
    const double scale = Dm.col(0).norm() * Dm.col(1).norm() * Dm.col(2).norm();
    if (!(std::abs(Dm.determinant()) > 1e-12 * scale))
      fail(name_, describe(k) + " has zero volume at rest: no frame can be built on it");
    const Vec3 m3 = k.rest_axis.normalized(), m1 = physics::rods::any_perpendicular(m3);
    const Eigen::Matrix3d inv = Dm.inverse();
    const Vec3 w3 = inv * m3, w1 = inv * m1;
    coef = {w3[0], w3[1], w3[2], w1[0], w1[1], w1[2]};
  };
  // A vertex side: every ring triangle has an area, their normals a sum, the first edge leaves it.
  auto check_vertex = [&](const VertexSide& v, const Eigen::VectorXd& q) {
    const int ring = static_cast<int>(v.ring.size());
    if (ring < 3) fail(name_, describe(v) + ": a one-ring needs at least 3 nodes");
    double angles = 0;
    Vec3 w = Vec3::Zero();
    for (int i = 0; i < ring; ++i) {
      const Vec3 a = q.segment<3>(3 * (i + 1)) - q.segment<3>(0), b = q.segment<3>(3 * ((i + 1) % ring + 1)) - q.segment<3>(0);
      const Vec3 c = a.cross(b);
      if (!(c.norm() > 1e-12 * a.norm() * b.norm()) || !(c.norm() > 0))
        fail(name_, describe(v) + ": its triangle (" + std::to_string(v.joint) + ", " + std::to_string(v.ring[static_cast<std::size_t>(i)]) +
                        ", " + std::to_string(v.ring[static_cast<std::size_t>((i + 1) % ring)]) + ") has zero area at rest");
      const double alpha = std::atan2(c.norm(), a.dot(b));
      angles += alpha;
      w += alpha * c.normalized();
    }
    if (!(w.norm() > 1e-9 * angles)) fail(name_, describe(v) + ": its one-ring's normals cancel at rest: no vertex normal");
    const Vec3 e = q.segment<3>(3) - q.segment<3>(0);
    if (!(e.cross(w.normalized()).norm() > 1e-9 * e.norm()))
      fail(name_, describe(v) + ": its first ring edge lies along the vertex normal at rest");
  };
  // Per side: geometry checks, the frame constants, the into/out-of-joint sign.
  auto prepare = [&](Side& s, const Eigen::VectorXd& q, Coef& coef, double into_joint) -> double {
    if (auto* r = std::get_if<RodEdgeSide>(&s)) {
      const Vec3 e = q.segment<3>(3) - q.segment<3>(0);
      if (!(e.norm() > 0)) fail(name_, describe(s) + " has zero length at rest");
      if (std::abs(r->tangent.norm() - 1) > 1e-9 || std::abs(r->director.norm() - 1) > 1e-9 ||
          std::abs(r->tangent.dot(r->director)) > 1e-9)
        fail(name_, describe(s) + ": its stored tangent and director are not an orthonormal pair");
      const double out_sign = (r->from == joint_) ? 1.0 : -1.0;  // t points out of the joint if it starts there
      return into_joint * out_sign;
    }
    if (auto* k = std::get_if<TetSide>(&s)) {
      *k = rotated(*k, joint_);
      prepare_tet(*k, q, coef);
      // The rest axis points out of the solid, so the body lies along −axis (a triangle's lies
      // along its axis): a rod standing on the surface continues the solid's axis straight.
      return -into_joint;
    }
    if (const auto* v = std::get_if<VertexSide>(&s)) {
      check_vertex(*v, q);
      return into_joint;  // the normal's sign is arbitrary: the orientation rule below sets the pair's
    }
    auto& t = std::get<TriangleSide>(s);
    t = rotated(t, joint_);
    const Vec3 e1 = q.segment<3>(3) - q.segment<3>(0), e2 = q.segment<3>(6) - q.segment<3>(0);
    const Vec3 nrm = e1.cross(e2);
    if (!(nrm.norm() > 1e-12 * e1.norm() * e2.norm()) || !(nrm.norm() > 0))
      fail(name_, describe(s) + " has zero area at rest: no frame can be built on it");
    Vec3 axis = e1.normalized() + e2.normalized();
    if (t.rest_axis) {
      axis = *t.rest_axis;
      if (!(axis.norm() > 0) || !axis.allFinite()) fail(name_, describe(s) + ": rest axis is zero or not finite");
      if (std::abs(axis.normalized().dot(nrm.normalized())) > 1e-6)
        fail(name_, describe(s) + ": rest axis is not in the triangle's plane");
    }
    // axis = c1 e1 + c2 e2 by the Gram system; inside the corner iff both coefficients >= 0.
    Eigen::Matrix2d g;
    g << e1.dot(e1), e1.dot(e2), e1.dot(e2), e2.dot(e2);
    const Eigen::Vector2d c = g.inverse() * Eigen::Vector2d(e1.dot(axis), e2.dot(axis));
    if (c[0] < 0 || c[1] < 0) fail(name_, describe(s) + ": rest axis lies outside the joint corner's angle");
    coef = {c[0], c[1]};
    return into_joint;  // the axis points from the joint into the triangle: out of the joint
  };
  const Eigen::VectorXd qm = q_rest.head(dofs_m_), qn = q_rest.tail(dofs_n_);
  sign_m_ = prepare(m_, qm, coef_m_, -1.0);
  sign_n_ = prepare(n_, qn, coef_n_, 1.0);
  const auto fm = build_frame<double>(m_, qm, 0, sign_m_, coef_m_);
  const auto fn = build_frame<double>(n_, qn, 0, sign_n_, coef_n_);
  if (detail::dot(fm.m3, fn.m3) < 0) sign_n_ = -sign_n_;
  const auto fn2 = build_frame<double>(n_, qn, 0, sign_n_, coef_n_);
  rest_d_ = Vec3(detail::dot(fn2.m3, fm.m1), detail::dot(fn2.m3, fm.m2), detail::dot(fn2.m3, fm.m3));
  // The twist's frame: m's frame turned (the shortest way, in its own coordinates) until its axis
  // is n̄3, so the transport's singularity m'3 = −n3 is the bend ω = π and no joint starts
  // nearer to it than a straight one. d̄3 = m̄3·n̄3 ≥ 0 after the flip: that turn is defined.
  const Vec3 e1 = physics::rods::parallel_transport(Vec3::UnitZ(), rest_d_, Vec3::UnitX());
  turn_.col(0) = e1;
  turn_.col(1) = rest_d_.cross(e1);
  turn_.col(2) = rest_d_;
  const auto ft = turned(fm, turn_);
  rest_twist_ = signed_angle(transport(ft.m3, fn2.m3, ft.m1), fn2.m1, fn2.m3);
  accepted_twist_ = rest_twist_;
}

PointEval PointConnection::evaluate(const Eigen::VectorXd& q, TwistUpdate update, bool want_gradient, Eigen::MatrixXd* hessian,
                                    HessianMethod method) const {
  if (q.size() != num_dofs())
    fail(name_, "configuration has " + std::to_string(q.size()) + " entries, the stencil " + std::to_string(num_dofs()));
  if (!q.allFinite()) fail(name_, "configuration is not finite");
  PointEval out;
  // Frames → energy and angles (everything after the frame constructions).
  auto core = [&](const auto& fm, const auto& fn) {
    using T = std::decay_t<decltype(fm.m1.x)>;
    using detail::cross;
    using detail::dot;
    using std::atan2;
    using std::cos;
    using std::sin;
    using std::sqrt;
    Core<T> c;
    const Frame<T> ft = turned(fm, turn_);  // the twist is measured from m's frame turned onto n̄3
    c.one_plus_c = 1 + value_of(dot(ft.m3, fn.m3));
    const T raw = signed_angle(transport(ft.m3, fn.m3, ft.m1), fn.m1, fn.m3);
    T delta = raw;
    if (update == TwistUpdate::incremental_i) {
      delta = raw + T(two_pi * std::round((accepted_twist_ - value_of(raw)) / two_pi));
    } else if (update == TwistUpdate::incremental_ii) {
      // Turn m1 by the accepted δ first: what is left to measure is the step's increment (< π).
      const V3<T> m1t = cos(T(accepted_twist_)) * ft.m1 + sin(T(accepted_twist_)) * ft.m2;
      delta = T(accepted_twist_) + signed_angle(transport(ft.m3, fn.m3, m1t), fn.m1, fn.m3);
    }
    const V3<T> d{dot(fn.m3, fm.m1), dot(fn.m3, fm.m2), dot(fn.m3, fm.m3)};
    const V3<T> db = detail::constant<T>(rest_d_.x(), rest_d_.y(), rest_d_.z());
    const V3<T> cr = cross(d, db);
    const T s2 = dot(cr, cr);
    T eb;
    if (value_of(s2) < 1e-16 && value_of(dot(d, db)) > 0) {
      // ω < 1e-8: |d − d̄|² = 2 − 2cos ω = ω² + O(ω⁴), and smooth where sqrt(s2) is not.
      const V3<T> dd = d - db;
      eb = (0.5 * k_.bend) * dot(dd, dd);
      c.bend = std::sqrt(value_of(s2));
    } else {
      const T w = atan2(sqrt(s2), dot(d, db));
      eb = (0.5 * k_.bend) * (w * w);
      c.bend = value_of(w);
    }
    const T dt = delta - T(rest_twist_);
    c.energy = (0.5 * k_.twist) * (dt * dt) + eb;
    c.twist = value_of(delta);
    c.twist_raw = value_of(raw);
    return c;
  };
  auto run = [&](const auto& qt) {
    using T = std::decay_t<decltype(qt[0])>;
    return core(build_frame<T>(m_, qt, 0, sign_m_, coef_m_), build_frame<T>(n_, qt, dofs_m_, sign_n_, coef_n_));
  };
  // Whole-stencil forward AD in N directions, second order if H: the gradient (and Hessian) into
  // out (and *hessian); the values returned.
  auto whole = [&]<int N, bool H>() {
    using J = detail::Jet<N, H>;
    std::array<J, max_dofs> qa;  // sized for any stencil, so no path reads past it
    for (int i = 0; i < num_dofs(); ++i) qa[static_cast<std::size_t>(i)] = J::variable(q[i], i);
    const auto ca = run(qa);
    out.gradient.resize(num_dofs());
    if (H) hessian->resize(num_dofs(), num_dofs());
    for (int i = 0; i < num_dofs(); ++i) {
      out.gradient[i] = ca.energy.g[static_cast<std::size_t>(i)];
      if (H)
        for (int j = 0; j < num_dofs(); ++j) (*hessian)(i, j) = ca.energy.hessian(i, j);
    }
    return Core<double>{value_of(ca.energy), ca.twist, ca.twist_raw, ca.bend, ca.one_plus_c};
  };
  // E(q) = C(F_m(q_m), F_n(q_n)) with F = (m1, m3) per side: ∇E = Jᵀ C_F and ∇²E = Jᵀ C_FF J +
  // Σ_k C_F[k] ∇²F_k, J block-diagonal. AD of each side's frame (≤ 9 directions, or a vertex
  // side's chained jets) and of the core (12 directions) instead of the whole stencil at once
  // (18); second order only if H.
  auto chained = [&]<bool H>() {
    const SideJet jm = side_jet<H>(m_, q, 0, dofs_m_, sign_m_, coef_m_);
    const SideJet jn = side_jet<H>(n_, q, dofs_m_, dofs_n_, sign_n_, coef_n_);
    using CF = detail::Jet<12, H>;
    std::array<CF, 12> F;
    for (int i = 0; i < 12; ++i) F[static_cast<std::size_t>(i)] = CF::variable((i < 6 ? jm : jn).value[i % 6], i);
    Frame<CF> fm, fn;
    fm.m1 = {F[0], F[1], F[2]};
    fm.m3 = {F[3], F[4], F[5]};
    fm.m2 = detail::cross(fm.m3, fm.m1);
    fn.m1 = {F[6], F[7], F[8]};
    fn.m3 = {F[9], F[10], F[11]};
    fn.m2 = detail::cross(fn.m3, fn.m1);
    const auto cc = core(fm, fn);
    Eigen::Matrix<double, 12, 1> eF;
    for (int i = 0; i < 12; ++i) eF[i] = cc.energy.g[static_cast<std::size_t>(i)];
    const Eigen::Index dm = dofs_m_, dn = dofs_n_;
    Eigen::MatrixXd J = Eigen::MatrixXd::Zero(12, q.size());
    J.topLeftCorner(6, dm) = jm.jacobian.leftCols(dm);
    J.bottomRightCorner(6, dn) = jn.jacobian.leftCols(dn);
    out.gradient = J.transpose() * eF;
    if constexpr (H) {
      Eigen::Matrix<double, 12, 12> eFF;
      for (int i = 0; i < 12; ++i)
        for (int j = 0; j < 12; ++j) eFF(i, j) = cc.energy.hessian(i, j);
      *hessian = J.transpose() * eFF * J;
      for (int k = 0; k < 6; ++k) {
        hessian->topLeftCorner(dm, dm) += eF[k] * jm.hessian[static_cast<std::size_t>(k)].topLeftCorner(dm, dm);
        hessian->bottomRightCorner(dn, dn) += eF[6 + k] * jn.hessian[static_cast<std::size_t>(k)].topLeftCorner(dn, dn);
      }
    }
    return Core<double>{value_of(cc.energy), cc.twist, cc.twist_raw, cc.bend, cc.one_plus_c};
  };
  const bool wide = num_dofs() > 18;  // a tet side
  // A vertex side's one-ring is wider than the whole-stencil jets: its derivatives are chained.
  const bool vertex = std::holds_alternative<VertexSide>(m_) || std::holds_alternative<VertexSide>(n_);
  Core<double> c;
  if (hessian && (vertex || method == HessianMethod::chained)) {
    c = chained.template operator()<true>();
  } else if (want_gradient && vertex) {
    c = chained.template operator()<false>();
  } else if (hessian) {
    c = wide ? whole.template operator()<max_dofs, true>() : whole.template operator()<18, true>();
  } else if (want_gradient) {
    c = wide ? whole.template operator()<max_dofs, false>() : whole.template operator()<18, false>();
  } else {
    c = run(q);
  }
  out.energy = c.energy;
  out.twist = c.twist;
  out.twist_raw = c.twist_raw;
  out.bend_angle = c.bend;
  out.near_antiparallel = c.one_plus_c < antiparallel_margin;
  out.bend_near_pi = c.bend > std::numbers::pi - bend_margin;
  return out;
}

void PointConnection::accept(const Eigen::VectorXd& q, TwistUpdate update) {
  accepted_twist_ = evaluate(q, update, false).twist;
  auto advance = [](Side& s, const Eigen::VectorXd& qs) {
    if (auto* r = std::get_if<RodEdgeSide>(&s)) {
      const Vec3 t = (qs.segment<3>(3) - qs.segment<3>(0)).normalized();
      r->director = physics::rods::parallel_transport(r->tangent, t, r->director).normalized();
      r->tangent = t;
    }
  };
  advance(m_, q.head(dofs_m_));
  advance(n_, q.tail(dofs_n_));
}

void PointConnection::remap_nodes(std::span<const Index> old_to_new) {
  auto map = [&](Index& i) { i = old_to_new[i]; };
  map(joint_);
  for (Index& i : nodes_) map(i);
  for (Side* s : {&m_, &n_}) {
    if (auto* r = std::get_if<RodEdgeSide>(s)) {
      map(r->from);
      map(r->to);
    } else if (auto* t = std::get_if<TriangleSide>(s)) {
      for (Index& i : t->nodes) map(i);
    } else if (auto* v = std::get_if<VertexSide>(s)) {
      map(v->joint);
      for (Index& i : v->ring) map(i);
    } else {
      for (Index& i : std::get<TetSide>(*s).nodes) map(i);
    }
  }
}

std::array<Vec3, 4> PointConnection::frames(const Eigen::VectorXd& q) const {
  (void)evaluate(q, TwistUpdate::direct, false);  // the size and finiteness checks, naming the connection
  const Eigen::VectorXd qm = q.head(dofs_m_), qn = q.tail(dofs_n_);
  const auto fm = build_frame<double>(m_, qm, 0, sign_m_, coef_m_);
  const auto fn = build_frame<double>(n_, qn, 0, sign_n_, coef_n_);
  auto vec = [](const auto& v) { return Vec3(v.x, v.y, v.z); };
  return {vec(fm.m1), vec(fm.m3), vec(fn.m1), vec(fn.m3)};
}

ConnectionHistory PointConnection::history() const { return detail::make_history(accepted_twist_, m_, n_); }

void PointConnection::restore(const ConnectionHistory& h) {
  accepted_twist_ = detail::take_history(h, m_, n_, "point connection '" + name_ + "'");
}

}  // namespace sewn::connect
