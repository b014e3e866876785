#pragma once
// Internal: a copy of a supernodal CHOLMOD factor with its values rounded to single precision,
// and the two triangular solves on it (cholmod-pcg's preconditioner on large factors).
//
// Why: a kept factor's triangular solves are memory bound. On the N = 8 cantilever (19 683
// unknowns, 3.9e6 entries in L) the double factor's values take 31 MB, about this machine's
// whole 32 MB L3, so every CG iteration streams them twice from memory; in float they take half
// (docs/solvers.md, "Single-precision triangular solves"). As a preconditioner the rounding
// costs little: it perturbs P⁻¹ by ~1e-7 relative, far less than a kept factor of an earlier
// matrix already does, and CG corrects both (6.0 -> 6.2 iterations a step there). The arithmetic stays in double (only the stored values are
// float), so the solves are as stable as the double ones on the rounded factor.

#include <cholmod.h>

#include <cstddef>
#include <span>
#include <vector>

namespace sewn::physics::solve::detail {

class FloatSupernodalFactor {
 public:
  /// Copies L (a numeric supernodal LLᵀ factor) with its values rounded to float. Returns false
  /// (the copy is then unusable: clear() it) if a value overflows float or a diagonal entry
  /// falls below float's smallest normal number (a matrix in extreme units). O(entries).
  [[nodiscard]] bool assign(const cholmod_factor& L);
  /// Drops the copy. O(1).
  void clear();
  [[nodiscard]] bool empty() const { return super_.empty(); }
  /// out = (L Lᵀ)⁻¹ rhs in the original order (Perm applied); rhs and out may alias. 3n values.
  /// Two sweeps over the values, no allocation once sized.
  void solve(std::span<const double> rhs, std::span<double> out);

 private:
  std::vector<int> super_, s_, perm_;
  std::vector<std::size_t> pi_, px_;
  std::vector<float> x_;
  std::vector<double> y_, w_;  // the permuted vector; one supernode's rows
};

}  // namespace sewn::physics::solve::detail
