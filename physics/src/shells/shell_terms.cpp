#include "sewn/physics/shells/shell_terms.hpp"

#include <algorithm>
#include <cmath>
#include <tuple>

#include "sewn/physics/errors.hpp"

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
  // 1) every directed edge (from, to) with its triangle and opposite node, keyed by the
  //    undirected edge;
  struct Half {
    Index lo, hi, from, to, opposite, tri;
  };
  std::vector<Half> halves;
  halves.reserve(3 * triangles.size());
  const std::size_t n_nodes = rest_x.size() / 3;
  for (Index t = 0; t < triangles.size(); ++t) {
    const auto& v = triangles[t];
    for (int k = 0; k < 3; ++k) {
      if (v[k] >= n_nodes)
        throw InputError("hinges: triangle " + std::to_string(t) + " refers to node " + std::to_string(v[k]) +
                         " but there are " + std::to_string(n_nodes) + " rest positions");
      const Index a = v[k], b = v[(k + 1) % 3];
      halves.push_back({std::min(a, b), std::max(a, b), a, b, v[(k + 2) % 3], t});
    }
  }
  std::sort(halves.begin(), halves.end(),
            [](const Half& p, const Half& q) { return std::tie(p.lo, p.hi, p.tri) < std::tie(q.lo, q.hi, q.tri); });
  // 2) an edge seen exactly twice, in opposite directions, is a hinge.
  Index added = 0;
  for (std::size_t i = 0; i < halves.size();) {
    std::size_t j = i;
    while (j < halves.size() && halves[j].lo == halves[i].lo && halves[j].hi == halves[i].hi) ++j;
    if (j - i == 2) {
      const Half& A = halves[i];
      const Half& B = halves[i + 1];
      if (B.from != A.to)
        throw InputError("hinges: triangles " + std::to_string(A.tri) + " and " + std::to_string(B.tri) +
                         " are oriented inconsistently across edge " + std::to_string(A.lo) + "-" + std::to_string(A.hi));
      const std::array<Index, 4> nodes{A.opposite, A.from, A.to, B.opposite};
      HingePositions X;
      for (int c = 0; c < 4; ++c)
        for (int a = 0; a < 3; ++a) X(a, c) = rest_x[3 * std::size_t{nodes[c]} + a];
      add(nodes, X, 0.5 * (k_b_of_triangle[A.tri] + k_b_of_triangle[B.tri]));
      ++added;
    }
    i = j;
  }
  return added;
}

}  // namespace sewn::physics::shells
