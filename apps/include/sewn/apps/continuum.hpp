#pragma once
// The continuum models of a scene (model.type solid, shell or mixed) on the mass-spring
// model's nodes: its springs give way to tetrahedra, membranes with hinges, and discrete
// elastic rods, chosen per cell (cell_models.hpp). Masses stay the model's lumped ones.

#include <cstdint>
#include <span>
#include <string>
#include <utility>
#include <vector>

#include "sewn/apps/cell_models.hpp"
#include "sewn/apps/scene.hpp"
#include "sewn/cmap/mesh.hpp"
#include "sewn/physics/mss_model.hpp"
#include "sewn/physics/rods/rods_term.hpp"
#include "sewn/physics/solids/tets.hpp"

namespace sewn::app {

/// The terms built, and which model element each of their elements stands for: rods for
/// output (per model element its rod and edge, (invalid_index, 0) if not a rod segment),
/// tetrahedra to follow cuts.
struct ContinuumParts {
  physics::rods::Rods* rods = nullptr;
  std::vector<std::pair<physics::Index, int>> rod_edge_of_element;
  physics::solids::Tets* tets = nullptr;
  std::vector<physics::Index> element_of_tet;
};

/// Rod segments whose group gives a section get a copy of their material whose `area` is the
/// section's, so that the lumped masses match the rod. Appends to `materials` and rewrites
/// `material_of_cell`. O(cells).
void apply_rod_sections(const Scene& scene, const IndexedMesh& mesh, const std::vector<CellModel>& models,
                        std::vector<physics::MaterialParams>& materials, std::vector<std::uint32_t>& material_of_cell);

/// Removes every spring of `model` and adds the force terms of the cells' models: Tets (solid
/// cells, scene.law), Membranes and Hinges (shell cells: hinges on the edges two shell
/// triangles share), Rods (rod segments chained wherever exactly two segments of one group and
/// material meet; sections from the group, else the circle of the material's area). Throws
/// SceneError for what a continuum model cannot take (per-spring damping; cuts of shells or
/// rods, whose hinges and rod stencils cannot follow a cut yet; piercing, which removes
/// elements) and for a rod or hinge the rest shape makes impossible, naming the key. O(cells).
ContinuumParts build_continuum(const Scene& scene, const std::vector<physics::MaterialParams>& materials, const IndexedMesh& mesh,
                               const std::vector<CellModel>& models, physics::MssModel<3>& model);

/// Brings the continuum in line with the model after refine::cut: the tetrahedra move onto the
/// particles the cut duplicated (same rest data, so the energy at the current state does not
/// change). O(tetrahedra).
void follow_cut(const ContinuumParts& parts, const physics::MssModel<3>& model);

/// The first material director m1 of each listed element's rod edge at the current state (the
/// zero vector for an element that is not a rod segment): the rods' material frame for output.
std::vector<Point3> rod_directors(const ContinuumParts& parts, const physics::MssModel<3>& model,
                                  std::span<const physics::Index> elements);

}  // namespace sewn::app
