#include "sewn/connect/curve.hpp"

#include <cmath>
#include <numbers>

#include "history.hpp"
#include "jet.hpp"

namespace sewn::connect {

namespace {

using detail::signed_angle;
using detail::transport;
using detail::V3;
using detail::vec_at;
using physics::InputError;

constexpr int edge_max_dofs = 18;  // edge (6) + two hinges (6 + 6)
constexpr double full_turn = 2 * std::numbers::pi;
// A hinge whose two normals nearly cancel (|n_A + n_B| < this: folded to within ~0.01 rad of
// flat onto itself) has no average normal to speak of.
constexpr double hinge_margin = 1e-2;
// A triangle or edge this thin (relative) gives no direction.
constexpr double thin_margin = 1e-12;

[[noreturn]] void fail_edge(const std::string& name, const std::string& why) {
  throw InputError("curve connection '" + name + "': " + why);
}

int extra_dofs(const EdgeSide& s) {
  if (std::holds_alternative<RodEdgeSide>(s)) return 1;
  return std::holds_alternative<FaceSide>(s) ? 3 : 6;
}

std::string describe(const EdgeSide& s) {
  if (const auto* r = std::get_if<RodEdgeSide>(&s))
    return "rod edge (" + std::to_string(r->from) + ", " + std::to_string(r->to) + ")";
  if (const auto* f = std::get_if<FaceSide>(&s)) return "face with apex " + std::to_string(f->apex);
  const auto& h = std::get<HingeSide>(s);
  return "hinge with apices " + std::to_string(h.left) + ", " + std::to_string(h.right);
}

template <class T>
struct SideFrame {
  V3<T> m1;
  bool degenerate = false;
};

// A side's m1 from the stencil q: `at` is the side's first extra DOF, e the unit edge direction.
template <class T, class Q>
SideFrame<T> side_frame(const EdgeSide& side, Index a, const Q& q, int at, const V3<T>& e) {
  using detail::cross;
  using detail::dot;
  using std::cos;
  using std::sin;
  SideFrame<T> f;
  const V3<T> xa = vec_at<T>(q, 0), xb = vec_at<T>(q, 3);
  if (const auto* r = std::get_if<RodEdgeSide>(&side)) {
    const V3<T> t = (r->from == a ? 1.0 : -1.0) * e;
    const V3<T> tb = detail::constant<T>(r->tangent.x(), r->tangent.y(), r->tangent.z());
    const V3<T> db = detail::constant<T>(r->director.x(), r->director.y(), r->director.z());
    f.degenerate = 1 + detail::value_of(dot(tb, t)) < antiparallel_margin;
    const V3<T> a1 = transport(tb, t, db);
    f.m1 = cos(q[at]) * a1 + sin(q[at]) * cross(t, a1);
    return f;
  }
  auto normal = [&](const V3<T>& p, const V3<T>& s, const V3<T>& apex) {
    const V3<T> u = s - p, v = apex - p, n = cross(u, v);
    const double nn = detail::value_of(dot(n, n));
    if (!(nn > thin_margin * detail::value_of(dot(u, u)) * detail::value_of(dot(v, v)))) f.degenerate = true;
    return n;
  };
  if (std::holds_alternative<FaceSide>(side)) {
    f.m1 = detail::normalized(normal(xa, xb, vec_at<T>(q, at)));
    return f;
  }
  const V3<T> na = detail::normalized(normal(xa, xb, vec_at<T>(q, at)));
  const V3<T> nb = detail::normalized(normal(xb, xa, vec_at<T>(q, at + 3)));
  const V3<T> s = na + nb;
  if (!(detail::value_of(dot(s, s)) > hinge_margin * hinge_margin)) f.degenerate = true;
  f.m1 = detail::normalized(s);
  return f;
}

template <class T>
struct Angles {
  T twist;
  double raw = 0;
  bool degenerate = false;
};

// What the twist needs of a connection (EdgeConnection's members).
struct EdgeView {
  Index a;
  const EdgeSide& m;
  const EdgeSide& n;
  int extra_m;
  double sign_n, accepted;
};

// δ at q (stencil order; any scalar) by `update`.
template <class T, class Q>
Angles<T> edge_twist(const EdgeView& c, const Q& q, TwistUpdate update) {
  using std::cos;
  using std::sin;
  const V3<T> d = vec_at<T>(q, 3) - vec_at<T>(q, 0);
  const double dd = detail::value_of(detail::dot(d, d));
  const V3<T> e = detail::normalized(d);
  const SideFrame<T> fm = side_frame<T>(c.m, c.a, q, 6, e);
  SideFrame<T> fn = side_frame<T>(c.n, c.a, q, 6 + c.extra_m, e);
  fn.m1 = T(c.sign_n) * fn.m1;
  Angles<T> out{signed_angle(fm.m1, fn.m1, e), 0.0, fm.degenerate || fn.degenerate || !(dd > 0)};
  out.raw = detail::value_of(out.twist);
  if (update == TwistUpdate::incremental_i) {
    out.twist = out.twist + T(full_turn * std::round((c.accepted - out.raw) / full_turn));
  } else if (update == TwistUpdate::incremental_ii) {
    // Turn m1 by the accepted δ first: what is left is the step's increment (< π).
    const V3<T> m1t = cos(T(c.accepted)) * fm.m1 + sin(T(c.accepted)) * detail::cross(e, fm.m1);
    out.twist = T(c.accepted) + signed_angle(m1t, fn.m1, e);
  }
  return out;
}

// ∂δ/∂θ of a rod side: m1 turns by θ about its tangent t = ±e, i.e. by ±θ about e; δ is the
// angle from m1 to n1, so it falls by that on side m and rises by it on side n (the sign rule
// that flips n1 does not turn it). 0 if the side is not a rod.
double twist_rate(const EdgeSide& side, Index a, int which) {
  const auto* r = std::get_if<RodEdgeSide>(&side);
  if (!r) return 0;
  const double along = r->from == a ? 1.0 : -1.0;
  return which == 0 ? -along : along;
}

// EdgeDerivatives::reduced: δ differentiated in y = the stencil's positions other than x_a,
// relative to x_a (J's directions: 3 per position block after x_a), the θ slots exactly; then
// with c = k l̄ and dt = δ − δ̄: dE/dq = c dt ∇δ, d²E/dq² = c (∇δ ∇δᵀ + dt ∇²δ), ∇δ = D ∇_y δ
// with D the map y → q (x_a's rows minus the sum of the others').
template <class J>
void reduced_derivatives(const EdgeView& c, const Eigen::VectorXd& q, int extra_n, TwistUpdate update, double factor,
                         double dt, Eigen::VectorXd& gradient, Eigen::MatrixXd* hessian) {
  const int n = 6 + c.extra_m + extra_n;
  // Each stencil slot's reduced direction: -1 for x_a and θ slots (handled apart).
  std::array<int, edge_max_dofs> dir{};
  std::array<int, edge_max_dofs> axis{};     // a position slot's axis (0, 1, 2)
  std::array<double, edge_max_dofs> rate{};  // ∂δ/∂θ at θ slots
  std::array<J, edge_max_dofs> qa;
  int r = 0;
  const Vec3 xa = q.segment<3>(0);
  auto position_block = [&](int at) {
    for (int k = 0; k < 3; ++k) {
      const auto s = static_cast<std::size_t>(at + k);
      dir[s] = at == 0 ? -1 : r;
      axis[s] = k;
      qa[s] = at == 0 ? J(0.0) : J::variable(q[at + k] - xa[k], r);
      if (at != 0) ++r;
    }
  };
  position_block(0);
  position_block(3);
  int at = 6;
  for (int which = 0; which < 2; ++which) {
    const EdgeSide& side = which == 0 ? c.m : c.n;
    const int extra = which == 0 ? c.extra_m : extra_n;
    if (std::holds_alternative<RodEdgeSide>(side)) {
      const auto s = static_cast<std::size_t>(at);
      dir[s] = -1;
      rate[s] = twist_rate(side, c.a, which);
      qa[s] = J(q[at]);
    } else {
      for (int b = 0; b < extra; b += 3) position_block(at + b);
    }
    at += extra;
  }
  const J twist = edge_twist<J>(c, qa, update).twist;
  // ∇δ in stencil order.
  Eigen::VectorXd grad_delta = Eigen::VectorXd::Zero(n);
  for (int i = 0; i < n; ++i) {
    const auto s = static_cast<std::size_t>(i);
    if (dir[s] >= 0) {
      const double gi = twist.g[static_cast<std::size_t>(dir[s])];
      grad_delta[i] = gi;
      grad_delta[axis[s]] -= gi;  // x_a: minus the sum of the other positions' (same axis)
    } else if (i >= 6) {
      grad_delta[i] = rate[s];
    }
  }
  gradient = factor * dt * grad_delta;
  if (!hessian) return;
  // ∇²δ: only position-position entries (δ is affine in θ); x_a's rows and columns by D.
  Eigen::MatrixXd Hd = Eigen::MatrixXd::Zero(n, n);
  for (int i = 3; i < n; ++i) {
    const int di = dir[static_cast<std::size_t>(i)], ai = axis[static_cast<std::size_t>(i)];
    if (di < 0) continue;
    for (int j = 3; j < n; ++j) {
      const int dj = dir[static_cast<std::size_t>(j)], aj = axis[static_cast<std::size_t>(j)];
      if (dj < 0) continue;
      const double h = twist.hessian(di, dj);
      Hd(i, j) += h;
      Hd(ai, j) -= h;
      Hd(i, aj) -= h;
      Hd(ai, aj) += h;
    }
  }
  *hessian = factor * (grad_delta * grad_delta.transpose() + dt * Hd);
}

}  // namespace

std::vector<Index> edge_stencil_nodes(Index a, Index b, const EdgeSide& m, const EdgeSide& n) {
  std::vector<Index> out{a, b};
  for (const EdgeSide* s : {&m, &n}) {
    if (const auto* f = std::get_if<FaceSide>(s)) out.push_back(f->apex);
    if (const auto* h = std::get_if<HingeSide>(s)) out.insert(out.end(), {h->left, h->right});
  }
  return out;
}

EdgeConnection::EdgeConnection(std::string name, Index a, Index b, EdgeSide m, EdgeSide n, double k_per_length,
                               const Eigen::VectorXd& q_rest)
    : name_(std::move(name)), a_(a), b_(b), m_(std::move(m)), n_(std::move(n)), k_(k_per_length) {
  if (!std::isfinite(k_) || k_ < 0) fail_edge(name_, "stiffness per length must be finite and >= 0, got " + std::to_string(k_));
  if (a_ == b_) fail_edge(name_, "the edge's two nodes are both " + std::to_string(a_));
  nodes_ = edge_stencil_nodes(a_, b_, m_, n_);
  for (std::size_t i = 0; i < nodes_.size(); ++i)
    for (std::size_t j = i + 1; j < nodes_.size(); ++j)
      if (nodes_[i] == nodes_[j])
        fail_edge(name_, "node " + std::to_string(nodes_[i]) + " appears twice in the edge (" + std::to_string(a_) + ", " +
                        std::to_string(b_) + ") and its sides' apices");
  for (const EdgeSide* s : {&m_, &n_})
    if (const auto* r = std::get_if<RodEdgeSide>(s)) {
      if (!((r->from == a_ && r->to == b_) || (r->from == b_ && r->to == a_)))
        fail_edge(name_, describe(*s) + " is not the shared edge (" + std::to_string(a_) + ", " + std::to_string(b_) + ")");
      if (std::abs(r->tangent.norm() - 1) > 1e-9 || std::abs(r->director.norm() - 1) > 1e-9 ||
          std::abs(r->tangent.dot(r->director)) > 1e-9)
        fail_edge(name_, describe(*s) + ": its stored tangent and director are not an orthonormal pair");
    }
  extra_m_ = extra_dofs(m_);
  extra_n_ = extra_dofs(n_);
  if (q_rest.size() != num_dofs())
    fail_edge(name_, "rest configuration has " + std::to_string(q_rest.size()) + " entries, the stencil " +
                    std::to_string(num_dofs()));
  if (!q_rest.allFinite()) fail_edge(name_, "rest configuration is not finite");
  rest_length_ = (q_rest.segment<3>(3) - q_rest.segment<3>(0)).norm();
  if (!(rest_length_ > 0)) fail_edge(name_, "the edge has zero length at rest");
  const EdgeEval e = evaluate(q_rest, TwistUpdate::direct, false);
  if (e.degenerate)
    fail_edge(name_, "no frame can be built at rest (a zero-area triangle, a hinge folded flat onto itself or whose two "
                     "triangles are not consistently oriented, or a rod frame turned against its edge) on " +
                         describe(m_) + " or " + describe(n_));
  rest_twist_ = e.twist_raw;
  if (std::abs(rest_twist_) > std::numbers::pi / 2) {  // the orientation rule
    sign_n_ = -1;
    rest_twist_ = evaluate(q_rest, TwistUpdate::direct, false).twist_raw;
  }
  accepted_twist_ = rest_twist_;
}

int EdgeConnection::angle_slot(int side) const {
  const EdgeSide& s = side == 0 ? m_ : n_;
  if (!std::holds_alternative<RodEdgeSide>(s)) return -1;
  return side == 0 ? 6 : 6 + extra_m_;
}

EdgeEval EdgeConnection::evaluate(const Eigen::VectorXd& q, TwistUpdate update, bool want_gradient,
                                  Eigen::MatrixXd* hessian, EdgeDerivatives method) const {
  if (q.size() != num_dofs())
    fail_edge(name_, "configuration has " + std::to_string(q.size()) + " entries, the stencil " + std::to_string(num_dofs()));
  if (!q.allFinite()) fail_edge(name_, "configuration is not finite");
  const EdgeView view{a_, m_, n_, extra_m_, sign_n_, accepted_twist_};
  const double factor = k_ * rest_length_;  // E = ½ factor (δ − δ̄)²
  EdgeEval out;
  const Angles<double> angles = edge_twist<double>(view, q, update);
  out.twist = angles.twist;
  out.twist_raw = angles.raw;
  out.degenerate = angles.degenerate;
  const double dt = out.twist - rest_twist_;
  out.energy = 0.5 * factor * dt * dt;
  if (!hessian && !want_gradient) return out;
  const int n = num_dofs();
  if (method == EdgeDerivatives::reduced) {
    // Reduced directions: the positions after x_a (n − 3 minus the θ slots). A Hessian costs
    // their square: a rod along a face has 6 (the frisbee's and the toy tunnel's rims), two
    // faces or a rod and a hinge 9, a hinge and a face 12, two hinges 15.
    const int thetas = (std::holds_alternative<RodEdgeSide>(m_) ? 1 : 0) + (std::holds_alternative<RodEdgeSide>(n_) ? 1 : 0);
    const int r = n - 3 - thetas;
    auto run = [&](auto tag) { reduced_derivatives<decltype(tag)>(view, q, extra_n_, update, factor, dt, out.gradient, hessian); };
    if (hessian && r <= 6)
      run(detail::Jet<6, true>{});
    else if (hessian && r <= 9)
      run(detail::Jet<9, true>{});
    else if (hessian)
      run(detail::Jet<edge_max_dofs - 3, true>{});
    else if (r <= 6)
      run(detail::Jet<6, false>{});
    else if (r <= 9)
      run(detail::Jet<9, false>{});
    else
      run(detail::Jet<edge_max_dofs - 3, false>{});
    return out;
  }
  // The reference: E itself differentiated to second order in every stencil DOF.
  using J = detail::Jet<edge_max_dofs, true>;
  std::array<J, edge_max_dofs> qa;
  for (int i = 0; i < n; ++i) qa[static_cast<std::size_t>(i)] = J::variable(q[i], i);
  const J dtj = edge_twist<J>(view, qa, update).twist - J(rest_twist_);
  const J energy = J(0.5 * factor) * dtj * dtj;
  out.gradient.resize(n);
  for (int i = 0; i < n; ++i) out.gradient[i] = energy.g[static_cast<std::size_t>(i)];
  if (hessian) {
    hessian->resize(n, n);
    for (int i = 0; i < n; ++i)
      for (int j = 0; j < n; ++j) (*hessian)(i, j) = energy.hessian(i, j);
  }
  return out;
}

void EdgeConnection::accept(const Eigen::VectorXd& q, TwistUpdate update) {
  accepted_twist_ = evaluate(q, update, false).twist;
  const Vec3 e = (q.segment<3>(3) - q.segment<3>(0)).normalized();
  for (EdgeSide* s : {&m_, &n_})
    if (auto* r = std::get_if<RodEdgeSide>(s)) {
      const Vec3 t = r->from == a_ ? e : Vec3(-e);
      r->director = physics::rods::parallel_transport(r->tangent, t, r->director).normalized();
      r->tangent = t;
    }
}

void EdgeConnection::remap_nodes(std::span<const Index> old_to_new) {
  auto map = [&](Index& i) { i = old_to_new[i]; };
  map(a_);
  map(b_);
  for (Index& i : nodes_) map(i);
  for (EdgeSide* s : {&m_, &n_}) {
    if (auto* r = std::get_if<RodEdgeSide>(s)) {
      map(r->from);
      map(r->to);
    } else if (auto* f = std::get_if<FaceSide>(s)) {
      map(f->apex);
    } else {
      auto& h = std::get<HingeSide>(*s);
      map(h.left);
      map(h.right);
    }
  }
}

ConnectionHistory EdgeConnection::history() const { return detail::make_history(accepted_twist_, m_, n_); }

void EdgeConnection::restore(const ConnectionHistory& h) {
  accepted_twist_ = detail::take_history(h, m_, n_, "curve connection '" + name_ + "'");
}

}  // namespace sewn::connect
