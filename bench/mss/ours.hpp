#pragma once
// "Ours": a ModelSpec built with the library, as a physics::System stepped by the library's
// integrators. Everything the suite needs besides stepping (state by mesh point, forces,
// the implicit system for cross-checks) goes through this class, so the builder behind it
// changes in one place.

#include <cstdint>
#include <memory>
#include <span>
#include <vector>

#include "model.hpp"
#include "sewn/physics/mss_model.hpp"
#include "sewn/physics/physics.hpp"

namespace sewn::bench::mss {

class Ours {
 public:
  explicit Ours(const ModelSpec& spec);
  Ours(const Ours&) = delete;
  Ours& operator=(const Ours&) = delete;
  ~Ours();

  [[nodiscard]] physics::System& system();
  /// The model on the map behind the system.
  [[nodiscard]] const physics::MssModel<3>& model() const;
  [[nodiscard]] physics::MssModel<3>& model();
  /// The node of mesh point p.
  [[nodiscard]] physics::Index node(std::uint32_t p) const;
  [[nodiscard]] Counts counts() const;
  /// Name of the builder behind "ours", for the report.
  [[nodiscard]] static const char* builder();

  void set_state(const State& s);
  [[nodiscard]] State state() const;
  /// Remembers the current positions and velocities / puts them back (node order, O(n) copies).
  void save();
  void restore();
  /// Forces at the current state, per mesh point (fixed points included).
  [[nodiscard]] std::vector<double> forces();
  [[nodiscard]] std::vector<double> masses() const;
  /// The library's implicit system at the current state, assembled as LinearlyImplicitEuler
  /// assembles it (see LinearSystemSample).
  [[nodiscard]] LinearSystemSample linear_system(double h, std::span<const double> p);
  [[nodiscard]] double max_abs_position() const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace sewn::bench::mss
