#pragma once
// Where the bodies of one conforming mesh meet: the point, curve and surface connections a
// mixed model needs, found from the cells and the points they share (cells identified by their
// points, as the map is built from them). Components first: solid tetrahedra joined through
// shared faces, shell triangles through edges exactly two of them share (an edge of three or
// more is a non-manifold junction: the triangles around it stay separate components), rod
// segments through points exactly two of them share (a rod's chain; with chain keys, two of
// one key: CellList::chain). Then, for each pair of
// components meeting somewhere, the rule — the highest-dimensional contact wins at each place:
//   - a face of both (a shell triangle that is a tet's face, or two solids sharing a face):
//     one surface connection per face;
//   - an edge of both that is on no face they share: one curve connection per edge;
//   - a point of both that is on no edge they share: one point connection.
// So a fin sewn along a block's edge line gives curve connections there and no point ones at
// the line's nodes; a mast hanging from the fin by one node gives one point connection.
//
//   sewn::connect::CellList cells;
//   cells.add(sewn::connect::Body::shell, {0, 1, 2});
//   const auto found = sewn::connect::detect_connections(cells);

#include <array>
#include <cstdint>
#include <initializer_list>
#include <span>
#include <string>
#include <vector>

namespace sewn::connect {

enum class Body : std::uint8_t { rod = 0, shell = 1, solid = 2 };
/// "rod", "shell", "solid".
const char* to_string(Body b);

/// The simulated cells: rods are segments (2 points), shells triangles (3), solids tetrahedra (4).
struct CellList {
  std::vector<Body> body;
  /// Per cell, which chain a rod segment may join (0 unless given): two segments sharing a
  /// point chain into one rod component only with equal keys, as a model that splits its rods
  /// by group or material does (apps: the Rods term's rod of each segment).
  std::vector<std::uint32_t> chain;
  std::vector<std::uint32_t> offsets{0};
  std::vector<std::uint32_t> points;
  /// Appends a cell; throws std::invalid_argument if the point count does not match the body
  /// or a point repeats.
  void add(Body b, std::span<const std::uint32_t> cell_points, std::uint32_t chain_key = 0);
  void add(Body b, std::initializer_list<std::uint32_t> cell_points, std::uint32_t chain_key = 0) {
    add(b, std::span(cell_points.begin(), cell_points.size()), chain_key);
  }
  [[nodiscard]] std::uint32_t size() const { return static_cast<std::uint32_t>(body.size()); }
  [[nodiscard]] std::span<const std::uint32_t> cell(std::uint32_t c) const {
    return {points.data() + offsets[c], points.data() + offsets[c + 1]};
  }
};

enum class ConnectionKind : std::uint8_t { point = 0, curve = 1, surface = 2 };
/// "point", "curve", "surface".
const char* to_string(ConnectionKind k);

/// One place where two components meet: its points (1, 2 or 3, sorted) and the two components
/// (first < second).
struct FoundConnection {
  ConnectionKind kind = ConnectionKind::point;
  std::vector<std::uint32_t> points;
  std::array<std::uint32_t, 2> components{};
};

/// The pairs of bodies in report order: rod–rod, rod–shell, rod–solid, shell–shell,
/// shell–solid, solid–solid.
inline constexpr int num_body_pairs = 6;
/// Index of the unordered pair (a, b) in that order.
int body_pair_index(Body a, Body b);
/// "rod-rod", "rod-shell", ... by index.
const char* body_pair_name(int pair);

struct FoundConnections {
  std::vector<std::uint32_t> component_of_cell;
  std::vector<Body> component_body;
  std::vector<FoundConnection> connections;  ///< surfaces, then curves, then points; each sorted by points
  /// counts[kind][pair]: how many of each.
  std::array<std::array<std::uint32_t, num_body_pairs>, 3> counts{};
  [[nodiscard]] std::uint32_t total() const { return static_cast<std::uint32_t>(connections.size()); }
};

/// Components and connections of `cells` by the rule above. O(cells log cells).
FoundConnections detect_connections(const CellList& cells);

/// One line per kind with a nonzero count, e.g. "  curve: 12 shell-solid" (none: one line
/// saying so), each starting with two spaces.
std::string connections_text(const FoundConnections& found);

}  // namespace sewn::connect
