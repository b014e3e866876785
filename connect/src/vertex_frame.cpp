#include "vertex_frame.hpp"

#include <cmath>
#include <vector>

#include "jet.hpp"

namespace sewn::connect::detail {

namespace {

// αi hat(a × b): triangle (x0, xi, xi+1)'s unit normal weighted by its angle at the joint.
template <class T>
V3<T> weighted_normal(const V3<T>& a, const V3<T>& b) {
  using std::atan2;
  using std::sqrt;
  const V3<T> c = cross(a, b);
  const T s = sqrt(dot(c, c));
  return (atan2(s, dot(a, b)) / s) * c;
}

// {m1, m3} from the vertex normal's sum w and the first ring edge e.
template <class T>
std::array<V3<T>, 2> frame_of(const V3<T>& w, const V3<T>& e, double sign) {
  const V3<T> n = normalized(w);
  const V3<T> u = e - dot(e, n) * n;
  return {normalized(u), T(sign) * n};
}

V3<double> edge(const Eigen::VectorXd& q, int at, int i) {
  return vec_at<double>(q, at + 3 * (i + 1)) - vec_at<double>(q, at);
}

template <class J6>
V3<J6> jet_vec(const std::array<J6, 6>& a, int first) {
  return {a[static_cast<std::size_t>(first)], a[static_cast<std::size_t>(first + 1)], a[static_cast<std::size_t>(first + 2)]};
}

// Six independent variables: two 3-vectors.
template <class J6>
std::array<J6, 6> variables(const V3<double>& a, const V3<double>& b) {
  return {J6::variable(a.x, 0), J6::variable(a.y, 1), J6::variable(a.z, 2),
          J6::variable(b.x, 3), J6::variable(b.y, 4), J6::variable(b.z, 5)};
}

// The DOFs (x0, x1..xv) map to the edges by e_i = x_i − x0, L = [−S I] with S (3v × 3) the
// stacked 3×3 identities: a derivative over the edges becomes one over the DOFs by Lᵀ on each
// side. By its structure, in O(v²) rather than dense products' O(v³) (the toy ball's foot
// joint, a ring of the platform's 6 triangles, spent 5 % of a Newton step in those products).
Eigen::RowVectorXd edges_to_dofs_row(const Eigen::RowVectorXd& r) {
  const Eigen::Index ne = r.size();
  Eigen::RowVectorXd out(ne + 3);
  out.head<3>().setZero();
  for (Eigen::Index k = 0; k < ne; ++k) out[k % 3] -= r[k];
  out.tail(ne) = r;
  return out;
}
Eigen::MatrixXd edges_to_dofs(const Eigen::MatrixXd& he) {
  const Eigen::Index ne = he.rows();
  Eigen::MatrixXd out(ne + 3, ne + 3);
  out.bottomRightCorner(ne, ne) = he;
  Eigen::MatrixXd hs = Eigen::MatrixXd::Zero(ne, 3), sh = Eigen::MatrixXd::Zero(3, ne);  // he S, Sᵀ he
  for (Eigen::Index k = 0; k < ne; ++k) {
    hs.col(k % 3) += he.col(k);
    sh.row(k % 3) += he.row(k);
  }
  Eigen::Matrix3d shs = Eigen::Matrix3d::Zero();  // Sᵀ he S
  for (Eigen::Index k = 0; k < ne; ++k) shs.row(k % 3) += hs.row(k);
  out.topLeftCorner<3, 3>() = shs;
  out.bottomLeftCorner(ne, 3) = -hs;
  out.topRightCorner(3, ne) = -sh;
  return out;
}

template <bool H>
FrameJet frame_jet(const Eigen::VectorXd& q, int at, int ring, double sign) {
  using J6 = Jet<6, H>;
  // Derivatives over the ring edges e (3·ring) first, mapped to the DOFs (x0, ring) at the end.
  const Eigen::Index ne = 3 * ring;
  V3<double> w{0, 0, 0};
  Eigen::MatrixXd wj = Eigen::MatrixXd::Zero(3, ne);
  std::array<Eigen::MatrixXd, 3> wh;
  if constexpr (H)
    for (auto& m : wh) m = Eigen::MatrixXd::Zero(ne, ne);
  for (int i = 0; i < ring; ++i) {
    const int j = (i + 1) % ring;
    const auto a = variables<J6>(edge(q, at, i), edge(q, at, j));
    const V3<J6> c = weighted_normal(jet_vec(a, 0), jet_vec(a, 3));
    const std::array<const J6*, 3> comp{&c.x, &c.y, &c.z};
    const std::array<Eigen::Index, 6> col{3 * i, 3 * i + 1, 3 * i + 2, 3 * j, 3 * j + 1, 3 * j + 2};
    w = w + V3<double>{c.x.v, c.y.v, c.z.v};
    for (std::size_t r = 0; r < 3; ++r)
      for (int k = 0; k < 6; ++k) {
        wj(static_cast<Eigen::Index>(r), col[static_cast<std::size_t>(k)]) += comp[r]->g[static_cast<std::size_t>(k)];
        if constexpr (H)
          for (int l = 0; l < 6; ++l)
            wh[r](col[static_cast<std::size_t>(k)], col[static_cast<std::size_t>(l)]) += comp[r]->hessian(k, l);
      }
  }
  // The frame as a function of u = (w, e1): its jets, chained through u's derivatives.
  const auto u = variables<J6>(w, edge(q, at, 0));
  const auto f = frame_of(jet_vec(u, 0), jet_vec(u, 3), sign);
  const std::array<const J6*, 6> out{&f[0].x, &f[0].y, &f[0].z, &f[1].x, &f[1].y, &f[1].z};
  Eigen::MatrixXd uj = Eigen::MatrixXd::Zero(6, ne);
  uj.topRows(3) = wj;
  uj.block(3, 0, 3, 3).setIdentity();
  FrameJet jet;
  jet.jacobian.resize(6, ne + 3);
  for (std::size_t k = 0; k < 6; ++k) {
    const J6& v = *out[k];
    Eigen::Matrix<double, 1, 6> g;
    for (int a = 0; a < 6; ++a) g[a] = v.g[static_cast<std::size_t>(a)];
    jet.value[static_cast<Eigen::Index>(k)] = v.v;
    jet.jacobian.row(static_cast<Eigen::Index>(k)) = edges_to_dofs_row(g * uj);
    if constexpr (H) {
      Eigen::Matrix<double, 6, 6> h;
      for (int a = 0; a < 6; ++a)
        for (int b = 0; b < 6; ++b) h(a, b) = v.hessian(a, b);
      Eigen::MatrixXd he = uj.transpose() * h * uj;
      for (std::size_t r = 0; r < 3; ++r) he += g[static_cast<Eigen::Index>(r)] * wh[r];
      jet.hessian[k] = edges_to_dofs(he);
    }
  }
  return jet;
}

}  // namespace

std::array<Eigen::Vector3d, 2> vertex_frame(const Eigen::VectorXd& q, int at, int ring, double sign) {
  V3<double> w{0, 0, 0};
  for (int i = 0; i < ring; ++i) w = w + weighted_normal(edge(q, at, i), edge(q, at, (i + 1) % ring));
  const auto f = frame_of(w, edge(q, at, 0), sign);
  return {Eigen::Vector3d(f[0].x, f[0].y, f[0].z), Eigen::Vector3d(f[1].x, f[1].y, f[1].z)};
}

FrameJet vertex_frame_jet(const Eigen::VectorXd& q, int at, int ring, double sign, bool second_order) {
  return second_order ? frame_jet<true>(q, at, ring, sign) : frame_jet<false>(q, at, ring, sign);
}

}  // namespace sewn::connect::detail
