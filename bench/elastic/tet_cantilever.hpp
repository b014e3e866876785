#pragma once
// The StVK tetrahedral cantilever of bench_elastic (PHYSICS_NOTES §4), shared with the tests
// that check its orders: 1 m × 0.1 m × 0.1 m, E = 100 MPa, ν = 0.3, ρ = 1000 kg/m³, g = 9.81
// m/s², clamped at x = 0 (every x = 0 node held); 10N×N×N cubes of 6 Kuhn tetrahedra around
// the cube's main diagonal, lumped masses ρV/4. Tip = mean z displacement of the x = L nodes,
// in mm; the continuum answer is Timoshenko's 14.868 mm.

#include <array>
#include <cmath>
#include <vector>

#include "sewn/physics/basic_terms.hpp"
#include "sewn/physics/solids/tets.hpp"
#include "sewn/physics/system.hpp"

namespace sewn::tet_cantilever {

using physics::Index;
using physics::System;
using Eigen::Vector3d;
namespace solids = physics::solids;
using physics::Gravity;

constexpr double E = 100e6, nu = 0.3, rho = 1000.0, g = 9.81, L = 1.0, b = 0.1;
constexpr double timoshenko_mm = 14.868;

struct Beam {
  System sys;
  std::vector<Index> tip;  // nodes at x = L
  std::vector<double> rest_z;
};

// 10N×N×N cubes, 6 tetrahedra each around the cube's main diagonal; lumped masses ρV/4.
inline void build(Beam& beam, int n) {
  const int nx = 10 * n, ny = n, nz = n;
  const double a = b / n;
  auto id = [&](int i, int j, int k) { return static_cast<Index>(i + (nx + 1) * (j + (ny + 1) * k)); };
  std::vector<Vector3d> x;
  for (int k = 0; k <= nz; ++k)
    for (int j = 0; j <= ny; ++j)
      for (int i = 0; i <= nx; ++i) x.emplace_back(a * i, a * j, a * k);
  static const int path[6][3] = {{0, 1, 2}, {0, 2, 1}, {1, 0, 2}, {1, 2, 0}, {2, 0, 1}, {2, 1, 0}};
  std::vector<std::array<Index, 4>> tets;
  for (int k = 0; k < nz; ++k)
    for (int j = 0; j < ny; ++j)
      for (int i = 0; i < nx; ++i)
        for (const auto& p : path) {
          int c[3] = {i, j, k};
          std::array<Index, 4> t{};
          t[0] = id(c[0], c[1], c[2]);
          for (int s = 0; s < 3; ++s) {
            ++c[p[s]];
            t[s + 1] = id(c[0], c[1], c[2]);
          }
          tets.push_back(t);
        }
  const double node_mass = rho * a * a * a / 6.0 / 4.0;  // per incident tetrahedron
  std::vector<double> mass(x.size(), 0.0);
  for (const auto& t : tets)
    for (Index v : t) mass[v] += node_mass;
  for (std::size_t i = 0; i < x.size(); ++i) beam.sys.nodes().add(x[i], Vector3d::Zero(), mass[i]);
  auto& term = beam.sys.add<solids::Tets>(solids::TetLaw::stvk);
  for (const auto& t : tets) {
    solids::TetPositions X;
    for (int c = 0; c < 4; ++c) X.col(c) = x[t[c]];
    term.add(t, X, E, nu);
  }
  beam.sys.add<Gravity>(Vector3d(0, 0, -g));
  for (std::size_t i = 0; i < x.size(); ++i) {
    if (x[i].x() == 0.0) beam.sys.nodes().fix(static_cast<Index>(i));
    if (std::abs(x[i].x() - L) < 1e-12) {
      beam.tip.push_back(static_cast<Index>(i));
      beam.rest_z.push_back(x[i].z());
    }
  }
}

inline double tip_mm(const Beam& beam) {
  double s = 0.0;
  for (std::size_t k = 0; k < beam.tip.size(); ++k) s += beam.sys.nodes().position(beam.tip[k]).z() - beam.rest_z[k];
  return -1e3 * s / static_cast<double>(beam.tip.size());
}

}  // namespace sewn::tet_cantilever
