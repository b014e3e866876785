#pragma once
// Internal: CG preconditioned by something set up from a recent matrix and kept across solves
// (a Cholesky factorization, an algebraic multigrid hierarchy), refreshed when CG slows down.
// The backends cholmod-pcg and hypre-pcg are KeptPcg over their preconditioner.

#include <algorithm>
#include <cstdint>
#include <functional>
#include <span>
#include <string>
#include <vector>

#include "backends.hpp"
#include "fine_level.hpp"
#include "sewn/physics/aligned.hpp"
#include "sewn/physics/errors.hpp"

namespace sewn::physics::solve::detail {

struct PcgWorkspace {
  AlignedVector<double> r, z, p, q, x;
};

/// What pcg_with() ended with.
struct PcgOutcome {
  int iterations = 0;
  double residual = 0, relative_residual = 0;
  bool converged = false;
  bool breakdown = false;  ///< pᵀAp ≤ 0 or rᵀz ≤ 0: the matrix or the preconditioner is not positive definite
};

/// Filtered PCG (PHYSICS_NOTES §1.5) with z = S P⁻¹ r, P⁻¹ applied by `precondition(r, z)`
/// (it may leave anything on the fixed axes: they are zeroed after). Stops when
/// ‖S(b - Ax)‖ ≤ max(tolerance · ‖Sb‖, floor). Deterministic. O(iterations · (product + P⁻¹)).
PcgOutcome pcg_with(const BlockMatrix& A, std::span<const double> b, std::span<double> x, std::span<const double> free_dof,
                    double tolerance, double floor, int max_iterations,
                    const std::function<void(std::span<const double>, std::span<double>)>& precondition, PcgWorkspace& ws);

/// pcg_with on vectors padded to 4 doubles a node, A applied by `fine` (bound to the solve's
/// matrix) and P⁻¹ by `precondition(r4, z4)`: the layout of the packed symmetric product, so that
/// a preconditioner working on it (sa-pcg's V-cycle) needs no copies. Same stopping rule.
PcgOutcome pcg_padded(FineLevel& fine, std::span<const double> b, std::span<double> x, std::span<const double> free_dof,
                      double tolerance, double floor, int max_iterations,
                      const std::function<void(const double*, double*)>& precondition, PcgWorkspace& ws);

/// The preconditioner P must offer (see Factorization in cholmod.cpp, AmgHierarchy in hypre.cpp):
///   bool sync_pattern(A)           rebuild for A's pattern if it changed; true then
///   bool analysed(), void analyse() the per-pattern set-up
///   void fill_values(A, free_dof)  the filtered matrix S A S + (I - S) from A
///   void factorize(who, keep)      the per-values set-up (throws SolverError if not SPD)
///   double setup_cost()            the per-values set-up's cost in CG iterations (deterministic)
///   bool valid(); const std::vector<double>& factored_values()
///   void factor_values(A, values, who); void forget(); void solve(r, z)
/// and may offer (SaPreconditioner in sa_pcg.cpp):
///   void configure(options)         the solver's options, before a set-up
///   void set_coordinates(xyz)       the nodes' positions, for the next set-up
///   void bind(A, free_dof)          the matrix of the solve about to run
///   FineLevel& fine(); void solve4(r4, z4)  that matrix and P⁻¹ on padded vectors: CG runs
///                                   on them (pcg_padded)
template <class P>
class KeptPcg final : public LinearSolver {
 public:
  KeptPcg(SolverOptions o, Backend tag, const char* who) : LinearSolver(o), tag_(tag), who_(who) {}
  [[nodiscard]] Backend backend() const override { return tag_; }
  void reset() override {
    p_.forget();
    stale_ = false;
    cycle_solves_ = cycle_iterations_ = 0;
  }
  [[nodiscard]] SolverState state() const override {
    SolverState s;
    if (p_.valid()) s.factored = p_.factored_values();
    s.refresh_due = stale_;
    s.cycle_solves = cycle_solves_;
    s.cycle_iterations = cycle_iterations_;
    return s;
  }
  void restore(const BlockMatrix& A, const SolverState& s) override {
    p_.forget();
    configure();
    if (!s.factored.empty()) p_.factor_values(A, s.factored, (who_ + " restore").c_str());
    stale_ = s.refresh_due;
    cycle_solves_ = s.cycle_solves;
    cycle_iterations_ = s.cycle_iterations;
  }
  void set_coordinates(std::span<const double> xyz) override {
    if constexpr (requires { p_.set_coordinates(xyz); }) p_.set_coordinates(xyz);
  }

  SolveReport solve(const BlockMatrix& A, std::span<const double> b, std::span<double> x, std::span<const double> free_dof,
                    std::span<const double> mass_scale) override {
    check_sizes((who_ + " solve").c_str(), A, b, x, free_dof, mass_scale);
    SolveReport rep;
    rep.backend = tag_;
    const double floor = absolute_floor(opt_, free_dof, mass_scale);
    configure();
    if (p_.sync_pattern(A) || !p_.valid() || stale_) refresh(A, free_dof, rep);
    if constexpr (requires { p_.bind(A, free_dof); }) p_.bind(A, free_dof);  // a preconditioner that also uses A itself
    x0_.assign(x.begin(), x.end());
    auto t = Clock::now();
    PcgOutcome out = run(A, b, x, free_dof, floor);
    rep.solve_ms += ms_since(t);
    if ((!out.converged || out.breakdown) && rep.factorizations == 0) {
      // The kept preconditioner no longer serves: refresh it and start over.
      std::copy(x0_.begin(), x0_.end(), x.begin());
      refresh(A, free_dof, rep);
      const int before = out.iterations;
      t = Clock::now();
      out = run(A, b, x, free_dof, floor);
      out.iterations += before;
      rep.solve_ms += ms_since(t);
    }
    rep.iterations = out.iterations;
    rep.residual = out.residual;
    rep.relative_residual = out.relative_residual;
    rep.converged = out.converged;
    stale_ = refresh_pays(rep.iterations);
    if (out.breakdown)
      throw SolverError(who_ + " solve: CG broke down (pᵀAp ≤ 0 or rᵀz ≤ 0) with a fresh preconditioner: the matrix is not "
                               "positive definite on the free axes",
                        rep.iterations, rep.relative_residual);
    return rep;
  }

 private:
  void configure() {
    if constexpr (requires { p_.configure(opt_); }) p_.configure(opt_);
  }
  PcgOutcome run(const BlockMatrix& A, std::span<const double> b, std::span<double> x, std::span<const double> free_dof,
                 double floor) {
    if constexpr (requires { p_.fine(); })
      return pcg_padded(p_.fine(), b, x, free_dof, opt_.tolerance, floor, opt_.max_iterations,
                        [this](const double* r, double* z) { p_.solve4(r, z); }, ws_);
    else
      return pcg_with(A, b, x, free_dof, opt_.tolerance, floor, opt_.max_iterations,
                    [this](std::span<const double> r, std::span<double> z) { p_.solve(r, z); }, ws_);
  }
  // The refresh rule. A cycle is a set-up and the solves that use it; its mean cost per solve,
  // (set-up + Σ iterations) / solves in CG iterations, falls while the solves stay cheaper than
  // that mean and rises once they cost more (iterations grow as A drifts from the matrix set up
  // on). So refresh once the last solve cost more than the cycle's mean: going on would raise
  // it, a new cycle starts low again. The margin of one iteration: at a steady distance from
  // the factored matrix the count still moves by one from solve to solve (0 and 1 on the
  // 8x8x10 beam), and without it a long cycle, whose mean has come down to that level, would
  // be refreshed for such noise. Iteration counts and the set-up's flop-based cost make the
  // decision deterministic (a rerun or a resumed checkpoint decides the same), unlike timings.
  // The option refresh_iterations > 0 adds a hard cap.
  bool refresh_pays(int iterations) {
    ++cycle_solves_;
    cycle_iterations_ += static_cast<std::uint64_t>(iterations);
    const double mean = (p_.setup_cost() + static_cast<double>(cycle_iterations_)) / static_cast<double>(cycle_solves_);
    return iterations > mean + 1.0 || (opt_.refresh_iterations > 0 && iterations > opt_.refresh_iterations);
  }
  void refresh(const BlockMatrix& A, std::span<const double> free_dof, SolveReport& rep) {
    auto t = Clock::now();
    if (!p_.analysed()) {
      p_.analyse();
      rep.symbolic_analyses = 1;
      rep.analyse_ms += ms_since(t);
      t = Clock::now();
    }
    p_.fill_values(A, free_dof);
    p_.factorize((who_ + " solve").c_str(), true);  // the values are kept for state()
    ++rep.factorizations;
    rep.factor_ms += ms_since(t);
    stale_ = false;
    cycle_solves_ = cycle_iterations_ = 0;
  }

  Backend tag_;
  std::string who_;
  P p_;
  bool stale_ = false;
  std::uint64_t cycle_solves_ = 0, cycle_iterations_ = 0;  // since the last set-up (refresh_pays)
  PcgWorkspace ws_;
  std::vector<double> x0_;
};

}  // namespace sewn::physics::solve::detail
