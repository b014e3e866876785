#pragma once
// The mass-spring model the cut and refine suites measure: one material, the 2013 paper's
// per-spring viscosity and gravity along z; each suite passes its paper's constants.

#include <memory>
#include <string>
#include <vector>

#include "sewn/cmap/mesh.hpp"
#include "sewn/physics/mss_model.hpp"

namespace sewn::bench {

inline std::unique_ptr<physics::MssModel<3>> viscous_model(const IndexedMesh& mesh, double young, double poisson,
                                                            double density, double gravity_z, std::string source) {
  physics::MaterialParams mat;
  mat.young = young;
  mat.poisson = poisson;
  mat.density = density;
  physics::MssOptions opt;
  opt.damping = physics::DampingModel::viscous;
  opt.gravity = Eigen::Vector3d(0, 0, gravity_z);
  opt.source = std::move(source);
  return std::make_unique<physics::MssModel<3>>(mesh, std::vector<physics::MaterialParams>{mat}, std::vector<std::uint32_t>{}, opt);
}

}  // namespace sewn::bench
