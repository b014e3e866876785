#pragma once
// Shared helpers of the solver-layer tests (test_solve.cpp, and test_solve_mpi.cpp on several
// MPI ranks): the filtered systems every backend solves and an independent reference answer.

#include <cmath>
#include <cstdint>
#include <memory>
#include <random>
#include <vector>

#include <Eigen/SparseCholesky>
#include <doctest/doctest.h>

#include "helpers.hpp"
#include "sewn/physics/mss_model.hpp"
#include "sewn/physics/physics.hpp"

namespace sewn::physics::test::solve_helpers {

struct Problem {
  std::vector<double> b, x0, free_dof, mass;
};

// An independent reference: the filtered matrix S A S + (I - S) in Eigen, factored by Eigen.
inline Eigen::VectorXd reference_solve(const BlockMatrix& A, const Problem& p) {
  const Eigen::Index n3 = 3 * Eigen::Index{A.size()};
  const Eigen::SparseMatrix<double> M = A.to_sparse();
  Eigen::VectorXd xt(n3), f(n3), b(n3);
  for (Eigen::Index k = 0; k < n3; ++k) {
    f[k] = p.free_dof[k];
    xt[k] = f[k] == 0 ? p.x0[k] : 0.0;
    b[k] = p.b[k];
  }
  Eigen::SparseMatrix<double> K = f.asDiagonal() * M * f.asDiagonal();
  for (Eigen::Index k = 0; k < n3; ++k)
    if (f[k] == 0) K.coeffRef(k, k) = 1.0;
  const Eigen::VectorXd rhs = f.asDiagonal() * (b - M * xt);
  Eigen::SimplicialLDLT<Eigen::SparseMatrix<double>> ldlt(K);
  REQUIRE(ldlt.info() == Eigen::Success);
  return xt + f.asDiagonal() * ldlt.solve(rhs);
}

// ‖S(b - Ax)‖ / ‖Sb‖, computed here from the matrix's Eigen copy.
inline double relative_residual(const BlockMatrix& A, const Problem& p, const std::vector<double>& x) {
  const Eigen::Index n3 = 3 * Eigen::Index{A.size()};
  const Eigen::VectorXd ax = A.to_sparse() * Eigen::Map<const Eigen::VectorXd>(x.data(), n3);
  double rr = 0, bb = 0;
  for (Eigen::Index k = 0; k < n3; ++k) {
    const double r = p.free_dof[k] * (p.b[k] - ax[k]);
    rr += r * r;
    bb += p.free_dof[k] * p.b[k] * p.b[k];
  }
  return std::sqrt(rr / bb);
}

// The implicit-Euler matrix M - h ∂F/∂V - h² ∂F/∂P of the model at its current state.
inline void assemble(System& sys, double h) {
  sys.refresh();
  BlockMatrix& A = sys.matrix();
  A.set_zero();
  JacobianRequest req;
  req.matrix = &A;
  req.cx = -h * h;
  req.cv = -h;
  sys.add_jacobians(req);
  for (Index i = 0; i < sys.nodes().size(); ++i) A.block(A.diagonal(i)).diagonal().array() += sys.nodes().mass(i);
}

inline Problem random_problem(const BlockMatrix& A, const NodeTable* nodes, double fixed_fraction, unsigned seed) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> u(-1, 1), u01(0, 1);
  const std::size_t n3 = 3 * std::size_t{A.size()};
  Problem p{std::vector<double>(n3), std::vector<double>(n3), std::vector<double>(n3, 1.0), std::vector<double>(n3, 1.0)};
  for (std::size_t k = 0; k < n3; ++k) {
    p.b[k] = u(rng);
    if (nodes && ((nodes->fixed(Index(k / 3)) >> (k % 3)) & 1u)) p.free_dof[k] = 0.0;
    if (u01(rng) < fixed_fraction) p.free_dof[k] = 0.0;
    p.x0[k] = p.free_dof[k] == 0.0 ? u(rng) : 0.0;  // prescribed values on fixed axes
    if (nodes) p.mass[k] = nodes->mass(Index(k / 3));
  }
  return p;
}

// Random symmetric values on A's pattern, SPD by block diagonal dominance.
inline void random_spd_values(BlockMatrix& A, std::mt19937& rng, double diagonal_shift = 1.0) {
  const Index n = A.size();
  std::uniform_real_distribution<double> u(-1, 1);
  std::vector<double> rowsum(3 * std::size_t{n}, 0.0);
  for (Index i = 0; i < n; ++i) {
    const auto rows = A.row_offsets();
    for (Index k = rows[i]; k < rows[i + 1]; ++k) {
      const Index j = A.columns()[k];
      if (j <= i) continue;
      Eigen::Matrix3d G;
      for (int e = 0; e < 9; ++e) G.data()[e] = u(rng);
      A.block(k) = G;
      A.block(A.find(j, i)) = G.transpose();
      for (int a = 0; a < 3; ++a) {
        rowsum[3 * i + a] += G.row(a).cwiseAbs().sum();
        rowsum[3 * j + a] += G.col(a).cwiseAbs().sum();
      }
    }
  }
  for (Index i = 0; i < n; ++i) {
    Eigen::Matrix3d R;
    for (int e = 0; e < 9; ++e) R.data()[e] = u(rng);
    Eigen::Matrix3d D = 0.1 * R * R.transpose();
    for (int a = 0; a < 3; ++a) D(a, a) += rowsum[3 * i + a] + D.row(a).cwiseAbs().sum() + diagonal_shift;
    A.block(A.diagonal(i)) = D;
  }
}

// A random symmetric block matrix on a random pattern, SPD by block diagonal dominance.
inline void random_spd(BlockMatrix& A, Index n, unsigned seed, double diagonal_shift = 1.0) {
  std::mt19937 rng(seed);
  std::uniform_int_distribution<Index> node(0, n - 1);
  std::vector<NodePair> pairs;
  for (Index k = 0; k < 4 * n; ++k) {
    const Index i = node(rng), j = node(rng);
    if (i != j) pairs.push_back({i, j});
  }
  A.build_pattern(n, pairs);
  random_spd_values(A, rng, diagonal_shift);
}

// The SOFA comparison's beam (891 particles), clamped at its base.
// nx × ny × nz cubes of side a, the paper's material, the nodes at coordinate 0 on `axis` fixed.
inline std::unique_ptr<MssModel<3>> clamped_hex_grid(std::uint32_t nx, std::uint32_t ny, std::uint32_t nz, double a, int axis) {
  auto m = std::make_unique<MssModel<3>>(hex_grid(nx, ny, nz, {{a, a, a}, {}}), std::vector<MaterialParams>{paper_material},
                                         std::vector<std::uint32_t>{});
  for (Index i = 0; i < m->nodes().size(); ++i)
    if (m->rest_position(i)[axis] <= 1e-12) m->nodes().fix(i);
  return m;
}

inline std::unique_ptr<MssModel<3>> beam_8x8x10() { return clamped_hex_grid(8, 8, 10, 0.0125, 2); }

}  // namespace sewn::physics::test::solve_helpers
