// Orientation of top cells, boundary components and their genus, links of vertices and edges;
// and compute_topology, which runs them all.
#include <algorithm>
#include <string>

#include "complex.hpp"

namespace sewn::topo {

namespace {

// Index of key in a sorted, deduplicated vector.
template <class T>
std::uint32_t index_of(const std::vector<T>& sorted, const T& key) {
  return static_cast<std::uint32_t>(std::lower_bound(sorted.begin(), sorted.end(), key) - sorted.begin());
}

template <class T>
void sort_unique(std::vector<T>& v) {
  std::sort(v.begin(), v.end());
  v.erase(std::unique(v.begin(), v.end()), v.end());
}

// Signs s ∈ {+1, -1} for items 0..n-1 such that s[a]·rel = s[b] on every constraint (a, b, rel),
// found breadth-first; an item of a set whose constraints contradict each other gets bad = 1
// through the callback. O(n + constraints).
struct Constraint {
  std::uint32_t a, b;
  std::int8_t rel;
};
template <class Bad>
std::vector<std::int8_t> solve_signs(std::uint32_t n, const std::vector<Constraint>& cons, Bad&& bad) {
  const Csr by_item = Csr::group(n, static_cast<std::uint32_t>(2 * cons.size()),
                                 [&](std::uint32_t i) { return i % 2 == 0 ? cons[i / 2].a : cons[i / 2].b; });
  std::vector<std::int8_t> s(n, 0);
  std::vector<std::uint32_t> queue;
  for (std::uint32_t t0 = 0; t0 < n; ++t0) {
    if (s[t0] != 0) continue;
    s[t0] = 1;
    queue.assign(1, t0);
    for (std::size_t h = 0; h < queue.size(); ++h) {
      const std::uint32_t t = queue[h];
      for (const std::uint32_t* p = by_item.begin(t); p != by_item.end(t); ++p) {
        const Constraint& k = cons[*p / 2];
        const std::uint32_t u = *p % 2 == 0 ? k.b : k.a;
        const auto want = static_cast<std::int8_t>(s[t] * k.rel);
        if (s[u] == 0) {
          s[u] = want;
          queue.push_back(u);
        } else if (s[u] != want) {
          bad(t);
        }
      }
    }
  }
  return s;
}

}  // namespace

void compute_orientation(const Complex& c, const std::vector<std::uint32_t>& comp_of_vertex, Topology& out) {
  const int D = c.dim;
  const std::uint32_t ntop = c.count[static_cast<std::size_t>(D)];
  auto comp_of_top = [&](std::uint32_t t) { return comp_of_vertex[c.cell[0][c.root[static_cast<std::size_t>(D)][t]]]; };
  // across a facet of two top cells, their orientations must induce opposite ones on it
  std::vector<Constraint> cons;
  for (std::uint32_t f = 0; f < c.by_facet.rows(); ++f) {
    if (c.by_facet.size(f) != 2) continue;
    const Incidence& i1 = c.incidences[c.by_facet.begin(f)[0]];
    const Incidence& i2 = c.incidences[c.by_facet.begin(f)[1]];
    cons.push_back({i1.top, i2.top, static_cast<std::int8_t>(-i1.sign * i2.sign)});
  }
  std::vector<std::uint8_t> bad(out.components.size(), 0);
  out.orientation = solve_signs(ntop, cons, [&](std::uint32_t t) { bad[comp_of_top(t)] = 1; });
  out.orientable = true;
  for (std::size_t k = 0; k < bad.size(); ++k) {
    out.components[k].orientable = !bad[k];
    out.orientable = out.orientable && !bad[k];
  }
  out.total.orientable = out.orientable;
  for (std::uint32_t t = 0; t < ntop; ++t)
    if (bad[comp_of_top(t)]) out.orientation[t] = 0;
}

void compute_boundary(const Complex& c, const std::vector<std::uint32_t>& comp_of_vertex, Topology& out) {
  const int D = c.dim;
  // boundary facets: on one side of one top cell; each given by its incidence's dart
  std::vector<std::uint32_t> facet_dart;
  for (std::uint32_t f = 0; f < c.by_facet.rows(); ++f)
    if (c.by_facet.size(f) == 1) facet_dart.push_back(c.incidences[c.by_facet.begin(f)[0]].dart);
  auto for_each_side_dart = [&](std::uint32_t x, auto&& g) {
    if (D == 2) {
      g(x);
      return;
    }
    std::uint32_t y = x;
    do {
      g(y);
      y = c.b(y, 1);
    } while (y != x);
  };
  UnionFind uf(c.count[0]);
  for (std::uint32_t x : facet_dart)
    for_each_side_dart(x, [&](std::uint32_t y) { uf.unite(c.cell[0][y], c.cell[0][c.b(y, 1)]); });
  std::vector<std::uint32_t> bc_of_root(c.count[0], null), edge_bc(c.count[1], null), vertex_bc(c.count[0], null);
  std::vector<std::uint32_t> bc_of_facet(facet_dart.size());
  out.boundary.clear();
  for (std::size_t i = 0; i < facet_dart.size(); ++i) {
    const std::uint32_t x = facet_dart[i];
    std::uint32_t& bc = bc_of_root[uf.find(c.cell[0][x])];
    if (bc == null) {
      bc = static_cast<std::uint32_t>(out.boundary.size());
      BoundaryComponent b;
      b.component = comp_of_vertex[c.cell[0][x]];
      b.dart = Dart(x);
      out.boundary.push_back(b);
      ++out.components[b.component].boundary_components;
    }
    bc_of_facet[i] = bc;
    auto& b = out.boundary[bc];
    if (D == 3) ++b.cells[2];
    for_each_side_dart(x, [&](std::uint32_t y) {
      if (std::uint32_t& e = edge_bc[c.cell[1][y]]; e == null) {
        e = bc;
        ++b.cells[1];
      }
      for (std::uint32_t v : {c.cell[0][y], c.cell[0][c.b(y, 1)]})
        if (vertex_bc[v] == null) {
          vertex_bc[v] = bc;
          ++b.cells[0];
        }
    });
  }
  for (auto& b : out.boundary) b.euler = b.cells[0] - b.cells[1] + b.cells[2];
  if (D == 3) {
    // orientation of each boundary surface: its faces across the edges shared by two of them
    struct Side {
      std::uint32_t edge, face;
      std::int8_t sign;
      bool operator<(const Side& o) const { return edge < o.edge; }
    };
    std::vector<Side> sides;
    for (std::uint32_t i = 0; i < facet_dart.size(); ++i)
      for_each_side_dart(facet_dart[i], [&](std::uint32_t y) {
        sides.push_back({c.cell[1][y], i, static_cast<std::int8_t>(c.edge_rev[y] ? -1 : 1)});
      });
    std::stable_sort(sides.begin(), sides.end());
    std::vector<Constraint> cons;
    for (std::size_t i = 0; i < sides.size();) {
      std::size_t j = i;
      while (j < sides.size() && sides[j].edge == sides[i].edge) ++j;
      if (j - i == 2) cons.push_back({sides[i].face, sides[i + 1].face, static_cast<std::int8_t>(-sides[i].sign * sides[i + 1].sign)});
      i = j;
    }
    (void)solve_signs(static_cast<std::uint32_t>(facet_dart.size()), cons,
                      [&](std::uint32_t i) { out.boundary[bc_of_facet[i]].orientable = false; });
    // a closed surface: every edge in two of its faces, the face corners at every vertex one cycle
    std::vector<std::uint8_t> surface(out.boundary.size(), 1);
    for (std::size_t i = 0; i < sides.size();) {
      std::size_t j = i;
      while (j < sides.size() && sides[j].edge == sides[i].edge) ++j;
      if (j - i != 2) surface[bc_of_facet[sides[i].face]] = 0;
      i = j;
    }
    struct Corner {
      std::uint32_t vertex, from, to, bc;
      bool operator<(const Corner& o) const { return vertex < o.vertex; }
    };
    std::vector<Corner> corners;
    for (std::uint32_t i = 0; i < facet_dart.size(); ++i)
      for_each_side_dart(facet_dart[i], [&](std::uint32_t y) {
        corners.push_back({c.cell[0][y], c.end_key(c.b(y, 0)), c.start_key(y), bc_of_facet[i]});
      });
    std::stable_sort(corners.begin(), corners.end());
    std::vector<std::uint32_t> keys;
    for (std::size_t i = 0; i < corners.size();) {
      std::size_t j = i;
      while (j < corners.size() && corners[j].vertex == corners[i].vertex) ++j;
      keys.clear();
      for (std::size_t k = i; k < j; ++k) keys.insert(keys.end(), {corners[k].from, corners[k].to});
      std::vector<std::uint32_t> nodes = keys;
      sort_unique(nodes);
      std::vector<std::uint32_t> degree(nodes.size(), 0);
      UnionFind local(static_cast<std::uint32_t>(nodes.size()));
      auto pieces = static_cast<std::uint32_t>(nodes.size());
      for (std::size_t k = 0; k < keys.size(); k += 2) {
        const std::uint32_t a = index_of(nodes, keys[k]), b = index_of(nodes, keys[k + 1]);
        ++degree[a];
        ++degree[b];
        if (local.unite(a, b)) --pieces;
      }
      if (pieces != 1 || std::any_of(degree.begin(), degree.end(), [](std::uint32_t d) { return d != 2; }))
        surface[corners[i].bc] = 0;
      i = j;
    }
    for (std::size_t k = 0; k < out.boundary.size(); ++k) {
      auto& b = out.boundary[k];
      b.surface = surface[k] != 0;
      if (b.surface) b.genus = b.orientable ? (2 - b.euler) / 2 : 2 - b.euler;
    }
  } else {
    for (auto& comp : out.components) {
      const std::int64_t k = 2 - comp.euler - comp.boundary_components;
      comp.genus = comp.orientable ? k / 2 : k;
    }
  }
  out.total.boundary_components = static_cast<std::uint32_t>(out.boundary.size());
}

namespace {

// The link of a vertex of a 2-map: a graph whose nodes are the ends of its edges at the vertex
// and whose edges are its face corners. A circle or a path when the vertex is manifold.
std::string vertex_link_2(const Complex& c, const std::uint32_t* first, const std::uint32_t* last) {
  std::vector<std::uint32_t> keys;
  for (const std::uint32_t* p = first; p != last; ++p) {
    keys.push_back(c.end_key(c.b(*p, 0)));
    keys.push_back(c.start_key(*p));
  }
  std::vector<std::uint32_t> nodes = keys;
  sort_unique(nodes);
  std::vector<std::uint32_t> degree(nodes.size(), 0);
  UnionFind uf(static_cast<std::uint32_t>(nodes.size()));
  auto pieces = static_cast<std::uint32_t>(nodes.size());
  for (std::size_t i = 0; i < keys.size(); i += 2) {
    const std::uint32_t a = index_of(nodes, keys[i]), b = index_of(nodes, keys[i + 1]);
    ++degree[a];
    ++degree[b];
    if (uf.unite(a, b)) --pieces;
  }
  if (pieces != 1) return "its link has " + std::to_string(pieces) + " pieces (cells meet only at this vertex)";
  const std::uint32_t dmax = *std::max_element(degree.begin(), degree.end());
  if (dmax > 2) return "an edge at it lies in " + std::to_string(dmax) + " face corners";
  return {};
}

// The link of a vertex of a 3-map: a surface whose vertices are the ends of its edges at the
// vertex, whose edges are its face corners and whose faces are its volume corners. A sphere or
// a disc when the vertex is manifold.
std::string vertex_link_3(const Complex& c, const std::uint32_t* first, const std::uint32_t* last) {
  const auto k = static_cast<std::uint32_t>(last - first);
  // a face corner seen from either side of the face (with points: the face, which meets the
  // vertex once)
  auto corner = [&](std::uint32_t x) {
    if (c.by_points) return c.cell[2][x];
    const std::uint32_t x3 = c.b(x, 3);
    return x3 == null ? x : std::min(x, c.b(x3, 1));
  };
  std::vector<std::uint32_t> corners, nodes;
  std::vector<std::array<std::uint32_t, 2>> at;          // (link vertex, face corner)
  std::vector<std::array<std::uint32_t, 3>> fan;         // (link vertex, corner, next corner)
  for (const std::uint32_t* p = first; p != last; ++p) {
    const std::uint32_t x = *p, cx = corner(x);
    corners.push_back(cx);
    nodes.push_back(c.start_key(x));
    at.push_back({c.start_key(x), cx});
    at.push_back({c.end_key(c.b(x, 0)), cx});
    fan.push_back({c.start_key(x), cx, corner(c.b(c.b(x, 2), 1))});
  }
  // each face corner in at most two volume corners
  std::vector<std::uint32_t> sorted = corners;
  std::sort(sorted.begin(), sorted.end());
  bool open = false;
  for (std::size_t i = 0; i < sorted.size();) {
    std::size_t j = i;
    while (j < sorted.size() && sorted[j] == sorted[i]) ++j;
    if (j - i > 2) return "a face at it lies in " + std::to_string(j - i) + " volumes";
    open = open || j - i == 1;
    i = j;
  }
  sort_unique(nodes);
  sort_unique(at);
  sort_unique(corners);
  // around each link vertex the corners must form one fan
  {
    UnionFind uf(static_cast<std::uint32_t>(at.size()));
    auto pieces = static_cast<std::uint32_t>(at.size());
    for (const auto& f : fan)
      if (uf.unite(index_of(at, {f[0], f[1]}), index_of(at, {f[0], f[2]}))) --pieces;
    if (pieces != nodes.size()) return "the volumes around an edge at it form " + std::to_string(pieces - nodes.size() + 1) + " fans";
  }
  // connected
  {
    UnionFind uf(static_cast<std::uint32_t>(nodes.size()));
    auto pieces = static_cast<std::uint32_t>(nodes.size());
    // join the two ends of each corner
    std::vector<std::uint32_t> first_node(corners.size(), null);
    for (const auto& a : at) {
      std::uint32_t& fn = first_node[index_of(corners, a[1])];
      const std::uint32_t v = index_of(nodes, a[0]);
      if (fn == null) fn = v;
      else if (uf.unite(fn, v)) --pieces;
    }
    if (pieces != 1) return "its link has " + std::to_string(pieces) + " pieces (cells meet only at this vertex)";
  }
  // χ of the link: volume corners are the orbits of β1∘β2 among the vertex's darts
  std::int64_t faces = 0;
  {
    std::vector<std::uint8_t> seen(k, 0);
    for (std::uint32_t i = 0; i < k; ++i) {
      if (seen[i]) continue;
      ++faces;
      std::uint32_t y = first[i];
      for (std::uint32_t g = 0; g <= k; ++g) {
        const auto j = static_cast<std::uint32_t>(std::lower_bound(first, last, y) - first);
        if (j == k || first[j] != y || seen[j]) break;
        seen[j] = 1;
        y = c.b(c.b(y, 2), 1);
      }
    }
  }
  const std::int64_t chi = static_cast<std::int64_t>(nodes.size()) - static_cast<std::int64_t>(corners.size()) + faces;
  if (open && chi != 1) return "its link is a surface with boundary and χ = " + std::to_string(chi) + ", not a disc";
  if (!open && chi != 2) return "its link is a closed surface with χ = " + std::to_string(chi) + ", not a sphere";
  return {};
}

// The link of an edge of a 3-map: a graph whose nodes are the faces at the edge and whose edges
// are the volumes' wedges along it. A circle or a path when the edge is manifold.
std::string edge_link_3(const Complex& c, const std::uint32_t* first, const std::uint32_t* last) {
  auto side = [&](std::uint32_t x) {
    if (c.by_points) return c.cell[2][x];
    const std::uint32_t x3 = c.b(x, 3);
    return x3 == null ? x : std::min(x, x3);
  };
  std::vector<std::uint32_t> ends, nodes;
  for (const std::uint32_t* p = first; p != last; ++p)
    if (c.edge_rev[*p] == 0) {
      ends.push_back(side(*p));
      ends.push_back(side(c.b(*p, 2)));
    }
  nodes = ends;
  sort_unique(nodes);
  std::vector<std::uint32_t> degree(nodes.size(), 0);
  UnionFind uf(static_cast<std::uint32_t>(nodes.size()));
  auto pieces = static_cast<std::uint32_t>(nodes.size());
  for (std::size_t i = 0; i < ends.size(); i += 2) {
    const std::uint32_t a = index_of(nodes, ends[i]), b = index_of(nodes, ends[i + 1]);
    ++degree[a];
    ++degree[b];
    if (uf.unite(a, b)) --pieces;
  }
  const std::uint32_t dmax = nodes.empty() ? 0 : *std::max_element(degree.begin(), degree.end());
  if (dmax > 2) return "a face at it lies in " + std::to_string(dmax) + " volumes";
  if (pieces != 1) return "the volumes around it form " + std::to_string(pieces) + " fans";
  return {};
}

}  // namespace

void compute_manifoldness(const Complex& c, Topology& out) {
  const int D = c.dim;
  for (int i = 0; i <= 1; ++i) {
    const auto& cell = c.cell[static_cast<std::size_t>(i)];
    const Csr darts = Csr::group(c.count[static_cast<std::size_t>(i)], c.cap, [&](std::uint32_t x) { return cell[x]; });
    for (std::uint32_t k = 0; k < darts.rows(); ++k) {
      std::string why;
      if (i == 0)
        why = D == 2 ? vertex_link_2(c, darts.begin(k), darts.end(k)) : vertex_link_3(c, darts.begin(k), darts.end(k));
      else if (D == 3)
        why = edge_link_3(c, darts.begin(k), darts.end(k));
      else if (darts.size(k) > 2)
        why = "it lies in " + std::to_string(darts.size(k)) + " faces";
      if (!why.empty()) out.nonmanifold.push_back({i, k, Dart(c.root[static_cast<std::size_t>(i)][k]), std::move(why)});
    }
  }
  out.manifoldness_checked = true;
}

}  // namespace sewn::topo

namespace sewn::detail {

Topology compute_topology(const TopologyInput& in, const TopologyOptions& opt) {
  const topo::Complex c = topo::build_complex(in, opt.point_of_dart);
  Topology out;
  out.dim = c.dim;
  const std::vector<std::uint32_t> comp_of_vertex = topo::compute_homology(c, out);
  topo::compute_orientation(c, comp_of_vertex, out);
  topo::compute_boundary(c, comp_of_vertex, out);
  if (opt.manifoldness) topo::compute_manifoldness(c, out);
  for (int i = 0; i <= c.dim; ++i) out.cell_of_dart[static_cast<std::size_t>(i)] = c.cell[static_cast<std::size_t>(i)];
  out.component_of_dart.assign(c.cap, topo::null);
  for (std::uint32_t x = 0; x < c.cap; ++x)
    if (c.alive(x)) out.component_of_dart[x] = comp_of_vertex[c.cell[0][x]];
  return out;
}

}  // namespace sewn::detail
