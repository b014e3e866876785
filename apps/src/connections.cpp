#include "sewn/apps/connections.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <functional>
#include <limits>
#include <map>
#include <optional>
#include <variant>

#include <Eigen/Geometry>

namespace sewn::app {

namespace {

using physics::Index;
using Vec3d = Eigen::Vector3d;

// The rest stiffnesses of one side (auto): per joint for points, per unit length for curves.
struct SideStiffness {
  double twist = 0, bend = 0;
};

// Everything about the mesh around the joints: cells per point, each cell's component, element
// and material, rest positions of mesh points.
struct Around {
  const IndexedMesh& mesh;
  const physics::MssModel<3>& model;
  const std::vector<physics::MaterialParams>& materials;
  const ContinuumParts& parts;
  connect::FoundConnections found;
  std::vector<std::int64_t> component;          // per mesh cell, -1: a label
  std::vector<Index> element;                   // per mesh cell, its model element
  std::vector<std::vector<std::uint32_t>> at;   // per mesh point, its simulated cells
  std::function<std::string(std::uint32_t)> point_name;  // how messages name a mesh point

  [[nodiscard]] Vec3d x(std::uint32_t p) const { return model.rest_position(model.node_of_point(p)); }
  [[nodiscard]] Index node(std::uint32_t p) const { return model.node_of_point(p); }
  [[nodiscard]] const physics::MaterialParams& material(std::uint32_t cell) const {
    return materials[model.elements()[element[cell]].material];
  }
  // The cells of component `comp` holding every point of `pts`.
  [[nodiscard]] std::vector<std::uint32_t> cells_of(std::uint32_t comp, std::span<const std::uint32_t> pts) const {
    std::vector<std::uint32_t> out;
    for (std::uint32_t c : at[pts[0]]) {
      if (component[c] != comp) continue;
      const auto cp = mesh.cell(c);
      if (std::all_of(pts.begin(), pts.end(), [&](std::uint32_t p) { return std::find(cp.begin(), cp.end(), p) != cp.end(); }))
        out.push_back(c);
    }
    return out;
  }
};

Around gather(const IndexedMesh& mesh, const std::vector<CellModel>& models, const std::vector<physics::MaterialParams>& materials,
              const ContinuumParts& parts, const physics::MssModel<3>& model, const std::string& file) {
  Around a{mesh, model, materials, parts, {}, {}, {}, {}, {}};
  // rods as the Rods term chained them (split by group and material): two rods meeting at a
  // node are two components, joined by a rod–rod point connection
  std::vector<std::uint32_t> chain(mesh.num_cells(), 0);
  for (Index e = 0; e < parts.rod_edge_of_element.size(); ++e)
    if (parts.rod_edge_of_element[e].first != physics::invalid_index)
      chain[model.elements()[e].mesh_cell] = static_cast<std::uint32_t>(parts.rod_edge_of_element[e].first + 1);
  MeshConnections mc = mesh_connections(mesh, models, chain);
  if (!mc.skipped.empty()) throw SceneError(file, "model.connections", "connections cannot be found in this mesh: " + mc.skipped);
  a.found = std::move(mc.found);
  a.component.assign(mesh.num_cells(), -1);
  a.element.assign(mesh.num_cells(), physics::invalid_index);
  a.at.resize(mesh.num_points());
  std::uint32_t k = 0;
  for (std::uint32_t c = 0; c < mesh.num_cells(); ++c) {
    if (models[c] == CellModel::label) continue;
    a.component[c] = a.found.component_of_cell[k++];
    for (std::uint32_t p : mesh.cell(c)) a.at[p].push_back(c);
  }
  for (Index e = 0; e < model.elements().size(); ++e)
    if (model.elements()[e].alive) a.element[model.elements()[e].mesh_cell] = e;
  return a;
}

double plate_bending(const physics::MaterialParams& m) {
  return m.young * std::pow(m.thickness, 3) / (12 * (1 - m.poisson * m.poisson));
}
double shear_modulus(const physics::MaterialParams& m) { return m.young / (2 * (1 + m.poisson)); }
// Saint-Venant's torsion constant of a square section of side ℓ is 0.1406 ℓ⁴.
constexpr double square_torsion = 0.1406;

// ---- point connections: one side per component at the joint ----

struct PointSide {
  connect::SideRef ref;
  SideStiffness k;
  std::vector<std::uint32_t> cells;  // the mesh cells its frame is built on (a shell vertex: its whole fan)
};

double mean_edge(const Around& a, std::span<const std::uint32_t> pts) {
  double sum = 0;
  int n = 0;
  for (std::size_t i = 0; i < pts.size(); ++i)
    for (std::size_t j = i + 1; j < pts.size(); ++j, ++n) sum += (a.x(pts[i]) - a.x(pts[j])).norm();
  return sum / n;
}

// A solid's side at point p (PHYSICS_NOTES §3.5, option i): the rest axis is the solid's
// outward surface normal at p (angle-weighted over the component's boundary faces there), and
// the tet is the one the inward ray enters. At a point inside the solid there is no surface:
// the axis then points at the other side's cells (`toward`), out of the solid into the joint.
PointSide solid_point_side(const Around& a, std::uint32_t comp, std::uint32_t p, const Vec3d& toward, const std::string& who,
                           const std::string& file, const std::string& key) {
  const std::uint32_t pp[1] = {p};
  const std::vector<std::uint32_t> tets = a.cells_of(comp, pp);
  // boundary faces of the component at p: faces of one of its tets only
  std::map<std::array<std::uint32_t, 3>, std::pair<int, std::uint32_t>> faces;  // sorted face -> (count, opposite point)
  for (std::uint32_t t : tets) {
    const auto c = a.mesh.cell(t);
    for (int skip = 0; skip < 4; ++skip) {
      if (c[static_cast<std::size_t>(skip)] == p) continue;
      std::array<std::uint32_t, 3> f{};
      int n = 0;
      for (int v = 0; v < 4; ++v)
        if (v != skip) f[static_cast<std::size_t>(n++)] = c[static_cast<std::size_t>(v)];
      std::sort(f.begin(), f.end());
      auto& e = faces[f];
      ++e.first;
      e.second = c[static_cast<std::size_t>(skip)];
    }
  }
  Vec3d normal = Vec3d::Zero();
  bool surface = false;
  for (const auto& [f, info] : faces) {
    if (info.first != 1) continue;
    surface = true;
    std::array<std::uint32_t, 2> o{};
    int n = 0;
    for (std::uint32_t v : f)
      if (v != p) o[static_cast<std::size_t>(n++)] = v;
    const Vec3d e1 = a.x(o[0]) - a.x(p), e2 = a.x(o[1]) - a.x(p);
    Vec3d nf = e1.cross(e2);
    if (nf.dot(a.x(p) - a.x(info.second)) < 0) nf = -nf;  // away from the tet's fourth point
    const double angle = std::atan2(e1.cross(e2).norm(), e1.dot(e2));
    if (nf.norm() > 0) normal += angle * nf.normalized();
  }
  const double scale = mean_edge(a, a.mesh.cell(tets.front()));
  if (!surface) normal = toward;
  if (!(normal.norm() > 1e-9 * (surface ? 1.0 : scale)))
    throw SceneError(file, key,
                     who + ": the solid's frame cannot be built at " + a.point_name(p) +
                         (surface ? ": its surface one-ring has no normal (the angle-weighted face normals cancel)"
                                  : ": the joint's other side sits on the point itself"));
  normal.normalize();
  // the tet whose corner cone at p holds −normal (largest smallest barycentric weight)
  std::uint32_t best = tets.front();
  double best_min = -std::numeric_limits<double>::infinity();
  for (std::uint32_t t : tets) {
    const auto c = a.mesh.cell(t);
    Eigen::Matrix3d E;
    int n = 0;
    for (std::uint32_t v : c)
      if (v != p) E.col(n++) = a.x(v) - a.x(p);
    const Vec3d w = E.fullPivLu().solve(-normal);
    if (w.minCoeff() > best_min) {
      best_min = w.minCoeff();
      best = t;
    }
  }
  const auto c = a.mesh.cell(best);
  connect::TetSide side;
  side.nodes[0] = a.node(p);
  int n = 1;
  for (std::uint32_t v : c)
    if (v != p) side.nodes[static_cast<std::size_t>(n++)] = a.node(v);
  side.rest_axis = normal;
  const auto& m = a.material(best);
  const double l = mean_edge(a, c);
  return {side, {shear_modulus(m) * square_torsion * l * l * l, m.young * l * l * l / 12}, {best}};
}

// A shell's side at point p. At a boundary vertex (its fan runs from one boundary edge to
// another) the axis is the rest bisector of the fan's whole angle, carried by the triangle it
// lies in; at an interior vertex (one closed fan) the one-ring's vertex normal (VertexSide; both
// PHYSICS_NOTES §3.5); elsewhere (a vertex where fans pinch) the corner bisector of the first
// triangle: a frame carried rigidly by that triangle.
PointSide shell_point_side(const Around& a, const std::vector<std::uint32_t>& tris, std::uint32_t p) {
  auto others = [&](std::uint32_t t) {
    std::array<std::uint32_t, 2> o{};
    int n = 0;
    for (std::uint32_t v : a.mesh.cell(t))
      if (v != p) o[static_cast<std::size_t>(n++)] = v;
    return o;
  };
  auto side_on = [&](std::uint32_t t, std::optional<Vec3d> axis) {
    connect::TriangleSide side;
    const auto cp = a.mesh.cell(t);
    for (int v = 0; v < 3; ++v) side.nodes[static_cast<std::size_t>(v)] = a.node(cp[static_cast<std::size_t>(v)]);
    side.rest_axis = axis;
    return PointSide{side, {}, {t}};
  };
  std::map<std::uint32_t, int> uses;  // the far end of each edge from p -> triangles using it
  for (std::uint32_t t : tris)
    for (std::uint32_t v : others(t)) ++uses[v];
  std::vector<std::uint32_t> ends;
  for (const auto& u : uses)
    if (u.second == 1) ends.push_back(u.first);
  if (ends.size() != 2 && !ends.empty()) return side_on(tris.front(), std::nullopt);
  // walk the fan from one boundary edge to the other, or around: (triangle, from, to, angle at p)
  struct Wedge {
    std::uint32_t tri, from, to;
    double angle;
  };
  std::vector<Wedge> fan;
  std::vector<bool> used(tris.size(), false);
  double total = 0;
  for (std::uint32_t from = ends.empty() ? others(tris.front())[0] : ends[0]; fan.size() < tris.size();) {
    std::size_t k = 0;
    while (k < tris.size() && (used[k] || (others(tris[k])[0] != from && others(tris[k])[1] != from))) ++k;
    if (k == tris.size()) break;
    used[k] = true;
    const auto o = others(tris[k]);
    const std::uint32_t to = o[0] == from ? o[1] : o[0];
    const Vec3d e1 = a.x(from) - a.x(p), e2 = a.x(to) - a.x(p);
    fan.push_back({tris[k], from, to, std::atan2(e1.cross(e2).norm(), e1.dot(e2))});
    total += fan.back().angle;
    from = to;
  }
  if (ends.empty()) {
    if (fan.size() != tris.size() || fan.back().to != fan.front().from) return side_on(tris.front(), std::nullopt);  // pinched
    connect::VertexSide side;
    side.joint = a.node(p);
    for (const Wedge& w : fan) side.ring.push_back(a.node(w.from));
    return PointSide{side, {}, tris};
  }
  if (fan.size() != tris.size() || fan.back().to != ends[1]) return side_on(tris.front(), std::nullopt);
  double before = 0;
  for (const Wedge& w : fan) {
    if (before + w.angle >= total / 2 || &w == &fan.back()) {
      // the bisector, turned from this wedge's first edge by what is left of half the fan
      const double r = std::clamp(total / 2 - before, 1e-6 * w.angle, (1 - 1e-6) * w.angle);
      const Vec3d e1 = (a.x(w.from) - a.x(p)).normalized();
      const Vec3d e2 = a.x(w.to) - a.x(p);
      const Vec3d u = (e2 - e2.dot(e1) * e1).normalized();
      return side_on(w.tri, Vec3d(std::cos(r) * e1 + std::sin(r) * u));
    }
    before += w.angle;
  }
  return side_on(tris.front(), std::nullopt);
}

PointSide point_side(const Around& a, std::uint32_t comp, std::uint32_t p, const Vec3d& toward, const std::string& who,
                     const std::string& file, const std::string& key) {
  const std::uint32_t pp[1] = {p};
  const std::vector<std::uint32_t> cells = a.cells_of(comp, pp);
  const std::uint32_t c = cells.front();
  switch (a.found.component_body[comp]) {
    case connect::Body::rod: {
      const auto [r, edge] = a.parts.rod_edge_of_element[a.element[c]];
      const auto& rod = a.parts.rods->rod(r);
      const double l = rod.rest_length(edge);
      return {connect::RodEdgeRef{r, edge}, {rod.section().GJ / l, std::min(rod.section().EI1, rod.section().EI2) / l}, {c}};
    }
    case connect::Body::shell: {
      const auto& m = a.material(c);
      PointSide side = shell_point_side(a, cells, p);
      side.k = {shear_modulus(m) * std::pow(m.thickness, 3) / 3, plate_bending(m)};
      return side;
    }
    case connect::Body::solid: return solid_point_side(a, comp, p, toward, who, file, key);
  }
  return {};
}

// Centroid of the cells of component `comp` at p, at rest.
Vec3d cells_centroid(const Around& a, std::uint32_t comp, std::uint32_t p) {
  const std::uint32_t pp[1] = {p};
  Vec3d sum = Vec3d::Zero();
  int n = 0;
  for (std::uint32_t c : a.cells_of(comp, pp))
    for (std::uint32_t v : a.mesh.cell(c)) {
      sum += a.x(v);
      ++n;
    }
  return sum / n;
}

// ---- curve connections: one or more sides per component along the edge ----

struct EdgeSides {
  std::vector<connect::EdgeSideRef> refs;
  std::vector<std::vector<std::uint32_t>> cells;  // per ref, the mesh cells its frame is built on
  double k = 0;                                   // auto, per unit length
};

// Height of the triangle (a, b, c) over the edge (a, b).
double height(const Around& a, std::uint32_t p, std::uint32_t q, std::uint32_t r) {
  const Vec3d e = a.x(q) - a.x(p);
  return e.cross(a.x(r) - a.x(p)).norm() / e.norm();
}

std::uint32_t apex(const Around& a, std::uint32_t cell, std::uint32_t p, std::uint32_t q) {
  for (std::uint32_t v : a.mesh.cell(cell))
    if (v != p && v != q) return v;
  return p;
}

EdgeSides edge_sides(const Around& a, std::uint32_t comp, std::uint32_t p, std::uint32_t q) {
  const std::uint32_t pq[2] = {p, q};
  const std::vector<std::uint32_t> cells = a.cells_of(comp, pq);
  EdgeSides out;
  const auto& m = a.material(cells.front());
  switch (a.found.component_body[comp]) {
    case connect::Body::rod: {
      const auto [r, edge] = a.parts.rod_edge_of_element[a.element[cells.front()]];
      const double l = a.parts.rods->rod(r).rest_length(edge);
      out.refs.emplace_back(connect::RodEdgeRef{r, edge});
      out.cells.push_back({cells.front()});
      out.k = a.parts.rods->rod(r).section().GJ / (l * l);
      break;
    }
    case connect::Body::shell: {
      // a boundary edge of the shell (one triangle), or an interior one (two: the hinge's frame)
      double w = 0;
      for (std::uint32_t c : cells) w += height(a, p, q, apex(a, c, p, q)) / static_cast<double>(cells.size());
      if (cells.size() == 1) out.refs.emplace_back(connect::FaceSide{a.node(apex(a, cells[0], p, q))});
      else out.refs.emplace_back(connect::HingeSide{a.node(apex(a, cells[0], p, q)), a.node(apex(a, cells[1], p, q))});
      out.cells.push_back(cells);
      out.k = plate_bending(m) / w;
      break;
    }
    case connect::Body::solid: {
      // the faces around the edge; a surface curve (two boundary faces) is framed by their mean
      // normal, an edge inside the solid by every face around it (one energy each)
      std::map<std::uint32_t, std::pair<int, std::uint32_t>> faces;  // apex -> (tets holding the face (p, q, apex), the first)
      for (std::uint32_t c : cells)
        for (std::uint32_t v : a.mesh.cell(c))
          if (v != p && v != q) {
            auto& f = faces.try_emplace(v, 0, c).first->second;
            ++f.first;
          }
      std::vector<std::uint32_t> boundary, all;
      for (const auto& [v, held] : faces) {
        all.push_back(v);
        if (held.first == 1) boundary.push_back(v);
      }
      double w = 0;
      const auto& used = boundary.size() == 2 ? boundary : all;
      for (std::uint32_t v : used) w += height(a, p, q, v) / static_cast<double>(used.size());
      if (boundary.size() == 2) {
        out.refs.emplace_back(connect::HingeSide{a.node(boundary[0]), a.node(boundary[1])});
        out.cells.push_back({faces.at(boundary[0]).second, faces.at(boundary[1]).second});
      } else {
        for (std::uint32_t v : all) {
          out.refs.emplace_back(connect::FaceSide{a.node(v)});
          out.cells.push_back({faces.at(v).second});
        }
      }
      out.k = m.young * w * w / (12 * (1 - m.poisson * m.poisson));
      break;
    }
  }
  return out;
}

// ---- which connections, with which stiffnesses ----

struct Choice {
  std::string key;    // the scene key that asked for it (errors name it)
  std::string label;  // "explicit[k]" or "" for detected
  std::optional<double> twisting, bending, stiffness;
  bool rigid = false;
};

std::uint32_t nearest_point(const Around& a, const std::array<double, 3>& at, const std::string& file, const std::string& key) {
  const Vec3d target(at[0], at[1], at[2]);
  Vec3d lo = Vec3d::Constant(std::numeric_limits<double>::infinity()), hi = -lo;
  std::uint32_t best = 0;
  double best_d = std::numeric_limits<double>::infinity();
  for (std::uint32_t p = 0; p < a.at.size(); ++p) {
    if (a.at[p].empty()) continue;
    const Vec3d x = a.x(p);
    lo = lo.cwiseMin(x);
    hi = hi.cwiseMax(x);
    if ((x - target).norm() < best_d) {
      best_d = (x - target).norm();
      best = p;
    }
  }
  const double tol = 1e-6 * (hi - lo).norm();
  if (!(best_d <= tol)) {
    const Vec3d x = a.x(best);
    char text[512];  // %g: a tolerance of 1e-7 m printed as 0.000000 read as "must be exact"
    std::snprintf(text, sizeof text, "no mesh point is there: the nearest is %s at [%g, %g, %g], %g m away (tolerance %g m)",
                  a.point_name(best).c_str(), x.x(), x.y(), x.z(), best_d, tol);
    throw SceneError(file, key + ".at", text);
  }
  return best;
}

// Per detected connection, what asks for its energy (none: not built).
std::vector<std::optional<Choice>> choose(const Around& a, const ConnectionsSpec& spec, const std::string& file) {
  std::vector<std::optional<Choice>> out(a.found.connections.size());
  for (std::size_t c = 0; c < out.size(); ++c)
    if (spec.detect && a.found.connections[c].kind != connect::ConnectionKind::surface)
      out[c] = Choice{"model.connections", "", spec.twisting, spec.bending, spec.curve_stiffness, spec.rigid};
  for (std::size_t k = 0; k < spec.explicit_connections.size(); ++k) {
    const ExplicitConnectionSpec& e = spec.explicit_connections[k];
    const std::string key = "model.connections.explicit[" + std::to_string(k) + "]";
    const std::uint32_t p = nearest_point(a, e.at, file, key);
    const auto kind = e.kind == "point" ? connect::ConnectionKind::point : connect::ConnectionKind::curve;
    // the component pairs meeting at p that way; a curve takes every edge of those pairs
    std::vector<std::array<std::uint32_t, 2>> pairs;
    for (const auto& f : a.found.connections)
      if (f.kind == kind && std::find(f.points.begin(), f.points.end(), p) != f.points.end()) pairs.push_back(f.components);
    if (pairs.empty())
      throw SceneError(file, key, "no two bodies meet in a " + e.kind + " connection at " + a.point_name(p) +
                                      " (`sewn check` lists where they meet)");
    const Choice ch{key, "explicit[" + std::to_string(k) + "] ", e.twisting ? e.twisting : spec.twisting,
                    e.bending ? e.bending : spec.bending, e.stiffness ? e.stiffness : spec.curve_stiffness, e.rigid.value_or(spec.rigid)};
    for (std::size_t c = 0; c < out.size(); ++c) {
      const auto& f = a.found.connections[c];
      if (f.kind != kind) continue;
      const bool here = kind == connect::ConnectionKind::point ? f.points[0] == p
                                                               : std::find(pairs.begin(), pairs.end(), f.components) != pairs.end();
      if (here) out[c] = ch;
    }
  }
  return out;
}

std::string connection_name(const Around& a, const Choice& ch, std::size_t c) {
  const auto& f = a.found.connections[c];
  std::string pts;
  for (std::uint32_t p : f.points) {
    if (!pts.empty()) pts += '-';
    pts += std::to_string(p);
  }
  return ch.label + connect::to_string(f.kind) + " connection " + std::to_string(c) + " (" +
         connect::body_pair_name(connect::body_pair_index(a.found.component_body[f.components[0]], a.found.component_body[f.components[1]])) +
         " at mesh point" + (f.points.size() > 1 ? "s " : " ") + pts + ")";
}

// The sources of a connection's stencil nodes (`stencil`, in slot order): every corner of the
// cells' model elements that is one of them.
std::vector<JointSource> sources_of(const Around& a, const std::vector<Index>& stencil, std::span<const std::uint32_t> cells) {
  std::vector<JointSource> out;
  for (std::uint32_t c : cells) {
    const Index e = a.element[c];
    const std::vector<Index> nodes = a.model.element_nodes(e);
    for (std::uint32_t k = 0; k < nodes.size(); ++k)
      for (std::uint32_t slot = 0; slot < stencil.size(); ++slot)
        if (stencil[slot] == nodes[k]) out.push_back({e, k, slot});
  }
  return out;
}

bool has_rod_side(const Around& a, const connect::FoundConnection& f) {
  return a.found.component_body[f.components[0]] == connect::Body::rod || a.found.component_body[f.components[1]] == connect::Body::rod;
}

// Rod twist inertia per length, the smallest over the rods: ρ (I1 + I2) of each rod's section.
double rod_inertia(const Around& a) {
  double j = std::numeric_limits<double>::infinity();
  for (std::size_t e = 0; e < a.parts.rod_edge_of_element.size(); ++e) {
    if (a.parts.rod_edge_of_element[e].first == physics::invalid_index) continue;
    const auto& m = a.materials[a.model.elements()[e].material];
    const auto& s = a.parts.rods->rod(a.parts.rod_edge_of_element[e].first).section();
    j = std::min(j, m.density * (s.EI1 + s.EI2) / m.young);
  }
  return std::isfinite(j) ? j : 0.0;
}

}  // namespace

ConnectionParts build_connections(const Scene& scene, const IndexedMesh& mesh, const std::vector<CellModel>& models,
                                  const std::vector<physics::MaterialParams>& materials, const ContinuumParts& parts,
                                  physics::MssModel<3>& model, const std::function<std::string(std::uint32_t)>& point_name) {
  ConnectionParts out;
  const ConnectionsSpec& spec = scene.connections;
  if (!spec.enabled) return out;
  if (scene.refinement.enabled)
    throw SceneError(scene.file, "refinement", "a scene with model.connections cannot be refined (the connections' stencils would not follow the new elements)");
  out.sources = std::make_shared<JointSources>();
  Around a = gather(mesh, models, materials, parts, model, scene.file);
  a.point_name = point_name ? point_name : [](std::uint32_t p) { return "mesh point " + std::to_string(p); };
  const std::vector<std::optional<Choice>> chosen = choose(a, spec, scene.file);
  const double rigid = spec.rigid_factor;
  physics::System& sys = model.system();
  const auto update = spec.update == "incremental_i" ? connect::TwistUpdate::incremental_i : connect::TwistUpdate::incremental_ii;

  bool rods = false;
  for (std::size_t c = 0; c < chosen.size(); ++c) rods = rods || (chosen[c] && has_rod_side(a, a.found.connections[c]));
  if (rods) {
    if (scene.integrator != "newton")
      throw SceneError(scene.file, "model.connections",
                       "a connection with a rod side turns the rods' twist angles into degrees of freedom, which only integrator.type "
                       "\"newton\" integrates (this scene has \"" + scene.integrator + "\")");
    parts.rods->use_angle_dofs(sys.angles(), rod_inertia(a));
  }
  for (std::size_t c = 0; c < chosen.size(); ++c) {
    if (!chosen[c]) continue;
    const Choice& ch = *chosen[c];
    const auto& f = a.found.connections[c];
    const std::string name = connection_name(a, ch, c);
    const double factor = ch.rigid ? rigid : 1.0;
    try {
      if (f.kind == connect::ConnectionKind::point) {
        const std::uint32_t p = f.points[0];
        const Vec3d c0 = cells_centroid(a, f.components[0], p), c1 = cells_centroid(a, f.components[1], p);
        const PointSide m = point_side(a, f.components[0], p, c1 - a.x(p), name, scene.file, ch.key);
        const PointSide n = point_side(a, f.components[1], p, c0 - a.x(p), name, scene.file, ch.key);
        const connect::PointStiffness k{ch.twisting.value_or(factor * std::min(m.k.twist, n.k.twist)),
                                        ch.bending.value_or(factor * std::min(m.k.bend, n.k.bend))};
        if (!out.points) out.points = &sys.add<connect::PointConnections>(parts.rods, update);
        const Index added = out.points->add(name, m.ref, n.ref, k, sys.state());
        std::vector<std::uint32_t> cells = m.cells;
        cells.insert(cells.end(), n.cells.begin(), n.cells.end());
        out.sources->points.push_back(sources_of(a, out.points->connection(added).position_nodes(), cells));
        ++out.point_joints;
      } else {
        const std::uint32_t p = f.points[0], q = f.points[1];
        const EdgeSides m = edge_sides(a, f.components[0], p, q), n = edge_sides(a, f.components[1], p, q);
        const double pairs = static_cast<double>(m.refs.size() * n.refs.size());
        const double k = ch.stiffness.value_or(factor * std::min(m.k, n.k)) / pairs;
        if (!out.curves) out.curves = &sys.add<connect::CurveConnections>(parts.rods, update);
        int i = 0;
        for (std::size_t im = 0; im < m.refs.size(); ++im)
          for (std::size_t in = 0; in < n.refs.size(); ++in, ++i) {
            const Index added = out.curves->add(pairs > 1 ? name + " face pair " + std::to_string(i) : name, a.node(p), a.node(q),
                                                m.refs[im], n.refs[in], k, sys.state());
            std::vector<std::uint32_t> cells = m.cells[im];
            cells.insert(cells.end(), n.cells[in].begin(), n.cells[in].end());
            out.sources->curves.push_back(sources_of(a, out.curves->connection(added).stencil_nodes(), cells));
            ++out.curve_elements;
          }
        ++out.curve_joints;
      }
    } catch (const physics::InputError& e) {
      throw SceneError(scene.file, ch.key, e.what());
    }
  }
  // every edit of the model (a cut, a piercing) is followed by the rule, before a piercing
  // compacts the particles; the listener shares the sources with the returned parts
  if (out.points || out.curves) model.after_edits([out, &model] { follow_connections(out, model); });
  return out;
}

namespace {

// The rule for one term: per connection, its sources' current nodes against its own.
template <class Term, class Nodes>
void follow_term(Term* term, std::vector<std::vector<JointSource>>& sources, const physics::MssModel<3>& model, const Nodes& nodes_of) {
  if (!term) return;
  const std::vector<bool> kept = term->follow_nodes(model.nodes().size(), [&](Index c, std::vector<std::pair<Index, Index>>& renames) {
    const std::vector<Index>& stencil = nodes_of(term->connection(c));
    std::map<Index, Index> to;  // the connection's node -> the node its elements have now
    for (const JointSource& s : sources[c]) {
      if (!model.elements()[s.element].alive) return false;  // a side was pierced away
      const Index now = model.element_nodes(s.element)[s.corner];
      const auto it = to.emplace(stencil[s.slot], now).first;
      if (it->second != now) return false;  // the sides no longer share this node: the cut separated them
    }
    for (const auto& r : to)
      if (r.first != r.second) renames.emplace_back(r.first, r.second);
    return true;
  });
  std::vector<std::vector<JointSource>> left;
  for (std::size_t c = 0; c < kept.size(); ++c)
    if (kept[c]) left.push_back(std::move(sources[c]));
  sources = std::move(left);
}

}  // namespace

void follow_connections(const ConnectionParts& joints, const physics::MssModel<3>& model) {
  if (!joints.sources) return;
  follow_term(joints.points, joints.sources->points, model, [](const connect::PointConnection& c) -> const std::vector<Index>& { return c.position_nodes(); });
  follow_term(joints.curves, joints.sources->curves, model, [](const connect::EdgeConnection& c) -> const std::vector<Index>& { return c.stencil_nodes(); });
}

std::string connection_energies_text(const ConnectionParts& c) {
  if (!c.sources) return "";  // model.connections not given
  if (!c.points && !c.curves) return "  energies: none (model.connections is given, but no joint found takes a rotational energy from it)\n";
  return "  energies: " + std::to_string(c.point_joints) + " point, " + std::to_string(c.curve_joints) + " curve (" +
         std::to_string(c.curve_elements) + " edge terms)\n";
}

}  // namespace sewn::app
