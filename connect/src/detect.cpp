#include "sewn/connect/detect.hpp"

#include <algorithm>
#include <map>
#include <numeric>
#include <set>
#include <sstream>
#include <stdexcept>

namespace sewn::connect {

namespace {

using Edge = std::array<std::uint32_t, 2>;
using Face = std::array<std::uint32_t, 3>;

struct UnionFind {
  std::vector<std::uint32_t> parent;
  explicit UnionFind(std::uint32_t n) : parent(n) { std::iota(parent.begin(), parent.end(), 0u); }
  std::uint32_t find(std::uint32_t x) {
    while (parent[x] != x) x = parent[x] = parent[parent[x]];
    return x;
  }
  void join(std::uint32_t a, std::uint32_t b) { parent[find(a)] = find(b); }
};

Edge edge_of(std::uint32_t a, std::uint32_t b) { return a < b ? Edge{a, b} : Edge{b, a}; }
Face face_of(std::uint32_t a, std::uint32_t b, std::uint32_t c) {
  Face f{a, b, c};
  std::sort(f.begin(), f.end());
  return f;
}

// The faces (tets: 4; triangles: 1) and edges (tets 6, triangles 3, segments 1) of a cell.
std::vector<Face> faces_of(std::span<const std::uint32_t> p) {
  if (p.size() == 3) return {face_of(p[0], p[1], p[2])};
  if (p.size() == 4) return {face_of(p[1], p[2], p[3]), face_of(p[0], p[2], p[3]), face_of(p[0], p[1], p[3]), face_of(p[0], p[1], p[2])};
  return {};
}
std::vector<Edge> edges_of(std::span<const std::uint32_t> p) {
  std::vector<Edge> out;
  for (std::size_t i = 0; i < p.size(); ++i)
    for (std::size_t j = i + 1; j < p.size(); ++j) out.push_back(edge_of(p[i], p[j]));
  return out;
}

// Components by the header's rule.
std::vector<std::uint32_t> components(const CellList& cells, std::uint32_t& count) {
  std::map<Face, std::vector<std::uint32_t>> solid_faces;
  std::map<Edge, std::vector<std::uint32_t>> shell_edges;
  std::map<std::uint32_t, std::vector<std::uint32_t>> rod_points;
  for (std::uint32_t c = 0; c < cells.size(); ++c) {
    const auto p = cells.cell(c);
    if (cells.body[c] == Body::solid)
      for (const Face& f : faces_of(p)) solid_faces[f].push_back(c);
    if (cells.body[c] == Body::shell)
      for (const Edge& e : edges_of(p)) shell_edges[e].push_back(c);
    if (cells.body[c] == Body::rod)
      for (std::uint32_t v : p) rod_points[v].push_back(c);
  }
  UnionFind uf(cells.size());
  auto join_pairs = [&](const auto& table) {
    for (const auto& [key, list] : table)
      if (list.size() == 2) uf.join(list[0], list[1]);
  };
  join_pairs(solid_faces);
  join_pairs(shell_edges);
  for (const auto& [point, list] : rod_points)
    if (list.size() == 2 && cells.chain[list[0]] == cells.chain[list[1]]) uf.join(list[0], list[1]);
  std::vector<std::uint32_t> label(cells.size(), ~0u), out(cells.size());
  count = 0;
  for (std::uint32_t c = 0; c < cells.size(); ++c) {
    const std::uint32_t r = uf.find(c);
    if (label[r] == ~0u) label[r] = count++;
    out[c] = label[r];
  }
  return out;
}

template <class Key>
void add_component(std::map<Key, std::set<std::uint32_t>>& table, const Key& k, std::uint32_t comp) {
  table[k].insert(comp);
}

}  // namespace

const char* to_string(Body b) {
  switch (b) {
    case Body::rod:
      return "rod";
    case Body::shell:
      return "shell";
    case Body::solid:
      return "solid";
  }
  return "?";
}

const char* to_string(ConnectionKind k) {
  switch (k) {
    case ConnectionKind::point:
      return "point";
    case ConnectionKind::curve:
      return "curve";
    case ConnectionKind::surface:
      return "surface";
  }
  return "?";
}

int body_pair_index(Body a, Body b) {
  int i = static_cast<int>(a), j = static_cast<int>(b);
  if (i > j) std::swap(i, j);
  // (0,0) (0,1) (0,2) (1,1) (1,2) (2,2)
  return i == 0 ? j : i == 1 ? 2 + j : 5;
}

const char* body_pair_name(int pair) {
  static const char* names[num_body_pairs] = {"rod-rod", "rod-shell", "rod-solid", "shell-shell", "shell-solid", "solid-solid"};
  return names[pair];
}

void CellList::add(Body b, std::span<const std::uint32_t> cell_points, std::uint32_t chain_key) {
  const std::size_t want = b == Body::rod ? 2 : b == Body::shell ? 3 : 4;
  if (cell_points.size() != want)
    throw std::invalid_argument(std::string("connect::CellList: a ") + to_string(b) + " cell has " + std::to_string(want) +
                                " points, got " + std::to_string(cell_points.size()) + " (cell " + std::to_string(size()) + ")");
  for (std::size_t i = 0; i < cell_points.size(); ++i)
    for (std::size_t j = i + 1; j < cell_points.size(); ++j)
      if (cell_points[i] == cell_points[j])
        throw std::invalid_argument("connect::CellList: cell " + std::to_string(size()) + " repeats point " +
                                    std::to_string(cell_points[i]));
  body.push_back(b);
  chain.push_back(chain_key);
  points.insert(points.end(), cell_points.begin(), cell_points.end());
  offsets.push_back(static_cast<std::uint32_t>(points.size()));
}

FoundConnections detect_connections(const CellList& cells) {
  FoundConnections out;
  std::uint32_t ncomp = 0;
  out.component_of_cell = components(cells, ncomp);
  out.component_body.assign(ncomp, Body::rod);
  std::map<Face, std::set<std::uint32_t>> at_face;
  std::map<Edge, std::set<std::uint32_t>> at_edge;
  std::map<std::uint32_t, std::set<std::uint32_t>> at_point;
  for (std::uint32_t c = 0; c < cells.size(); ++c) {
    const std::uint32_t comp = out.component_of_cell[c];
    out.component_body[comp] = cells.body[c];
    const auto p = cells.cell(c);
    for (const Face& f : faces_of(p)) add_component(at_face, f, comp);
    for (const Edge& e : edges_of(p)) add_component(at_edge, e, comp);
    for (std::uint32_t v : p) add_component(at_point, v, comp);
  }
  // Contacts already covered by a higher-dimensional one between the same two components.
  std::set<std::array<std::uint32_t, 4>> covered_edges;  // (a, b, p, q)
  std::set<std::array<std::uint32_t, 3>> covered_points;  // (a, b, p)
  auto record = [&](ConnectionKind kind, std::vector<std::uint32_t> pts, std::uint32_t a, std::uint32_t b) {
    out.counts[static_cast<std::size_t>(kind)][static_cast<std::size_t>(
        body_pair_index(out.component_body[a], out.component_body[b]))]++;
    out.connections.push_back({kind, std::move(pts), {a, b}});
  };
  auto for_pairs = [](const std::set<std::uint32_t>& comps, auto&& f) {
    for (auto i = comps.begin(); i != comps.end(); ++i)
      for (auto j = std::next(i); j != comps.end(); ++j) f(*i, *j);
  };
  // (no structured bindings below: clang 14 cannot capture them in the lambdas)
  for (const auto& entry : at_face) {
    const Face& f = entry.first;
    for_pairs(entry.second, [&](std::uint32_t a, std::uint32_t b) {
      record(ConnectionKind::surface, {f[0], f[1], f[2]}, a, b);
      for (const Edge& e : edges_of(f)) covered_edges.insert({a, b, e[0], e[1]});
      for (std::uint32_t v : f) covered_points.insert({a, b, v});
    });
  }
  for (const auto& entry : at_edge) {
    const Edge& e = entry.first;
    for_pairs(entry.second, [&](std::uint32_t a, std::uint32_t b) {
      if (covered_edges.count({a, b, e[0], e[1]})) return;
      record(ConnectionKind::curve, {e[0], e[1]}, a, b);
      for (std::uint32_t v : e) covered_points.insert({a, b, v});
    });
  }
  for (const auto& entry : at_point) {
    const std::uint32_t v = entry.first;
    for_pairs(entry.second, [&](std::uint32_t a, std::uint32_t b) {
      if (!covered_points.count({a, b, v})) record(ConnectionKind::point, {v}, a, b);
    });
  }
  return out;
}

std::string connections_text(const FoundConnections& found) {
  std::ostringstream os;
  bool any = false;
  for (int k = 0; k < 3; ++k) {
    std::string line;
    for (int p = 0; p < num_body_pairs; ++p) {
      const std::uint32_t n = found.counts[static_cast<std::size_t>(k)][static_cast<std::size_t>(p)];
      if (n) line += (line.empty() ? "" : ", ") + std::to_string(n) + " " + body_pair_name(p);
    }
    if (line.empty()) continue;
    any = true;
    os << "  " << to_string(static_cast<ConnectionKind>(k)) << ": " << line << "\n";
  }
  if (!any) os << "  none: the components share no point\n";
  return os.str();
}

}  // namespace sewn::connect
