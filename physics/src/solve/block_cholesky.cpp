#include "sewn/physics/solve/block_cholesky.hpp"

#include <algorithm>
#include <cmath>
#include <string>

#include <Eigen/Cholesky>
#include <Eigen/OrderingMethods>

#include "sewn/physics/errors.hpp"
#include "sewn/physics/threads.hpp"

namespace sewn::physics::solve {

namespace {

using Panel = Eigen::Map<Eigen::MatrixXd, 0, Eigen::OuterStride<>>;
using ConstPanel = Eigen::Map<const Eigen::MatrixXd, 0, Eigen::OuterStride<>>;
using Dense = Eigen::Map<Eigen::MatrixXd>;
using VecX = Eigen::Map<Eigen::VectorXd>;
using Vec3 = Eigen::Map<Eigen::Vector3d>;
using ConstBlock = Eigen::Map<const Eigen::Matrix3d>;

using Block3 = Eigen::Map<Eigen::Matrix3d, 0, Eigen::OuterStride<>>;
using ConstBlock3 = Eigen::Map<const Eigen::Matrix3d, 0, Eigen::OuterStride<>>;

constexpr Index none = invalid_index;

// Where a panel keeps its 3×3 blocks: block (a, b) (block row a, block column b) starts at
// a·step + 3b·ld, its columns ld apart. A panel one pivot wide stores them one after another
// (step 9, ld 3), what the fixed-size kernels read fastest; a wider one is column-major
// (step 3, ld its scalar rows), what the dense kernels take.
struct Layout {
  std::size_t step, ld;
  [[nodiscard]] std::size_t at(std::size_t a, std::size_t b) const { return a * step + 3 * b * ld; }
  [[nodiscard]] Eigen::OuterStride<> stride() const { return Eigen::OuterStride<>(static_cast<Eigen::Index>(ld)); }
};

Layout layout(std::size_t width, std::size_t below) {
  if (width == 1) return {9, 3};
  return {3, 3 * (width + below)};
}
constexpr std::size_t no_supernode = static_cast<std::size_t>(-1);

// Supernodes narrower than this many pivots are factored one pivot at a time with fixed-size
// 3×3 code: there Eigen's dynamic-size kernels cost more in dispatch than their flops. Measured
// on the connect scenes' matrices (docs/solvers.md): 4 against 1, 3, 6 and 8 best or equal on
// every one. Relaxed supernodes (merging pivots at the cost of explicit zeros, up to 4-16 wide
// and 20-50 % zeros) measured no faster on any, slower on the toy ball's and the jellyfish's.
constexpr Index dense_width = 4;

// to(pos(a), pos(b)) -= L(a) L(b)ᵀ for the block rows a ≥ b < n1 of a one-pivot-wide
// descendant (its blocks `l`, 9 values each; pos(a) = relpos[rows[a]]; b < n1: the rows among
// the pivots updated): fixed-size 3×3 products, as cheap as they get for a chain or a sparse mesh.
void subtract_blockwise(const double* l, const Index* rows, std::size_t n, std::size_t n1, const std::size_t* relpos, double* to,
                        const Layout& lay) {
  for (std::size_t b = 0; b < n1; ++b) {
    const Eigen::Matrix3d lb_t = ConstBlock(l + 9 * b).transpose();
    const std::size_t column = lay.at(0, relpos[rows[b]]);
    for (std::size_t a = b; a < n; ++a) Block3(to + column + lay.at(relpos[rows[a]], 0), lay.stride()).noalias() -= ConstBlock(l + 9 * a) * lb_t;
  }
}

// to(pos[a], pos[b]) -= c(a, b) for the block rows a ≥ b of a descendant's update c; in a
// column-major panel, runs of rows consecutive in it one column at a time.
void scatter_update(const Dense& c, std::span<const std::size_t> pos, double* to, const Layout& lay) {
  const std::size_t n1 = static_cast<std::size_t>(c.cols()) / 3, ldc = static_cast<std::size_t>(c.rows());
  for (std::size_t b = 0; b < n1; ++b)
    for (std::size_t a = b; a < pos.size();) {
      std::size_t run = 1;
      while (lay.step == 3 && a + run < pos.size() && pos[a + run] == pos[a] + run) ++run;
      for (std::size_t x = 0; x < 3; ++x) {
        double* into = to + lay.at(pos[a], pos[b]) + x * lay.ld;
        const double* from = c.data() + (3 * b + x) * ldc + 3 * a;
        for (std::size_t k = 0; k < 3 * run; ++k) into[k] -= from[k];
      }
      a += run;
    }
}

// In-place LLᵀ of a 3×3 block's lower triangle; the first pivot that is not positive (or
// NaN), or -1.
Eigen::Index llt3(Block3 l) {
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
Eigen::Matrix3d lower_inverse3(const Block3& l) {
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
    const Layout lay = layout(width_of(s), below_of(s));
    const Index c = perm_[j];
    for (Index k = rows[c]; k < rows[c + 1]; ++k) {
      const Index i = pinv_[cols[k]];
      if (i < j) continue;
      const std::size_t at = i < f + width ? std::size_t{i - f} : width + static_cast<std::size_t>(std::lower_bound(below, end, i) - below);
      a_slot_.push_back(A.find(cols[k], c));  // block (r, c): row r of column c
      a_row_.push_back(i);
      a_dst_.push_back(sn_val_[s] + lay.at(at, j - f));
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
  lx_.assign(sn_val_.back(), 0.0);
  tmp_.assign(std::max(work, 3 * std::size_t{nb}), 0.0);
  y_.assign(3 * std::size_t{nb}, 0.0);
  head_.assign(ns, no_supernode);
  next_.assign(ns, no_supernode);
  cursor_.assign(ns, 0);
  relpos_.assign(nb, 0);
  pos_.assign(nb, 0);
}

void BlockCholesky::factorize(const BlockMatrix& A, std::span<const double> free_dof, const char* who) {
  if (free_dof.size() != 3 * std::size_t{A.size()})
    throw InputError(std::string(who) + ": " + std::to_string(free_dof.size()) + " free-axis flags for a matrix of " +
                     std::to_string(3 * std::size_t{A.size()}) + " unknowns");
  if (!analysed_for(A)) analyse(A);
  // Eigen's GEMM forks an OpenMP team of omp_get_max_threads() for products over ~1e5 flops,
  // whatever thread_count() says: on the frisbee that made a run 15x slower (the team's spins
  // and wake-ups beside the other processes on 2 cores). The products here are small: serial.
  const SerialLibraryRegions serial(max_threads + 1);
  std::fill(head_.begin(), head_.end(), no_supernode);
  for (std::size_t s = 0; s + 1 < sn_first_.size(); ++s) {
    scatter_supernode(A, free_dof, s);
    update_supernode(s);
    finish_supernode(s, who);
    if (sn_rows_[s + 1] > sn_rows_[s]) link(s, sn_rows_[s]);
  }
}

// Supernode d's rows from rows_[position] on update the supernode holding that row next.
void BlockCholesky::link(std::size_t d, std::size_t position) {
  const std::size_t t = sn_of_[rows_[position]];
  cursor_[d] = position;
  next_[d] = head_[t];
  head_[t] = d;
}

// Supernode s's panel = its columns of K's lower triangle (permuted): free_r free_c A(r, c),
// zero diagonals 1, zero elsewhere.
void BlockCholesky::scatter_supernode(const BlockMatrix& A, std::span<const double> free_dof, std::size_t s) {
  const Index f = sn_first_[s], l = sn_first_[s + 1];
  std::fill(lx_.begin() + static_cast<std::ptrdiff_t>(sn_val_[s]), lx_.begin() + static_cast<std::ptrdiff_t>(sn_val_[s + 1]), 0.0);
  const Layout lay = layout(width_of(s), below_of(s));
  for (Index j = f; j < l; ++j) {
    const std::size_t c = perm_[j];
    for (std::size_t e = a_col_[j]; e < a_col_[j + 1]; ++e) {
      const Index i = a_row_[e];
      const std::size_t r = perm_[i];
      const ConstBlock a = A.block(a_slot_[e]);
      Block3 w(lx_.data() + a_dst_[e], lay.stride());
      for (int b = 0; b < 3; ++b)
        for (int x = 0; x < 3; ++x) {
          w(x, b) = free_dof[3 * r + static_cast<std::size_t>(x)] * free_dof[3 * c + static_cast<std::size_t>(b)] * a(x, b);
          if (i == j && x == b && w(x, b) == 0.0) w(x, b) = 1.0;
        }
    }
  }
}

// Left-looking: every earlier supernode d with rows among s's pivots subtracts its product
// L(rows ≥ s, d) L(rows in s, d)ᵀ (one GEMM into tmp_), scattered to s's panel by row.
void BlockCholesky::update_supernode(std::size_t s) {
  const Index f = sn_first_[s], l = sn_first_[s + 1];
  const std::size_t width = l - f;
  for (Index j = f; j < l; ++j) relpos_[j] = j - f;
  for (std::size_t q = sn_rows_[s]; q < sn_rows_[s + 1]; ++q) relpos_[rows_[q]] = width + q - sn_rows_[s];
  const Layout lay = layout(width_of(s), below_of(s));
  double* to = lx_.data() + sn_val_[s];
  std::size_t d = head_[s];
  head_[s] = no_supernode;
  while (d != no_supernode) {
    const std::size_t next = next_[d], p = cursor_[d], end = sn_rows_[d + 1];
    std::size_t q = p;
    while (q < end && rows_[q] < l) ++q;
    const std::size_t wd = sn_first_[d + 1] - sn_first_[d];
    if (wd == 1) {
      subtract_blockwise(lx_.data() + sn_val_[d] + 9 * (1 + p - sn_rows_[d]), rows_.data() + p, end - p, q - p, relpos_.data(), to, lay);
    } else {
      const auto m = static_cast<Eigen::Index>(3 * (end - p)), m1 = static_cast<Eigen::Index>(3 * (q - p));
      const Layout from = layout(width_of(d), below_of(d));
      const ConstPanel ld_rows(lx_.data() + sn_val_[d] + from.at(wd + p - sn_rows_[d], 0), m, static_cast<Eigen::Index>(3 * wd), from.stride());
      const std::size_t first = relpos_[rows_[p]];
      if (width > 1 && relpos_[rows_[end - 1]] - first == end - 1 - p) {
        // d's rows are consecutive in s's panel: one GEMM into it (the few products above the
        // diagonal land in the diagonal block's upper triangle, which nothing reads)
        Panel(to + lay.at(first, first), m, m1, lay.stride()).noalias() -= ld_rows * ld_rows.topRows(m1).transpose();
      } else {
        Dense c(tmp_.data(), m, m1);
        c.noalias() = ld_rows * ld_rows.topRows(m1).transpose();
        for (std::size_t k = p; k < end; ++k) pos_[k - p] = relpos_[rows_[k]];
        scatter_update(c, std::span<const std::size_t>(pos_.data(), end - p), to, lay);
      }
    }
    if (q < end) link(d, q);
    d = next;
  }
}


// The dense LLᵀ of the diagonal block, then the rows below: L(below, s) = K(below, s) L(s, s)⁻ᵀ.
// A supernode one pivot wide (most of a chain's or a sparse mesh's) takes fixed-size 3×3 code:
// Eigen's dynamic-size kernels cost more in dispatch than their few flops.
void BlockCholesky::finish_supernode(std::size_t s, const char* who) {
  const Index f = sn_first_[s], l = sn_first_[s + 1];
  const auto n = static_cast<Eigen::Index>(3 * (l - f));
  const auto ld = static_cast<Eigen::Index>(3 * (std::size_t{l - f} + sn_rows_[s + 1] - sn_rows_[s]));
  Panel panel(lx_.data() + sn_val_[s], ld, n, Eigen::OuterStride<>(ld));
  auto diagonal = panel.topRows(n);
  if (const Eigen::Index bad = n == 3 ? llt3(Block3(panel.data(), Eigen::OuterStride<>(3))) : dense_llt(diagonal); bad >= 0) {
    const auto pivot = 3 * std::size_t{f} + static_cast<std::size_t>(bad);
    throw SolverError(std::string(who) + ": the matrix is not positive definite on the free axes (Cholesky pivot " +
                          std::to_string(pivot) + " of " + std::to_string(3 * perm_.size()) + " failed at node " +
                          std::to_string(perm_[pivot / 3]) + ", axis " + "xyz"[pivot % 3] + ")",
                      0, 0);
  }
  if (n == 3) {
    // one pivot: L(j, j)⁻¹ replaces L(j, j) in the panel (the solves multiply by it)
    Block3 diagonal3(panel.data(), Eigen::OuterStride<>(3));
    const Eigen::Matrix3d inverse = lower_inverse3(diagonal3);
    diagonal3 = inverse;
    const Eigen::Matrix3d inverse_t = inverse.transpose();
    for (Eigen::Index a = 9; a < 3 * ld; a += 9) {  // blocks one after another (Layout)
      Block3 block(panel.data() + a, Eigen::OuterStride<>(3));
      const Eigen::Matrix3d k = block;
      block.noalias() = k * inverse_t;
    }
    return;
  }
  if (ld == n) return;
  auto below = panel.bottomRows(ld - n);
  diagonal.triangularView<Eigen::Lower>().transpose().solveInPlace<Eigen::OnTheRight>(below);
}

void BlockCholesky::solve(std::span<const double> rhs, std::span<double> out) {
  const std::size_t nb = perm_.size();
  if (rhs.size() != 3 * nb || out.size() != 3 * nb)
    throw InputError("block cholesky solve: vectors of " + std::to_string(rhs.size()) + " and " + std::to_string(out.size()) +
                     " values for a factor of " + std::to_string(3 * nb) + " unknowns");
  for (std::size_t j = 0; j < nb; ++j)
    for (std::size_t a = 0; a < 3; ++a) y_[3 * j + a] = rhs[3 * std::size_t{perm_[j]} + a];
  const std::size_t ns = supernodes();
  const auto panel_of = [this](std::size_t s) {
    const auto n = static_cast<Eigen::Index>(3 * (sn_first_[s + 1] - sn_first_[s]));
    const auto ld = n + static_cast<Eigen::Index>(3 * (sn_rows_[s + 1] - sn_rows_[s]));
    return ConstPanel(lx_.data() + sn_val_[s], ld, n, Eigen::OuterStride<>(ld));
  };
  for (std::size_t s = 0; s < ns; ++s) {  // L y = P b
    const ConstPanel panel = panel_of(s);
    const Eigen::Index n = panel.cols(), below = panel.rows() - n;
    double* ys = y_.data() + 3 * std::size_t{sn_first_[s]};
    if (n == 3) {  // one pivot: fixed-size blocks
      Vec3 yj(ys);
      yj = ConstBlock(panel.data()) * Eigen::Vector3d(yj);  // L(j, j)⁻¹ yj (its upper triangle zero)
      for (std::size_t q = sn_rows_[s]; q < sn_rows_[s + 1]; ++q)
        Vec3(y_.data() + 3 * std::size_t{rows_[q]}).noalias() -= ConstBlock(panel.data() + 9 * (q - sn_rows_[s] + 1)) * yj;
      continue;
    }
    VecX yn(ys, n);
    panel.topRows(n).triangularView<Eigen::Lower>().solveInPlace(yn);
    if (below == 0) continue;
    VecX t(tmp_.data(), below);
    t.noalias() = panel.bottomRows(below) * yn;
    for (std::size_t q = sn_rows_[s]; q < sn_rows_[s + 1]; ++q)
      for (std::size_t a = 0; a < 3; ++a) y_[3 * std::size_t{rows_[q]} + a] -= tmp_[3 * (q - sn_rows_[s]) + a];
  }
  for (std::size_t s = ns; s-- > 0;) {  // Lᵀ z = y
    const ConstPanel panel = panel_of(s);
    const Eigen::Index n = panel.cols(), below = panel.rows() - n;
    double* ys = y_.data() + 3 * std::size_t{sn_first_[s]};
    if (n == 3) {
      Vec3 yj(ys);
      for (std::size_t q = sn_rows_[s]; q < sn_rows_[s + 1]; ++q)
        yj.noalias() -= ConstBlock(panel.data() + 9 * (q - sn_rows_[s] + 1)).transpose() * Vec3(y_.data() + 3 * std::size_t{rows_[q]});
      yj = ConstBlock(panel.data()).transpose() * Eigen::Vector3d(yj);
      continue;
    }
    if (below > 0) {
      for (std::size_t q = sn_rows_[s]; q < sn_rows_[s + 1]; ++q)
        for (std::size_t a = 0; a < 3; ++a) tmp_[3 * (q - sn_rows_[s]) + a] = y_[3 * std::size_t{rows_[q]} + a];
      VecX(ys, n).noalias() -= panel.bottomRows(below).transpose() * VecX(tmp_.data(), below);
    }
    VecX yn(ys, n);
    panel.topRows(n).transpose().triangularView<Eigen::Upper>().solveInPlace(yn);
  }
  for (std::size_t j = 0; j < nb; ++j)
    for (std::size_t a = 0; a < 3; ++a) out[3 * std::size_t{perm_[j]} + a] = y_[3 * j + a];
}

}  // namespace sewn::physics::solve
