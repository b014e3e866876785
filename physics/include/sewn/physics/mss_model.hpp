#pragma once
// MssModel<D>: the mass-spring system of the 2013 paper living on a combinatorial map (an
// "LCC+MSS"). The map's 0-attributes hold node indices (particles), its 1-attributes edge-spring
// indices, and the attributes of its volumes (D = 3) and faces (2D cells) element indices.
// Particles, springs and elements live in dense arrays (the System's node table and Springs
// term); the map is consulted only when the topology changes.
//
// Elements: hexahedra (Baudet box stiffness, 4 body diagonals), tetrahedra (van Gelder),
// quads (Baudet rectangle, 2 diagonals) and triangles (van Gelder) with per-element material;
// segments (polylines) are axial springs k = E·A/l. Masses are lumped ρ·measure/corners. An
// edge spring's stiffness is the sum of its incident elements' contributions (PHYSICS_NOTES §1).
//
// Topology changes go through edit(): the map's split/merge/erase hooks create or retire
// particles and springs, and the model then recomputes, from the elements that remain incident,
// the masses of the touched particles, the stiffness and end particles of the touched springs,
// the particles each diagonal spring is attached to (the paper's Fig. 6) and the per-spring
// viscosities. Total mass is conserved up to the rounding of these sums. Springs the caller
// removed (a continuum model standing in for them) stay removed through later edits.

#include <array>
#include <cstdint>
#include <functional>
#include <span>
#include <type_traits>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "sewn/cmap/build.hpp"
#include "sewn/cmap/cmap.hpp"
#include "sewn/cmap/mesh.hpp"
#include "sewn/physics/basic_terms.hpp"
#include "sewn/physics/errors.hpp"
#include "sewn/physics/springs.hpp"
#include "sewn/physics/system.hpp"

namespace sewn::refine::detail {
template <int D>
struct ModelAccess;  // hierarchical refinement (sewn::refine) edits the model's rest data and darts
}  // namespace sewn::refine::detail

namespace sewn::physics {

/// Attribute values stored in the map.
struct NodeRef {
  Index node = invalid_index;
};
struct SpringRef {
  Index spring = invalid_index;
  Index segment = invalid_index;  ///< the element of a polyline segment (rods), else invalid_index
  /// Subdivision level l_e of the edge (1, 2, 4, ...: rest length = root edge's / l_e). An
  /// element E of level l_E gives each edge of its sides k_E · l_e / l_E (series springs).
  std::uint32_t level = 1;
};
struct ElementRef {
  Index element = invalid_index;
};

/// What to do with a box element whose Baudet edge stiffness is negative (an elongated box,
/// PHYSICS_NOTES §1.2): refuse it with a message naming it, or drop its negative edge
/// contributions (clamp them to 0: the diagonals then carry the load along the long axis).
enum class ElongatedPolicy : std::uint8_t { refuse, clamp };

struct MaterialParams {
  double young = 0;       ///< E, Pa (> 0)
  double poisson = 0.3;   ///< ν, in (-1, 0.5)
  double density = 0;     ///< ρ, kg/m³ (> 0)
  double thickness = 1;   ///< 2D cells: thickness, m (scales mass and stiffness)
  double area = 1e-4;     ///< segments: cross-section, m²
  ElongatedPolicy elongated = ElongatedPolicy::refuse;
};

enum class DampingModel : std::uint8_t {
  none,
  viscous,   ///< the 2013 paper's per-spring γ = 2√(k(mi+mj)/2), in forces and Jacobians
  rayleigh,  ///< C = αM + βK, in forces and Jacobians
};

struct MssOptions {
  DampingModel damping = DampingModel::viscous;
  double rayleigh_alpha = 0;  ///< 1/s
  double rayleigh_beta = 0;   ///< s
  double environment = 0;     ///< drag −c·m·v, 1/s
  Eigen::Vector3d gravity{0.0, 0.0, -9.81};
  std::string source = "mesh";  ///< names the mesh in error messages
};

enum class ElementKind : std::uint8_t { hexahedron, tetrahedron, quad, triangle, segment };

/// One element: its rest data and its contributions to the springs of its edges.
struct Element {
  ElementKind kind{};
  bool alive = true;
  std::uint32_t material = 0;
  std::uint32_t mesh_cell = 0;  ///< index of the source mesh cell
  Dart dart;                    ///< the dart starting at its local vertex 0 (to 1, or to the last vertex if reversed)
  bool reversed = false;        ///< a 2D cell the builder reversed to orient its surface
  bool clamped = false;         ///< its negative Baudet edge stiffnesses were clamped to 0 (ElongatedPolicy::clamp)
  double measure = 0;           ///< rest volume, area × thickness, or length × area
  std::array<double, 12> edge_k{};  ///< stiffness contribution to each local edge (see local_edges())
  double diagonal_k = 0;            ///< stiffness of each internal diagonal (hexahedra, quads)
  std::array<Index, 4> diagonal{invalid_index, invalid_index, invalid_index, invalid_index};
  /// Subdivision level l_E (1 for a built element, doubled by each refinement: rest size =
  /// root size / l_E), the element it was refined from and the first of its children (the
  /// children of one element are consecutive); invalid_index when none.
  std::uint32_t level = 1;
  Index parent = invalid_index;
  Index first_child = invalid_index;
};

/// Local vertex code of a dart that does not start at a corner of its element: it starts at a
/// T-junction, a particle strictly inside one of the element's sides (hierarchical refinement).
inline constexpr std::uint8_t not_a_corner = 0xFF;

template <int D>
class MssModel {
  static_assert(D == 2 || D == 3, "MssModel is defined for 2- and 3-maps");

 public:
  using Map = std::conditional_t<D == 3, CMap<3, NodeRef, SpringRef, ElementRef, ElementRef>,
                                 CMap<2, NodeRef, SpringRef, ElementRef>>;

  /// Builds the map and the mass-spring system of `mesh`. `material_of_cell` gives each mesh
  /// cell's index into `materials` (empty: every cell uses materials[0]). Throws InputError
  /// naming the cell for a degenerate element, a negative Baudet stiffness under the refuse
  /// policy, a bad material or a cell the map cannot hold, and MeshError for a malformed mesh.
  /// O(cells).
  MssModel(const IndexedMesh& mesh, std::vector<MaterialParams> materials, std::vector<std::uint32_t> material_of_cell,
           MssOptions options = {});
  MssModel(const MssModel&) = delete;  // the map's hooks refer to this object
  MssModel& operator=(const MssModel&) = delete;

  [[nodiscard]] System& system() { return system_; }
  [[nodiscard]] const System& system() const { return system_; }
  [[nodiscard]] NodeTable& nodes() { return system_.nodes(); }
  [[nodiscard]] const NodeTable& nodes() const { return system_.nodes(); }
  [[nodiscard]] Springs& springs() { return *springs_; }
  [[nodiscard]] const Springs& springs() const { return *springs_; }
  [[nodiscard]] const Map& map() const { return map_; }
  [[nodiscard]] const std::vector<Element>& elements() const { return elements_; }
  /// Number of elements not removed. O(1).
  [[nodiscard]] Index num_live_elements() const { return live_elements_; }
  [[nodiscard]] const std::vector<MaterialParams>& materials() const { return materials_; }
  [[nodiscard]] const MssOptions& options() const { return options_; }

  /// Changes the topology: f(map) runs with the hooks installed, then the physics is brought
  /// back in line (resync). Returns what f returns. Cost: f plus O(touched cells).
  template <class F>
  decltype(auto) edit(F&& f) {
    try {
      if constexpr (std::is_void_v<std::invoke_result_t<F, Map&>>) {
        f(map_);
        resync();
        notify_edited();
      } else {
        decltype(auto) result = f(map_);
        resync();
        notify_edited();
        return result;
      }
    } catch (...) {
      // a failed map operation leaves the map unchanged, but earlier ones in f may have fired
      // hooks: bring the physics in line with whatever the map now is
      resync();
      notify_edited();
      throw;
    }
  }

  /// Registers f, called after every edit() once the springs and masses are in line again:
  /// terms built over the elements (the volume term) re-read their corner particles there, so
  /// that a cut which duplicated a particle hands each element its own copy. f must outlive
  /// the model's edits (terms of the model's own System do). O(1).
  void after_edits(std::function<void()> f) { edit_listeners_.push_back(std::move(f)); }

  /// The node of mesh point p, as built (before any cut): invalid_index for unused points.
  [[nodiscard]] Index node_of_point(std::uint32_t p) const { return p < node_of_point_.size() ? node_of_point_[p] : invalid_index; }
  /// The node carried by the vertex of dart d (d a live dart of the map; unchecked: hot loops).
  [[nodiscard]] Index node_of(Dart d) const {
    return map_.template attribute_container<0>().value(map_.template attribute_index<0>(d.index())).node;
  }
  /// The spring carried by the edge of dart d (unchecked, as node_of).
  [[nodiscard]] Index spring_of(Dart d) const {
    return map_.template attribute_container<1>().value(map_.template attribute_index<1>(d.index())).spring;
  }
  /// The element of the cell of dart d (its volume in 3D, else its face; invalid_index if none).
  [[nodiscard]] Index element_of(Dart d) const;
  /// True if dart d starts at a corner of its element (a hierarchical dart: the first dart of
  /// one of the element's sides); false if it starts at a T-junction. O(1).
  [[nodiscard]] bool is_corner_dart(Dart d) const { return dart_vertex_[d.index()] != not_a_corner; }
  /// False until sewn::refine first splits an element. Until then every dart starts at a corner
  /// and every element and edge is at level 1: the model has no T-junction and no level jump,
  /// which lets a cut skip looking for them. Coarsening does not reset it. O(1).
  [[nodiscard]] bool ever_refined() const { return ever_refined_; }
  /// The local vertex of its element that dart d starts at (not_a_corner for a T-junction). O(1).
  [[nodiscard]] int corner_of_dart(Dart d) const { return dart_vertex_[d.index()]; }
  /// The local side (local edge, see local_edges()) of its element that dart d lies on. O(1).
  [[nodiscard]] int side_of(Dart d) const { return dart_edge_[d.index()] & 0x7f; }
  /// Rest position of node i.
  [[nodiscard]] Eigen::Vector3d rest_position(Index i) const { return rest_[i]; }
  /// The mesh point node i stands for (a particle duplicated by a cut keeps its original's).
  [[nodiscard]] std::uint32_t point_of_node(Index i) const { return point_of_node_[i]; }
  /// Σ ρ·measure over live elements: what the node masses must add up to.
  [[nodiscard]] double element_mass() const;
  /// Σ of live node masses.
  [[nodiscard]] double node_mass() const;
  /// Nodes of element e's corners, in its local (VTK) order.
  [[nodiscard]] std::vector<Index> element_nodes(Index e) const;
  /// Rest centroid of element e.
  [[nodiscard]] Eigen::Vector3d element_centroid(Index e) const;
  /// Local edges of a kind, as (local vertex, local vertex), in the order of Element::edge_k.
  static std::span<const std::array<std::uint8_t, 2>> local_edges(ElementKind k);

  /// Recomputes the physics of every cell touched since the last resync (edit() calls it).
  void resync();
  /// Drops removed particles and springs from the arrays, renumbering the rest and the map's
  /// attributes. Invalidates node and spring indices held by the caller (node_of_point() is
  /// kept up to date). O(particles + springs + attributes).
  void compact();

 private:
  void build_elements(const IndexedMesh& mesh, const BuildResult& built, const std::vector<std::uint32_t>& material_of_cell);
  void install_hooks();
  Element make_element(const IndexedMesh& mesh, std::uint32_t cell, std::uint32_t material, Dart dart) const;
  // For each dart of element e, its local half-edge start vertex; calls f(dart, local vertex,
  // local end vertex). Walks the element's darts from its canonical dart.
  template <class F>
  void for_each_local_dart(const Element& el, F&& f) const;
  // Records, for every dart of element e, its local start vertex and local edge.
  void index_darts(Index e);
  [[nodiscard]] double edge_stiffness(Dart edge_dart) const;
  template <class F>
  void for_each_edge_dart(std::uint32_t d, F&& f) const;
  // Mass of the vertex cell of 0-attribute v, in one pass over its darts that also appends its
  // edges (those whose darts end there too) to `edges`, with duplicates, and its live elements
  // not yet seen this resync to `elems`.
  [[nodiscard]] double walk_vertex(std::uint32_t v, std::vector<std::uint32_t>& edges, std::vector<Index>& elems);
  void attach_diagonals(Index e);
  [[nodiscard]] Index end_node(Dart d) const;
  void link_vertex(Index node, std::uint32_t vertex);
  // Unlinks `vertex` from node's list; true if the list is now empty.
  bool unlink_vertex(Index node, std::uint32_t vertex);

  Map map_;
  System system_;
  Springs* springs_ = nullptr;
  std::vector<MaterialParams> materials_;
  MssOptions options_;
  std::vector<Element> elements_;
  std::vector<Eigen::Vector3d> rest_;            // rest position per node
  // The 0-attributes naming each node, as singly linked lists threaded through the attribute
  // indices: a node almost always has one, and a cut adds nodes one by one, so a vector per node
  // would cost an allocation per particle and a move of all of them whenever the outer array grows.
  std::vector<std::uint32_t> first_vertex_;  // per node: one of its 0-attributes, or null
  std::vector<std::uint32_t> next_vertex_;   // per 0-attribute: the next naming the same node, or null
  std::vector<Index> node_of_point_;
  std::vector<std::uint32_t> point_of_node_;
  // Per dart: its local start vertex in its element, and its local edge index with bit 7 set on
  // one dart per element and edge, so that sums over an edge's darts count each element once.
  std::vector<std::uint8_t> dart_vertex_, dart_edge_;
  Index live_elements_ = 0;
  // touched since the last resync
  std::vector<std::uint32_t> dirty_vertices_, dirty_edges_;
  // generation stamps: an index is listed once per resync without sorting
  std::uint32_t generation_ = 0;
  std::vector<std::uint32_t> seen_edge_, seen_element_, seen_node_, seen_spring_;
  std::string unsupported_;  // an edit the model cannot follow (element merge), reported by resync
  bool refining_ = false;    // element splits and merges are refinement and coarsening, which set up the elements
  bool ever_refined_ = false;  // see ever_refined()
  std::vector<std::function<void()>> edit_listeners_;  // see after_edits()
  void notify_edited() {
    for (const auto& f : edit_listeners_) f();
  }

  friend struct refine::detail::ModelAccess<D>;
};

extern template class MssModel<2>;
extern template class MssModel<3>;

}  // namespace sewn::physics
