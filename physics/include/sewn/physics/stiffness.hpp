#pragma once
// Stiffness and mass formulas of the mass-spring models, as pure functions (PHYSICS_NOTES
// §1.1-1.3). All take SI units (E in Pa, lengths in m, ρ in kg/m³; in 2D, E and ρ per unit
// thickness) and throw InputError on E ≤ 0, ν ∉ (-1, 0.5), or a length, area or volume that is
// not finite and > 0. Each is O(1).

#include <array>
#include <string>

#include <Eigen/Core>

namespace sewn::physics {

// ---------------------------------------------------------------- Baudet et al. 2009 (quads, boxes)

/// Edge stiffness of a rectangle for its edges of length i, the other side being j:
/// E (j²(3ν+2) - i²) / (4 i j (1+ν)). Negative when i/j > √(2+3ν).
[[nodiscard]] double baudet_rectangle_edge(double E, double nu, double i, double j);
/// Stiffness of each of the rectangle's 2 diagonals: E (lx² + ly²) / (4 lx ly (1+ν)). Always > 0.
[[nodiscard]] double baudet_rectangle_diagonal(double E, double nu, double lx, double ly);
/// Edge stiffness of a box for its edges of length i, the others being j and k:
/// E (6 j²k²(1+ν) + (ν(j²+k²) - i²)(i²+j²+k²)) / (24 (1+ν) i j k). Negative for elongated boxes.
[[nodiscard]] double baudet_box_edge(double E, double nu, double i, double j, double k);
/// Stiffness of each of the box's 4 body diagonals: E (lx²+ly²+lz²)² / (24 (1+ν) lx ly lz). Always > 0.
[[nodiscard]] double baudet_box_diagonal(double E, double nu, double lx, double ly, double lz);

/// The springs one rectangle contributes: edge[a] for its 2 edges along axis a (a = x, y).
struct RectangleStiffness {
  std::array<double, 2> edge{};
  double diagonal = 0;
  /// True if every value is > 0.
  [[nodiscard]] bool valid() const { return edge[0] > 0 && edge[1] > 0 && diagonal > 0; }
};
/// The springs one box contributes: edge[a] for its 4 edges along axis a (x, y, z).
struct BoxStiffness {
  std::array<double, 3> edge{};
  double diagonal = 0;
  [[nodiscard]] bool valid() const { return edge[0] > 0 && edge[1] > 0 && edge[2] > 0 && diagonal > 0; }
};
/// All Baudet values of an lx × ly rectangle, reported as computed (negative edges included:
/// check valid(), then refuse the element or apply a fallback below).
[[nodiscard]] RectangleStiffness baudet_rectangle(double E, double nu, double lx, double ly);
/// All Baudet values of an lx × ly × lz box, reported as computed (see valid()).
[[nodiscard]] BoxStiffness baudet_box(double E, double nu, double lx, double ly, double lz);
/// "edge k along x = -12.3, along y = ..." for error messages naming the element.
[[nodiscard]] std::string describe(const BoxStiffness& s);
[[nodiscard]] std::string describe(const RectangleStiffness& s);

/// Largest aspect ratio i/j (= i/k for a box with j = k) with a non-negative Baudet edge
/// stiffness: √(2+3ν) for rectangles (1.703 at ν = 0.3), the positive root of
/// r⁴ + 2(1-ν) r² - (6 + 10ν) = 0 for boxes (1.543 at ν = 0.3).
[[nodiscard]] double baudet_rectangle_max_aspect(double nu);
[[nodiscard]] double baudet_box_max_aspect(double nu);

/// Fallback 1, "clamp": every edge stiffness below floor is raised to floor (floor ≥ 0; 0 just
/// removes the negative springs, leaving the long direction to the diagonals, which makes the
/// element softer along it than the formula intends). Diagonals unchanged.
[[nodiscard]] BoxStiffness clamp_edges(BoxStiffness s, double floor);
[[nodiscard]] RectangleStiffness clamp_edges(RectangleStiffness s, double floor);
/// Fallback 2, "cube-equivalent": the values of a cube (square) of the same volume (area),
/// (∛(lx ly lz))³; isotropic and positive but ignores the shape.
[[nodiscard]] BoxStiffness baudet_box_cube_equivalent(double E, double nu, double lx, double ly, double lz);
[[nodiscard]] RectangleStiffness baudet_rectangle_square_equivalent(double E, double nu, double lx, double ly);

// ---------------------------------------------------------------- van Gelder 1998 (simplices)

/// One triangle's contribution to the stiffness of one of its edges: E·area/|c|² (sum over
/// the triangles sharing the edge). Exact for equilateral meshes at ν = 1/3.
[[nodiscard]] double van_gelder_triangle_edge(double E, double area, double edge_length);
/// One tetrahedron's contribution to one of its edges: E·volume/|c|² (sum over incident
/// tetrahedra). For a regular tet of edge l: E·l/(6√2).
[[nodiscard]] double van_gelder_tet_edge(double E, double volume, double edge_length);
/// The 6 edge contributions of a tetrahedron p0..p3, edges in the order (0,1) (0,2) (0,3)
/// (1,2) (1,3) (2,3). Throws InputError if it is degenerate (volume ≤ 1e-14·max edge³).
[[nodiscard]] std::array<double, 6> van_gelder_tet(double E, const Eigen::Vector3d& p0, const Eigen::Vector3d& p1,
                                                   const Eigen::Vector3d& p2, const Eigen::Vector3d& p3);
/// The 3 edge contributions of a triangle, edges (0,1) (1,2) (2,0). Throws on a degenerate triangle.
[[nodiscard]] std::array<double, 3> van_gelder_triangle(double E, const Eigen::Vector3d& p0, const Eigen::Vector3d& p1,
                                                        const Eigen::Vector3d& p2);

// ---------------------------------------------------------------- measures and lumped masses

/// |det|/6 of the tetrahedron (unsigned volume).
[[nodiscard]] double tet_volume(const Eigen::Vector3d& p0, const Eigen::Vector3d& p1, const Eigen::Vector3d& p2,
                                const Eigen::Vector3d& p3);
[[nodiscard]] double triangle_area(const Eigen::Vector3d& p0, const Eigen::Vector3d& p1, const Eigen::Vector3d& p2);
/// Mass each of the element's `corners` corner particles receives: ρ·measure/corners
/// (corners = 8 hexahedron, 4 tetrahedron and quad, 3 triangle). Throws on ρ ≤ 0, measure ≤ 0
/// or corners = 0.
[[nodiscard]] double lumped_corner_mass(double rho, double measure, int corners);

}  // namespace sewn::physics
