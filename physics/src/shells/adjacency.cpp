#include "sewn/physics/shells/adjacency.hpp"

#include <algorithm>
#include <string>
#include <tuple>

#include "sewn/physics/cell_input_error.hpp"
#include "sewn/physics/errors.hpp"

namespace sewn::physics::shells {

std::vector<std::array<Across, 3>> triangles_across(std::span<const std::array<Index, 3>> triangles, std::size_t n_nodes) {
  // every directed edge (from, to) with its triangle and opposite corner, keyed by the
  // undirected edge; an edge seen exactly twice is interior
  struct Half {
    Index lo, hi, from, to, tri;
    int corner;
  };
  std::vector<Half> halves;
  halves.reserve(3 * triangles.size());
  for (Index t = 0; t < triangles.size(); ++t) {
    const auto& v = triangles[t];
    for (int k = 0; k < 3; ++k) {
      if (v[static_cast<std::size_t>(k)] >= n_nodes)
        throw InputError("shell triangles: triangle " + std::to_string(t) + " refers to node " +
                         std::to_string(v[static_cast<std::size_t>(k)]) + " but there are " + std::to_string(n_nodes) +
                         " rest positions");
      const Index a = v[static_cast<std::size_t>((k + 1) % 3)], b = v[static_cast<std::size_t>((k + 2) % 3)];
      halves.push_back({std::min(a, b), std::max(a, b), a, b, t, k});
    }
  }
  std::sort(halves.begin(), halves.end(),
            [](const Half& p, const Half& q) { return std::tie(p.lo, p.hi, p.tri) < std::tie(q.lo, q.hi, q.tri); });
  std::vector<std::array<Across, 3>> out(triangles.size());
  for (std::size_t i = 0; i < halves.size();) {
    std::size_t j = i;
    while (j < halves.size() && halves[j].lo == halves[i].lo && halves[j].hi == halves[i].hi) ++j;
    if (j - i == 2) {
      const Half& A = halves[i];
      const Half& B = halves[i + 1];
      if (B.from != A.to)  // named by the later triangle, as a file's reader names a cell (CellInputError)
        throw CellInputError("shell triangles", static_cast<std::uint32_t>(B.tri),
                             "(triangle) runs its edge from corner " + std::to_string((B.corner + 1) % 3) + " to corner " +
                                 std::to_string((B.corner + 2) % 3) + " the same way as the shell triangle across it: the two are oriented inconsistently (their normals, and so the sign of "
                                 "bending, disagree); reverse one, or orient the sheet consistently");
      out[A.tri][static_cast<std::size_t>(A.corner)] = {B.tri, B.corner};
      out[B.tri][static_cast<std::size_t>(B.corner)] = {A.tri, A.corner};
    }
    i = j;
  }
  return out;
}

}  // namespace sewn::physics::shells
