#include "sewn/physics/stiffness.hpp"

#include <algorithm>
#include <cmath>

#include <Eigen/Geometry>

#include "sewn/physics/errors.hpp"
#include "format.hpp"

namespace sewn::physics {

namespace {

void check_material(const char* where, double E, double nu) {
  if (!(std::isfinite(E) && E > 0)) throw InputError(std::string(where) + ": Young's modulus E must be finite and > 0, got " + detail::format_number(E));
  if (!(std::isfinite(nu) && nu > -1.0 && nu < 0.5))
    throw InputError(std::string(where) + ": Poisson ratio nu must lie in (-1, 0.5), got " + detail::format_number(nu));
}

void check_positive(const char* where, const char* what, double v) {
  if (!(std::isfinite(v) && v > 0)) throw InputError(std::string(where) + ": " + what + " must be finite and > 0, got " + detail::format_number(v));
}

void check_nu(const char* where, double nu) {
  if (!(std::isfinite(nu) && nu > -1.0 && nu < 0.5))
    throw InputError(std::string(where) + ": Poisson ratio nu must lie in (-1, 0.5), got " + detail::format_number(nu));
}

}  // namespace

double baudet_rectangle_edge(double E, double nu, double i, double j) {
  check_material("baudet_rectangle_edge", E, nu);
  check_positive("baudet_rectangle_edge", "edge length i", i);
  check_positive("baudet_rectangle_edge", "edge length j", j);
  return E * (j * j * (3 * nu + 2) - i * i) / (4 * i * j * (1 + nu));
}

double baudet_rectangle_diagonal(double E, double nu, double lx, double ly) {
  check_material("baudet_rectangle_diagonal", E, nu);
  check_positive("baudet_rectangle_diagonal", "lx", lx);
  check_positive("baudet_rectangle_diagonal", "ly", ly);
  return E * (lx * lx + ly * ly) / (4 * lx * ly * (1 + nu));
}

double baudet_box_edge(double E, double nu, double i, double j, double k) {
  check_material("baudet_box_edge", E, nu);
  check_positive("baudet_box_edge", "edge length i", i);
  check_positive("baudet_box_edge", "edge length j", j);
  check_positive("baudet_box_edge", "edge length k", k);
  const double s = i * i + j * j + k * k;
  return E * (6 * j * j * k * k * (1 + nu) + (nu * (j * j + k * k) - i * i) * s) / (24 * (1 + nu) * i * j * k);
}

double baudet_box_diagonal(double E, double nu, double lx, double ly, double lz) {
  check_material("baudet_box_diagonal", E, nu);
  check_positive("baudet_box_diagonal", "lx", lx);
  check_positive("baudet_box_diagonal", "ly", ly);
  check_positive("baudet_box_diagonal", "lz", lz);
  const double s = lx * lx + ly * ly + lz * lz;
  return E * s * s / (24 * (1 + nu) * lx * ly * lz);
}

RectangleStiffness baudet_rectangle(double E, double nu, double lx, double ly) {
  RectangleStiffness s;
  s.edge[0] = baudet_rectangle_edge(E, nu, lx, ly);
  s.edge[1] = baudet_rectangle_edge(E, nu, ly, lx);
  s.diagonal = baudet_rectangle_diagonal(E, nu, lx, ly);
  return s;
}

BoxStiffness baudet_box(double E, double nu, double lx, double ly, double lz) {
  BoxStiffness s;
  s.edge[0] = baudet_box_edge(E, nu, lx, ly, lz);
  s.edge[1] = baudet_box_edge(E, nu, ly, lx, lz);
  s.edge[2] = baudet_box_edge(E, nu, lz, lx, ly);
  s.diagonal = baudet_box_diagonal(E, nu, lx, ly, lz);
  return s;
}

std::string describe(const BoxStiffness& s) {
  return "edge stiffness along x = " + detail::format_number(s.edge[0]) + ", along y = " + detail::format_number(s.edge[1]) + ", along z = " + detail::format_number(s.edge[2]) +
         ", diagonal = " + detail::format_number(s.diagonal);
}

std::string describe(const RectangleStiffness& s) {
  return "edge stiffness along x = " + detail::format_number(s.edge[0]) + ", along y = " + detail::format_number(s.edge[1]) + ", diagonal = " + detail::format_number(s.diagonal);
}

double baudet_rectangle_max_aspect(double nu) {
  check_nu("baudet_rectangle_max_aspect", nu);
  return std::sqrt(2 + 3 * nu);
}

double baudet_box_max_aspect(double nu) {
  check_nu("baudet_box_max_aspect", nu);
  const double b = 1 - nu;
  return std::sqrt(-b + std::sqrt(b * b + 6 + 10 * nu));
}

BoxStiffness clamp_edges(BoxStiffness s, double floor) {
  if (!(std::isfinite(floor) && floor >= 0)) throw InputError("clamp_edges: floor must be finite and >= 0, got " + detail::format_number(floor));
  for (double& e : s.edge) e = std::max(e, floor);
  return s;
}

RectangleStiffness clamp_edges(RectangleStiffness s, double floor) {
  if (!(std::isfinite(floor) && floor >= 0)) throw InputError("clamp_edges: floor must be finite and >= 0, got " + detail::format_number(floor));
  for (double& e : s.edge) e = std::max(e, floor);
  return s;
}

BoxStiffness baudet_box_cube_equivalent(double E, double nu, double lx, double ly, double lz) {
  check_positive("baudet_box_cube_equivalent", "lx", lx);
  check_positive("baudet_box_cube_equivalent", "ly", ly);
  check_positive("baudet_box_cube_equivalent", "lz", lz);
  const double a = std::cbrt(lx * ly * lz);
  return baudet_box(E, nu, a, a, a);
}

RectangleStiffness baudet_rectangle_square_equivalent(double E, double nu, double lx, double ly) {
  check_positive("baudet_rectangle_square_equivalent", "lx", lx);
  check_positive("baudet_rectangle_square_equivalent", "ly", ly);
  const double a = std::sqrt(lx * ly);
  return baudet_rectangle(E, nu, a, a);
}

double van_gelder_triangle_edge(double E, double area, double edge_length) {
  check_positive("van_gelder_triangle_edge", "E", E);
  check_positive("van_gelder_triangle_edge", "area", area);
  check_positive("van_gelder_triangle_edge", "edge length", edge_length);
  return E * area / (edge_length * edge_length);
}

double van_gelder_tet_edge(double E, double volume, double edge_length) {
  check_positive("van_gelder_tet_edge", "E", E);
  check_positive("van_gelder_tet_edge", "volume", volume);
  check_positive("van_gelder_tet_edge", "edge length", edge_length);
  return E * volume / (edge_length * edge_length);
}

double tet_volume(const Eigen::Vector3d& p0, const Eigen::Vector3d& p1, const Eigen::Vector3d& p2,
                  const Eigen::Vector3d& p3) {
  return std::abs((p1 - p0).dot((p2 - p0).cross(p3 - p0))) / 6.0;
}

double triangle_area(const Eigen::Vector3d& p0, const Eigen::Vector3d& p1, const Eigen::Vector3d& p2) {
  return 0.5 * (p1 - p0).cross(p2 - p0).norm();
}

std::array<double, 6> van_gelder_tet(double E, const Eigen::Vector3d& p0, const Eigen::Vector3d& p1,
                                     const Eigen::Vector3d& p2, const Eigen::Vector3d& p3) {
  const Eigen::Vector3d* p[4] = {&p0, &p1, &p2, &p3};
  constexpr int edges[6][2] = {{0, 1}, {0, 2}, {0, 3}, {1, 2}, {1, 3}, {2, 3}};
  double lmax = 0;
  for (const auto& e : edges) lmax = std::max(lmax, (*p[e[1]] - *p[e[0]]).norm());
  const double vol = tet_volume(p0, p1, p2, p3);
  if (!(std::isfinite(vol) && vol > 1e-14 * lmax * lmax * lmax))
    throw InputError("van_gelder_tet: degenerate tetrahedron (volume " + detail::format_number(vol) + ", longest edge " + detail::format_number(lmax) + ")");
  std::array<double, 6> k{};
  for (int e = 0; e < 6; ++e) k[e] = van_gelder_tet_edge(E, vol, (*p[edges[e][1]] - *p[edges[e][0]]).norm());
  return k;
}

std::array<double, 3> van_gelder_triangle(double E, const Eigen::Vector3d& p0, const Eigen::Vector3d& p1,
                                          const Eigen::Vector3d& p2) {
  const Eigen::Vector3d* p[3] = {&p0, &p1, &p2};
  double lmax = 0;
  for (int e = 0; e < 3; ++e) lmax = std::max(lmax, (*p[(e + 1) % 3] - *p[e]).norm());
  const double area = triangle_area(p0, p1, p2);
  if (!(std::isfinite(area) && area > 1e-14 * lmax * lmax))
    throw InputError("van_gelder_triangle: degenerate triangle (area " + detail::format_number(area) + ", longest edge " + detail::format_number(lmax) + ")");
  std::array<double, 3> k{};
  for (int e = 0; e < 3; ++e) k[e] = van_gelder_triangle_edge(E, area, (*p[(e + 1) % 3] - *p[e]).norm());
  return k;
}

double lumped_corner_mass(double rho, double measure, int corners) {
  check_positive("lumped_corner_mass", "density", rho);
  check_positive("lumped_corner_mass", "measure", measure);
  if (corners <= 0) throw InputError("lumped_corner_mass: corner count must be > 0, got " + std::to_string(corners));
  return rho * measure / corners;
}

}  // namespace sewn::physics
