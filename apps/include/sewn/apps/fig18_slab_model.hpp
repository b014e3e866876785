#pragma once
// The 2019 paper's Fig. 18 slab as a simulation model, set up once for the tests and the
// benchmarks that compare it with the all-solid slab and with Euler–Bernoulli.
#include <cstdint>
#include <memory>
#include <vector>

#include "sewn/physics/mss_model.hpp"

namespace sewn::app {

/// The slab's shape (cells of side `cell` along x from x = 0: `solid` columns of tetrahedra,
/// then `shell` columns of the mid-surface shell; see fig18_slab), its one material and how
/// the two halves are joined.
struct Fig18SlabSpec {
  std::uint32_t solid = 20, shell = 0, ny = 4, nz = 2;
  double cell = 0.01;
  double young = 1e7, poisson = 0.3, density = 1000, gravity = 9.81;
  bool connections = false;  ///< the curve connections between the halves (else hinged)
  bool rigid = false;        ///< the stiff connection option (else stiffnesses from the materials)
};

/// The slab clamped at x = 0 under gravity along −z, undamped, its shell as thick as the solid.
struct Fig18SlabModel {
  std::unique_ptr<physics::MssModel<3>> model;  ///< by pointer: the model's terms point into it
  std::vector<physics::Index> tip;              ///< the nodes at x = L
  std::uint32_t curve_joints = 0;               ///< curve connections built between the halves

  /// The tip's deflection: the mean −z displacement of the tip nodes from their rest positions.
  double sag() const;
};

Fig18SlabModel build_fig18_slab_model(const Fig18SlabSpec& spec);

}  // namespace sewn::app
