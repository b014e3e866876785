#pragma once
// Exceptions of sewn::physics. Every message names what is wrong and where (function, node,
// spring, value).

#include <cstdint>
#include <limits>
#include <stdexcept>
#include <string>

#include "sewn/physics/types.hpp"

namespace sewn::physics {

/// Bad input: negative or NaN mass, index out of range, ν ∉ (-1, 0.5), E ≤ 0, h ≤ 0, ...
/// Thrown before anything is changed.
class InputError : public std::invalid_argument {
 public:
  using std::invalid_argument::invalid_argument;
};

/// A semi-implicit step larger than the stable-step bound was asked for. The state is unchanged.
class StabilityError : public std::runtime_error {
 public:
  StabilityError(const std::string& what, double h, double bound)
      : std::runtime_error(what), h_(h), bound_(bound) {}
  [[nodiscard]] double step() const { return h_; }
  [[nodiscard]] double bound() const { return bound_; }

 private:
  double h_, bound_;
};

/// The state became non-finite or the energy grew beyond its budget. `node()` names the node
/// (invalid_index if none applies), `quantity()` the offending quantity ("position", ...);
/// an energy blow-up also gives the integrator's step count and a step to retry with (NaN
/// when the integrator has none to suggest).
class BlowupError : public std::runtime_error {
 public:
  BlowupError(const std::string& what, Index node, std::string quantity, std::uint64_t step = 0,
              double suggested_step = std::numeric_limits<double>::quiet_NaN())
      : std::runtime_error(what), node_(node), quantity_(std::move(quantity)), step_(step), suggested_(suggested_step) {}
  [[nodiscard]] Index node() const { return node_; }
  [[nodiscard]] const std::string& quantity() const { return quantity_; }
  [[nodiscard]] std::uint64_t step() const { return step_; }
  [[nodiscard]] double suggested_step() const { return suggested_; }

 private:
  Index node_;
  std::string quantity_;
  std::uint64_t step_;
  double suggested_;
};

/// A linear solve did not reach its tolerance (or broke down on a matrix that is not positive
/// definite). The state is unchanged.
class SolverError : public std::runtime_error {
 public:
  SolverError(const std::string& what, int iterations, double residual)
      : std::runtime_error(what), iterations_(iterations), residual_(residual) {}
  [[nodiscard]] int iterations() const { return iterations_; }
  [[nodiscard]] double residual() const { return residual_; }

 private:
  int iterations_;
  double residual_;
};

}  // namespace sewn::physics
