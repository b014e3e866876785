#pragma once
// A regular box lattice built straight into a System, without the combinatorial map: nx×ny×nz
// boxes of size lx×ly×lz, one node per grid point, one spring per grid edge (Baudet stiffness
// summed over the boxes sharing the edge) and 4 body-diagonal springs per box, masses lumped
// ρV/8 per corner. It is the reference the map-based builder must reproduce (same counts and
// values), and what benchmarks and tests use.

#include "sewn/physics/springs.hpp"
#include "sewn/physics/system.hpp"

namespace sewn::physics {

struct BoxLatticeSpec {
  Index nx = 1, ny = 1, nz = 1;        ///< boxes per axis (≥ 1)
  double lx = 1, ly = 1, lz = 1;       ///< box size, m
  double E = 1, nu = 0.3, rho = 1;     ///< Pa, -, kg/m³
  SpringDamping damping = SpringDamping::none;
  double rayleigh_beta = 0;            ///< for SpringDamping::stiffness_proportional
};

struct BoxLattice {
  Springs* springs = nullptr;  ///< the term added to the system
  Index first_node = 0;        ///< index of grid point (0, 0, 0)
  Index nx = 0, ny = 0, nz = 0;
  Index edge_springs = 0, diagonal_springs = 0;
  /// Node of grid point (i, j, k), 0 ≤ i ≤ nx, ...
  [[nodiscard]] Index node(Index i, Index j, Index k) const { return first_node + i + (nx + 1) * (j + (ny + 1) * k); }
};

/// Adds the lattice's nodes and a Springs term to sys (grid points in x-fastest order; edges
/// along x, y, z point by point, then 4 diagonals per box; γ from paper_viscosity when
/// spec.damping is viscous). Throws InputError if the Baudet edge stiffness of the box is not
/// positive (elongated box; the message gives the values) or on bad sizes/material. O(boxes).
BoxLattice build_box_lattice(System& sys, const BoxLatticeSpec& spec);

}  // namespace sewn::physics
