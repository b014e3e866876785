// The cell complex of a map (see topology.hpp): cells as orbits or, with points, as point sets;
// reference orientations of edges and faces; the incidences of top cells on their facets.
#include <algorithm>
#include <string>
#include <unordered_map>

#include "complex.hpp"

namespace sewn::topo {

namespace {

std::string dart_str(std::uint32_t x) { return "dart " + std::to_string(x); }

// Labels every live dart with its orbit under the generators `nbr` calls back with, numbering
// orbits in order of their smallest dart (each orbit's walk starts there). O(n).
template <class Nbr>
std::uint32_t label_orbits(const Complex& c, std::vector<std::uint32_t>& label, std::vector<std::uint32_t>& root, Nbr&& nbr) {
  label.assign(c.cap, null);
  root.clear();
  std::vector<std::uint32_t> stack;
  for (std::uint32_t x = 0; x < c.cap; ++x) {
    if (!c.alive(x) || label[x] != null) continue;
    const auto id = static_cast<std::uint32_t>(root.size());
    root.push_back(x);
    label[x] = id;
    stack.assign(1, x);
    while (!stack.empty()) {
      const std::uint32_t y = stack.back();
      stack.pop_back();
      nbr(y, [&](std::uint32_t z) {
        if (z != null && label[z] == null) {
          label[z] = id;
          stack.push_back(z);
        }
      });
    }
  }
  return static_cast<std::uint32_t>(root.size());
}

// Renumbers cells that share a key (points) into one, in order of their smallest dart; roots
// are recomputed as the smallest dart of each merged cell. `key(cell)` returns a hashable key.
template <class Key, class Hash, class KeyOf>
std::uint32_t merge_by_key(const Complex& c, std::vector<std::uint32_t>& label, std::vector<std::uint32_t>& root, KeyOf&& key_of) {
  std::unordered_map<Key, std::uint32_t, Hash> id_of_key;
  id_of_key.reserve(root.size());
  std::vector<std::uint32_t> new_id(root.size());
  std::vector<std::uint32_t> new_root;
  // map cells are numbered by smallest dart, so visiting them in order gives merged cells
  // numbered by smallest dart too
  for (std::uint32_t k = 0; k < root.size(); ++k) {
    auto [it, fresh] = id_of_key.try_emplace(key_of(root[k]), static_cast<std::uint32_t>(new_root.size()));
    if (fresh) new_root.push_back(root[k]);
    new_id[k] = it->second;
  }
  for (std::uint32_t x = 0; x < c.cap; ++x)
    if (label[x] != null) label[x] = new_id[label[x]];
  root = std::move(new_root);
  return static_cast<std::uint32_t>(root.size());
}

struct VecHash {
  std::size_t operator()(const std::vector<std::uint32_t>& v) const noexcept {
    std::size_t h = v.size();
    for (std::uint32_t x : v) h = h * 0x9E3779B97F4A7C15ull + x + (h >> 29);
    return h;
  }
};
struct PairHash {
  std::size_t operator()(std::uint64_t k) const noexcept { return std::hash<std::uint64_t>{}(k * 0x9E3779B97F4A7C15ull); }
};

}  // namespace

Complex build_complex(const detail::TopologyInput& in, std::span<const std::uint32_t> point_of_dart) {
  Complex c;
  c.dim = in.dim;
  c.beta = &in.beta;
  c.cap = static_cast<std::uint32_t>(in.beta.size());
  c.by_points = !point_of_dart.empty();
  const int D = c.dim;
  if (D != 2 && D != 3) throw TopologyError("topology: invariants are computed for 2- and 3-maps, not " + std::to_string(D) + "-maps");

  // 1) preconditions: closed faces, closed volumes, points for every dart
  for (std::uint32_t x = 0; x < c.cap; ++x) {
    if (!c.alive(x)) continue;
    if (c.b(x, 1) == null || c.b(x, 0) == null)
      throw TopologyError("topology: " + dart_str(x) + " is " + (c.b(x, 1) == null ? "1" : "0") +
                          "-free (an open face); the cell complex needs closed faces");
    if (D == 3 && c.b(x, 2) == null)
      throw TopologyError("topology: " + dart_str(x) + " is 2-free (an open volume); the cell complex of a 3-map needs closed volumes");
    if (c.by_points && (x >= point_of_dart.size() || point_of_dart[x] == null))
      throw TopologyError("topology: " + dart_str(x) + " has no point in point_of_dart (" + std::to_string(point_of_dart.size()) +
                          " entries)");
  }

  // 2) orbits: vertices, edges, faces (3-maps), top cells
  c.count[0] = label_orbits(c, c.cell[0], c.root[0], [&](std::uint32_t x, auto&& f) {
    const std::uint32_t x0 = c.b(x, 0);
    for (int j = 2; j <= D; ++j) {
      if (const std::uint32_t y = c.b(x, j); y != null) {
        f(c.b(y, 1));
        for (int k = 2; k <= D; ++k)
          if (k != j) f(c.b(y, k));
      }
      f(c.b(x0, j));
    }
  });
  c.count[1] = label_orbits(c, c.cell[1], c.root[1], [&](std::uint32_t x, auto&& f) {
    for (int j = 2; j <= D; ++j) f(c.b(x, j));
  });
  if (D == 3)
    c.count[2] = label_orbits(c, c.cell[2], c.root[2], [&](std::uint32_t x, auto&& f) {
      f(c.b(x, 0));
      f(c.b(x, 1));
      f(c.b(x, 3));
    });
  c.count[D] = label_orbits(c, c.cell[D], c.root[D], [&](std::uint32_t x, auto&& f) {
    f(c.b(x, 0));
    f(c.b(x, 1));
    if (D == 3) f(c.b(x, 2));
  });

  // 3) reference orientations: an edge runs as its smallest dart, a face as its smallest
  //    dart's β1 cycle (the other side, if 3-sewn, runs against it)
  c.edge_rev.assign(c.cap, 0);
  {
    std::vector<std::uint32_t> stack;
    std::vector<std::uint8_t> seen(c.cap, 0);
    for (std::uint32_t r : c.root[1]) {
      seen[r] = 1;
      stack.assign(1, r);
      while (!stack.empty()) {
        const std::uint32_t y = stack.back();
        stack.pop_back();
        for (int j = 2; j <= D; ++j)
          if (const std::uint32_t z = c.b(y, j); z != null && !seen[z]) {
            seen[z] = 1;
            c.edge_rev[z] = static_cast<std::uint8_t>(1 - c.edge_rev[y]);
            stack.push_back(z);
          }
      }
    }
  }
  if (D == 3) {
    c.face_rev.assign(c.cap, 1);
    for (std::uint32_t r : c.root[2]) {
      std::uint32_t y = r;
      do {
        c.face_rev[y] = 0;
        y = c.b(y, 1);
      } while (y != r);
    }
  }

  // 4) with points: identify vertices, edges and (3-maps) faces by their points
  if (c.by_points) {
    auto pt = [&](std::uint32_t x) { return point_of_dart[x]; };
    for (std::uint32_t x = 0; x < c.cap; ++x)
      if (c.alive(x) && pt(x) != pt(c.root[0][c.cell[0][x]]))
        throw TopologyError("topology: " + dart_str(x) + " starts at point " + std::to_string(pt(x)) + " but " +
                            dart_str(c.root[0][c.cell[0][x]]) + " of the same vertex at point " +
                            std::to_string(pt(c.root[0][c.cell[0][x]])));
    c.count[0] = merge_by_key<std::uint32_t, std::hash<std::uint32_t>>(c, c.cell[0], c.root[0], pt);
    for (std::uint32_t x = 0; x < c.cap; ++x) {
      if (!c.alive(x)) continue;
      const std::uint32_t p = pt(x), q = pt(c.b(x, 1));
      if (p == q)
        throw TopologyError("topology: the edge of " + dart_str(x) + " starts and ends at point " + std::to_string(p) +
                            "; identifying cells by points needs edges between two points");
      c.edge_rev[x] = p > q ? 1 : 0;
    }
    c.count[1] = merge_by_key<std::uint64_t, PairHash>(c, c.cell[1], c.root[1], [&](std::uint32_t x) {
      const std::uint32_t p = pt(x), q = pt(c.b(x, 1));
      return (std::uint64_t{std::min(p, q)} << 32) | std::max(p, q);
    });
    if (D == 3) {
      // a face side runs along the reference if, from its smallest point, it goes next to the
      // smaller of that point's two neighbours
      std::vector<std::uint32_t> pts;
      for (std::uint32_t x = 0; x < c.cap; ++x) {
        if (!c.alive(x)) continue;
        std::uint32_t lo = x;
        for (std::uint32_t y = c.b(x, 1); y != x; y = c.b(y, 1))
          if (pt(y) < pt(lo)) lo = y;
        c.face_rev[x] = pt(c.b(lo, 1)) > pt(c.b(lo, 0)) ? 1 : 0;
      }
      c.count[2] = merge_by_key<std::vector<std::uint32_t>, VecHash>(c, c.cell[2], c.root[2], [&](std::uint32_t r) {
        pts.clear();
        std::uint32_t y = r;
        do {
          pts.push_back(pt(y));
          y = c.b(y, 1);
        } while (y != r);
        std::sort(pts.begin(), pts.end());
        return pts;
      });
    }
  }

  // 5) top cells across their facets: each dart of a 2-map, each β1 cycle of a 3-map (by its
  //    smallest dart)
  const int F = D - 1;
  for (std::uint32_t x = 0; x < c.cap; ++x) {
    if (!c.alive(x)) continue;
    if (D == 3) {
      bool smallest = true;
      for (std::uint32_t y = c.b(x, 1); y != x && smallest; y = c.b(y, 1)) smallest = y > x;
      if (!smallest) continue;
    }
    const bool rev = D == 2 ? c.edge_rev[x] != 0 : c.face_rev[x] != 0;
    c.incidences.push_back({c.cell[D][x], c.cell[F][x], x, static_cast<std::int8_t>(rev ? -1 : 1)});
  }
  c.by_facet = Csr::group(c.count[F], static_cast<std::uint32_t>(c.incidences.size()),
                          [&](std::uint32_t i) { return c.incidences[i].facet; });
  return c;
}

}  // namespace sewn::topo
