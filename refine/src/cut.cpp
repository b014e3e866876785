#include "sewn/refine/cut.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <map>
#include <set>
#include <span>
#include <stdexcept>
#include <string>
#include <utility>

#include <Eigen/Geometry>

#include "hierarchy/bilinear.hpp"
#include "hierarchy/neighbours.hpp"
#include "hierarchy/sides.hpp"
#include "sewn/refine/hierarchy.hpp"
#include "sewn/refine/subdivide.hpp"

namespace sewn::refine {

using physics::ElementKind;
using physics::InputError;
using physics::invalid_index;
using Vec3 = Eigen::Vector3d;

namespace {

bool is_volume(ElementKind k) { return k == ElementKind::hexahedron || k == ElementKind::tetrahedron; }
bool is_surface(ElementKind k) { return k == ElementKind::quad || k == ElementKind::triangle; }

// The darts of a facet on one side: a face's β1 cycle, or the single dart of an edge.
template <int D>
std::vector<Dart> facet_darts(const MssModel<D>& m, const Facet& f) {
  std::vector<Dart> out{f.dart};
  if (f.index == 3)
    for (Dart x = m.map().beta(f.dart, 1); x && x != f.dart; x = m.map().beta(x, 1)) out.push_back(x);
  return out;
}

// Sorted mesh points of a facet (through the particles' original points).
template <int D>
std::vector<std::uint32_t> facet_points(const MssModel<D>& m, const Facet& f) {
  std::vector<std::uint32_t> pts;
  for (Dart x : facet_darts(m, f)) pts.push_back(m.point_of_node(m.node_of(x)));
  // an edge's other end: where the next dart of its face starts (β2 is null on a free edge)
  if (f.index == 2) pts.push_back(m.point_of_node(m.node_of(m.map().beta(f.dart, 1))));
  std::sort(pts.begin(), pts.end());
  return pts;
}

// Rest positions of a facet's vertices (an edge: both ends).
template <int D>
std::vector<Vec3> facet_rest_vertices(const MssModel<D>& m, const Facet& f) {
  std::vector<Vec3> out;
  for (Dart x : facet_darts(m, f)) out.push_back(m.rest_position(m.node_of(x)));
  if (f.index == 2) out.push_back(m.rest_position(m.node_of(m.map().beta(f.dart, 1))));
  return out;
}

template <int D>
Vec3 facet_centroid(const MssModel<D>& m, const Facet& f) {
  Vec3 c = Vec3::Zero();
  const std::vector<Vec3> v = facet_rest_vertices(m, f);
  for (const Vec3& p : v) c += p;
  return c / static_cast<double>(v.size());
}

// True if the rest position q lies on the facet with these rest corners (2: a segment; more: a
// planar convex polygon, corners in order, as every face of a mesh cell), to round-off of its size.
bool on_facet(std::span<const Vec3> c, const Vec3& q) {
  double size = 0;
  for (const Vec3& p : c) size = std::max(size, (p - c[0]).norm());
  const double tol = 1e-9 * size;
  if (c.size() == 2) {
    const Vec3 d = c[1] - c[0];
    const double t = d.dot(q - c[0]) / d.squaredNorm();
    return t >= -1e-9 && t <= 1 + 1e-9 && (c[0] + t * d - q).norm() <= tol;
  }
  Vec3 n = Vec3::Zero();  // Newell's normal
  for (std::size_t i = 0; i < c.size(); ++i) n += c[i].cross(c[(i + 1) % c.size()]);
  n.normalize();
  if (std::abs(n.dot(q - c[0])) > tol) return false;
  for (std::size_t i = 0; i < c.size(); ++i)
    if ((c[(i + 1) % c.size()] - c[i]).cross(q - c[i]).dot(n) < -tol * size) return false;
  return true;
}

// The inner facets lying on the mesh facet whose points are `points`: the pieces refinement
// split it into (their particles, made by refinement, have no mesh point to be named by).
template <int D>
std::vector<Facet> pieces_of(const MssModel<D>& m, std::span<const Facet> inner, std::span<const std::uint32_t> points) {
  std::vector<Vec3> corners;
  for (std::uint32_t p : points) {
    const Index n = m.node_of_point(p);
    if (n == invalid_index) return {};
    corners.push_back(m.rest_position(n));
  }
  std::vector<Facet> out;
  if (corners.size() < 2 || !(corners[1] - corners[0]).allFinite()) return out;
  for (const Facet& f : inner) {
    if ((f.index == 2) != (corners.size() == 2)) continue;
    const std::vector<Vec3> v = facet_rest_vertices(m, f);
    if (std::all_of(v.begin(), v.end(), [&](const Vec3& q) { return on_facet(corners, q); })) out.push_back(f);
  }
  return out;
}

std::string point_list(std::span<const std::uint32_t> pts) {
  std::string s;
  for (std::uint32_t p : pts) s += (s.empty() ? "" : " ") + std::to_string(p);
  return s;
}

template <int D>
struct Counts {
  std::int64_t particles, springs, elements;
  explicit Counts(const MssModel<D>& m)
      : particles(m.nodes().num_alive()), springs(m.springs().num_alive()), elements(m.num_live_elements()) {}
};

template <int D>
CutReport difference(const Counts<D>& before, const MssModel<D>& m, std::uint32_t facets) {
  const Counts<D> after(m);
  return {facets, after.particles - before.particles, after.springs - before.springs, after.elements - before.elements};
}

// The coarser of a facet's two elements when their levels differ (a level jump: the facet is a
// whole side or face of the finer element and a part of one of the coarser).
template <int D>
bool level_jump(const MssModel<D>& m, const Facet& f, Index& coarser) {
  const Dart other = m.map().beta(f.dart, f.index);
  if (other.is_null()) return false;
  const Index a = m.element_of(f.dart), b = m.element_of(other);
  if (a == invalid_index || b == invalid_index) return false;
  const std::uint32_t la = m.elements()[a].level, lb = m.elements()[b].level;
  if (la == lb) return false;
  coarser = la < lb ? a : b;
  return true;
}

// A requested facet as a piece of the rest configuration: the 2 ends of an edge or the 4 corners
// of a hexahedron face, taken on its finer side, which holds it whole. Refining the coarser side
// splits the facet; the facets it becomes are those inside this piece.
struct RestFacet {
  int index = 0;
  std::array<Vec3, 4> corner;
  Vec3 lo, hi;  // bounding box, padded for round-off
};

template <int D>
bool rest_facet(const MssModel<D>& m, const Facet& f, RestFacet& r) {
  Dart d = f.dart;
  if (Index coarser = invalid_index; level_jump(m, f, coarser) && m.element_of(d) == coarser) d = m.map().beta(d, f.index);
  r.index = f.index;
  int n = 0;
  if (f.index == 2) {
    r.corner[0] = m.rest_position(m.node_of(d));
    r.corner[1] = m.rest_position(m.node_of(m.map().beta(d, 1)));
    n = 2;
  } else {
    Dart x = d;
    do {
      if (m.is_corner_dart(x)) {
        if (n == 4) return false;
        r.corner[static_cast<std::size_t>(n++)] = m.rest_position(m.node_of(x));
      }
      x = m.map().beta(x, 1);
    } while (x != d);
    if (n != 4) return false;  // a triangle: tetrahedra are never refined, so it stays one facet
  }
  r.lo = r.hi = r.corner[0];
  for (int k = 1; k < n; ++k) {
    r.lo = r.lo.cwiseMin(r.corner[static_cast<std::size_t>(k)]);
    r.hi = r.hi.cwiseMax(r.corner[static_cast<std::size_t>(k)]);
  }
  const double pad = 1e-9 * (r.hi - r.lo).norm();
  r.lo.array() -= pad;
  r.hi.array() += pad;
  return true;
}

// True if facet g (now) lies inside the rest piece r.
template <int D>
bool inside(const MssModel<D>& m, const RestFacet& r, const Facet& g) {
  if (g.index != r.index) return false;
  auto in_box = [&](const Vec3& p) { return (p.array() >= r.lo.array()).all() && (p.array() <= r.hi.array()).all(); };
  if (r.index == 2) {
    const Vec3 u = r.corner[1] - r.corner[0];
    for (const Dart x : {g.dart, m.map().beta(g.dart, 1)}) {
      const Vec3 p = m.rest_position(m.node_of(x));
      if (!in_box(p)) return false;
      const double t = (p - r.corner[0]).dot(u) / u.squaredNorm();
      if ((p - r.corner[0] - t * u).norm() > 1e-9 * u.norm()) return false;
    }
    return true;
  }
  const Vec3 c = facet_centroid(m, g);
  double s = 0, t = 0;
  return in_box(c) && detail::bilinear_inside(r.corner, c, s, t, 1e-9);
}

// Can the vertex of `s` leave a copy no element weighs, or (3D) a T-junction on separated sides?
// Only if some element around it does not have it as a corner, or (3D) has it on an edge finer
// than itself: the darts orphan_holders would report. O(vertex degree).
template <int D>
bool holds_t_junction(const MssModel<D>& m, Dart s) {
  for (Dart x : m.map().template cell<0>(s)) {
    const Index e = m.element_of(x);
    if (e == invalid_index) continue;
    if (!m.is_corner_dart(x)) return true;
    if constexpr (D == 3)
      if (detail::edge_level(m, x) > m.elements()[e].level) return true;
  }
  return false;
}

// The elements to refine so that a cut of `facets` leaves no particle with no mass, nor (3D) a
// T-junction on sides whose corners it separated. Unsewing splits each vertex of the
// facets into one particle per group of darts around it that stay joined once the facets' links
// are gone (what the map's split hooks do); a group in which no element has the vertex as a
// corner holds only T-junctions of its elements: nothing would weigh that copy. Returns, for
// each such group, its coarsest element, whose refinement makes the vertex a corner there (or
// brings it one level closer). Faces between volumes and edges between 2D cells (of a 2-map or
// membranes of a 3-map) alike. O(facet darts · vertex degree).
template <int D>
std::vector<Index> orphan_holders(const MssModel<D>& m, std::span<const Facet> facets) {
  const auto& map = m.map();
  std::vector<std::pair<int, Dart>> cut_darts;  // the links the cut removes: (β index, dart)
  std::vector<Dart> starts;                     // the darts to group
  // per particle: 0 not looked at, 1 nothing to group, 2 holds a T-junction (each vertex is
  // walked once, though every facet around it names it)
  std::vector<std::uint8_t> vertex(m.nodes().size(), 0);
  auto needs_grouping = [&](Dart x) {
    std::uint8_t& v = vertex[m.node_of(x)];
    if (v == 0) v = holds_t_junction(m, x) ? 2 : 1;
    return v == 2;
  };
  for (const Facet& f : facets) {
    for (Dart x : facet_darts(m, f))
      if (const Dart y = map.beta(x, f.index); !y.is_null()) {
        cut_darts.emplace_back(f.index, x);
        cut_darts.emplace_back(f.index, y);
        // only vertices with a hierarchical dart can leave an orphan (a cut of an unrefined
        // model, the common case, ends here without grouping any vertex)
        if (needs_grouping(x)) starts.push_back(x);
        if (needs_grouping(y)) starts.push_back(y);
      }
  }
  if (starts.empty()) return {};
  std::set<std::pair<int, std::uint32_t>> unsewn;
  for (const auto& [j, x] : cut_darts) unsewn.emplace(j, x.index());
  auto link = [&](Dart x, int j) { return unsewn.count({j, x.index()}) ? Dart{} : map.beta(x, j); };
  std::set<std::uint32_t> seen;
  std::vector<Index> out;
  for (Dart s : starts) {
    if (seen.count(s.index())) continue;
    std::vector<std::vector<Dart>> groups;
    for (Dart r : map.template cell<0>(s)) {
      if (!seen.insert(r.index()).second) continue;
      // the darts at the vertex that stay joined: the map's vertex generators without the cut links
      std::vector<Dart> group{r};
      auto visit = [&](Dart z) {
        if (!z.is_null() && seen.insert(z.index()).second) group.push_back(z);
      };
      for (std::size_t h = 0; h < group.size(); ++h) {
        const Dart x = group[h], x0 = map.beta(x, 0);
        for (int j = 2; j <= D; ++j) {
          if (const Dart y = link(x, j); !y.is_null()) {
            visit(map.beta(y, 1));
            for (int k = 2; k <= D; ++k)
              if (k != j) visit(link(y, k));
          }
          if (!x0.is_null()) visit(link(x0, j));
        }
      }
      groups.push_back(std::move(group));
    }
    for (const auto& group : groups) {
      bool weighed = false;
      Index coarsest = invalid_index;
      for (Dart x : group) {
        const Index e = m.element_of(x);
        if (e == invalid_index) continue;
        if (m.is_corner_dart(x))
          weighed = true;
        else if (coarsest == invalid_index || m.elements()[e].level < m.elements()[coarsest].level)
          coarsest = e;
      }
      if (!weighed && coarsest != invalid_index) out.push_back(coarsest);
      // hexahedra: a vertex the cut splits must not end a side that holds T-junctions, nor be
      // one: many hexahedra share an edge, and a T-junction the cut leaves whole could stay on the
      // sides of elements whose corners it separated, slaved to one side and off the other
      if constexpr (D == 3)
        if (groups.size() > 1)
          for (Dart x : group) {
            const Index e = m.element_of(x);
            if (e != invalid_index && m.elements()[e].kind == ElementKind::hexahedron &&
                (!m.is_corner_dart(x) || detail::edge_level(m, x) > m.elements()[e].level))
              out.push_back(e);
          }
    }
    groups.clear();
  }
  return out;
}

// The elements to refine before cutting `facets`: the coarser side of each facet on a level jump
// and the holders of would-be massless copies (orphan_holders). Throws physics::InputError if
// one is no quad or hexahedron (nothing else refines).
template <int D>
std::vector<Index> to_refine(const MssModel<D>& m, std::span<const Facet> facets) {
  if (!m.ever_refined()) return {};  // no T-junction, no level jump: the common cut ends here
  std::vector<Index> out = orphan_holders(m, facets);
  for (const Facet& f : facets)
    if (Index c = invalid_index; level_jump(m, f, c)) out.push_back(c);
  std::sort(out.begin(), out.end());
  out.erase(std::unique(out.begin(), out.end()), out.end());
  for (Index e : out)
    if (!detail::refinable_kind<D>(m.elements()[e].kind))
      throw InputError("cut: element " + std::to_string(e) +
                       " holds T-junctions on the cut (a level jump) but cannot be refined to meet it (only quads and hexahedra are)");
  return out;
}

// The facets to unsew for the requested ones. A facet across a level jump holds T-junctions of
// its coarser element, and in 3D an element that only touches a facet along an edge may hold one
// at a facet's vertex; separating such a T-junction from the elements it is a corner of would
// leave a copy that is a corner of no element, with no mass, which the model cannot integrate.
// So those elements are refined first (the paper's own operation, mass and momentum exact: the
// T-junctions become their children's corners), as often as needed, and each facet is cut as the
// finer facets it became. A refinement may split another requested facet between equal levels:
// each requested facet is kept as a piece of the rest configuration, and the loop runs until
// nothing inside the pieces needs refining. Throws physics::InputError, before any change, if an
// element to refine first is no quad or hexahedron.
template <int D>
std::vector<Facet> level_facets(MssModel<D>& m, std::span<const Facet> facets, std::uint32_t& refined) {
  std::vector<Index> coarse = to_refine(m, facets);
  if (coarse.empty()) return {facets.begin(), facets.end()};
  std::vector<RestFacet> pieces;
  std::vector<Facet> whole;  // triangles: never split
  for (const Facet& f : facets) {
    if (m.map().beta(f.dart, f.index).is_null()) continue;  // already free
    RestFacet r;
    if (rest_facet(m, f, r))
      pieces.push_back(r);
    else
      whole.push_back(f);
  }
  RefineOptions up_to_the_finer;  // a refinement here never passes the finest level around
  up_to_the_finer.max_level = 20;  // the largest index refine_element accepts
  for (;;) {
    for (Index e : coarse) {
      (void)refine_element(m, e, up_to_the_finer);
      ++refined;
    }
    std::vector<Facet> within;
    for (const Facet& g : inner_facets(m))
      if (std::any_of(pieces.begin(), pieces.end(), [&](const RestFacet& r) { return inside(m, r, g); })) within.push_back(g);
    within.insert(within.end(), whole.begin(), whole.end());
    coarse = to_refine(m, std::span<const Facet>(within));
    if (coarse.empty()) return within;
  }
}

}  // namespace

template <int D>
std::vector<Facet> inner_facets(const MssModel<D>& m) {
  std::vector<Facet> out;
  const auto& map = m.map();
  if constexpr (D == 3) {
    // faces between two volume elements
    for (Dart d : map.template cells<2>())
      if (map.beta(d, 3) && map.template attribute<3>(d) && map.template attribute<3>(map.beta(d, 3))) out.push_back({d, 3});
  }
  // edges between two 2D elements: β2 joins two face elements (never the faces of one volume)
  for (Dart d : map.template cells<1>()) {
    for (Dart x : map.template cell<1>(d)) {
      const Dart y = map.beta(x, 2);
      if (!y || !map.template attribute<2>(x) || !map.template attribute<2>(y)) continue;
      if constexpr (D == 3)
        if (map.template attribute<3>(x)) continue;
      out.push_back({x, 2});
      break;
    }
  }
  return out;
}

template <int D>
std::vector<Facet> facets_with_points(const MssModel<D>& m, std::span<const std::vector<std::uint32_t>> faces) {
  std::map<std::vector<std::uint32_t>, Facet> by_points;
  const std::vector<Facet> inner = inner_facets(m);
  for (const Facet& f : inner) by_points.emplace(facet_points(m, f), f);
  // facets some cut already separated: both sides still name the same mesh points
  std::map<std::vector<std::uint32_t>, int> free_sides;  // a cut facet has two, a boundary facet one
  auto record_free = [&](Dart x, int index) {
    if (!m.map().beta(x, index)) ++free_sides[facet_points(m, Facet{x, index})];
  };
  if constexpr (D == 3)
    for (Dart d : m.map().template cells<2>())
      if (m.map().template attribute<3>(d)) record_free(d, 3);
  for (Dart d : m.map().template cells<1>())
    if (m.map().template attribute<2>(d)) {
      if constexpr (D == 3)
        if (m.map().template attribute<3>(d)) continue;
      record_free(d, 2);
    }
  std::vector<Facet> out;
  for (std::size_t k = 0; k < faces.size(); ++k) {
    std::vector<std::uint32_t> key = faces[k];
    std::sort(key.begin(), key.end());
    if (const auto it = by_points.find(key); it != by_points.end()) {
      out.push_back(it->second);
      continue;
    }
    if (const auto it = free_sides.find(key); it != free_sides.end() && it->second >= 2) continue;  // already cut
    // refined since the scene named it: the pieces on it, matched by rest position
    if (const std::vector<Facet> pieces = pieces_of(m, inner, faces[k]); !pieces.empty()) {
      out.insert(out.end(), pieces.begin(), pieces.end());
      continue;
    }
    throw InputError("face " + std::to_string(k) + " (points " + point_list(faces[k]) +
                     ") is not a face between two elements: no such face, or it lies on the boundary" +
                     " (or every piece refinement split it into is already cut)");
  }
  return out;
}

template <int D>
std::vector<Facet> facets_across_plane(const MssModel<D>& m, const Vec3& point, const Vec3& normal, const Region& within) {
  if (!(normal.norm() > 0) || !normal.allFinite() || !point.allFinite())
    throw InputError("facets_across_plane: the plane needs a finite point and a non-zero normal");
  std::vector<Facet> out;
  for (const Facet& f : inner_facets(m)) {
    const double a = normal.dot(m.element_centroid(m.element_of(f.dart)) - point);
    const double b = normal.dot(m.element_centroid(m.element_of(m.map().beta(f.dart, f.index))) - point);
    if (!((a < 0 && b > 0) || (a > 0 && b < 0))) continue;
    if (within && !within(facet_centroid(m, f))) continue;
    out.push_back(f);
  }
  return out;
}

template <int D>
std::vector<Facet> facets_among_points(const MssModel<D>& m, std::span<const std::uint32_t> points) {
  std::vector<std::uint32_t> sorted(points.begin(), points.end());
  std::sort(sorted.begin(), sorted.end());
  std::vector<Facet> out;
  for (const Facet& f : inner_facets(m)) {
    const auto pts = facet_points(m, f);
    if (std::all_of(pts.begin(), pts.end(), [&](std::uint32_t p) { return std::binary_search(sorted.begin(), sorted.end(), p); }))
      out.push_back(f);
  }
  return out;
}

template <int D>
std::vector<Index> elements_in(const MssModel<D>& m, const Region& region) {
  std::vector<Index> out;
  for (Index e = 0; e < m.elements().size(); ++e) {
    const physics::Element& el = m.elements()[e];
    if (el.alive && (is_volume(el.kind) || is_surface(el.kind)) && region(m.element_centroid(e))) out.push_back(e);
  }
  return out;
}

template <int D>
CutReport cut(MssModel<D>& m, std::span<const Facet> facets) {
  for (const Facet& f : facets)
    if (!m.map().is_alive(f.dart)) throw InputError("cut: dart " + std::to_string(f.dart.index()) + " is not a live dart");
  const Counts<D> before(m);
  std::uint32_t refined = 0;
  const std::vector<Facet> level = level_facets(m, facets, refined);
  std::uint32_t done = 0;
  // One batch per facet dimension: a vertex or an edge shared by several of the facets is then
  // walked once, when its cell is rebuilt, instead of once per facet (each interior vertex of a
  // cut plane bounds four of its faces). Facets already separated are skipped by unsew_all.
  std::vector<Dart> faces, edges;
  for (const Facet& f : level) (f.index == 3 ? faces : edges).push_back(f.dart);
  m.edit([&](auto& map) {
    if constexpr (D == 3) done += map.template unsew_all<3>(faces);
    done += map.template unsew_all<2>(edges);
  });
  // a particle duplicated by the cut may be a T-junction or a master of one
  if (!m.system().slaves().empty()) constrain_t_junctions(m, m.system().slaves().treatment());
  CutReport report = difference(before, m, done);
  report.refined = refined;
  return report;
}

template <int D>
CutReport pierce(MssModel<D>& m, std::span<const Index> elements, bool remove) {
  for (Index e : elements)
    if (e >= m.elements().size() || !m.elements()[e].alive)
      throw InputError("pierce: element " + std::to_string(e) + " does not exist or was already removed");
  const Counts<D> before(m);
  std::uint32_t done = 0;
  const std::set<Index> chosen(elements.begin(), elements.end());
  m.edit([&](auto& map) {
    for (Index e : elements) {
      const physics::Element& el = m.elements()[e];
      const int index = is_volume(el.kind) ? 3 : 2;
      // every facet that joins the element to one not chosen: the chosen elements come out as
      // one piece (the paper's 3 cubes freed by 14 faces)
      DartList darts;
      if (index == 2)
        darts = map.template cell<2>(el.dart);
      else if constexpr (D == 3)
        darts = map.template cell<3>(el.dart);
      for (Dart x : darts) {
        const Dart y = map.beta(x, index);
        if (!y || chosen.count(m.element_of(y))) continue;
        if (index == 3) {
          if constexpr (D == 3) map.template unsew<3>(x);
        } else {
          map.template unsew<2>(x);
        }
        ++done;
      }
    }
    if (remove)
      for (Index e : elements) {
        const Dart d = m.elements()[e].dart;
        if (!map.is_alive(d)) continue;  // removed with a chosen neighbour
        // the freed piece is a connected component now: erase all of it
        for (Dart x : map.component(d))
          if (map.is_alive(x)) map.template remove_cell<D>(x);
      }
  });
  if (remove) m.compact();
  return difference(before, m, done);
}

#define SEWN_REFINE_INSTANTIATE(D)                                                                                        \
  template std::vector<Facet> inner_facets(const MssModel<D>&);                                                           \
  template std::vector<Facet> facets_with_points(const MssModel<D>&, std::span<const std::vector<std::uint32_t>>);        \
  template std::vector<Facet> facets_across_plane(const MssModel<D>&, const Vec3&, const Vec3&, const Region&);           \
  template std::vector<Facet> facets_among_points(const MssModel<D>&, std::span<const std::uint32_t>);                    \
  template std::vector<Index> elements_in(const MssModel<D>&, const Region&);                                             \
  template CutReport cut(MssModel<D>&, std::span<const Facet>);                                                           \
  template CutReport pierce(MssModel<D>&, std::span<const Index>, bool);
SEWN_REFINE_INSTANTIATE(2)
SEWN_REFINE_INSTANTIATE(3)

}  // namespace sewn::refine
