#include "grids.hpp"

#include <map>

namespace sewn::bench::cmap {

std::vector<std::uint32_t> hex_sizes(Scale s) {
  switch (s) {
    case Scale::smoke: return {3};
    case Scale::small: return {8};
    case Scale::full: return {16, 32};
  }
  return {};
}

std::vector<std::uint32_t> quad_sizes(Scale s) {
  switch (s) {
    case Scale::smoke: return {3};
    case Scale::small: return {128};
    case Scale::full: return {512};
  }
  return {};
}

const IndexedMesh& hex_mesh(std::uint32_t n) {
  static std::map<std::uint32_t, IndexedMesh> made;
  auto it = made.find(n);
  if (it == made.end()) it = made.emplace(n, hex_grid(n, n, n)).first;
  return it->second;
}

const IndexedMesh& quad_mesh(std::uint32_t n) {
  static std::map<std::uint32_t, IndexedMesh> made;
  auto it = made.find(n);
  if (it == made.end()) it = made.emplace(n, quad_grid(n, n)).first;
  return it->second;
}

std::string to_string(const Counts& c) {
  return std::to_string(c.darts) + " darts, cells " + std::to_string(c.cells[0]) + "/" + std::to_string(c.cells[1]) +
         "/" + std::to_string(c.cells[2]) + "/" + std::to_string(c.cells[3]);
}

Counts hex_counts(std::uint32_t n) {
  const std::uint64_t m = n, p = n + 1;
  Counts c;
  c.cells = {p * p * p, 3 * m * p * p, 3 * m * m * p, m * m * m};
  c.darts = 24 * c.cells[3];
  return c;
}

Counts quad_counts(std::uint32_t n) {
  const std::uint64_t m = n, p = n + 1;
  Counts c;
  c.cells = {p * p, 2 * m * p, m * m, 0};
  c.darts = 4 * c.cells[2];
  return c;
}

Counts after_vertex_in_every_edge(const Counts& c) {
  Counts r = c;
  r.cells[0] += c.cells[1];
  r.cells[1] *= 2;
  r.darts *= 2;
  return r;
}

Counts after_vertex_in_every_face(const Counts& c) {
  Counts r = c;
  r.cells[0] += c.cells[2];
  r.cells[1] += 4 * c.cells[2];
  r.cells[2] *= 4;
  r.darts *= 3;
  return r;
}

Counts after_dangling_edge_in_every_boundary_face(std::uint32_t n) {
  Counts r = hex_counts(n);
  const std::uint64_t faces = 6 * std::uint64_t{n} * n;
  r.cells[0] += faces;
  r.cells[1] += faces;
  r.darts += 2 * faces;
  return r;
}

Counts after_edge_in_every_face(const Counts& c) {
  Counts r = c;
  r.cells[1] += c.cells[2];
  r.cells[2] *= 2;
  r.darts += 2 * c.cells[2];
  return r;
}

Counts after_unsew_middle_plane(std::uint32_t n) {
  const std::uint64_t m = n, p = n + 1;
  Counts r = hex_counts(n);
  r.cells[0] += p * p;
  r.cells[1] += 2 * m * p;
  r.cells[2] += m * m;
  return r;
}

std::string mismatch(const char* what, const Counts& want, const Counts& got) {
  if (want == got) return {};
  return std::string(what) + ": expected " + to_string(want) + ", got " + to_string(got);
}

}  // namespace sewn::bench::cmap
