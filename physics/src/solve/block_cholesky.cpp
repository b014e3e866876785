#include "sewn/physics/solve/block_cholesky.hpp"

#include <algorithm>
#include <cmath>
#include <cstring>
#include <limits>
#include <string>

#include <Eigen/Cholesky>
#include <Eigen/OrderingMethods>

#include "panel_solve.hpp"
#include "sewn/physics/errors.hpp"
#include "sewn/physics/threads.hpp"

namespace sewn::physics::solve {

namespace {

using Panel = Eigen::Map<Eigen::MatrixXd, 0, Eigen::OuterStride<>>;
using ConstPanel = Eigen::Map<const Eigen::MatrixXd, 0, Eigen::OuterStride<>>;
using Dense = Eigen::Map<Eigen::MatrixXd>;
using Vec3 = Eigen::Map<Eigen::Vector3d>;
using Block = Eigen::Map<Eigen::Matrix3d>;
using Block3 = Eigen::Map<Eigen::Matrix3d, 0, Eigen::OuterStride<>>;  // a 3×3 block of a panel
using ConstBlock = Eigen::Map<const Eigen::Matrix3d>;

constexpr Index none = invalid_index;
constexpr std::size_t wide = static_cast<std::size_t>(-1);  // no one-pivot panel's block

// Supernodes narrower than this many pivots are factored one pivot at a time with fixed-size
// 3×3 code: there Eigen's dynamic-size kernels cost more in dispatch than their flops. Measured
// on the connect scenes' matrices (docs/solvers.md): 4 and 8 equal within the noise, 16 slower on
// the frisbee's (1.22x against 1.47x main's speed), 1 (dense kernels for every supernode)
// 0.6-0.7x main's on the toy ball's and the jellyfish's. Relaxed supernodes (merging pivots at
// the cost of explicit zeros, 4-16 wide, 20-50 % zeros) measured no faster on any matrix.
constexpr Index dense_width = 4;

// The rows of a column-major panel (width pivots, `below` block rows under them) from its
// block row `from` below the diagonal block on.
ConstPanel rows_below(const double* panel, std::size_t width, std::size_t below, std::size_t from) {
  const auto ld = static_cast<Eigen::Index>(3 * (width + below));
  return {panel + 3 * (width + from), static_cast<Eigen::Index>(3 * (below - from)), static_cast<Eigen::Index>(3 * width), Eigen::OuterStride<>(ld)};
}

// to(pos(a), pos(b)) -= L(a) L(b)ᵀ for the block rows a ≥ b < n1 of a one-pivot-wide
// descendant (its blocks `l`, 9 values each; pos(a) = relpos[rows[a]]; b < n1: the rows among
// the pivots updated): fixed-size 3×3 products, as cheap as they get for a chain or a sparse mesh.
void subtract_blockwise(const double* l, const Index* rows, std::size_t n, std::size_t n1, const std::size_t* relpos, double* to,
                        std::size_t ld) {
  for (std::size_t b = 0; b < n1; ++b) {
    const Eigen::Matrix3d lb_t = ConstBlock(l + 9 * b).transpose();
    double* column = to + 3 * relpos[rows[b]] * ld;
    const Eigen::OuterStride<> stride(static_cast<Eigen::Index>(ld));
    for (std::size_t a = b; a < n; ++a) Block3(column + 3 * relpos[rows[a]], stride).noalias() -= ConstBlock(l + 9 * a) * lb_t;
  }
}

// to(pos[a], pos[b]) -= c(a, b) for the block rows a ≥ b of a descendant's update c; in a
// column-major panel, runs of rows consecutive in it one column at a time.
void scatter_update(const Dense& c, std::span<const std::size_t> pos, double* to, std::size_t ld) {
  const std::size_t n1 = static_cast<std::size_t>(c.cols()) / 3, ldc = static_cast<std::size_t>(c.rows());
  for (std::size_t b = 0; b < n1; ++b)
    for (std::size_t a = b; a < pos.size();) {
      std::size_t run = 1;
      while (a + run < pos.size() && pos[a + run] == pos[a] + run) ++run;
      for (std::size_t x = 0; x < 3; ++x) {
        double* into = to + (3 * pos[b] + x) * ld + 3 * pos[a];
        const double* from = c.data() + (3 * b + x) * ldc + 3 * a;
        for (std::size_t k = 0; k < 3 * run; ++k) into[k] -= from[k];
      }
      a += run;
    }
}

// In-place LLᵀ of a 3×3 block's lower triangle; the first pivot that is not positive (or
// NaN), or -1.
Eigen::Index llt3(Block l) {
  for (int a = 0; a < 3; ++a) {
    double d = l(a, a);
    for (int b = 0; b < a; ++b) d -= l(a, b) * l(a, b);
    if (!(d > 0.0)) return a;
    l(a, a) = std::sqrt(d);
    for (int r = a + 1; r < 3; ++r) {
      double v = l(r, a);
      for (int b = 0; b < a; ++b) v -= l(r, b) * l(a, b);
      l(r, a) = v / l(a, a);
    }
  }
  return -1;
}

// L⁻¹ of a lower triangular 3×3 block, by forward substitution on the identity.
Eigen::Matrix3d lower_inverse3(const Block& l) {
  Eigen::Matrix3d inv = Eigen::Matrix3d::Zero();
  for (int a = 0; a < 3; ++a) inv(a, a) = 1.0 / l(a, a);
  inv(1, 0) = -l(1, 0) * inv(0, 0) * inv(1, 1);
  inv(2, 1) = -l(2, 1) * inv(1, 1) * inv(2, 2);
  inv(2, 0) = -(l(2, 0) * inv(0, 0) + l(2, 1) * inv(1, 0)) * inv(2, 2);
  return inv;
}

// In-place LLᵀ of a dense block's lower triangle by Eigen's blocked kernel; the first pivot
// that is not positive (or NaN), or -1.
template <class Matrix>
Eigen::Index dense_llt(Matrix& m) {
  Eigen::Index bad = Eigen::internal::llt_inplace<double, Eigen::Lower>::blocked(m);
  // Eigen stops at a pivot ≤ 0; a NaN passes its test and leaves a NaN on the diagonal
  for (Eigen::Index k = 0; k < (bad < 0 ? m.cols() : bad); ++k)
    if (!(m(k, k) > 0.0)) return k;
  return bad;
}

}  // namespace

void BlockCholesky::analyse(const BlockMatrix& A) {
  order(A);
  postorder(A);
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

// The elimination tree of the ordered block graph (each pivot's parent: the first row below
// its diagonal in L), then the pivots renumbered in a postorder of it: the same fill, and every
// subtree's pivots consecutive, so that chains of the tree become contiguous supernodes.
void BlockCholesky::postorder(const BlockMatrix& A) {
  const Index nb = A.size();
  const auto rows = A.row_offsets();
  const auto cols = A.columns();
  std::vector<Index> parent(nb, none), ancestor(nb, none);
  for (Index j = 0; j < nb; ++j) {
    const Index c = perm_[j];
    for (Index k = rows[c]; k < rows[c + 1]; ++k) {
      // climb from an earlier pivot to its subtree's root, pointing the path at j on the way
      for (Index r = pinv_[cols[k]]; r < j;) {
        const Index up = ancestor[r];
        ancestor[r] = j;
        if (up == none) {
          parent[r] = j;
          break;
        }
        r = up;
      }
    }
  }
  std::vector<Index> head(nb, none), next(nb, none), stack, order;
  for (Index j = nb; j-- > 0;)  // children listed ascending
    if (parent[j] != none) {
      next[j] = head[parent[j]];
      head[parent[j]] = j;
    }
  order.reserve(nb);
  for (Index root = 0; root < nb; ++root) {
    if (parent[root] != none) continue;
    stack.push_back(root);
    while (!stack.empty()) {
      const Index j = stack.back();
      if (const Index child = head[j]; child != none) {
        head[j] = next[child];
        stack.push_back(child);
      } else {
        stack.pop_back();
        order.push_back(j);
      }
    }
  }
  std::vector<Index> old = perm_;
  for (Index k = 0; k < nb; ++k) {
    perm_[k] = old[order[k]];
    pinv_[perm_[k]] = k;
  }
}

// L's exact structure column by column in pivot order: column j holds A's lower entries of
// pivot j and, from each child c in the elimination tree, c's rows below j. From it the flop
// count, the supernodes (partition()) and the scatter of A's blocks into their panels.
void BlockCholesky::symbolic(const BlockMatrix& A) {
  const Index nb = A.size();
  const auto rows = A.row_offsets();
  const auto cols = A.columns();
  std::vector<Index> mark(nb, none), child_head(nb, none), next_child(nb, none), parent(nb, none), row;
  std::vector<std::size_t> col(1, 0);
  flops_ = 0;
  for (Index j = 0; j < nb; ++j) {
    const Index c = perm_[j];
    const std::size_t start = row.size();
    mark[j] = j;
    for (Index k = rows[c]; k < rows[c + 1]; ++k)
      if (const Index i = pinv_[cols[k]]; i > j && mark[i] != j) {
        mark[i] = j;
        row.push_back(i);
      }
    for (Index ch = child_head[j]; ch != none; ch = next_child[ch])
      for (std::size_t q = col[ch]; q < col[ch + 1]; ++q)
        if (const Index i = row[q]; mark[i] != j) {
          mark[i] = j;
          row.push_back(i);
        }
    std::sort(row.begin() + static_cast<std::ptrdiff_t>(start), row.end());
    col.push_back(row.size());
    if (row.size() > start) {
      parent[j] = row[start];
      next_child[j] = child_head[parent[j]];
      child_head[parent[j]] = j;
    }
    // the scalar columns 3j, 3j+1, 3j+2: (entries below the diagonal + 1)², as CHOLMOD counts
    const double below = 3.0 * static_cast<double>(row.size() - start);
    for (int a = 0; a < 3; ++a) flops_ += (below + 3.0 - a) * (below + 3.0 - a);
  }
  entries_ = 6.0 * static_cast<double>(nb) + 9.0 * static_cast<double>(row.size());
  partition(parent, col, row);

  // A's lower blocks (pivot row i ≥ pivot column j) and their places in the panels
  a_col_.assign(1, 0);
  a_slot_.clear();
  a_row_.clear();
  a_dst_.clear();
  for (Index j = 0; j < nb; ++j) {
    const std::size_t s = sn_of_[j];
    const Index f = sn_first_[s], width = sn_first_[s + 1] - f;
    const auto below = rows_.begin() + static_cast<std::ptrdiff_t>(sn_rows_[s]);
    const auto end = rows_.begin() + static_cast<std::ptrdiff_t>(sn_rows_[s + 1]);
    const std::size_t ld = 3 * (width_of(s) + below_of(s));  // the column-major panel's (one pivot wide: unused)
    const Index c = perm_[j];
    for (Index k = rows[c]; k < rows[c + 1]; ++k) {
      const Index i = pinv_[cols[k]];
      if (i < j) continue;
      const std::size_t at = i < f + width ? std::size_t{i - f} : width + static_cast<std::size_t>(std::lower_bound(below, end, i) - below);
      a_slot_.push_back(A.find(cols[k], c));  // block (r, c): row r of column c
      a_row_.push_back(i);
      a_dst_.push_back(sn_val_[s] + 3 * std::size_t{j - f} * ld + 3 * at);
    }
    a_col_.push_back(a_slot_.size());
  }
}

// Fundamental supernodes: pivots f .. l-1 where each pivot's parent is the next one and its
// structure is the next one's plus that row, so no explicit zeros. A supernode's rows below are
// its last pivot's structure. Those narrower than dense_width pivots are split into one
// supernode per pivot, for the fixed-size 3×3 code.
void BlockCholesky::partition(const std::vector<Index>& parent, const std::vector<std::size_t>& col, const std::vector<Index>& row) {
  const Index nb = static_cast<Index>(parent.size());
  const auto count = [&col](Index j) { return col[j + 1] - col[j]; };
  sn_first_.assign(1, 0);
  for (Index j = 0, f = 0; j < nb; ++j) {
    if (j + 1 < nb && parent[j] == j + 1 && count(j) == count(j + 1) + 1) continue;
    if (j + 1 - f < dense_width)
      for (Index k = f + 1; k <= j; ++k) sn_first_.push_back(k);
    sn_first_.push_back(j + 1);
    f = j + 1;
  }
  const std::size_t ns = sn_first_.size() - 1;
  sn_of_.resize(nb);
  sn_rows_.assign(1, 0);
  sn_val_.assign(1, 0);
  rows_.clear();
  std::size_t work = 0;
  for (std::size_t s = 0; s < ns; ++s) {
    const Index f = sn_first_[s], l = sn_first_[s + 1];
    for (Index j = f; j < l; ++j) sn_of_[j] = s;
    rows_.insert(rows_.end(), row.begin() + static_cast<std::ptrdiff_t>(col[l - 1]), row.begin() + static_cast<std::ptrdiff_t>(col[l]));
    sn_rows_.push_back(rows_.size());
    const std::size_t below = sn_rows_[s + 1] - sn_rows_[s], width = l - f;
    sn_val_.push_back(sn_val_[s] + 9 * (width + below) * width);
    // an update of s's rows on a later supernode's pivots: at most all of them by the widest
    work = std::max(work, 9 * below * below);
  }
  lx_.assign(sn_val_.back() + 1, 0.0);
  tmp_.assign(std::max(work, 3 * std::size_t{nb}), 0.0);
  y_.assign(4 * std::size_t{nb}, 0.0);
  // the updates each supernode receives: (d, position in rows_ of d's first row in it), d
  // ascending; d reaches t when one of its rows is among t's pivots
  const auto reaches = [this](std::size_t d, std::size_t q) { return q == sn_rows_[d] || sn_of_[rows_[q]] != sn_of_[rows_[q - 1]]; };
  upd_start_.assign(ns + 1, 0);
  for (std::size_t d = 0; d < ns; ++d)
    for (std::size_t q = sn_rows_[d]; q < sn_rows_[d + 1]; ++q)
      if (reaches(d, q)) ++upd_start_[sn_of_[rows_[q]] + 1];
  for (std::size_t t = 0; t < ns; ++t) upd_start_[t + 1] += upd_start_[t];
  upd_from_.resize(upd_start_.back());
  upd_row_.resize(upd_start_.back());
  upd_rows_.resize(upd_start_.back());
  upd_block_.resize(upd_start_.back());
  std::vector<std::size_t> fill(upd_start_.begin(), upd_start_.end() - 1);
  for (std::size_t d = 0; d < ns; ++d)
    for (std::size_t q = sn_rows_[d]; q < sn_rows_[d + 1]; ++q)
      if (reaches(d, q)) {
        const std::size_t at = fill[sn_of_[rows_[q]]]++;
        upd_from_[at] = d;
        upd_row_[at] = q;
        upd_rows_[at] = sn_rows_[d + 1] - q;
        upd_block_[at] = width_of(d) == 1 ? sn_val_[d] + 9 * (1 + q - sn_rows_[d]) : wide;
      }
  relpos_.assign(nb, 0);
  w_.assign(9 * std::size_t{nb}, 0.0);
  pos_.assign(nb, 0);
}

void BlockCholesky::factorize(const BlockMatrix& A, std::span<const double> free_dof, const char* who) {
  if (free_dof.size() != 3 * std::size_t{A.size()})
    throw InputError(std::string(who) + ": " + std::to_string(free_dof.size()) + " free-axis flags for a matrix of " +
                     std::to_string(3 * std::size_t{A.size()}) + " unknowns");
  if (!analysed_for(A)) analyse(A);
  lf_.clear();
  // Eigen's GEMM forks an OpenMP team of omp_get_max_threads() for products over ~1e5 flops,
  // whatever thread_count() says: on the frisbee that made a run 15x slower (the team's spins
  // and wake-ups beside the other processes on 2 cores). The products here are small: serial.
  const SerialLibraryRegions serial(max_threads + 1);
  for (std::size_t s = 0; s + 1 < sn_first_.size(); ++s) {
    if (width_of(s) == 1) {
      factor_pivot(A, free_dof, s, who);
    } else {
      scatter_supernode(A, free_dof, s);
      update_supernode(s);
      finish_supernode(s, who);
    }
  }
  if (single_ && !round_panels()) lf_.clear();
}

// lf_ = lx_ in float; false if a value overflows float or a diagonal entry the solves divide by
// (multiply by, one pivot wide: L(j, j)⁻¹'s) is not a normal float (a matrix in extreme units).
bool BlockCholesky::round_panels() {
  lf_.resize(lx_.size());
  std::transform(lx_.begin(), lx_.end(), lf_.begin(), [](double v) { return static_cast<float>(v); });
  float biggest = 0;
  for (const float v : lf_) biggest = std::max(biggest, std::abs(v));
  if (!(biggest <= std::numeric_limits<float>::max())) return false;  // inf or NaN
  for (std::size_t s = 0; s < supernodes(); ++s) {
    const std::size_t n = 3 * width_of(s), ld = n + 3 * below_of(s), d = width_of(s) == 1 ? 3 : ld;
    for (std::size_t j = 0; j < n; ++j)
      if (!(std::abs(lf_[sn_val_[s] + j * d + j]) >= std::numeric_limits<float>::min())) return false;
  }
  return true;
}

// Supernode s's panel = its columns of K's lower triangle (permuted): free_r free_c A(r, c),
// zero diagonals 1, zero elsewhere.
void BlockCholesky::scatter_supernode(const BlockMatrix& A, std::span<const double> free_dof, std::size_t s) {
  const Index f = sn_first_[s], l = sn_first_[s + 1];
  std::fill(lx_.begin() + static_cast<std::ptrdiff_t>(sn_val_[s]), lx_.begin() + static_cast<std::ptrdiff_t>(sn_val_[s + 1]), 0.0);
  const auto ld = static_cast<Eigen::Index>(3 * (width_of(s) + below_of(s)));
  for (Index j = f; j < l; ++j) {
    const std::size_t c = perm_[j];
    for (std::size_t e = a_col_[j]; e < a_col_[j + 1]; ++e) {
      const Index i = a_row_[e];
      const std::size_t r = perm_[i];
      const ConstBlock a = A.block(a_slot_[e]);
      Block3 w(lx_.data() + a_dst_[e], Eigen::OuterStride<>(ld));
      for (int b = 0; b < 3; ++b)
        for (int x = 0; x < 3; ++x) {
          w(x, b) = free_dof[3 * r + static_cast<std::size_t>(x)] * free_dof[3 * c + static_cast<std::size_t>(b)] * a(x, b);
          if (i == j && x == b && w(x, b) == 0.0) w(x, b) = 1.0;
        }
    }
  }
}

// Left-looking, for a supernode of dense_width pivots or more: every earlier supernode d with
// rows among s's pivots subtracts L(rows ≥ s, d) L(rows in s, d)ᵀ: 3×3 blocks from a one-pivot
// d, else one GEMM, straight into s's panel or through tmp_ scattered by rows.
void BlockCholesky::update_supernode(std::size_t s) {
  const Index f = sn_first_[s], l = sn_first_[s + 1];
  const std::size_t width = l - f;
  for (Index j = f; j < l; ++j) relpos_[j] = j - f;
  for (std::size_t q = sn_rows_[s]; q < sn_rows_[s + 1]; ++q) relpos_[rows_[q]] = width + q - sn_rows_[s];
  const std::size_t ld = 3 * (width + below_of(s));
  double* to = lx_.data() + sn_val_[s];
  for (std::size_t u = upd_start_[s]; u < upd_start_[s + 1]; ++u) {
    const std::size_t d = upd_from_[u], p = upd_row_[u], end = sn_rows_[d + 1];
    std::size_t q = p;
    while (q < end && rows_[q] < l) ++q;
    const std::size_t wd = sn_first_[d + 1] - sn_first_[d];
    if (wd == 1) {
      subtract_blockwise(lx_.data() + sn_val_[d] + 9 * (1 + p - sn_rows_[d]), rows_.data() + p, end - p, q - p, relpos_.data(), to, ld);
    } else {
      const auto m = static_cast<Eigen::Index>(3 * (end - p)), m1 = static_cast<Eigen::Index>(3 * (q - p));
      const ConstPanel ld_rows = rows_below(lx_.data() + sn_val_[d], wd, below_of(d), p - sn_rows_[d]);
      const std::size_t first = relpos_[rows_[p]];
      if (relpos_[rows_[end - 1]] - first == end - 1 - p) {
        // d's rows are consecutive in s's panel: one GEMM into it (the few products above the
        // diagonal land in the diagonal block's upper triangle, which nothing reads)
        Panel(to + 3 * first * (ld + 1), m, m1, Eigen::OuterStride<>(static_cast<Eigen::Index>(ld))).noalias() -= ld_rows * ld_rows.topRows(m1).transpose();
      } else {
        Dense c(tmp_.data(), m, m1);
        c.noalias() = ld_rows * ld_rows.topRows(m1).transpose();
        for (std::size_t k = p; k < end; ++k) pos_[k - p] = relpos_[rows_[k]];
        scatter_update(c, std::span<const std::size_t>(pos_.data(), end - p), to, ld);
      }
    }
  }
}


// The dense LLᵀ of the diagonal block, then the rows below: L(below, s) = K(below, s) L(s, s)⁻ᵀ.
void BlockCholesky::finish_supernode(std::size_t s, const char* who) {
  const Index f = sn_first_[s], l = sn_first_[s + 1];
  const auto n = static_cast<Eigen::Index>(3 * (l - f));
  const auto ld = static_cast<Eigen::Index>(3 * (std::size_t{l - f} + sn_rows_[s + 1] - sn_rows_[s]));
  Panel panel(lx_.data() + sn_val_[s], ld, n, Eigen::OuterStride<>(ld));
  auto diagonal = panel.topRows(n);
  if (const Eigen::Index bad = dense_llt(diagonal); bad >= 0) not_positive_definite(3 * std::size_t{f} + static_cast<std::size_t>(bad), who);
  if (ld == n) return;
  auto below = panel.bottomRows(ld - n);
  diagonal.triangularView<Eigen::Lower>().transpose().solveInPlace<Eigen::OnTheRight>(below);
}

// A supernode of one pivot j, as the column-at-a-time factorization did it: column j of K and
// the updates of the earlier supernodes with a block in row j accumulate in w_ (9 per pivot
// row, no indirection), then the 3×3 LLᵀ of the diagonal block and L(i, j) = w_(i) L(j, j)⁻ᵀ.
// Its panel keeps L(j, j)⁻¹ (the solves multiply by it) and the blocks below one after another.
void BlockCholesky::factor_pivot(const BlockMatrix& A, std::span<const double> free_dof, std::size_t s, const char* who) {
  const Index j = sn_first_[s];
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
  for (std::size_t u = upd_start_[s]; u < upd_start_[s + 1]; ++u) {  // row j: the only row of s
    const std::size_t p = upd_row_[u], n = upd_rows_[u];
    const Index* rows = rows_.data() + p;
    if (const std::size_t at = upd_block_[u]; at != wide) {  // a one-pivot d: its blocks from row j on
      const double* l = lx_.data() + at;
      const Eigen::Matrix3d lj_t = ConstBlock(l).transpose();
      for (std::size_t a = 0; a < n; ++a) Block(w_.data() + 9 * std::size_t{rows[a]}).noalias() -= ConstBlock(l + 9 * a) * lj_t;
    } else {
      const std::size_t d = upd_from_[u];
      const ConstPanel ld_rows = rows_below(lx_.data() + sn_val_[d], width_of(d), below_of(d), p - sn_rows_[d]);
      Dense update(tmp_.data(), ld_rows.rows(), 3);
      update.noalias() = ld_rows * ld_rows.topRows(3).transpose();
      for (std::size_t a = 0; a < n; ++a) Block(w_.data() + 9 * std::size_t{rows[a]}) -= update.block<3, 3>(static_cast<Eigen::Index>(3 * a), 0);
    }
  }
  Block wj(w_.data() + 9 * std::size_t{j});
  if (const Eigen::Index bad = llt3(wj); bad >= 0) {
    std::fill(w_.begin(), w_.end(), 0.0);  // zero between pivots, also after a failed one
    not_positive_definite(3 * std::size_t{j} + static_cast<std::size_t>(bad), who);
  }
  const Eigen::Matrix3d inverse = lower_inverse3(wj);
  const Eigen::Matrix3d inverse_t = inverse.transpose();
  double* panel = lx_.data() + sn_val_[s];
  Block{panel} = inverse;
  wj.setZero();
  for (std::size_t q = sn_rows_[s]; q < sn_rows_[s + 1]; ++q) {
    Block wi(w_.data() + 9 * std::size_t{rows_[q]});
    Block(panel + 9 * (1 + q - sn_rows_[s])).noalias() = wi * inverse_t;
    wi.setZero();
  }
}

// Throws the SolverError of a pivot (in the factorization's order) that is not positive.
void BlockCholesky::not_positive_definite(std::size_t pivot, const char* who) const {
  throw SolverError(std::string(who) + ": the matrix is not positive definite on the free axes (Cholesky pivot " +
                        std::to_string(pivot) + " of " + std::to_string(3 * perm_.size()) + " failed at node " +
                        std::to_string(perm_[pivot / 3]) + ", axis " + "xyz"[pivot % 3] + ")",
                    0, 0);
}


void BlockCholesky::solve(std::span<const double> rhs, std::span<double> out) {
  const std::size_t nb = perm_.size();
  if (rhs.size() != 3 * nb || out.size() != 3 * nb)
    throw InputError("block cholesky solve: vectors of " + std::to_string(rhs.size()) + " and " + std::to_string(out.size()) +
                     " values for a factor of " + std::to_string(3 * nb) + " unknowns");
  for (std::size_t j = 0; j < nb; ++j) {
    for (std::size_t a = 0; a < 3; ++a) y_[4 * j + a] = rhs[3 * std::size_t{perm_[j]} + a];
    y_[4 * j + 3] = 0.0;  // the scratch lane: what it gathers stays bounded
  }
  if (lf_.empty()) solve_panels(lx_.data());
  else solve_panels(lf_.data());
  for (std::size_t j = 0; j < nb; ++j)
    for (std::size_t a = 0; a < 3; ++a) out[3 * std::size_t{perm_[j]} + a] = y_[4 * j + a];
}

namespace {

using Lanes4 = solve::detail::panel_lanes::D4;  // a node's entries of y_ (3 and a scratch lane)

// Column c of a column-major 3×3 block, and in lane 3 the value that follows it (not used). A
// block times a node's entries is then 3 multiply-adds of 4 lanes (one instruction each with
// AVX), where scalar code spent 9 converts and 9 multiply-adds.
template <class T>
inline void load_column(const T* block, std::size_t c, Lanes4& to) {
  solve::detail::panel_lanes::load(block + 3 * c, to);
}

inline void load_node(const double* at, Lanes4& to) { std::memcpy(&to, at, sizeof to); }
inline void store_node(const Lanes4& v, double* at) { std::memcpy(at, &v, sizeof v); }

// to -= B v, lanes 0-2 (lane 3 takes what the columns' lane 3 give: scratch).
template <class T>
inline void subtract_product(const T* block, const Lanes4& v, Lanes4& to) {
  Lanes4 c0, c1, c2;
  load_column(block, 0, c0);
  load_column(block, 1, c1);
  load_column(block, 2, c2);
  to -= c0 * v[0] + c1 * v[1] + c2 * v[2];
}

// parts[c] += B's column c ⊙ v lane-wise: (Bᵀ v)[c] is the sum of parts[c]'s lanes 0-2.
template <class T>
inline void add_transposed(const T* block, const Lanes4& v, Lanes4 (&parts)[3]) {
  Lanes4 c;
  for (std::size_t k = 0; k < 3; ++k) {
    load_column(block, k, c);
    parts[k] += c * v;
  }
}

inline double sum3(const Lanes4& v) { return (v[0] + v[1]) + v[2]; }

}  // namespace

// L Lᵀ y_ = y_ on the panels lx (lx_ or its float copy). A one-pivot supernode: its 3×3 blocks
// on 4 lanes, L(j, j)⁻¹ multiplied; a wider one: its rows gathered into tmp_, the panel's
// triangle and rows below in one pass (panel_solve.hpp), scattered back.
template <class T>
void BlockCholesky::solve_panels(const T* lx) {
  const std::size_t ns = supernodes();
  double* y = y_.data();
  double* w = tmp_.data();
  for (std::size_t s = 0; s < ns; ++s) {  // L y = P b
    const std::size_t n = 3 * width_of(s), nr = n + 3 * below_of(s), r0 = sn_rows_[s];
    const T* panel = lx + sn_val_[s];
    double* ys = y + 4 * std::size_t{sn_first_[s]};
    if (n == 3) {
      Lanes4 yj, minus = {0, 0, 0, 0};
      load_node(ys, yj);
      subtract_product(panel, yj, minus);  // -L(j, j)⁻¹ yj (its upper triangle zero)
      yj = -minus;
      store_node(yj, ys);
      for (std::size_t q = r0; q < sn_rows_[s + 1]; ++q) {
        double* yr = y + 4 * std::size_t{rows_[q]};
        Lanes4 v;
        load_node(yr, v);
        subtract_product(panel + 9 * (1 + q - r0), yj, v);
        store_node(v, yr);
      }
      continue;
    }
    for (std::size_t k = 0; k < n / 3; ++k) std::copy_n(ys + 4 * k, 3, w + 3 * k);
    std::fill(w + n, w + nr, 0.0);
    solve::detail::panel_forward(panel, n, nr, w);
    for (std::size_t k = 0; k < n / 3; ++k) std::copy_n(w + 3 * k, 3, ys + 4 * k);
    for (std::size_t q = r0; q < sn_rows_[s + 1]; ++q)
      for (std::size_t a = 0; a < 3; ++a) y[4 * std::size_t{rows_[q]} + a] += w[n + 3 * (q - r0) + a];
  }
  for (std::size_t s = ns; s-- > 0;) {  // Lᵀ z = y
    const std::size_t n = 3 * width_of(s), nr = n + 3 * below_of(s), r0 = sn_rows_[s];
    const T* panel = lx + sn_val_[s];
    double* ys = y + 4 * std::size_t{sn_first_[s]};
    if (n == 3) {
      Lanes4 parts[3] = {};
      for (std::size_t q = r0; q < sn_rows_[s + 1]; ++q) {
        Lanes4 v;
        load_node(y + 4 * std::size_t{rows_[q]}, v);
        add_transposed(panel + 9 * (1 + q - r0), v, parts);
      }
      const Lanes4 t = {ys[0] - sum3(parts[0]), ys[1] - sum3(parts[1]), ys[2] - sum3(parts[2]), 0.0};  // yj - L(below)ᵀ y(below)
      Lanes4 yj[3] = {};
      add_transposed(panel, t, yj);  // L(j, j)⁻ᵀ t
      for (std::size_t k = 0; k < 3; ++k) ys[k] = sum3(yj[k]);
      continue;
    }
    for (std::size_t k = 0; k < n / 3; ++k) std::copy_n(ys + 4 * k, 3, w + 3 * k);
    for (std::size_t q = r0; q < sn_rows_[s + 1]; ++q)
      for (std::size_t a = 0; a < 3; ++a) w[n + 3 * (q - r0) + a] = y[4 * std::size_t{rows_[q]} + a];
    solve::detail::panel_backward(panel, n, nr, w);
    for (std::size_t k = 0; k < n / 3; ++k) std::copy_n(w + 3 * k, 3, ys + 4 * k);
  }
}

}  // namespace sewn::physics::solve
