#include "sewn/apps/fig18_slab_model.hpp"

#include "sewn/apps/connections.hpp"
#include "sewn/apps/continuum.hpp"
#include "sewn/apps/paper_shapes.hpp"
#include "sewn/io/cleanup.hpp"

namespace sewn::app {

Fig18SlabModel build_fig18_slab_model(const Fig18SlabSpec& spec) {
  const IndexedMesh mesh = fig18_slab(spec.solid, spec.shell, spec.ny, spec.nz, spec.cell);
  const double thickness = spec.nz * spec.cell;
  std::vector<physics::MaterialParams> materials{
      {spec.young, spec.poisson, spec.density, thickness, 1e-4, physics::ElongatedPolicy::refuse}};
  Scene scene;
  scene.file = "fig18 slab";
  scene.model = "mixed";
  scene.damping = "none";
  scene.integrator = "newton";
  scene.connections.enabled = spec.connections;
  scene.connections.rigid = spec.rigid;
  physics::MssOptions options;
  options.gravity = Eigen::Vector3d(0, 0, -spec.gravity);
  options.damping = physics::DampingModel::none;
  Fig18SlabModel out;
  out.model = std::make_unique<physics::MssModel<3>>(mesh, materials, std::vector<std::uint32_t>{}, options);
  physics::MssModel<3>& model = *out.model;
  const auto models = cell_models(mesh, io::embedded_cells(mesh), scene, "fig18 slab");
  const auto parts = build_continuum(scene, materials, mesh, models, std::vector<int>(mesh.num_cells(), -1), model);
  out.curve_joints = build_connections(scene, mesh, models, materials, parts, model).curve_joints;
  const double length = (spec.solid + spec.shell) * spec.cell;
  for (physics::Index i = 0; i < model.nodes().size(); ++i) {
    const Eigen::Vector3d x = model.rest_position(i);
    if (x.x() < 1e-9) model.nodes().fix(i, physics::all_axes);
    if (x.x() > length - 1e-9) out.tip.push_back(i);
  }
  return out;
}

double Fig18SlabModel::sag() const {
  double z = 0;
  for (physics::Index i : tip) z += model->nodes().position(i).z() - model->rest_position(i).z();
  return -z / static_cast<double>(tip.size());
}

}  // namespace sewn::app
