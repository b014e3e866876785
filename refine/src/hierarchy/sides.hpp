#pragma once
// Walking an element's sides (hierarchical edges) on the map: its corner darts and the
// middle-dart search of PHYSICS_NOTES §2.3, in integer dyadic sums.

#include <array>
#include <cstdint>
#include <stdexcept>
#include <string>

#include "sewn/physics/mss_model.hpp"

namespace sewn::refine::detail {

/// Σ 1/l_e in units of 2^-40: exact for every level up to 2^40.
inline constexpr std::uint64_t whole = std::uint64_t{1} << 40;

template <int D>
std::uint32_t edge_level(const physics::MssModel<D>& m, Dart d) {
  return m.map().value(m.map().template attribute<1>(d)).level;
}

/// The 4 hierarchical darts of a quad's face ring, in β1 order from its canonical dart.
template <int D>
std::array<Dart, 4> corner_darts(const physics::MssModel<D>& m, const physics::Element& el) {
  std::array<Dart, 4> c{};
  int n = 0;
  Dart x = el.dart;
  do {
    if (m.is_corner_dart(x)) {
      if (n == 4) throw std::logic_error("refine: a quad's face ring has more than 4 corner darts");
      c[static_cast<std::size_t>(n++)] = x;
    }
    x = m.map().beta(x, 1);
  } while (x != el.dart && !x.is_null());
  if (n != 4) throw std::logic_error("refine: a quad's face ring has " + std::to_string(n) + " corner darts");
  return c;
}

struct Middle {
  Dart dart;  ///< the side's dart starting at its middle; null if the side is one edge
};

/// The middle-dart search: from the side's hierarchical dart c, accumulate 1/l_e until half of
/// the side (1/(2 l_E)) is reached. Null when the side is still a single edge.
template <int D>
Middle middle_of_side(const physics::MssModel<D>& m, Dart c, std::uint32_t element_level) {
  const std::uint64_t half = whole / (2 * std::uint64_t{element_level});
  std::uint64_t acc = 0;
  Dart x = c;
  while (acc < half) {
    acc += whole / edge_level(m, x);
    x = m.map().beta(x, 1);
    if (acc < half && m.is_corner_dart(x))
      throw std::logic_error("refine: a side ends before its middle (edge levels inconsistent)");
  }
  if (acc != half && acc != 2 * half)
    throw std::logic_error("refine: the middle of a side falls inside a sub-edge (edge levels inconsistent)");
  return acc == half ? Middle{x} : Middle{};
}

}  // namespace sewn::refine::detail
