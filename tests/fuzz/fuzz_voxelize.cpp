// libFuzzer target for the voxelizer (io/surface.hpp): the first byte picks the surface format
// the input falls back on (its value mod 3: OFF, OBJ, STL), the second the cells along the
// longest side (1 + value mod 24, so one input runs in milliseconds; huge resolutions are the
// library's to refuse, tested in tests/io), the rest is the surface file. Contract: the surface
// is voxelized or refused with an IoError naming the source; the hexahedra of a voxelization
// are grid cubes, and for sampled grid cells whose centre has a clear integer winding number,
// a cell is in the mesh exactly when that number is odd (the parity rule the voxelizer states).
#include <algorithm>
#include <array>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <optional>
#include <set>
#include <string>
#include <string_view>

#include "fuzz_check.hpp"
#include "sewn/io/surface.hpp"

namespace {

using sewn::Point3;

[[noreturn]] void finding(const char* what) { sewn::fuzz::finding("fuzz_voxelize", what); }

Point3 minus(const Point3& a, const Point3& b) { return {a[0] - b[0], a[1] - b[1], a[2] - b[2]}; }
double dot(const Point3& a, const Point3& b) { return a[0] * b[0] + a[1] * b[1] + a[2] * b[2]; }
double norm(const Point3& a) { return std::sqrt(dot(a, a)); }

// The winding number of the surface around q: the sum of its triangles' signed solid angles
// (van Oosterom and Strackee 1983) over 4 pi.
double winding(const sewn::io::Surface& s, const Point3& q) {
  double sum = 0;
  for (const auto& t : s.triangles) {
    const Point3 a = minus(s.points[t[0]], q), b = minus(s.points[t[1]], q), c = minus(s.points[t[2]], q);
    const Point3 bxc{b[1] * c[2] - b[2] * c[1], b[2] * c[0] - b[0] * c[2], b[0] * c[1] - b[1] * c[0]};
    const double la = norm(a), lb = norm(b), lc = norm(c);
    sum += 2 * std::atan2(dot(a, bxc), la * lb * lc + dot(a, b) * lc + dot(b, c) * la + dot(c, a) * lb);
  }
  return sum / (4 * M_PI);
}

struct Grid {
  Point3 lo{};
  double a = 0;
  std::array<long, 3> n{};
};

// The grid the voxelizer uses (surface.hpp): `cells` cubes along the bounding box's longest side.
Grid grid_of(const sewn::io::Surface& s, std::uint32_t cells) {
  Grid g;
  Point3 hi = s.points[0];
  g.lo = s.points[0];
  for (const Point3& p : s.points)
    for (std::size_t k = 0; k < 3; ++k) g.lo[k] = std::min(g.lo[k], p[k]), hi[k] = std::max(hi[k], p[k]);
  g.a = std::max({hi[0] - g.lo[0], hi[1] - g.lo[1], hi[2] - g.lo[2]}) / cells;
  for (std::size_t k = 0; k < 3; ++k) g.n[k] = std::max(1L, static_cast<long>(std::ceil((hi[k] - g.lo[k]) / g.a)));
  return g;
}

// Every cell a hexahedron centred on a grid cube, within 1e-5 of a cell (the voxelizer keeps
// cells above 1e-9 of the distance from the origin: corners round by 2.2e-7 of a cell at most);
// returns the cubes' indices.
std::set<std::array<long, 3>> cubes_of(const sewn::IndexedMesh& m, const Grid& g) {
  std::set<std::array<long, 3>> cubes;
  for (std::size_t c = 0; c < m.types.size(); ++c) {
    if (m.types[c] != sewn::CellType::hexahedron || m.offsets[c + 1] - m.offsets[c] != 8) finding("a cell is not a hexahedron");
    Point3 centre{};
    for (std::uint32_t i = m.offsets[c]; i < m.offsets[c + 1]; ++i) {
      if (m.conn[i] >= m.points.size()) finding("a cell names a point that does not exist");
      for (std::size_t k = 0; k < 3; ++k) centre[k] += m.points[m.conn[i]][k] / 8;
    }
    std::array<long, 3> ijk{};
    for (std::size_t k = 0; k < 3; ++k) {
      const double u = (centre[k] - g.lo[k]) / g.a - 0.5;
      ijk[k] = std::lround(u);
      if (!(std::abs(u - static_cast<double>(ijk[k])) <= 1e-5) || ijk[k] < 0 || ijk[k] >= g.n[k]) finding("a cell is not a cube of the grid");
    }
    if (!cubes.insert(ijk).second) finding("a grid cube appears twice");
  }
  return cubes;
}

// The winding number around q where it is clearly one integer: the same at q and at q moved
// by a millionth of a cell along each axis (a q on or next to the surface, where the
// voxelizer's perturbation decides, gives none), and within 1e-6 of it (an inconsistently
// oriented surface gives none).
std::optional<long> clear_winding(const sewn::io::Surface& s, const Point3& q) {
  const double w = winding(s, q), r = std::round(w);
  if (!(std::abs(w - r) <= 1e-6)) return std::nullopt;
  for (std::size_t k = 0; k < 3; ++k)
    for (const double d : {-1e-6, 1e-6}) {
      Point3 p = q;
      p[k] += d;
      if (!(std::abs(winding(s, p) - r) <= 1e-6)) return std::nullopt;
    }
  return std::lround(r);
}

// Up to 32 grid cells spread over the grid: in the mesh exactly when the winding number around
// their centre is odd, where it is clearly an integer.
// The winding numbers are taken in grid units (corner at 0, cells of side 1), where coordinates
// of 1e200 do not overflow their products.
void check_parity(const sewn::io::Surface& s, const Grid& g, const std::set<std::array<long, 3>>& cubes) {
  sewn::io::Surface unit = s;
  for (Point3& p : unit.points)
    for (std::size_t k = 0; k < 3; ++k) p[k] = (p[k] - g.lo[k]) / g.a;
  const long total = g.n[0] * g.n[1] * g.n[2], step = std::max(1L, total / 32);
  for (long c = 0; c < total; c += step) {
    const std::array<long, 3> ijk{c % g.n[0], c / g.n[0] % g.n[1], c / (g.n[0] * g.n[1])};
    const Point3 q{static_cast<double>(ijk[0]) + 0.5, static_cast<double>(ijk[1]) + 0.5, static_cast<double>(ijk[2]) + 0.5};
    const std::optional<long> w = clear_winding(unit, q);
    if (w && (*w % 2 != 0) != (cubes.count(ijk) == 1)) finding("a cell's membership disagrees with the parity of its winding number");
  }
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  if (size < 2) return 0;
  static const std::array<std::string, 3> sources{"fuzz-input.off", "fuzz-input.obj", "fuzz-input.stl"};
  const std::string& source = sources[data[0] % 3];
  const std::uint32_t cells = 1 + data[1] % 24;
  const std::string_view bytes(reinterpret_cast<const char*>(data + 2), size - 2);
  sewn::io::Surface s;
  sewn::fuzz::read_or_refusal(
      "fuzz_voxelize", source,
      [&] {
        s = sewn::io::parse_surface(bytes, source);
        return sewn::io::voxelize(s, cells, source);
      },
      [&](const sewn::IndexedMesh& m) {
        const Grid g = grid_of(s, cells);
        check_parity(s, g, cubes_of(m, g));
      });
  return 0;
}
