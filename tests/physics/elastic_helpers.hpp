#pragma once
// Meshes and checks shared by the elastic tests: a box of Kuhn tetrahedra, a triangulated
// rectangle, random rotations and central finite differences of element energies.

#include <array>
#include <cmath>
#include <functional>
#include <random>
#include <vector>

#include <doctest/doctest.h>

#include <Eigen/Dense>
#include <Eigen/Geometry>

#include "sewn/physics/solids/tets.hpp"
#include "sewn/physics/system.hpp"

namespace sewn::physics::test {

struct TetMesh {
  std::vector<Eigen::Vector3d> x;
  std::vector<std::array<std::uint32_t, 4>> tets;
  std::uint32_t index(int i, int j, int k, int nx, int ny) const {
    return static_cast<std::uint32_t>(i + (nx + 1) * (j + (ny + 1) * k));
  }
};

/// nx×ny×nz cubes of size lx×ly×lz split into 6 tetrahedra each around the main diagonal.
inline TetMesh kuhn_box(int nx, int ny, int nz, double lx, double ly, double lz) {
  TetMesh m;
  for (int k = 0; k <= nz; ++k)
    for (int j = 0; j <= ny; ++j)
      for (int i = 0; i <= nx; ++i) m.x.emplace_back(lx * i / nx, ly * j / ny, lz * k / nz);
  static const int path[6][3] = {{0, 1, 2}, {0, 2, 1}, {1, 0, 2}, {1, 2, 0}, {2, 0, 1}, {2, 1, 0}};
  for (int k = 0; k < nz; ++k)
    for (int j = 0; j < ny; ++j)
      for (int i = 0; i < nx; ++i)
        for (const auto& p : path) {
          int c[3] = {i, j, k};
          std::array<std::uint32_t, 4> t;
          t[0] = m.index(c[0], c[1], c[2], nx, ny);
          for (int s = 0; s < 3; ++s) {
            ++c[p[s]];
            t[s + 1] = m.index(c[0], c[1], c[2], nx, ny);
          }
          m.tets.push_back(t);
        }
  return m;
}

struct TriMesh {
  std::vector<Eigen::Vector3d> x;
  std::vector<std::array<std::uint32_t, 3>> tris;
};

/// nx×ny rectangles of the lx×ly rectangle in the z = 0 plane, each split along a diagonal
/// (alternating when `alternate`), all triangles counter-clockwise seen from +z.
inline TriMesh tri_rectangle(int nx, int ny, double lx, double ly, bool alternate) {
  TriMesh m;
  for (int j = 0; j <= ny; ++j)
    for (int i = 0; i <= nx; ++i) m.x.emplace_back(lx * i / nx, ly * j / ny, 0.0);
  auto id = [&](int i, int j) { return static_cast<std::uint32_t>(i + (nx + 1) * j); };
  for (int j = 0; j < ny; ++j)
    for (int i = 0; i < nx; ++i) {
      const auto a = id(i, j), b = id(i + 1, j), c = id(i + 1, j + 1), d = id(i, j + 1);
      if (alternate && (i + j) % 2 == 1) {
        m.tris.push_back({a, b, d});
        m.tris.push_back({b, c, d});
      } else {
        m.tris.push_back({a, b, c});
        m.tris.push_back({a, c, d});
      }
    }
  return m;
}

inline Eigen::Matrix3d random_rotation(std::mt19937& rng) {
  std::normal_distribution<double> n(0.0, 1.0);
  Eigen::Quaterniond q(n(rng), n(rng), n(rng), n(rng));
  return q.normalized().toRotationMatrix();
}

/// Central-difference gradient of f over the entries of x (column-major).
template <class M>
Eigen::VectorXd fd_gradient(const std::function<double(const M&)>& f, M x, double delta) {
  Eigen::VectorXd g(x.size());
  for (Eigen::Index k = 0; k < x.size(); ++k) {
    const double keep = x.data()[k];
    x.data()[k] = keep + delta;
    const double fp = f(x);
    x.data()[k] = keep - delta;
    const double fm = f(x);
    x.data()[k] = keep;
    g[k] = (fp - fm) / (2 * delta);
  }
  return g;
}

/// Central-difference Jacobian of a vector function (column k: derivative along entry k).
template <class M>
Eigen::MatrixXd fd_jacobian(const std::function<Eigen::VectorXd(const M&)>& f, M x, double delta) {
  Eigen::MatrixXd J(x.size(), x.size());
  for (Eigen::Index k = 0; k < x.size(); ++k) {
    const double keep = x.data()[k];
    x.data()[k] = keep + delta;
    const Eigen::VectorXd fp = f(x);
    x.data()[k] = keep - delta;
    const Eigen::VectorXd fm = f(x);
    x.data()[k] = keep;
    J.col(k) = (fp - fm) / (2 * delta);
  }
  return J;
}

/// ‖a - b‖∞ / ‖b‖∞ (b nonzero in every use).
inline double rel_err(const Eigen::MatrixXd& a, const Eigen::MatrixXd& b) {
  return (a - b).cwiseAbs().maxCoeff() / b.cwiseAbs().maxCoeff();
}

/// Σ_i g_i and Σ_i x_i × g_i of a stencil gradient (node-major), the net force and torque.
template <int N>
std::pair<Eigen::Vector3d, Eigen::Vector3d> net_force_torque(const Eigen::Matrix<double, 3, N>& x,
                                                             const Eigen::Matrix<double, 3 * N, 1>& g) {
  Eigen::Vector3d f = Eigen::Vector3d::Zero(), t = Eigen::Vector3d::Zero();
  for (int a = 0; a < N; ++a) {
    const Eigen::Vector3d ga = g.template segment<3>(3 * a);
    f += ga;
    t += x.col(a).cross(ga);
  }
  return {f, t};
}

// Checks one element at x: gradient vs FD of the energy, Hessian vs FD of the gradient, net
// force and torque zero; returns the FD errors for the caller's message.
template <int N>
void check_element(const std::function<double(const Eigen::Matrix<double, 3, N>&)>& E,
                   const std::function<Eigen::Matrix<double, 3 * N, 1>(const Eigen::Matrix<double, 3, N>&)>& G,
                   const std::function<Eigen::Matrix<double, 3 * N, 3 * N>(const Eigen::Matrix<double, 3, N>&)>& H,
                   const Eigen::Matrix<double, 3, N>& x, double delta, double tol) {
  using P = Eigen::Matrix<double, 3, N>;
  const Eigen::VectorXd g = G(x);
  const Eigen::VectorXd g_fd = fd_gradient<P>(E, x, delta);
  const Eigen::MatrixXd h = H(x);
  const Eigen::MatrixXd h_fd = fd_jacobian<P>([&](const P& y) { return Eigen::VectorXd(G(y)); }, x, delta);
  CAPTURE(g.transpose());
  CAPTURE(g_fd.transpose());
  CHECK(rel_err(g, g_fd) < tol);
  CHECK(rel_err(h, h_fd) < tol);
  CHECK((h - h.transpose()).cwiseAbs().maxCoeff() <= 1e-12 * h.cwiseAbs().maxCoeff());
  const auto [f, t] = net_force_torque<N>(x, G(x));
  const double scale = g.cwiseAbs().maxCoeff() * (1.0 + x.cwiseAbs().maxCoeff());
  CHECK(f.norm() <= 1e-12 * scale);
  CHECK(t.norm() <= 1e-12 * scale);
}

/// Adds m's nodes (lumped masses of density rho) and its tetrahedra to sys as one Tets term.
inline solids::Tets& add_tets(System& sys, const TetMesh& m, solids::TetLaw law, double E, double nu, double rho) {
  const Index first = sys.nodes().size();
  std::vector<double> mass(m.x.size(), 0.0);
  for (const auto& t : m.tets) {
    const double v = std::abs((m.x[t[1]] - m.x[t[0]]).cross(m.x[t[2]] - m.x[t[0]]).dot(m.x[t[3]] - m.x[t[0]])) / 6.0;
    for (auto i : t) mass[i] += rho * v / 4.0;
  }
  for (std::size_t i = 0; i < m.x.size(); ++i) sys.nodes().add(m.x[i], Eigen::Vector3d::Zero(), mass[i]);
  auto& tets = sys.add<solids::Tets>(law);
  for (const auto& t : m.tets) {
    solids::TetPositions X;
    for (int a = 0; a < 4; ++a) X.col(a) = m.x[t[a]];
    tets.add({first + t[0], first + t[1], first + t[2], first + t[3]}, X, E, nu);
  }
  return tets;
}

}  // namespace sewn::physics::test
