// The `auto` backend: block-Jacobi CG, which needs no set-up and wins wherever a model's mass
// keeps its systems well conditioned, until one solve shows the model stiff against its mass
// (more than auto_switch_iterations CG iterations) on a model small enough for a kept
// factorization; from then on cholmod-pcg, whose factor, kept across steps, brings the
// iterations down to a few. Measured in bench/solve (docs/solvers.md): on the N = 8
// cantilever at h = 10 ms (6561 nodes) block-Jacobi needs ~590 iterations a step and
// cholmod-pcg is 1.6x faster; on the beams at h = 1 ms (12-40 iterations) and on 16³ at
// h = 0.1 ms (51 iterations, cholmod-pcg 5x slower) block-Jacobi stays; beyond
// auto_factor_nodes (the N = 16 cantilever, 32³) the factor takes minutes and GBs: block-Jacobi.
// A new pattern starts the decision over.

#include <cstdint>
#include <memory>

#include "backends.hpp"

namespace sewn::physics::solve::detail {

namespace {

// The iteration count that proves a model stiff: above every well-conditioned case of the
// suite (the beams: 12-106, 16³ and 32³: 20-51) and below the stiff ones (the N = 2 cantilever
// of the smoke run: 136, N = 8: ~590).
constexpr int auto_switch_iterations = 120;
// The largest model auto factors: the N = 8 cantilever (6561 nodes, a factor of ~13 ms in
// single precision) is the largest the suite factors within its budget; CHOLMOD counts
// 2.0e11 flops for the N = 16 one (46 529 nodes) and 7.1e9 already for 16³ (4913 nodes, but
// a cube fills in far more than a slender beam), so the limit is conservative.
constexpr std::size_t auto_factor_nodes = 8000;

class AutoSolver final : public LinearSolver {
 public:
  explicit AutoSolver(SolverOptions o) : LinearSolver(o), jacobi_(make_jacobi(o)) {}
  [[nodiscard]] Backend backend() const override { return switched_ ? Backend::cholmod_pcg : Backend::jacobi; }

  SolveReport solve(const BlockMatrix& A, std::span<const double> b, std::span<double> x, std::span<const double> free_dof,
                    std::span<const double> mass_scale) override {
    if (have_pattern_ && A.pattern_version() != pattern_) forget_switch();
    pattern_ = A.pattern_version();
    have_pattern_ = true;
    LinearSolver& s = current();
    s.options() = opt_;
    const SolveReport r = s.solve(A, b, x, free_dof, mass_scale);
    if (!switched_ && r.iterations > auto_switch_iterations && can_factor(A)) switched_ = true;
    return r;
  }
  // The decision is not a factorization: it stays, the kept factor goes.
  void reset() override {
    if (pcg_) pcg_->reset();
  }
  void set_coordinates(std::span<const double> xyz) override { current().set_coordinates(xyz); }
  // Block-Jacobi keeps nothing, so an empty state means "not switched"; once switched the
  // state is cholmod-pcg's, or "a set-up is due" before its first solve.
  [[nodiscard]] SolverState state() const override {
    if (!switched_) return {};
    if (pcg_) return pcg_->state();
    SolverState s;
    s.refresh_due = true;
    return s;
  }
  void restore(const BlockMatrix& A, const SolverState& s) override {
    forget_switch();
    pattern_ = A.pattern_version();
    have_pattern_ = true;
    switched_ = !s.factored.empty() || s.refresh_due;
    if (switched_) current().restore(A, s);
  }

 private:
  [[nodiscard]] static bool can_factor(const BlockMatrix& A) {
    return available(Backend::cholmod_pcg) && static_cast<std::size_t>(A.size()) <= auto_factor_nodes;
  }
  // A new pattern (a cut, a refinement) decides afresh, starting from block-Jacobi: the
  // integrators keep no solver state across a topology change (a checkpoint taken after a cut
  // resumes with a fresh solver), so a run and its resumed copy decide the same.
  void forget_switch() {
    switched_ = false;
    pcg_.reset();
  }
  LinearSolver& current() {
#ifdef SEWN_HAVE_CHOLMOD
    if (switched_) {
      if (!pcg_) pcg_ = make_cholmod_pcg(opt_);
      return *pcg_;
    }
#endif
    return *jacobi_;
  }

  std::unique_ptr<LinearSolver> jacobi_, pcg_;
  bool switched_ = false, have_pattern_ = false;
  std::uint64_t pattern_ = 0;
};

}  // namespace

std::unique_ptr<LinearSolver> make_auto(SolverOptions o) { return std::make_unique<AutoSolver>(o); }

}  // namespace sewn::physics::solve::detail
