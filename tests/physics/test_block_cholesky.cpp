// BlockCholesky (physics/solve/block_cholesky.hpp), the supernodal 3×3-block LLᵀ the direct
// backend uses on small and medium matrices: its solves against independent factorizations of
// the filtered matrix (Eigen's sparse LDLᵀ and dense LLᵀ) on random sparse matrices, chains
// (one pivot per supernode, no fill), cliques (one dense panel) and meshes mixing them;
// indefinite and NaN pivots named in either kernel; new patterns.
#include <doctest/doctest.h>

#include <cmath>
#include <random>
#include <string>
#include <vector>

#include <Eigen/Cholesky>

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

// The filtered matrix K = S A S + (I - S) (a free axis with a zero diagonal also 1) as a dense
// matrix, x = x̃ + S K⁻¹ S(b - A x̃) by Eigen's dense LLᵀ.
Eigen::VectorXd dense_reference(const BlockMatrix& A, const Problem& p) {
  const Eigen::Index n3 = 3 * Eigen::Index{A.size()};
  const Eigen::MatrixXd M = Eigen::MatrixXd(A.to_sparse());
  const Eigen::VectorXd f = Eigen::Map<const Eigen::VectorXd>(p.free_dof.data(), n3);
  Eigen::VectorXd xt(n3);
  for (Eigen::Index k = 0; k < n3; ++k) xt[k] = f[k] == 0 ? p.x0[static_cast<std::size_t>(k)] : 0.0;
  Eigen::MatrixXd K = f.asDiagonal() * M * f.asDiagonal();
  for (Eigen::Index k = 0; k < n3; ++k)
    if (K(k, k) == 0.0) K(k, k) = 1.0;
  const Eigen::VectorXd rhs = f.asDiagonal() * (Eigen::Map<const Eigen::VectorXd>(p.b.data(), n3) - M * xt);
  const Eigen::LLT<Eigen::MatrixXd> llt(K);
  REQUIRE(llt.info() == Eigen::Success);
  return xt + f.asDiagonal() * llt.solve(rhs);
}

// x against the sparse reference, its residual, and the fixed axes' prescribed values.
void check_solution(const BlockMatrix& A, const Problem& p, const std::vector<double>& x) {
  CHECK(max_difference(x, reference_solve(A, p)) < 1e-12);
  CHECK(relative_residual(A, p, x) < 1e-13);
  for (std::size_t k = 0; k < x.size(); ++k)
    if (p.free_dof[k] == 0.0) REQUIRE(x[k] == p.x0[k]);
}

// The factorization of A for p is refused as not positive definite at `where` ("node N, axis a").
void check_refused(solve::BlockCholesky& f, const BlockMatrix& A, const Problem& p, const std::string& where) {
  try {
    (void)block_solve(f, A, p);
    FAIL("a matrix that is not positive definite was factored");
  } catch (const SolverError& e) {
    const std::string what = e.what();
    CHECK(what.find("test: the matrix is not positive definite on the free axes") != std::string::npos);
    CHECK(what.find("failed at " + where + ")") != std::string::npos);
  }
}

// Node pairs: all of nodes [first, first + count) coupled with each other.
void clique(std::vector<NodePair>& pairs, Index first, Index count) {
  for (Index i = first; i < first + count; ++i)
    for (Index j = i + 1; j < first + count; ++j) pairs.push_back({i, j});
}

// Mesh-like patterns on n nodes, random SPD values: shape 0 a clique of half the nodes with
// a chain hanging off it; 1 two cliques joined through one node (a wide supernode updating a
// one-pivot one, then a wide one again); 2 a clique plus random couplings.
void shaped_spd(BlockMatrix& A, Index n, int shape, unsigned seed) {
  std::mt19937 rng(seed);
  std::vector<NodePair> pairs;
  const Index half = n / 2;
  if (shape == 0) {
    clique(pairs, 0, half);
    for (Index i = half; i < n; ++i) pairs.push_back({i - 1, i});
  } else if (shape == 1) {
    clique(pairs, 0, half);
    for (Index i = 0; i < half; ++i) pairs.push_back({i, half});
    pairs.push_back({half, half + 1});
    clique(pairs, half + 1, n - half - 1);
  } else {
    clique(pairs, 0, half);
    std::uniform_int_distribution<Index> node(0, n - 1);
    for (Index k = 0; k < 2 * n; ++k)
      if (const Index i = node(rng), j = node(rng); i != j) pairs.push_back({i, j});
  }
  A.build_pattern(n, pairs);
  random_spd_values(A, rng);
}

// n nodes all coupled, random SPD values.
void dense_spd(BlockMatrix& A, Index n, unsigned seed) {
  std::vector<NodePair> pairs;
  clique(pairs, 0, n);
  A.build_pattern(n, pairs);
  std::mt19937 rng(seed);
  random_spd_values(A, rng);
}

}  // namespace

TEST_CASE("block cholesky: supernodes on cliques, chains and random couplings, with fixed axes, solve as Eigen's dense LLᵀ") {
  solve::BlockCholesky f;
  for (unsigned seed = 1; seed <= 9; ++seed) {
    const int shape = static_cast<int>(seed % 3);
    const Index n = 20 + 7 * seed;
    CAPTURE(seed);
    CAPTURE(shape);
    BlockMatrix A;
    shaped_spd(A, n, shape, seed);
    const Problem p = random_problem(A, nullptr, seed % 2 ? 0.0 : 0.25, seed + 70);
    const std::vector<double> x = block_solve(f, A, p);
    CHECK(f.supernodes() < A.size());  // some pivots share a dense panel
    CHECK(max_difference(x, dense_reference(A, p)) < 1e-12);
    check_solution(A, p, x);
  }
}

TEST_CASE("block cholesky's single-precision solves: within float's rounding of the double ones; double where float cannot hold the factor") {
  for (unsigned seed = 1; seed <= 6; ++seed) {
    CAPTURE(seed);
    BlockMatrix A;
    shaped_spd(A, 30 + 5 * seed, static_cast<int>(seed % 3), seed);  // dense panels and one-pivot ones
    const Problem p = random_problem(A, nullptr, seed % 2 ? 0.0 : 0.25, seed + 90);
    solve::BlockCholesky exact, single;
    single.set_single_solves(true);
    const std::vector<double> x = block_solve(exact, A, p), y = block_solve(single, A, p);
    CHECK_FALSE(exact.single_solves());
    CHECK(single.single_solves());
    CHECK(x != y);  // the float panels were used
    // the factor's entries rounded to float (2^-24 relative): a small multiple of that in x
    CHECK(max_difference(y, reference_solve(A, p)) < 1e-5);
    for (std::size_t k = 0; k < y.size(); ++k)
      if (p.free_dof[k] == 0.0) REQUIRE(y[k] == p.x0[k]);
    // In extreme units (entries ~1e±90, the factor's ~1e±45) float overflows or loses its
    // normal range: the solves stay in double, exact, not infinite or NaN.
    for (double scale : {1e90, 1e-90}) {
      CAPTURE(scale);
      BlockMatrix B = A;
      for (Index k = 0; k < B.num_blocks(); ++k) B.block(k) *= scale;
      Problem q = p;
      for (double& v : q.b) v *= scale;
      const std::vector<double> z = block_solve(single, B, q);
      CHECK_FALSE(single.single_solves());
      check_solution(B, q, z);
    }
  }
}

TEST_CASE("block cholesky: a clique is one dense panel, with a dense factor's entries and flops") {
  BlockMatrix A;
  const Index n = 12;
  dense_spd(A, n, 5);
  solve::BlockCholesky f;
  const Problem p = random_problem(A, nullptr, 0.1, 6);
  CHECK(max_difference(block_solve(f, A, p), dense_reference(A, p)) < 1e-13);
  CHECK(f.supernodes() == 1);
  CHECK(f.factor_entries() == 6.0 * n + 9.0 * n * (n - 1) / 2);
  CHECK(f.stored_entries() == 9.0 * n * n);  // one column-major panel, its upper triangle unused
  double flops = 0;  // scalar column k of 3n: (3n - k)² counting the diagonal
  for (int k = 1; k <= 3 * static_cast<int>(n); ++k) flops += static_cast<double>(k) * k;
  CHECK(f.flops() == flops);
}

TEST_CASE("block cholesky: a zero-diagonal free axis inside a dense panel is solved as the identity") {
  BlockMatrix A;
  shaped_spd(A, 24, 0, 11);
  // node 5 of the clique loses its couplings and mass: its row and column are zero
  const auto rows = A.row_offsets();
  for (Index k = rows[5]; k < rows[6]; ++k) {
    const Index j = A.columns()[k];
    A.block(k).setZero();
    A.block(A.find(j, 5)).setZero();
  }
  const Problem p = random_problem(A, nullptr, 0.0, 12);
  solve::BlockCholesky f;
  const std::vector<double> x = block_solve(f, A, p);
  CHECK(f.supernodes() < A.size());
  CHECK(max_difference(x, dense_reference(A, p)) < 1e-12);
}

TEST_CASE("block cholesky: the dense kernel names the indefinite pivot's node and axis; a NaN fails too") {
  BlockMatrix A;
  dense_spd(A, 16, 8);
  A.block(A.diagonal(9))(2, 2) = -1e4;  // no Schur complement before its pivot makes it positive
  Problem p = random_problem(A, nullptr, 0.0, 9);
  solve::BlockCholesky f;
  check_refused(f, A, p, "node 9, axis z");
  CHECK(f.supernodes() == 1);
  p.free_dof[3 * 9 + 2] = 0.0;  // that axis fixed: nothing indefinite left
  CHECK(relative_residual(A, p, block_solve(f, A, p)) < 1e-13);
  A.block(A.diagonal(9))(2, 2) = 1e4;
  A.block(A.diagonal(4))(0, 0) = std::nan("");
  check_refused(f, A, random_problem(A, nullptr, 0.0, 10), "node 4, axis x");
}

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
    check_solution(A, p, x);
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
  check_refused(f, A, p, "node 17, axis y");
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
