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
                                  Eigen::MatrixXd* hessian) const {
  if (q.size() != num_dofs())
    fail_edge(name_, "configuration has " + std::to_string(q.size()) + " entries, the stencil " + std::to_string(num_dofs()));
  if (!q.allFinite()) fail_edge(name_, "configuration is not finite");
  auto run = [&](const auto& qt) {
    using T = std::decay_t<decltype(qt[0])>;
    using std::cos;
    using std::sin;
    const V3<T> d = vec_at<T>(qt, 3) - vec_at<T>(qt, 0);
    const double dd = detail::value_of(detail::dot(d, d));
    const V3<T> e = detail::normalized(d);
    const SideFrame<T> fm = side_frame<T>(m_, a_, qt, 6, e);
    SideFrame<T> fn = side_frame<T>(n_, a_, qt, 6 + extra_m_, e);
    fn.m1 = T(sign_n_) * fn.m1;
    Angles<T> out{signed_angle(fm.m1, fn.m1, e), 0.0, fm.degenerate || fn.degenerate || !(dd > 0)};
    out.raw = detail::value_of(out.twist);
    if (update == TwistUpdate::incremental_i) {
      out.twist = out.twist + T(full_turn * std::round((accepted_twist_ - out.raw) / full_turn));
    } else if (update == TwistUpdate::incremental_ii) {
      // Turn m1 by the accepted δ first: what is left is the step's increment (< π).
      const V3<T> m1t = cos(T(accepted_twist_)) * fm.m1 + sin(T(accepted_twist_)) * detail::cross(e, fm.m1);
      out.twist = T(accepted_twist_) + signed_angle(m1t, fn.m1, e);
    }
    const T dt = out.twist - T(rest_twist_);
    const T energy = T(0.5 * k_ * rest_length_) * dt * dt;
    return std::pair{out, energy};
  };
  EdgeEval out;
  const int n = num_dofs();
  auto finish = [&](const auto& result) {
    out.twist = detail::value_of(result.first.twist);
    out.twist_raw = result.first.raw;
    out.degenerate = result.first.degenerate;
    out.energy = detail::value_of(result.second);
  };
  if (hessian || want_gradient) {
    auto differentiate = [&](auto tag) {
      using J = decltype(tag);
      std::array<J, edge_max_dofs> qa;
      for (int i = 0; i < n; ++i) qa[static_cast<std::size_t>(i)] = J::variable(q[i], i);
      const auto result = run(qa);
      finish(result);
      out.gradient.resize(n);
      for (int i = 0; i < n; ++i) out.gradient[i] = result.second.g[static_cast<std::size_t>(i)];
      if (hessian) {
        hessian->resize(n, n);
        for (int i = 0; i < n; ++i)
          for (int j = 0; j < n; ++j) (*hessian)(i, j) = result.second.hessian(i, j);
      }
    };
    // In as few directions as the stencil needs (a Hessian costs their square): a rod edge
    // with a face (10: the frisbee's and the toy tunnel's rims), a rod or face on each side (12),
    // a hinge (18). The forces too, which every line-search trial evaluates.
    if (hessian && n <= 10)
      differentiate(detail::Jet<10, true>{});
    else if (hessian && n <= 12)
      differentiate(detail::Jet<12, true>{});
    else if (hessian)
      differentiate(detail::Jet<edge_max_dofs, true>{});
    else if (n <= 10)
      differentiate(detail::Jet<10, false>{});
    else if (n <= 12)
      differentiate(detail::Jet<12, false>{});
    else
      differentiate(detail::Jet<edge_max_dofs, false>{});
  } else {
    finish(run(q));
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
