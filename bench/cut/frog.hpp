#pragma once
// A procedural stand-in for the 2013 paper's frog (Fig. 9): a hexahedral mesh with exactly its
// counts, 26 125 hexahedra and 32 934 particles, so that cutting and stepping it costs what the
// paper's mesh would. The real mesh is not available; see frog.cpp for the shape.

#include <cstdint>

#include "sewn/cmap/mesh.hpp"

namespace sewn::bench::cut {

inline constexpr std::uint32_t frog_hexahedra = 26125;
inline constexpr std::uint32_t frog_particles = 32934;

/// The frog as cubes of side `a` (m) on an integer lattice: body along x, head at +x, legs at
/// the sides, belly on z = 0. Throws std::logic_error if its counts are not the paper's.
IndexedMesh frog_mesh(double a);

/// The frog's body spans cells [0, body_cells[k]) along axis k (the rest sticks out of it).
inline constexpr std::uint32_t frog_body_cells[3] = {76, 55, 5};

}  // namespace sewn::bench::cut
