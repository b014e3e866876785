#pragma once
// Basic vocabulary of sewn::physics: node and element indices, axis masks, the state view
// that force terms read.

#include <cstdint>
#include <limits>
#include <span>

namespace sewn::physics {

/// Index of a node, spring or other element. Dense: 0..size()-1.
using Index = std::uint32_t;
/// "No index" (removed node in an old->new map, absent block in a pattern).
inline constexpr Index invalid_index = std::numeric_limits<Index>::max();

/// Bit set of axes: bit 0 = x, bit 1 = y, bit 2 = z.
using AxisMask = std::uint8_t;
inline constexpr AxisMask axis_x = 1, axis_y = 2, axis_z = 4, all_axes = 7, no_axes = 0;

/// Read-only view of a state that force terms evaluate: 3n positions and velocities (node i
/// at [3i, 3i+3)), n masses, and the scalar angle DOFs beyond positions (rods' twist angles,
/// System::angles(); empty when there are none). Terms never read the node table directly, so
/// integrators can evaluate forces at trial states.
///
/// Force arrays that go with a state have 3n entries, followed by one generalised force
/// (torque, N·m) per angle when the integrator integrates angles: a term writes angle a's
/// torque at f[3n + a] only if f has those entries.
struct StateView {
  std::span<const double> x;
  std::span<const double> v;
  std::span<const double> mass;
  std::span<const double> angles{};       ///< rad
  std::span<const double> angle_rates{};  ///< rad/s
  [[nodiscard]] Index size() const { return static_cast<Index>(mass.size()); }
};

}  // namespace sewn::physics
