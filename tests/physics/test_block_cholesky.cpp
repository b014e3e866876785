// BlockCholesky (physics/solve/block_cholesky.hpp), the 3×3-block LLᵀ the direct backend uses on
// small and very sparse matrices: its solves against an independent factorization of the
// filtered matrix, its structure on a chain (no fill), indefinite matrices, new patterns.
#include <doctest/doctest.h>

#include <cmath>
#include <string>
#include <vector>

#include "solve_helpers.hpp"
#include "sewn/physics/errors.hpp"
#include "sewn/physics/solve/block_cholesky.hpp"

namespace test_block_cholesky {

using namespace sewn;
using namespace sewn::physics;

namespace {

using namespace sewn::physics::test::solve_helpers;

// x = x̃ + S K⁻¹ S(b - A x̃) by the block factorization (x̃: p.x0 on the fixed axes, else 0):
// what the reference solves, built the same way as the direct backend builds it.
std::vector<double> block_solve(solve::BlockCholesky& f, const BlockMatrix& A, const Problem& p) {
  const std::size_t n3 = p.b.size();
  std::vector<double> xt(n3), ax(n3), r(n3);
  for (std::size_t k = 0; k < n3; ++k) xt[k] = p.free_dof[k] == 0.0 ? p.x0[k] : 0.0;
  A.multiply(xt, ax);
  for (std::size_t k = 0; k < n3; ++k) r[k] = p.free_dof[k] * (p.b[k] - ax[k]);
  f.factorize(A, p.free_dof, "test");
  f.solve(r, r);
  for (std::size_t k = 0; k < n3; ++k) xt[k] += p.free_dof[k] * r[k];
  return xt;
}

double max_difference(const std::vector<double>& x, const Eigen::VectorXd& ref) {
  double d = 0;
  for (std::size_t k = 0; k < x.size(); ++k) d = std::max(d, std::abs(x[k] - ref[static_cast<Eigen::Index>(k)]));
  return d / ref.cwiseAbs().maxCoeff();
}

// A chain of n nodes: blocks (i, i+1) only, SPD by diagonal dominance.
void chain(BlockMatrix& A, Index n) {
  std::vector<NodePair> pairs;
  for (Index i = 0; i + 1 < n; ++i) pairs.push_back({i, i + 1});
  A.build_pattern(n, pairs);
  for (Index i = 0; i + 1 < n; ++i) {
    Eigen::Matrix3d G;
    G << 1, 0.5, 0, -0.25, 1, 0.1, 0, 0.3, -1;
    A.block(A.find(i, i + 1)) = G;
    A.block(A.find(i + 1, i)) = G.transpose();
  }
  for (Index i = 0; i < n; ++i) A.block(A.diagonal(i)) = Eigen::Vector3d(6, 7, 8).asDiagonal();
}

}  // namespace

TEST_CASE("block cholesky solves random SPD block matrices with fixed axes as the reference factorization does") {
  solve::BlockCholesky f;  // one object across patterns: each new one analysed afresh
  for (unsigned seed = 1; seed <= 8; ++seed) {
    CAPTURE(seed);
    BlockMatrix A;
    random_spd(A, 20 + 37 * seed, seed);
    const Problem p = random_problem(A, nullptr, seed % 2 ? 0.0 : 0.2, seed + 50);
    CHECK(!f.analysed_for(A));
    const std::vector<double> x = block_solve(f, A, p);
    CHECK(f.analysed_for(A));
    CHECK(max_difference(x, reference_solve(A, p)) < 1e-12);
    CHECK(relative_residual(A, p, x) < 1e-13);
    for (std::size_t k = 0; k < x.size(); ++k)
      if (p.free_dof[k] == 0.0) REQUIRE(x[k] == p.x0[k]);
  }
}

TEST_CASE("block cholesky refactors new values and fixed axes on a kept analysis") {
  BlockMatrix A;
  random_spd(A, 150, 3);
  solve::BlockCholesky f;
  const Problem p0 = random_problem(A, nullptr, 0.0, 4);
  (void)block_solve(f, A, p0);
  const double flops = f.flops();
  for (Index k = 0; k < A.num_blocks(); ++k) A.block(k) *= 1.3;
  for (Index i = 0; i < A.size(); ++i) A.block(A.diagonal(i)) += Eigen::Matrix3d::Identity() * (3.0 + (i % 5));
  const Problem p1 = random_problem(A, nullptr, 0.3, 5);
  const std::vector<double> x = block_solve(f, A, p1);
  CHECK(f.analysed_for(A));
  CHECK(f.flops() == flops);  // the same analysis
  CHECK(max_difference(x, reference_solve(A, p1)) < 1e-12);
}

TEST_CASE("block cholesky on a chain: no fill, and the flops of a tridiagonal block factor") {
  BlockMatrix A;
  const Index n = 40;
  chain(A, n);
  solve::BlockCholesky f;
  const Problem p = random_problem(A, nullptr, 0.0, 1);
  const std::vector<double> x = block_solve(f, A, p);
  CHECK(max_difference(x, reference_solve(A, p)) < 1e-13);
  // a chain eliminated from its ends keeps L's pattern A's: n diagonal blocks, n - 1 below
  CHECK(f.factor_entries() == 6.0 * n + 9.0 * (n - 1));
  // per block column with one block below: scalar columns of 6, 5, 4 entries (diagonal
  // included), counted squared; the last column 3, 2, 1
  CHECK(f.flops() == (n - 1) * (36.0 + 25 + 16) + (9 + 4 + 1));
}

TEST_CASE("block cholesky: a free axis with nothing on its diagonal is solved as the identity, as CHOLMOD's backends do") {
  BlockMatrix A;
  chain(A, 12);
  // node 5 loses its springs and mass: its row and column are zero
  for (Index j : {4u, 6u}) {
    A.block(A.find(5, j)).setZero();
    A.block(A.find(j, 5)).setZero();
  }
  A.block(A.diagonal(5)).setZero();
  Problem p = random_problem(A, nullptr, 0.0, 2);
  solve::BlockCholesky f;
  const std::vector<double> x = block_solve(f, A, p);
  BlockMatrix B = A;
  B.block(B.diagonal(5)) = Eigen::Matrix3d::Identity();
  CHECK(max_difference(x, reference_solve(B, p)) < 1e-13);
}

TEST_CASE("block cholesky refuses an indefinite matrix naming the node and axis, unless that axis is fixed") {
  BlockMatrix A;
  chain(A, 30);
  A.block(A.diagonal(17))(1, 1) = -2.0;
  Problem p = random_problem(A, nullptr, 0.0, 3);
  solve::BlockCholesky f;
  try {
    (void)block_solve(f, A, p);
    FAIL("an indefinite matrix was factored");
  } catch (const SolverError& e) {
    const std::string what = e.what();
    CHECK(what.find("test: the matrix is not positive definite on the free axes") != std::string::npos);
    CHECK(what.find("failed at node 17, axis y") != std::string::npos);
  }
  // the same axis fixed: an identity row, nothing indefinite left
  p.free_dof[3 * 17 + 1] = 0.0;
  p.x0[3 * 17 + 1] = 0.5;
  const std::vector<double> x = block_solve(f, A, p);
  CHECK(x[3 * 17 + 1] == 0.5);
  CHECK(relative_residual(A, p, x) < 1e-13);
  // a NaN is no pivot either
  A.block(A.diagonal(3))(2, 2) = std::nan("");
  CHECK_THROWS_AS(block_solve(f, A, random_problem(A, nullptr, 0.0, 3)), SolverError);
}

TEST_CASE("block cholesky: an empty matrix and a single node") {
  BlockMatrix E;
  E.build_pattern(0, {});
  solve::BlockCholesky f;
  std::vector<double> none;
  f.factorize(E, none, "test");
  f.solve(none, none);
  CHECK(f.flops() == 0);
  BlockMatrix A;
  A.build_pattern(1, {});
  A.block(A.diagonal(0)) << 4, 1, 0, 1, 3, 0, 0, 0, 2;
  const Problem p = random_problem(A, nullptr, 0.0, 8);
  CHECK(max_difference(block_solve(f, A, p), reference_solve(A, p)) < 1e-15);
}

TEST_CASE("block cholesky: bad sizes are refused naming what") {
  BlockMatrix A;
  chain(A, 5);
  solve::BlockCholesky f;
  std::vector<double> free(14, 1.0), v(15, 1.0), w(14, 0.0);
  CHECK_THROWS_WITH_AS(f.factorize(A, free, "test"), doctest::Contains("14 free-axis flags for a matrix of 15 unknowns"), InputError);
  free.resize(15, 1.0);
  f.factorize(A, free, "test");
  CHECK_THROWS_WITH_AS(f.solve(v, w), doctest::Contains("for a factor of 15 unknowns"), InputError);
}

}  // namespace test_block_cholesky
