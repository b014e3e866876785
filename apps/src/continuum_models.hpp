#pragma once
// The continuum models a scene may ask for instead of springs (model.type): the same nodes
// and lumped masses as the mass-spring model, the springs replaced by elements.

#include <vector>

#include "sewn/apps/scene.hpp"
#include "sewn/cmap/mesh.hpp"
#include "sewn/physics/mss_model.hpp"

namespace sewn::app::detail {

/// "shell": membrane triangles and hinges on the interior edges. Throws SceneError for cells
/// that are not triangles, cuts, or damping that acts on springs.
void use_shell_model(const Scene& scene, const std::vector<physics::MaterialParams>& materials, const IndexedMesh& mesh,
                     physics::MssModel<3>& model);
/// "solid": finite-element tetrahedra (model.law). Throws SceneError as use_shell_model for
/// cells that are not tetrahedra.
void use_solid_model(const Scene& scene, const std::vector<physics::MaterialParams>& materials, const IndexedMesh& mesh,
                     physics::MssModel<3>& model);

}  // namespace sewn::app::detail
