// The CHOLMOD backends: a sparse Cholesky solve, and CG preconditioned by a factorization kept
// across solves (KeptPcg, kept_pcg.hpp). Both factor the filtered matrix K = S A S + (I - S):
// fixed axes become identity rows and columns. K's scalar pattern is that of A's blocks whatever
// the mask, so the symbolic analysis depends on A's pattern only and survives a change of fixed
// axes.

#include <cholmod.h>

#include <algorithm>
#include <array>
#include <cstring>
#include <initializer_list>
#include <limits>
#include <string>
#include <vector>

#include "backends.hpp"
#include "float_factor.hpp"
#include "kept_pcg.hpp"
#include "sewn/physics/aligned.hpp"
#include "sewn/physics/solve/block_cholesky.hpp"
#include "sewn/physics/errors.hpp"
#include "sewn/physics/threads.hpp"

namespace sewn::physics::solve::detail {

namespace {

// How much faster than the triangular solves' flops the factorization's run: the same on the
// reference BLAS (docs/solvers.md: ~3 against 2-6.5 GFlop/s), ~4x with OpenBLAS's blocked
// kernels (measured 3.7-4.1x on the beams and the cantilever, 2.9x on the umbrella under
// load). A build constant, so that the refresh rule stays deterministic within a build.
#if defined(SEWN_CHOLMOD_BLAS_OPTIMIZED)
constexpr double factor_flop_speedup = 4.0;
#else
constexpr double factor_flop_speedup = 1.0;
#endif

// The fill-reducing ordering: AMD, and where its factorization is large also METIS and nested
// dissection, keeping the least fill. The umbrella's 9702 unknowns factor in 6.1e8 flops with
// METIS against 7.8e8 with AMD (its analysis 30-53 ms against 9, once per pattern); on the
// sticky hand (621 unknowns, 2.1e6 flops) all three find AMD's ordering, and trying the other
// two cost 2.0-2.6 ms against 0.5, about three of its factorizations, for nothing. Above this
// many flops (a factorization of a few ms with OpenBLAS) the search pays.
constexpr double ordering_search_flops = 3e7;


// The same for BlockCholesky's factorization against its float solves (the refresh rule's set-up
// cost). Measured on bench_solve: 1.45 on the 8×8×10 beam (9.0e7 flops, ~9.6 ms against ~0.25 ms
// a solve: narrow supernodes), 6.7 on the N = 8 cantilever (1.5e9 flops, ~100 ms against ~8 ms
// an iteration). 4, as for CHOLMOD, sets up as often as before there (set-up costs 13.9 and 21.4
// iterations against CHOLMOD's 11.6 and 21.6; 0.01 and 0.15 factorizations a step both).
constexpr double block_flop_speedup = 4.0;

// One CHOLMOD workspace, the filtered matrix in its upper-triangular CSC form, and its factor:
// CHOLMOD's, or for a kept factor below SolverOptions::block_factor_flops BlockCholesky's of the
// same matrix.
// K's CSC values are the factored values either way (state(): one format for both engines).
class Factorization {
 public:
  /// single_solves: after each numeric factorization of a supernodal analysis, solve on a copy
  /// of the factor in single precision (see factorize()); for a factor kept as a preconditioner.
  /// blocks: factor with BlockCholesky below configure()'s flops (cholmod-pcg's kept factor).
  explicit Factorization(bool single_solves = true, bool blocks = true) : single_solves_(single_solves), may_block_(blocks) {
    block_.set_single_solves(single_solves);
    cholmod_start(&c_);
    c_.print = 0;  // failures are reported by our exceptions, not on stderr
    // LLᵀ: a simplicial LDLᵀ would succeed on an indefinite matrix (only a zero pivot stops
    // it), and indefiniteness is what must be reported.
    c_.final_ll = 1;
  }
  ~Factorization() {
    free_factor();
    if (K_) cholmod_free_sparse(&K_, &c_);
    if (X_) cholmod_free_dense(&X_, &c_);
    if (Y_) cholmod_free_dense(&Y_, &c_);
    if (E_) cholmod_free_dense(&E_, &c_);
    cholmod_finish(&c_);
  }
  Factorization(const Factorization&) = delete;
  Factorization& operator=(const Factorization&) = delete;

  /// The solver's options: block_factor_flops decides the engine at the next analyse(). O(1).
  void configure(const SolverOptions& o) { block_flops_ = o.block_factor_flops; }

  /// Rebuilds K's pattern if A's changed; returns true then (the analysis is stale). O(blocks · log).
  bool sync_pattern(const BlockMatrix& A) {
    if (K_ && pattern_ == A.pattern_version()) return false;
    free_factor();
    if (K_) cholmod_free_sparse(&K_, &c_);
    const Index nb = A.size();
    const std::size_t n = 3 * std::size_t{nb};
    const auto rows = A.row_offsets();
    const auto cols = A.columns();
    std::vector<int> p(n + 1, 0), i;
    src_.clear();
    mirror_.clear();
    i.reserve(9 * std::size_t{A.num_blocks()} / 2 + n);
    src_.reserve(i.capacity());
    // Column 3bj+c holds rows 3bi+a for the blocks (bi, bj), bi ≤ bj, ascending; the value
    // A(bi,bj)(a,c) sits in that block's column-major storage at 3c + a.
    for (Index bj = 0; bj < nb; ++bj) {
      for (int c = 0; c < 3; ++c) {
        for (Index k = rows[bj]; k < rows[bj + 1]; ++k) {
          const Index bi = cols[k];
          if (bi > bj) break;
          const Index slot = A.find(bi, bj), twin = A.find(bj, bi);
          for (int a = 0; a < 3 && (bi < bj || a <= c); ++a) {
            const auto ua = static_cast<std::size_t>(a), uc = static_cast<std::size_t>(c);
            i.push_back(static_cast<int>(3 * bi + static_cast<Index>(a)));
            src_.push_back(9 * std::size_t{slot} + 3 * uc + ua);
            if (may_block_) mirror_.push_back(9 * std::size_t{twin} + 3 * ua + uc);  // (bj, bi)(c, a)
          }
        }
        p[3 * std::size_t{bj} + static_cast<std::size_t>(c) + 1] = static_cast<int>(i.size());
      }
    }
    K_ = cholmod_allocate_sparse(n, n, i.size(), 1, 1, 1, CHOLMOD_REAL, &c_);
    if (!K_) throw SolverError("cholmod: out of memory for a matrix of " + std::to_string(i.size()) + " entries", 0, 0);
    std::memcpy(K_->p, p.data(), p.size() * sizeof(int));
    std::memcpy(K_->i, i.data(), i.size() * sizeof(int));
    col_of_.resize(i.size());
    for (std::size_t col = 0; col < n; ++col)
      for (int e = p[col]; e < p[col + 1]; ++e) col_of_[static_cast<std::size_t>(e)] = static_cast<int>(col);
    if (may_block_) {
      kb_ = A;  // K's values go in at each factorization
      ones_.assign(n, 1.0);
    }
    pattern_ = A.pattern_version();
    return true;
  }

  /// K's values from A and the mask. O(entries).
  void fill_values(const BlockMatrix& A, std::span<const double> free_dof) {
    const double* val = A.num_blocks() ? A.block(0).data() : nullptr;
    auto* kx = static_cast<double*>(K_->x);
    const auto* ki = static_cast<const int*>(K_->i);
    for (std::size_t e = 0; e < src_.size(); ++e) {
      const auto r = static_cast<std::size_t>(ki[e]);
      const auto c = static_cast<std::size_t>(col_of_[e]);
      kx[e] = free_dof[r] * free_dof[c] * val[src_[e]];
      // Fixed axes, and free ones with a zero diagonal (a node left without mass or springs,
      // e.g. removed by a piercing: in a semidefinite matrix its row is zero), get an identity
      // row, so that they neither stop the factorization nor change the others' solution.
      if (r == c && kx[e] == 0.0) kx[e] = 1.0;
    }
  }

  /// True if K's values equal those last factored (then the factor is exact for K). O(entries).
  [[nodiscard]] bool factor_matches_values() const {
    return valid_ && factored_.size() == src_.size() &&
           std::equal(factored_.begin(), factored_.end(), static_cast<const double*>(K_->x));
  }

  /// Symbolic analysis (fill-reducing ordering, elimination tree), BlockCholesky's first if
  /// the blocks may be used: below configure()'s flops CHOLMOD's is skipped. Milliseconds.
  void analyse() {
    const SerialLibraryRegions serial;
    free_factor();
    if (may_block_ && block_flops_ > 0) {
      block_.analyse(kb_);
      blocks_ = block_.flops() < block_flops_;
      if (blocks_) {
        setup_cost_ = block_.flops() / iteration_flops(block_.factor_entries()) / block_flop_speedup;
        return;
      }
    }
    L_ = analyse_with({CHOLMOD_AMD});
    if (!L_) throw SolverError("cholmod: symbolic analysis failed (status " + std::to_string(c_.status) + ")", 0, 0);
    if (c_.fl >= ordering_search_flops) {
      // CHOLMOD keeps the least fill of the methods it tries; AMD's is then found again (ms).
      cholmod_factor* best = analyse_with({CHOLMOD_AMD, CHOLMOD_METIS, CHOLMOD_NESDIS});
      if (!best) throw SolverError("cholmod: symbolic analysis failed (status " + std::to_string(c_.status) + ")", 0, 0);
      cholmod_free_factor(&L_, &c_);
      L_ = best;
    }
    if (L_->is_super) build_permuted();
    setup_cost_ = c_.fl / iteration_flops(c_.lnz) / factor_flop_speedup;
  }

  /// A numeric factorization's cost in PCG iterations (flop counts of the analysis; measured
  /// against CPU times in docs/solvers.md). Deterministic: KeptPcg's refresh rule uses it.
  [[nodiscard]] double setup_cost() const { return setup_cost_; }

  /// Numeric factorization of K's current values; throws SolverError naming the node and axis
  /// where a pivot was not positive.
  void factorize(const char* who, bool keep_values) {
    valid_ = false;
    if (blocks_) {
      factorize_blocks(who, keep_values);
      return;
    }
    bool ok = false;
    {
      const SerialLibraryRegions serial;  // one thread means one: CHOLMOD's own regions too
      if (S_) {
        // What cholmod_factorize does for a supernodal factor of an upper-triangular K, less
        // its permuted transpose of K (rebuilt, allocated and freed at every call): the values
        // go straight to their places in tril(PKPᵀ) (build_permuted()).
        const auto* kx = static_cast<const double*>(K_->x);
        auto* sx = static_cast<double*>(S_->x);
        for (std::size_t e = 0; e < to_s_.size(); ++e) sx[to_s_[e]] = kx[e];
        double zero[2] = {0.0, 0.0};
        ok = cholmod_super_numeric(S_, nullptr, zero, L_, &c_) && c_.status == CHOLMOD_OK;
      } else {
        ok = cholmod_factorize(K_, L_, &c_) && c_.status == CHOLMOD_OK;
      }
    }
    const std::size_t bad_pivot = ok ? nonpositive_pivot() : L_->minor;
    if (!ok && c_.status != CHOLMOD_NOT_POSDEF)
      throw SolverError(std::string(who) + ": CHOLMOD factorization failed (status " + std::to_string(c_.status) + ")", 0, 0);
    if (!ok || bad_pivot < L_->n) {
      // The pivot is counted in the fill-reducing order; Perm maps it back to the unknown.
      const auto* perm = static_cast<const int*>(L_->Perm);
      const std::size_t dof = (perm && bad_pivot < L_->n) ? static_cast<std::size_t>(perm[bad_pivot]) : bad_pivot;
      throw SolverError(std::string(who) + ": the matrix is not positive definite on the free axes (Cholesky pivot " +
                            std::to_string(bad_pivot) + " of " + std::to_string(L_->n) + " failed at node " +
                            std::to_string(dof / 3) + ", axis " + "xyz"[dof % 3] + ")",
                        0, 0);
    }
    // The triangular solves are memory bound (docs/solvers.md, "The N = 8 cantilever"): in
    // single precision they stream half the bytes (the N = 8 cantilever's step 1.7x faster in
    // CPU time under load, CG's iterations 6.0 -> 6.2 a step), at the cost of one O(entries)
    // copy per factorization. A simplicial analysis (small or very sparse matrices), or a factor
    // whose values float cannot hold (assign() says), keeps CHOLMOD's own double solves.
    if (!(single_solves_ && L_->is_super && single_.assign(*L_))) single_.clear();
    if (keep_values) factored_.assign(static_cast<const double*>(K_->x), static_cast<const double*>(K_->x) + src_.size());
    valid_ = true;
  }

  /// Records K's current values as factored by another engine (the direct backend's
  /// BlockCholesky): factor_matches_values() then compares with them. O(entries).
  void values_factored_elsewhere() {
    factored_.assign(static_cast<const double*>(K_->x), static_cast<const double*>(K_->x) + src_.size());
    valid_ = true;
  }
  /// The analysis's flop count of one numeric factorization (CHOLMOD's). O(1).
  [[nodiscard]] double flops() const { return c_.fl; }
  /// True if the factor is BlockCholesky's (analyse()). O(1).
  [[nodiscard]] bool blocks() const { return blocks_; }

  /// K's values when last factored (kept if factorize() was asked to). O(1).
  [[nodiscard]] const std::vector<double>& factored_values() const { return factored_; }

  /// Factors `values` as K's on A's pattern: how a kept factorization is taken up again.
  /// Throws InputError if their count is not the pattern's. O(one factorization).
  void factor_values(const BlockMatrix& A, std::span<const double> values, const char* who) {
    sync_pattern(A);
    if (values.size() != src_.size())
      throw InputError(std::string(who) + ": " + std::to_string(values.size()) + " factored values for a pattern of " +
                       std::to_string(src_.size()) + " entries");
    if (!analysed()) analyse();
    std::copy(values.begin(), values.end(), static_cast<double*>(K_->x));
    factorize(who, true);
  }

  [[nodiscard]] bool valid() const { return valid_; }
  /// True once analyse() ran on the current pattern (sync_pattern() drops it).
  [[nodiscard]] bool analysed() const { return L_ != nullptr || (blocks_ && block_.analysed_for(kb_)); }
  void invalidate() { valid_ = false; }
  void forget() {
    free_factor();
    if (K_) cholmod_free_sparse(&K_, &c_);
    pattern_ = 0;
  }

  /// out = K⁻¹ rhs (3n values each; may alias). Two triangular solves, no allocation once sized.
  void solve(std::span<const double> rhs, std::span<double> out) {
    if (blocks_) {
      block_.solve(rhs, out);
      return;
    }
    if (!single_.empty()) {
      single_.solve(rhs, out);
      return;
    }
    const SerialLibraryRegions serial;  // CHOLMOD's supernodal solves open regions too
    cholmod_dense B{};
    B.nrow = rhs.size();
    B.ncol = 1;
    B.nzmax = rhs.size();
    B.d = rhs.size();
    B.x = const_cast<double*>(rhs.data());  // read only by cholmod_solve2
    B.xtype = CHOLMOD_REAL;
    B.dtype = CHOLMOD_DOUBLE;
    if (!cholmod_solve2(CHOLMOD_A, L_, &B, nullptr, &X_, nullptr, &Y_, &E_, &c_))
      throw SolverError("cholmod: triangular solve failed (status " + std::to_string(c_.status) + ")", 0, 0);
    std::copy_n(static_cast<const double*>(X_->x), out.size(), out.data());
  }

 private:
  // One PCG iteration's flops with a factor of `entries` scalars: two triangular solves (2 flops
  // per entry each), the product with A (2 per stored scalar, both triangles) and the vector
  // passes (~10 per unknown).
  [[nodiscard]] double iteration_flops(double entries) const {
    const double n = static_cast<double>(3 * std::size_t{kb_.size()}), upper = static_cast<double>(src_.size());
    return 4.0 * entries + 2.0 * (2.0 * upper - n) + 10.0 * n;
  }
  // factorize() with BlockCholesky: K's values into both triangles of kb_, factored as they are
  // (all axes free: K's fixed rows are already identity rows).
  void factorize_blocks(const char* who, bool keep_values) {
    const auto* kx = static_cast<const double*>(K_->x);
    double* kv = kb_.num_blocks() ? kb_.block_data(0) : nullptr;
    for (std::size_t e = 0; e < src_.size(); ++e) kv[src_[e]] = kv[mirror_[e]] = kx[e];
    block_.factorize(kb_, ones_, who);
    if (keep_values) factored_.assign(kx, kx + src_.size());
    valid_ = true;
  }
  // A simplicial LDLᵀ factor (if CHOLMOD left one despite final_ll) with a pivot d_j ≤ 0: j, else n.
  [[nodiscard]] std::size_t nonpositive_pivot() const {
    if (L_->is_super || L_->is_ll) return L_->n;
    const auto* lp = static_cast<const int*>(L_->p);
    const auto* lx = static_cast<const double*>(L_->x);
    for (std::size_t j = 0; j < L_->n; ++j)
      if (!(lx[lp[j]] > 0.0)) return j;
    return L_->n;
  }
  // cholmod_analyze with these orderings tried (c_.fl and c_.lnz then describe its choice).
  cholmod_factor* analyse_with(std::initializer_list<int> orderings) {
    c_.nmethods = static_cast<int>(orderings.size());
    int k = 0;
    for (const int o : orderings) c_.method[k++].ordering = o;
    return cholmod_analyze(K_, &c_);
  }
  // S_ = tril(P K Pᵀ) (P the analysis's ordering, L_->Perm) in sorted CSC, what
  // cholmod_super_numeric factors, and to_s_: each entry of K's place in it. O(entries log).
  void build_permuted() {
    const std::size_t n = L_->n;
    const auto* perm = static_cast<const int*>(L_->Perm);
    std::vector<int> pinv(n);
    for (std::size_t k = 0; k < n; ++k) pinv[static_cast<std::size_t>(perm[k])] = static_cast<int>(k);
    const auto* kp = static_cast<const int*>(K_->p);
    const auto* ki = static_cast<const int*>(K_->i);
    const std::size_t nz = src_.size();
    // (column, row, K entry) of each entry in the permuted lower triangle, sorted column-major
    std::vector<std::array<int, 3>> at(nz);
    for (std::size_t c = 0; c < n; ++c)
      for (int e = kp[c]; e < kp[c + 1]; ++e) {
        const int pr = pinv[static_cast<std::size_t>(ki[e])], pc = pinv[c];
        at[static_cast<std::size_t>(e)] = {std::min(pr, pc), std::max(pr, pc), e};
      }
    std::sort(at.begin(), at.end());
    S_ = cholmod_allocate_sparse(n, n, nz, 1, 1, -1, CHOLMOD_REAL, &c_);
    if (!S_) throw SolverError("cholmod: out of memory for a matrix of " + std::to_string(nz) + " entries", 0, 0);
    auto* sp = static_cast<int*>(S_->p);
    auto* si = static_cast<int*>(S_->i);
    std::fill(sp, sp + n + 1, 0);
    to_s_.resize(nz);
    for (std::size_t q = 0; q < nz; ++q) {
      ++sp[static_cast<std::size_t>(at[q][0]) + 1];
      si[q] = at[q][1];
      to_s_[static_cast<std::size_t>(at[q][2])] = static_cast<int>(q);
    }
    for (std::size_t c = 0; c < n; ++c) sp[c + 1] += sp[c];
  }
  void free_factor() {
    blocks_ = false;
    if (S_) cholmod_free_sparse(&S_, &c_);
    if (L_) cholmod_free_factor(&L_, &c_);
    single_.clear();
    valid_ = false;
  }

  cholmod_common c_{};
  cholmod_sparse* K_ = nullptr;
  cholmod_sparse* S_ = nullptr;  // tril(P K Pᵀ) of a supernodal analysis (build_permuted)
  cholmod_factor* L_ = nullptr;
  cholmod_dense *X_ = nullptr, *Y_ = nullptr, *E_ = nullptr;
  std::uint64_t pattern_ = 0;
  std::vector<std::size_t> src_;  // per entry of K: its index in A's value array
  std::vector<int> col_of_;       // per entry of K: its column
  std::vector<int> to_s_;         // per entry of K: its index in S_
  std::vector<double> factored_;  // K's values when last factored (direct backend)
  bool valid_ = false;
  bool single_solves_;
  FloatSupernodalFactor single_;  // L_'s values in single precision, when single_solves_ and L_ is supernodal
  double setup_cost_ = 0;
  bool may_block_;                 // BlockCholesky may factor (below block_flops_)
  double block_flops_ = SolverOptions{}.block_factor_flops;
  bool blocks_ = false;            // it does, for the current analysis
  solve::BlockCholesky block_;
  BlockMatrix kb_;                 // K on A's pattern, both triangles, for block_
  std::vector<std::size_t> mirror_;  // per entry of K: its transpose's index in kb_'s values
  std::vector<double> ones_;       // block_'s free-axis mask: K is already filtered
};

// r = S(b - A x̃), x̃ = x on the fixed axes and 0 on the free ones: what the free axes must solve.
void filtered_rhs(const BlockMatrix& A, std::span<const double> b, std::span<const double> x,
                  std::span<const double> free_dof, AlignedVector<double>& xt, AlignedVector<double>& r) {
  const std::size_t n3 = b.size();
  xt.resize(n3);
  r.resize(n3);
  bool any_fixed_value = false;
  for (std::size_t k = 0; k < n3; ++k) {
    xt[k] = free_dof[k] == 0.0 ? x[k] : 0.0;
    any_fixed_value |= xt[k] != 0.0;
  }
  if (any_fixed_value) A.multiply(xt, r);
  else std::fill(r.begin(), r.end(), 0.0);
  for (std::size_t k = 0; k < n3; ++k) r[k] = free_dof[k] * (b[k] - r[k]);
}

// ‖S(b - Ax)‖ and ‖Sb‖; r = S(b - Ax).
std::pair<double, double> residual(const BlockMatrix& A, std::span<const double> b, std::span<const double> x,
                                   std::span<const double> free_dof, AlignedVector<double>& tmp, AlignedVector<double>& r) {
  tmp.resize(b.size());
  r.resize(b.size());
  A.multiply(x, tmp);
  double rr = 0, bb = 0;
  for (std::size_t k = 0; k < b.size(); ++k) {
    r[k] = free_dof[k] * (b[k] - tmp[k]);
    rr += r[k] * r[k];
    bb += free_dof[k] * b[k] * b[k];
  }
  return {std::sqrt(rr), std::sqrt(bb)};
}

// Below SolverOptions::block_factor_flops both backends factor K with BlockCholesky instead of
// CHOLMOD (block_cholesky.hpp). Its first, 3×3-column version paid below 3e7 flops (whole scenes
// 0.79x to 0.98x the CPU time, CHOLMOD's supernodes too narrow for BLAS). Its supernodal version
// (Eigen's AVX-512 kernels) measured, interleaved, against CHOLMOD with its METIS/nested-
// dissection search, with OpenBLAS's AVX-512 kernels (OPENBLAS_CORETYPE=SkylakeX, what sewn run
// and the benchmarks select on the Xeon model 207) and, in brackets, its SSE3 fallback: the toy
// tunnel (5e7 flops) 1.03-1.06x a frame (1.26x), bench_solve's 8×8×10 beam at h = 1 ms 1.55x a
// step (2.2x), the N = 8 cantilever (3.9e6 entries of L) 1.25-1.56x (2.2x), same errors to
// round-off. The direct backend still runs CHOLMOD's analysis for the flop count; cholmod-pcg
// (docs/solvers.md) decides on BlockCholesky's analysis and skips CHOLMOD's.
class CholmodDirect final : public LinearSolver {
 public:
  static constexpr int max_refinements = 3;
  explicit CholmodDirect(SolverOptions o) : LinearSolver(o) {}
  [[nodiscard]] Backend backend() const override { return Backend::cholmod; }
  void reset() override { f_.forget(); }

  SolveReport solve(const BlockMatrix& A, std::span<const double> b, std::span<double> x, std::span<const double> free_dof,
                    std::span<const double> mass_scale) override {
    check_sizes("cholmod solve", A, b, x, free_dof, mass_scale);
    SolveReport rep;
    rep.backend = Backend::cholmod;
    auto t = Clock::now();
    f_.sync_pattern(A);
    f_.fill_values(A, free_dof);
    if (!f_.analysed()) {
      f_.analyse();
      rep.symbolic_analyses = 1;
      rep.analyse_ms = ms_since(t);
      t = Clock::now();
    }
    if (!f_.factor_matches_values()) {
      blocks_ = f_.flops() < opt_.block_factor_flops;
      if (blocks_) {
        f_.invalidate();
        block_.factorize(A, free_dof, "cholmod solve");
        f_.values_factored_elsewhere();
      } else {
        f_.factorize("cholmod solve", true);
      }
      rep.factorizations = 1;
      rep.factor_ms = ms_since(t);
      t = Clock::now();
    }
    filtered_rhs(A, b, x, free_dof, xt_, r_);
    triangular_solves(r_);
    for (std::size_t k = 0; k < x.size(); ++k)
      if (free_dof[k] != 0.0) x[k] = r_[k];
    // Iterative refinement: an ill-conditioned matrix (large steps on stiff, slender meshes)
    // leaves a residual of cond·ε after one solve; each refinement costs two triangular solves.
    // A pass that did not halve the residual found its round-off floor (the residual's own
    // rounding, ε‖A‖‖x‖): further passes only move x by round-off, so refinement stops there,
    // LAPACK's rule (dgerfs). On the toy ball's Newton matrices the first pass takes the
    // relative residual from ~1e-11 to ~4e-12, the next two leave it there (±10 %).
    const double floor = absolute_floor(opt_, free_dof, mass_scale);
    double last = std::numeric_limits<double>::infinity();
    for (int pass = 0;; ++pass) {
      const auto [res, bn] = residual(A, b, x, free_dof, xt_, r_);
      rep.residual = res;
      rep.relative_residual = bn > 0 ? res / bn : 0.0;
      rep.converged = std::isfinite(res) && (res <= opt_.tolerance * bn || res <= floor);
      const bool stalled = !(res <= 0.5 * last);
      last = res;
      if (rep.converged || pass == max_refinements || stalled || !std::isfinite(res)) break;
      triangular_solves(r_);
      for (std::size_t k = 0; k < x.size(); ++k) x[k] += free_dof[k] * r_[k];
      ++rep.iterations;
    }
    rep.solve_ms = ms_since(t);
    return rep;
  }

 private:
  // r = K⁻¹ r with the engine that factored K
  void triangular_solves(AlignedVector<double>& r) {
    if (blocks_) block_.solve(r, r);
    else f_.solve(r, r);
  }

  // double solves: the refinement passes need the factor's full precision; CHOLMOD's own
  Factorization f_{false, false};
  // Below opt_.block_factor_flops, the supernodal block factorization of the same K (block_cholesky.hpp);
  // CHOLMOD's analysis is kept for its flop count and K's values for factor_matches_values().
  solve::BlockCholesky block_;
  bool blocks_ = false;
  AlignedVector<double> xt_, r_;
};

}  // namespace

std::unique_ptr<LinearSolver> make_cholmod(SolverOptions o) { return std::make_unique<CholmodDirect>(o); }
std::unique_ptr<LinearSolver> make_cholmod_pcg(SolverOptions o) {
  return std::make_unique<KeptPcg<Factorization>>(o, Backend::cholmod_pcg, "cholmod-pcg");
}

}  // namespace sewn::physics::solve::detail
