#pragma once
// The continuum models of a scene (model.type solid, shell or mixed) on the mass-spring
// model's nodes: its springs give way to tetrahedra, membranes with hinges, and discrete
// elastic rods, chosen per cell (cell_models.hpp). Masses stay the model's lumped ones.

#include <array>
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
#include "sewn/physics/shells/morley_terms.hpp"
#include "sewn/physics/shells/patch_terms.hpp"
#include "sewn/physics/shells/shell_terms.hpp"
#include "sewn/physics/solids/tets.hpp"

namespace sewn::app {

/// A hinge's place in its two membrane triangles (hinge_element.hpp's order: x0 opposite in
/// face A = (x0, x1, x2), x3 opposite in face B = (x3, x2, x1)): the membranes, and at which
/// corner of A each of x0, x1, x2 sits, and of B each of x3, x1, x2. A cut follows it through them.
struct HingeCorners {
  physics::Index a = 0, b = 0;
  std::array<std::uint8_t, 3> in_a{}, in_b{};
};

/// The terms built, and which model element each of their elements stands for: rods for
/// output (per model element its rod and edge, (invalid_index, 0) if not a rod segment),
/// tetrahedra, membranes and hinges to follow cuts.
struct ContinuumParts {
  physics::rods::Rods* rods = nullptr;
  std::vector<std::pair<physics::Index, int>> rod_edge_of_element;
  physics::solids::Tets* tets = nullptr;
  std::vector<physics::Index> element_of_tet;
  physics::shells::Membranes* membranes = nullptr;
  std::vector<physics::Index> element_of_membrane;
  physics::shells::Hinges* hinges = nullptr;
  std::vector<HingeCorners> hinge_corners;  ///< per hinge
  physics::shells::PatchTerms patches;      ///< scene.bending "patch" (no cuts)
  physics::shells::MorleyTerms morley;      ///< scene.bending "morley" (no cuts)
};

/// Rod segments whose group (`groups`: per cell its model.groups entry, -1: none) gives a
/// section get a copy of their material whose `area` is the section's, so that the lumped
/// masses match the rod. Appends to `materials` and rewrites `material_of_cell`. O(cells).
void apply_rod_sections(const Scene& scene, const IndexedMesh& mesh, const std::vector<CellModel>& models, const std::vector<int>& groups,
                        std::vector<physics::MaterialParams>& materials, std::vector<std::uint32_t>& material_of_cell);

/// Removes every spring of `model` and adds the force terms of the cells' models: Tets (solid
/// cells, scene.law), Membranes and Morley bending (shell cells; scene.bending "patch": patch bending; "hinge": Hinges
/// on the edges two shell triangles share), Rods (rod segments chained wherever exactly two segments of one group and
/// material meet; sections from the group, else the circle of the material's area). `groups`:
/// per mesh cell its model.groups entry, -1: none (match_groups). Throws
/// SceneError for what a continuum model cannot take (per-spring damping; cuts and piercing
/// of rods and of Morley- and patch-bent shells, whose stencils cannot follow a cut yet) and for a rod or hinge the rest shape
/// makes impossible, naming the key. Registers follow_cut with the model (after_edits).
/// `held` (per node, empty: none) marks the nodes the scene holds on every axis: a shell
/// triangle whose three nodes are held is a clamp of Morley and patch bending, so a shell held
/// by two rows of nodes is clamped exactly on the inner row (not half a cell beyond it). O(cells).
ContinuumParts build_continuum(const Scene& scene, const std::vector<physics::MaterialParams>& materials, const IndexedMesh& mesh,
                               const std::vector<CellModel>& models, const std::vector<int>& groups, physics::MssModel<3>& model,
                               std::span<const std::uint8_t> held = {});

/// Brings the continuum in line with the model after refine::cut or refine::pierce: the
/// tetrahedra and membrane triangles move onto the particles the cut duplicated (same rest
/// data, so their energy at the current state does not change), and leave their term for good
/// where the model element was removed; a hinge whose two triangles are still there and still
/// share its edge's particles follows them, any other leaves the Hinges term (the energy drops
/// by exactly what the removed elements held). build_continuum registers it to run after
/// every edit of the model, before a piercing compacts the particles; calling it again
/// changes nothing. O(tetrahedra + triangles + hinges).
void follow_cut(const ContinuumParts& parts, const physics::MssModel<3>& model);

/// The rods for .vtu output: each rod as the chain of its nodes in order (a closed rod's first
/// node repeated at its end: one VTK poly-line per rod), and per model node the rods' material
/// frame there (zero vectors off rods). The frame lives on edges; at an inner node m1 is the
/// mean of its two edges' first directors, made normal to the node's tangent t (the mean of
/// the two unit edge tangents) and unit, m2 = t × m1; an end node takes its edge's frame. A
/// node on two rods keeps the frame of the first. O(rod nodes).
struct RodOutput {
  std::vector<std::vector<physics::Index>> chains;  ///< per rod, its nodes along the poly-line
  std::vector<Point3> m1, m2;                       ///< per model node
};
RodOutput rod_output(const ContinuumParts& parts, const physics::MssModel<3>& model);

}  // namespace sewn::app
