#include "sewn/physics/shells/shell_terms.hpp"

#include <cmath>

#include "sewn/physics/errors.hpp"
#include "sewn/physics/shells/adjacency.hpp"

namespace sewn::physics::shells {

Index Membranes::add(const std::array<Index, 3>& nodes, const TriPositions& X, double young, double poisson,
                     double thickness) {
  try {
    const MembraneMaterial m = membrane_material(young, poisson, thickness);
    const TriRest r = tri_rest(X);
    const Index e = push_element(nodes);
    rest_.push_back(r);
    mat_.push_back(m);
    return e;
  } catch (const InputError& err) {
    throw InputError("membranes element " + std::to_string(size()) + ": " + err.what());
  }
}

Index Hinges::add(const std::array<Index, 4>& nodes, const HingePositions& X, double k_b) {
  try {
    if (!std::isfinite(k_b) || k_b <= 0.0)
      throw InputError("bending stiffness k_b must be finite and > 0, got " + std::to_string(k_b));
    const HingeRest r = hinge_rest(X);
    const Index e = push_element(nodes);
    rest_.push_back(r);
    k_.push_back(k_b);
    return e;
  } catch (const InputError& err) {
    throw InputError("hinges element " + std::to_string(size()) + ": " + err.what());
  }
}

Index Hinges::add_interior_edges(std::span<const std::array<Index, 3>> triangles, std::span<const double> rest_x,
                                 double k_b) {
  const std::vector<double> each(triangles.size(), k_b);
  return add_interior_edges(triangles, rest_x, each);
}

Index Hinges::add_interior_edges(std::span<const std::array<Index, 3>> triangles, std::span<const double> rest_x,
                                 std::span<const double> k_b_of_triangle) {
  if (k_b_of_triangle.size() != triangles.size())
    throw InputError("hinges: " + std::to_string(k_b_of_triangle.size()) + " stiffnesses for " +
                     std::to_string(triangles.size()) + " triangles");
  const auto across = triangles_across(triangles, rest_x.size() / 3);
  Index added = 0;
  for (Index t = 0; t < triangles.size(); ++t)
    for (int i = 0; i < 3; ++i) {
      const Across& o = across[t][static_cast<std::size_t>(i)];
      if (o.tri == invalid_index || o.tri < t) continue;  // boundary, or added from the other side
      const auto& v = triangles[t];
      const std::array<Index, 4> nodes{v[static_cast<std::size_t>(i)], v[static_cast<std::size_t>((i + 1) % 3)],
                                       v[static_cast<std::size_t>((i + 2) % 3)],
                                       triangles[o.tri][static_cast<std::size_t>(o.corner)]};
      HingePositions X;
      for (int c = 0; c < 4; ++c)
        for (int a = 0; a < 3; ++a) X(a, c) = rest_x[3 * std::size_t{nodes[static_cast<std::size_t>(c)]} + a];
      add(nodes, X, 0.5 * (k_b_of_triangle[t] + k_b_of_triangle[o.tri]));
      ++added;
    }
  return added;
}

}  // namespace sewn::physics::shells
