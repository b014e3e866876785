#include "sewn/physics/lattice.hpp"

#include <cmath>
#include <string>

#include "sewn/physics/errors.hpp"
#include "sewn/physics/stiffness.hpp"

namespace sewn::physics {

BoxLattice build_box_lattice(System& sys, const BoxLatticeSpec& spec) {
  if (spec.nx == 0 || spec.ny == 0 || spec.nz == 0)
    throw InputError("build_box_lattice: box counts must be >= 1, got " + std::to_string(spec.nx) + "x" +
                     std::to_string(spec.ny) + "x" + std::to_string(spec.nz));
  const BoxStiffness ks = baudet_box(spec.E, spec.nu, spec.lx, spec.ly, spec.lz);
  if (!ks.valid())
    throw InputError("build_box_lattice: box " + std::to_string(spec.lx) + " x " + std::to_string(spec.ly) + " x " +
                     std::to_string(spec.lz) + " has non-positive Baudet stiffness (" + describe(ks) + ")");
  const double corner_mass = lumped_corner_mass(spec.rho, spec.lx * spec.ly * spec.lz, 8);

  BoxLattice L;
  L.nx = spec.nx;
  L.ny = spec.ny;
  L.nz = spec.nz;
  NodeTable& nodes = sys.nodes();
  L.first_node = nodes.size();
  const Index np = (spec.nx + 1) * (spec.ny + 1) * (spec.nz + 1);
  nodes.reserve(nodes.size() + np);
  // Count boxes per corner first so each node gets its final mass at creation.
  auto boxes_at = [&](Index i, Index j, Index k) {
    const Index cx = (i > 0) + (i < spec.nx), cy = (j > 0) + (j < spec.ny), cz = (k > 0) + (k < spec.nz);
    return cx * cy * cz;
  };
  for (Index k = 0; k <= spec.nz; ++k)
    for (Index j = 0; j <= spec.ny; ++j)
      for (Index i = 0; i <= spec.nx; ++i)
        nodes.add({i * spec.lx, j * spec.ly, k * spec.lz}, Eigen::Vector3d::Zero(), corner_mass * boxes_at(i, j, k));

  Springs& springs = sys.add<Springs>(spec.damping, spec.rayleigh_beta);
  L.springs = &springs;
  const Index n_edges = spec.nx * (spec.ny + 1) * (spec.nz + 1) + (spec.nx + 1) * spec.ny * (spec.nz + 1) +
                        (spec.nx + 1) * (spec.ny + 1) * spec.nz;
  springs.reserve(n_edges + 4 * spec.nx * spec.ny * spec.nz);
  // An edge along one axis is shared by up to 4 boxes: those around it in the other two axes.
  auto share = [](Index p, Index n) -> Index { return (p > 0) + (p < n); };
  for (Index k = 0; k <= spec.nz; ++k)
    for (Index j = 0; j <= spec.ny; ++j)
      for (Index i = 0; i <= spec.nx; ++i) {
        const Index a = L.node(i, j, k);
        if (i < spec.nx)
          springs.add(a, L.node(i + 1, j, k), ks.edge[0] * share(j, spec.ny) * share(k, spec.nz), spec.lx);
        if (j < spec.ny)
          springs.add(a, L.node(i, j + 1, k), ks.edge[1] * share(i, spec.nx) * share(k, spec.nz), spec.ly);
        if (k < spec.nz)
          springs.add(a, L.node(i, j, k + 1), ks.edge[2] * share(i, spec.nx) * share(j, spec.ny), spec.lz);
      }
  L.edge_springs = springs.size();
  const double diag = std::sqrt(spec.lx * spec.lx + spec.ly * spec.ly + spec.lz * spec.lz);
  for (Index k = 0; k < spec.nz; ++k)
    for (Index j = 0; j < spec.ny; ++j)
      for (Index i = 0; i < spec.nx; ++i) {
        springs.add(L.node(i, j, k), L.node(i + 1, j + 1, k + 1), ks.diagonal, diag, SpringKind::diagonal);
        springs.add(L.node(i + 1, j, k), L.node(i, j + 1, k + 1), ks.diagonal, diag, SpringKind::diagonal);
        springs.add(L.node(i, j + 1, k), L.node(i + 1, j, k + 1), ks.diagonal, diag, SpringKind::diagonal);
        springs.add(L.node(i + 1, j + 1, k), L.node(i, j, k + 1), ks.diagonal, diag, SpringKind::diagonal);
      }
  L.diagonal_springs = springs.size() - L.edge_springs;
  if (spec.damping == SpringDamping::viscous) springs.set_paper_viscosity(nodes.masses());
  return L;
}

}  // namespace sewn::physics
