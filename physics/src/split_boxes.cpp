#include "sewn/physics/split_boxes.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <map>
#include <numeric>
#include <unordered_map>

#include "sewn/physics/cell_input_error.hpp"
#include "sewn/physics/errors.hpp"
#include "sewn/physics/mss_model.hpp"

namespace sewn::physics {

namespace {

// Parametric position (bit per local axis) of each VTK hexahedron corner.
constexpr std::array<std::array<std::uint8_t, 3>, 8> corner_bits{
    {{0, 0, 0}, {1, 0, 0}, {1, 1, 0}, {0, 1, 0}, {0, 0, 1}, {1, 0, 1}, {1, 1, 1}, {0, 1, 1}}};

int corner_at(int b0, int b1, int b2) {
  for (int c = 0; c < 8; ++c)
    if (corner_bits[c][0] == b0 && corner_bits[c][1] == b1 && corner_bits[c][2] == b2) return c;
  return -1;
}

std::uint64_t edge_key(std::uint32_t a, std::uint32_t b) {
  return (std::uint64_t{std::min(a, b)} << 32) | std::max(a, b);
}

// Union-find over the edges of the hexahedra: a sheet is a class of edges that must be split alike.
class Sheets {
 public:
  std::uint32_t id(std::uint32_t a, std::uint32_t b) {
    const auto [it, added] = ids_.try_emplace(edge_key(a, b), static_cast<std::uint32_t>(parent_.size()));
    if (added) {
      parent_.push_back(it->second);
      count_.push_back(1);
    }
    return it->second;
  }
  [[nodiscard]] const std::uint32_t* find_edge(std::uint32_t a, std::uint32_t b) const {
    const auto it = ids_.find(edge_key(a, b));
    return it == ids_.end() ? nullptr : &it->second;
  }
  std::uint32_t root(std::uint32_t e) {
    while (parent_[e] != e) e = parent_[e] = parent_[parent_[e]];
    return e;
  }
  void unite(std::uint32_t a, std::uint32_t b) {
    a = root(a);
    b = root(b);
    if (a != b) parent_[b] = a;
  }
  std::uint32_t& count(std::uint32_t e) { return count_[root(e)]; }

 private:
  std::unordered_map<std::uint64_t, std::uint32_t> ids_;
  std::vector<std::uint32_t> parent_, count_;
};

using P3 = Point3;
P3 lerp(const P3& a, const P3& b, double t) { return {a[0] + (b[0] - a[0]) * t, a[1] + (b[1] - a[1]) * t, a[2] + (b[2] - a[2]) * t}; }

// Points on edges and faces shared by several hexahedra, each computed once from the edge's or
// face's corners in a canonical order (the smallest point index first).
class SharedPoints {
 public:
  explicit SharedPoints(IndexedMesh& out) : out_(out) {}

  // The point at num/den of the way along edge (a, b), counted from a.
  std::uint32_t on_edge(std::uint32_t a, std::uint32_t b, std::uint32_t num, std::uint32_t den) {
    if (a > b) {
      std::swap(a, b);
      num = den - num;
    }
    const Key k{1, edge_key(a, b), (std::uint64_t{num} << 32) | den, 0};
    return find_or_add(k, [&] { return lerp(out_.points[a], out_.points[b], static_cast<double>(num) / den); });
  }

  // The point of a face with corners q[bu][bv], at iu/nu along u (bv = 0 side) and iv/nv along v.
  std::uint32_t on_face(std::array<std::array<std::uint32_t, 2>, 2> q, std::uint32_t iu, std::uint32_t nu, std::uint32_t iv,
                        std::uint32_t nv) {
    // canonical frame: the smallest corner at the origin, u towards its smaller neighbour
    std::uint32_t lo = std::min({q[0][0], q[0][1], q[1][0], q[1][1]});
    if (q[1][0] == lo || q[1][1] == lo) {  // flip u
      std::swap(q[0], q[1]);
      iu = nu - iu;
    }
    if (q[0][1] == lo) {  // flip v
      std::swap(q[0][0], q[0][1]);
      std::swap(q[1][0], q[1][1]);
      iv = nv - iv;
    }
    if (q[0][1] < q[1][0]) {  // transpose: u along the smaller neighbour
      std::swap(q[0][1], q[1][0]);
      std::swap(iu, iv);
      std::swap(nu, nv);
    }
    const Key k{2, (std::uint64_t{q[0][0]} << 32) | q[1][0], (std::uint64_t{q[0][1]} << 32) | q[1][1],
                (std::uint64_t{iu} << 48) | (std::uint64_t{nu} << 32) | (std::uint64_t{iv} << 16) | nv};
    return find_or_add(k, [&] {
      const double s = static_cast<double>(iu) / nu, t = static_cast<double>(iv) / nv;
      return lerp(lerp(out_.points[q[0][0]], out_.points[q[1][0]], s), lerp(out_.points[q[0][1]], out_.points[q[1][1]], s), t);
    });
  }

 private:
  using Key = std::array<std::uint64_t, 4>;
  template <class F>
  std::uint32_t find_or_add(const Key& k, F&& position) {
    const auto [it, added] = index_.try_emplace(k, out_.num_points());
    if (added) out_.points.push_back(position());
    return it->second;
  }
  IndexedMesh& out_;
  std::map<Key, std::uint32_t> index_;
};

// The pieces along one axis of length `length` for a box whose shortest axis is `shortest`:
// whichever of ⌊L/s⌋ and ⌈L/s⌉ gives pieces nearer to s (by ratio).
std::uint32_t pieces(double length, double shortest) {
  const double r = length / shortest;
  const double lo = std::max(1.0, std::floor(r)), hi = std::ceil(r);
  return static_cast<std::uint32_t>(std::max(r / lo, lo / r) <= std::max(r / hi, hi / r) ? lo : hi);
}

}  // namespace

std::array<double, 3> box_axis_lengths(const IndexedMesh& mesh, std::uint32_t cell) {
  const auto v = mesh.cell(cell);
  const auto edges = MssModel<3>::local_edges(ElementKind::hexahedron);
  std::array<double, 3> len{};
  for (std::size_t e = 0; e < 12; ++e) {
    const P3& a = mesh.points[v[edges[e][0]]];
    const P3& b = mesh.points[v[edges[e][1]]];
    len[e / 4] += std::hypot(b[0] - a[0], b[1] - a[1], b[2] - a[2]) / 4;
  }
  return len;
}

BoxSplit split_boxes(const IndexedMesh& mesh, std::span<const std::uint8_t> wanted, const std::string& source) {
  const auto edges = MssModel<3>::local_edges(ElementKind::hexahedron);  // 4 per axis, axis-major
  BoxSplit out;
  Sheets sheets;
  for (std::uint32_t c = 0; c < mesh.num_cells(); ++c) {
    if (mesh.types[c] != CellType::hexahedron) continue;
    const auto v = mesh.cell(c);
    for (std::size_t a = 0; a < 3; ++a)
      for (std::size_t k = 1; k < 4; ++k)
        sheets.unite(sheets.id(v[edges[4 * a][0]], v[edges[4 * a][1]]), sheets.id(v[edges[4 * a + k][0]], v[edges[4 * a + k][1]]));
  }
  std::unordered_map<std::uint32_t, std::uint32_t> asked_by;  // sheet root -> the hexahedron that set its count
  for (std::uint32_t c = 0; c < mesh.num_cells(); ++c) {
    if (c >= wanted.size() || wanted[c] == 0 || mesh.types[c] != CellType::hexahedron) continue;
    ++out.asked;
    const std::array<double, 3> len = box_axis_lengths(mesh, c);
    const double shortest = *std::min_element(len.begin(), len.end());
    const auto v = mesh.cell(c);
    for (std::size_t a = 0; a < 3; ++a) {
      const std::uint32_t n = pieces(len[a], shortest);
      if (n > 4096)
        throw CellInputError(source, IndexedMessage() << CellRef{c} << " (hexahedron): splitting it into near-cubes would take " +
                                                                       std::to_string(n) + " pieces along one axis (at most 4096)");
      const std::uint32_t sheet = sheets.id(v[edges[4 * a][0]], v[edges[4 * a][1]]);
      std::uint32_t& count = sheets.count(sheet);
      if (n > count) asked_by[sheets.root(sheet)] = c;
      count = std::max(count, n);
    }
  }
  // a cell that is not a hexahedron cannot follow a split edge
  for (std::uint32_t c = 0; c < mesh.num_cells(); ++c) {
    if (mesh.types[c] == CellType::hexahedron) continue;
    const auto v = mesh.cell(c);
    for (std::size_t i = 0; i < v.size(); ++i)
      for (std::size_t j = i + 1; j < v.size(); ++j)
        if (const std::uint32_t* e = sheets.find_edge(v[i], v[j]); e != nullptr && sheets.count(*e) > 1) {
          const std::uint32_t by = asked_by.at(sheets.root(*e));
          const std::array<double, 3> len = box_axis_lengths(mesh, by);
          const double aspect = *std::max_element(len.begin(), len.end()) / *std::min_element(len.begin(), len.end());
          char ratio[32];
          std::snprintf(ratio, sizeof ratio, "%.3g:1", aspect);
          const std::string type = to_string(mesh.types[c]);
          throw CellInputError(source, IndexedMessage()
                                           << CellRef{c} << " (" + type + ") shares the edge from " << PointRef{v[i]} << " to "
                                           << PointRef{v[j]} << " with hexahedra split into near-cubes (its edge would be cut into " +
                                                                    std::to_string(sheets.count(*e)) + " pieces because the hexahedron "
                                           << CellRef{by} << ", " + std::string(ratio) +
                                                                 ", is too elongated for Baudet's stiffness), and only hexahedra can follow such a split: a " +
                                                                 type + " would be left with a hanging point on its edge; mesh the "
                                                                        "elongated region finer, or use elongated = \"clamp\" there");
        }
  }

  out.mesh.points = mesh.points;
  SharedPoints shared(out.mesh);
  std::vector<std::uint32_t> lattice;
  for (std::uint32_t c = 0; c < mesh.num_cells(); ++c) {
    const auto v = mesh.cell(c);
    std::array<std::uint32_t, 3> n{1, 1, 1};
    if (mesh.types[c] == CellType::hexahedron)
      for (std::size_t a = 0; a < 3; ++a) n[a] = sheets.count(sheets.id(v[edges[4 * a][0]], v[edges[4 * a][1]]));
    if (n == std::array<std::uint32_t, 3>{1, 1, 1}) {
      out.mesh.add_cell(mesh.types[c], v, mesh.tags[c]);
      out.source_cell.push_back(c);
      continue;
    }
    ++out.split;
    // the (n0+1)(n1+1)(n2+1) lattice points of the cell
    const auto at = [&](std::uint32_t i, std::uint32_t j, std::uint32_t k) -> std::uint32_t& {
      return lattice[i + (n[0] + 1) * (j + (n[1] + 1) * k)];
    };
    lattice.assign(std::size_t{n[0] + 1} * (n[1] + 1) * (n[2] + 1), 0);
    for (std::uint32_t k = 0; k <= n[2]; ++k)
      for (std::uint32_t j = 0; j <= n[1]; ++j)
        for (std::uint32_t i = 0; i <= n[0]; ++i) {
          const std::array<std::uint32_t, 3> idx{i, j, k};
          std::array<int, 3> bit{};  // 0 or 1 on a side, -1 inside
          int inside = 0;
          for (std::size_t a = 0; a < 3; ++a) {
            bit[a] = idx[a] == 0 ? 0 : idx[a] == n[a] ? 1 : -1;
            inside += bit[a] < 0;
          }
          std::uint32_t& p = at(i, j, k);
          if (inside == 0) {
            p = v[static_cast<std::size_t>(corner_at(bit[0], bit[1], bit[2]))];
          } else if (inside == 1) {
            const std::size_t a = bit[0] < 0 ? 0 : bit[1] < 0 ? 1 : 2;
            std::array<int, 3> lo = bit, hi = bit;
            lo[a] = 0;
            hi[a] = 1;
            p = shared.on_edge(v[static_cast<std::size_t>(corner_at(lo[0], lo[1], lo[2]))],
                               v[static_cast<std::size_t>(corner_at(hi[0], hi[1], hi[2]))], idx[a], n[a]);
          } else if (inside == 2) {
            const std::size_t f = bit[0] >= 0 ? 0 : bit[1] >= 0 ? 1 : 2;  // the fixed axis
            const std::size_t u = (f + 1) % 3, w = (f + 2) % 3;
            std::array<std::array<std::uint32_t, 2>, 2> q{};
            for (int bu = 0; bu < 2; ++bu)
              for (int bw = 0; bw < 2; ++bw) {
                std::array<int, 3> b = bit;
                b[u] = bu;
                b[w] = bw;
                q[static_cast<std::size_t>(bu)][static_cast<std::size_t>(bw)] = v[static_cast<std::size_t>(corner_at(b[0], b[1], b[2]))];
              }
            p = shared.on_face(q, idx[u], n[u], idx[w], n[w]);
          } else {
            // inside the cell: trilinear in its corners, used by this cell only
            const double s[3] = {static_cast<double>(i) / n[0], static_cast<double>(j) / n[1], static_cast<double>(k) / n[2]};
            P3 x{0, 0, 0};
            for (std::size_t cnr = 0; cnr < 8; ++cnr) {
              double w8 = 1;
              for (std::size_t a = 0; a < 3; ++a) w8 *= corner_bits[cnr][a] != 0 ? s[a] : 1 - s[a];
              for (std::size_t d = 0; d < 3; ++d) x[d] += w8 * mesh.points[v[cnr]][d];
            }
            p = out.mesh.num_points();
            out.mesh.points.push_back(x);
          }
        }
    for (std::uint32_t k = 0; k < n[2]; ++k)
      for (std::uint32_t j = 0; j < n[1]; ++j)
        for (std::uint32_t i = 0; i < n[0]; ++i) {
          std::array<std::uint32_t, 8> piece{};
          for (std::size_t cnr = 0; cnr < 8; ++cnr)
            piece[cnr] = at(i + corner_bits[cnr][0], j + corner_bits[cnr][1], k + corner_bits[cnr][2]);
          out.mesh.add_cell(CellType::hexahedron, piece, mesh.tags[c]);
          out.source_cell.push_back(c);
        }
  }
  return out;
}

}  // namespace sewn::physics
