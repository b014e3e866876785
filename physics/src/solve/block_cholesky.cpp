#include "sewn/physics/solve/block_cholesky.hpp"

#include <algorithm>
#include <cmath>
#include <string>

#include <Eigen/OrderingMethods>

#include "sewn/physics/errors.hpp"

namespace sewn::physics::solve {

namespace {

using Block = Eigen::Map<Eigen::Matrix3d>;
using ConstBlock = Eigen::Map<const Eigen::Matrix3d>;
using Vec = Eigen::Map<Eigen::Vector3d>;

}  // namespace

void BlockCholesky::analyse(const BlockMatrix& A) {
  order(A);
  symbolic(A);
  pattern_ = A.pattern_version();
}

// AMD on the graph of A's blocks: on the 3×3-expanded pattern a node's three axes are
// indistinguishable (same neighbours), so the block graph loses nothing and is 9× smaller.
void BlockCholesky::order(const BlockMatrix& A) {
  const Index nb = A.size();
  const auto rows = A.row_offsets();
  const auto cols = A.columns();
  std::vector<Eigen::Triplet<double, int>> entries;
  entries.reserve(cols.size());
  for (Index i = 0; i < nb; ++i)
    for (Index k = rows[i]; k < rows[i + 1]; ++k) entries.emplace_back(static_cast<int>(cols[k]), static_cast<int>(i), 1.0);
  Eigen::SparseMatrix<double, Eigen::ColMajor, int> G(static_cast<int>(nb), static_cast<int>(nb));
  G.setFromTriplets(entries.begin(), entries.end());
  Eigen::PermutationMatrix<Eigen::Dynamic, Eigen::Dynamic, int> P;
  Eigen::AMDOrdering<int>()(G, P);
  // Eigen's convention (SimplicialCholesky): P.indices()[new] = old
  perm_.resize(nb);
  pinv_.resize(nb);
  for (Index j = 0; j < nb; ++j) {
    perm_[j] = static_cast<Index>(P.indices()[static_cast<int>(j)]);
    pinv_[perm_[j]] = j;
  }
}

// L's structure column by column in pivot order: column j holds A's lower entries of pivot j
// and, from each child c in the elimination tree (the columns whose first off-diagonal row is
// j), c's rows below j. Then the same blocks by row, for the left-looking updates.
void BlockCholesky::symbolic(const BlockMatrix& A) {
  const Index nb = A.size();
  const auto rows = A.row_offsets();
  const auto cols = A.columns();
  constexpr Index none = invalid_index;
  std::vector<Index> mark(nb, none), child_head(nb, none), next_child(nb, none);
  col_.assign(1, 0);
  row_.clear();
  a_col_.assign(1, 0);
  a_slot_.clear();
  a_row_.clear();
  flops_ = 0;
  for (Index j = 0; j < nb; ++j) {
    const Index c = perm_[j];
    const std::size_t start = row_.size();
    mark[j] = j;
    for (Index k = rows[c]; k < rows[c + 1]; ++k) {
      const Index i = pinv_[cols[k]];
      if (i < j) continue;
      a_slot_.push_back(A.find(cols[k], c));  // block (r, c): row r of column c
      a_row_.push_back(i);
      if (mark[i] != j) {
        mark[i] = j;
        row_.push_back(i);
      }
    }
    for (Index ch = child_head[j]; ch != none; ch = next_child[ch])
      for (std::size_t q = col_[ch]; q < col_[ch + 1]; ++q)
        if (const Index i = row_[q]; mark[i] != j) {
          mark[i] = j;
          row_.push_back(i);
        }
    std::sort(row_.begin() + static_cast<std::ptrdiff_t>(start), row_.end());
    col_.push_back(row_.size());
    a_col_.push_back(a_slot_.size());
    if (row_.size() > start) {
      const Index parent = row_[start];
      next_child[j] = child_head[parent];
      child_head[parent] = j;
    }
    // the scalar columns 3j, 3j+1, 3j+2: (entries below the diagonal + 1)², as CHOLMOD counts
    const double below = 3.0 * static_cast<double>(row_.size() - start);
    for (int a = 0; a < 3; ++a) flops_ += (below + 3.0 - a) * (below + 3.0 - a);
  }
  // by row: counting sort of the blocks on their row, columns ascending within a row
  by_row_.assign(nb + 1, 0);
  for (const Index i : row_) ++by_row_[i + 1];
  for (Index i = 0; i < nb; ++i) by_row_[i + 1] += by_row_[i];
  row_pos_.resize(row_.size());
  row_col_.resize(row_.size());
  std::vector<std::size_t> fill(by_row_.begin(), by_row_.end() - 1);
  for (Index k = 0; k < nb; ++k)
    for (std::size_t q = col_[k]; q < col_[k + 1]; ++q) {
      const std::size_t t = fill[row_[q]]++;
      row_pos_[t] = q;
      row_col_[t] = k;
    }
  lx_.assign(9 * row_.size(), 0.0);
  dinv_.assign(9 * std::size_t{nb}, 0.0);
  w_.assign(9 * std::size_t{nb}, 0.0);
  y_.assign(3 * std::size_t{nb}, 0.0);
}

void BlockCholesky::factorize(const BlockMatrix& A, std::span<const double> free_dof, const char* who) {
  if (free_dof.size() != 3 * std::size_t{A.size()})
    throw InputError(std::string(who) + ": " + std::to_string(free_dof.size()) + " free-axis flags for a matrix of " +
                     std::to_string(3 * std::size_t{A.size()}) + " unknowns");
  if (!analysed_for(A)) analyse(A);
  for (Index j = 0; j < A.size(); ++j) {
    scatter_column(A, free_dof, j);
    update_column(j);
    finish_column(j, who);
  }
}

// w_ = column j of K's lower triangle (permuted): free_r free_c A(r, c), zero diagonals 1.
void BlockCholesky::scatter_column(const BlockMatrix& A, std::span<const double> free_dof, Index j) {
  const std::size_t c = perm_[j];
  for (std::size_t e = a_col_[j]; e < a_col_[j + 1]; ++e) {
    const Index i = a_row_[e];
    const std::size_t r = perm_[i];
    const ConstBlock a = A.block(a_slot_[e]);
    Block w(w_.data() + 9 * std::size_t{i});
    for (int b = 0; b < 3; ++b)
      for (int x = 0; x < 3; ++x) {
        w(x, b) = free_dof[3 * r + static_cast<std::size_t>(x)] * free_dof[3 * c + static_cast<std::size_t>(b)] * a(x, b);
        if (i == j && x == b && w(x, b) == 0.0) w(x, b) = 1.0;
      }
  }
}

// w_ -= L(:, k) L(j, k)ᵀ for every earlier column k with a block in row j (left-looking).
void BlockCholesky::update_column(Index j) {
  for (std::size_t t = by_row_[j]; t < by_row_[j + 1]; ++t) {
    const std::size_t p = row_pos_[t], end = col_[std::size_t{row_col_[t]} + 1];  // rows from j down
    const Eigen::Matrix3d ljk_t = ConstBlock(lx_.data() + 9 * p).transpose();
    for (std::size_t q = p; q < end; ++q) Block(w_.data() + 9 * std::size_t{row_[q]}).noalias() -= ConstBlock(lx_.data() + 9 * q) * ljk_t;
  }
}

// The 3×3 Cholesky of the diagonal block, its inverse kept, and L(i, j) = w_(i) L(j, j)⁻ᵀ.
void BlockCholesky::finish_column(Index j, const char* who) {
  Block w(w_.data() + 9 * std::size_t{j});
  Eigen::Matrix3d l = Eigen::Matrix3d::Zero();
  for (int a = 0; a < 3; ++a) {
    double d = w(a, a);
    for (int b = 0; b < a; ++b) d -= l(a, b) * l(a, b);
    if (!(d > 0.0))  // also NaN
      throw SolverError(std::string(who) + ": the matrix is not positive definite on the free axes (Cholesky pivot " +
                            std::to_string(3 * std::size_t{j} + static_cast<std::size_t>(a)) + " of " +
                            std::to_string(3 * perm_.size()) + " failed at node " + std::to_string(perm_[j]) + ", axis " +
                            "xyz"[a] + ")",
                        0, 0);
    l(a, a) = std::sqrt(d);
    for (int r = a + 1; r < 3; ++r) {
      double s = w(r, a);
      for (int b = 0; b < a; ++b) s -= l(r, b) * l(a, b);
      l(r, a) = s / l(a, a);
    }
  }
  w.setZero();
  Block dinv(dinv_.data() + 9 * std::size_t{j});
  // L(j,j)⁻¹, lower triangular, by forward substitution on the identity
  dinv.setZero();
  for (int a = 0; a < 3; ++a) dinv(a, a) = 1.0 / l(a, a);
  dinv(1, 0) = -l(1, 0) * dinv(0, 0) * dinv(1, 1);
  dinv(2, 1) = -l(2, 1) * dinv(1, 1) * dinv(2, 2);
  dinv(2, 0) = -(l(2, 0) * dinv(0, 0) + l(2, 1) * dinv(1, 0)) * dinv(2, 2);
  const Eigen::Matrix3d dinv_t = dinv.transpose();
  for (std::size_t q = col_[j]; q < col_[j + 1]; ++q) {
    Block wi(w_.data() + 9 * std::size_t{row_[q]});
    Block(lx_.data() + 9 * q).noalias() = wi * dinv_t;
    wi.setZero();
  }
}

void BlockCholesky::solve(std::span<const double> rhs, std::span<double> out) {
  const std::size_t nb = perm_.size();
  if (rhs.size() != 3 * nb || out.size() != 3 * nb)
    throw InputError("block cholesky solve: vectors of " + std::to_string(rhs.size()) + " and " + std::to_string(out.size()) +
                     " values for a factor of " + std::to_string(3 * nb) + " unknowns");
  for (std::size_t j = 0; j < nb; ++j)
    for (std::size_t a = 0; a < 3; ++a) y_[3 * j + a] = rhs[3 * std::size_t{perm_[j]} + a];
  for (std::size_t j = 0; j < nb; ++j) {  // L y = P b
    Vec yj(y_.data() + 3 * j);
    yj = ConstBlock(dinv_.data() + 9 * j) * Eigen::Vector3d(yj);
    for (std::size_t q = col_[j]; q < col_[j + 1]; ++q)
      Vec(y_.data() + 3 * std::size_t{row_[q]}).noalias() -= ConstBlock(lx_.data() + 9 * q) * yj;
  }
  for (std::size_t j = nb; j-- > 0;) {  // Lᵀ z = y
    Vec yj(y_.data() + 3 * j);
    for (std::size_t q = col_[j]; q < col_[j + 1]; ++q)
      yj.noalias() -= ConstBlock(lx_.data() + 9 * q).transpose() * Vec(y_.data() + 3 * std::size_t{row_[q]});
    yj = ConstBlock(dinv_.data() + 9 * j).transpose() * Eigen::Vector3d(yj);
  }
  for (std::size_t j = 0; j < nb; ++j)
    for (std::size_t a = 0; a < 3; ++a) out[3 * std::size_t{perm_[j]} + a] = y_[3 * j + a];
}

}  // namespace sewn::physics::solve
