#include "sewn/apps/continuum.hpp"

#include <algorithm>
#include <cmath>
#include <map>
#include <numbers>

#include "sewn/physics/cell_input_error.hpp"
#include "sewn/physics/shells/shell_terms.hpp"

namespace sewn::app {

namespace {

using physics::Index;
using Vec3d = Eigen::Vector3d;

// Cuts and piercing are followed on tetrahedra and shells (follow_cut); a rod's stencils across
// a cut vertex and its twist angles would have to split into two rods, which the Rods term
// cannot do yet.
void check_cuts(const Scene& scene, const std::vector<CellModel>& models) {
  if (scene.cuts.empty()) return;
  const auto rods = std::count(models.begin(), models.end(), CellModel::rod);
  if (rods > 0)
    throw SceneError(scene.file, "cuts",
                     "cutting is supported on solid tetrahedra and shells only, and this scene has " + std::to_string(rods) +
                         " rod segments (a rod's stencils and twist angles cannot follow a cut yet)");
  const auto shells = std::count(models.begin(), models.end(), CellModel::shell);
  if (shells > 0 && scene.bending != "hinge")
    throw SceneError(scene.file, "model.bending",
                     "this scene cuts " + std::to_string(shells) + " shell triangles, which \"" + scene.bending +
                         "\" bending cannot follow yet (a triangle's bending element holds its neighbours' nodes"
                         " and its edges' angles): use \"hinge\"");
}

// Checks what a continuum model cannot take and removes the springs it replaces.
void drop_springs(const Scene& scene, physics::MssModel<3>& model) {
  const std::string m = "model \"" + scene.model + "\"";
  if (scene.damping == "viscous")
    throw SceneError(scene.file, "damping.model", "\"viscous\" is per-spring damping, which " + m + " has none of: use \"rayleigh\" (alpha) or \"none\"");
  if (scene.damping == "rayleigh" && scene.rayleigh_beta != 0.0)
    throw SceneError(scene.file, "damping.beta", "stiffness-proportional damping acts on springs, which " + m + " has none of: use alpha");
  physics::Springs& springs = model.springs();
  for (Index s = 0; s < springs.size(); ++s)
    if (springs.is_alive(s)) springs.remove(s);  // for good: the model's edits keep removed springs removed
}

template <int N>
std::array<Index, N> corner_nodes(const physics::MssModel<3>& model, std::span<const std::uint32_t> cell, Eigen::Matrix<double, 3, N>& X) {
  std::array<Index, N> nodes{};
  for (int a = 0; a < N; ++a) {
    nodes[static_cast<std::size_t>(a)] = model.node_of_point(cell[static_cast<std::size_t>(a)]);
    X.col(a) = model.rest_position(nodes[static_cast<std::size_t>(a)]);
  }
  return nodes;
}

std::vector<double> rest_state(const physics::MssModel<3>& model) {
  std::vector<double> rest_x;
  for (Index i = 0; i < model.nodes().size(); ++i) {
    const Vec3d p = model.rest_position(i);
    rest_x.insert(rest_x.end(), {p.x(), p.y(), p.z()});
  }
  return rest_x;
}

// A rod segment: its two nodes, its element, and what must agree for two segments to chain.
struct Segment {
  std::array<Index, 2> node;
  Index element;
  std::pair<std::uint32_t, int> kind;  // (material, group)
};

// Maximal chains of segments through nodes where exactly two segments of one kind meet:
// (element list, node list, closed) per chain.
struct Chain {
  std::vector<Index> elements, nodes;
  bool closed = false;
};

std::vector<Chain> chain_segments(const std::vector<Segment>& segs, Index num_nodes) {
  std::vector<std::vector<std::uint32_t>> at(num_nodes);
  for (std::uint32_t s = 0; s < segs.size(); ++s)
    for (Index n : segs[s].node) at[n].push_back(s);
  auto passes = [&](Index n) { return at[n].size() == 2 && segs[at[n][0]].kind == segs[at[n][1]].kind; };
  std::vector<bool> used(segs.size(), false);
  std::vector<Chain> chains;
  auto walk = [&](Index start, std::uint32_t s) {
    Chain c;
    c.nodes.push_back(start);
    Index n = start;
    while (true) {
      used[s] = true;
      c.elements.push_back(segs[s].element);
      n = segs[s].node[0] == n ? segs[s].node[1] : segs[s].node[0];
      if (n == start) {
        c.closed = true;
        break;
      }
      c.nodes.push_back(n);
      if (!passes(n)) break;
      s = at[n][0] == s ? at[n][1] : at[n][0];
    }
    chains.push_back(std::move(c));
  };
  for (Index n = 0; n < num_nodes; ++n)
    if (!passes(n))
      for (std::uint32_t s : at[n])
        if (!used[s]) walk(n, s);
  for (std::uint32_t s = 0; s < segs.size(); ++s)
    if (!used[s]) walk(segs[s].node[0], s);  // what is left are closed loops
  return chains;
}

physics::rods::Section rod_section(const Scene& scene, const physics::MaterialParams& mat, int group) {
  const auto axes = group >= 0 ? scene.model_groups[static_cast<std::size_t>(group)].semi_axes : std::array<double, 2>{};
  if (axes[0] > 0) return physics::rods::Section::elliptic(mat.young, mat.poisson, axes[0], axes[1]);
  return physics::rods::Section::circular(mat.young, mat.poisson, std::sqrt(mat.area / std::numbers::pi));
}

void add_rods(const Scene& scene, const std::vector<physics::MaterialParams>& materials, const IndexedMesh& mesh,
              const std::vector<CellModel>& models, const std::vector<int>& groups, physics::MssModel<3>& model, ContinuumParts& parts) {
  std::vector<Segment> segs;
  for (Index e = 0; e < model.elements().size(); ++e) {
    const auto& el = model.elements()[e];
    if (!el.alive || models[el.mesh_cell] != CellModel::rod) continue;
    const auto cell = mesh.cell(el.mesh_cell);
    segs.push_back({{model.node_of_point(cell[0]), model.node_of_point(cell[1])}, e, {el.material, groups[el.mesh_cell]}});
  }
  if (segs.empty()) return;
  parts.rods = &model.system().add<physics::rods::Rods>();
  parts.rod_edge_of_element.assign(model.elements().size(), {physics::invalid_index, 0});
  const std::vector<double> rest_x = rest_state(model);
  for (const Chain& c : chain_segments(segs, model.nodes().size())) {
    const auto& first = model.elements()[c.elements[0]];
    const int group = groups[first.mesh_cell];
    const std::string key = group >= 0 ? "model.groups[" + std::to_string(group) + "]" : "model.type";
    Index r = 0;
    try {
      r = parts.rods->add_rod(c.nodes, rest_x, c.closed, rod_section(scene, materials[first.material], group));
    } catch (const physics::InputError& e) {
      throw SceneError(scene.file, key, "the rod through mesh cell " + std::to_string(first.mesh_cell) + " cannot be built: " + e.what());
    }
    for (std::size_t j = 0; j < c.elements.size(); ++j) parts.rod_edge_of_element[c.elements[j]] = {r, static_cast<int>(j)};
  }
}

// Where each hinge sits in the triangles it was built from (all nodes distinct at build time,
// so a triangle is known by its node set).
std::vector<HingeCorners> hinge_corners(const physics::shells::Hinges& hinges, const std::vector<std::array<Index, 3>>& triangles) {
  std::map<std::array<Index, 3>, Index> by_nodes;
  for (Index t = 0; t < triangles.size(); ++t) {
    auto key = triangles[t];
    std::sort(key.begin(), key.end());
    by_nodes.emplace(key, t);
  }
  auto find = [&](Index o, Index p, Index q, Index& tri, std::array<std::uint8_t, 3>& at) {
    std::array<Index, 3> key{o, p, q};
    std::sort(key.begin(), key.end());
    tri = by_nodes.at(key);
    const std::array<Index, 3> want{o, p, q};
    for (std::size_t k = 0; k < 3; ++k)
      at[k] = static_cast<std::uint8_t>(std::find(triangles[tri].begin(), triangles[tri].end(), want[k]) - triangles[tri].begin());
  };
  std::vector<HingeCorners> out(hinges.size());
  for (Index h = 0; h < hinges.size(); ++h) {
    const auto& n = hinges.element_nodes(h);
    find(n[0], n[1], n[2], out[h].a, out[h].in_a);
    find(n[3], n[1], n[2], out[h].b, out[h].in_b);
  }
  return out;
}

void add_shells(const std::vector<physics::MaterialParams>& materials, const IndexedMesh& mesh, const std::vector<CellModel>& models,
                physics::MssModel<3>& model, const Scene& scene, std::span<const std::uint8_t> held, ContinuumParts& parts) {
  std::vector<std::array<Index, 3>> triangles;
  std::vector<double> k_b;
  std::vector<physics::shells::PlateMaterial> plates;
  for (Index e = 0; e < model.elements().size(); ++e) {
    const auto& el = model.elements()[e];
    if (!el.alive || models[el.mesh_cell] != CellModel::shell) continue;
    if (!parts.membranes) parts.membranes = &model.system().add<physics::shells::Membranes>();
    physics::shells::TriPositions X;
    const auto nodes = corner_nodes<3>(model, mesh.cell(el.mesh_cell), X);
    const auto& mat = materials[el.material];
    parts.membranes->add(nodes, X, mat.young, mat.poisson, mat.thickness);
    parts.element_of_membrane.push_back(e);
    triangles.push_back(nodes);
    k_b.push_back(physics::shells::hinge_stiffness(mat.young, mat.poisson, mat.thickness));
    plates.push_back(physics::shells::plate_material(mat.young, mat.poisson, mat.thickness));
  }
  if (triangles.empty()) return;
  // a triangle held on every node is a clamp: its edges hold the slope of the free triangles
  std::vector<std::uint8_t> clamp(triangles.size(), 0);
  if (!held.empty())
    for (std::size_t t = 0; t < triangles.size(); ++t)
      clamp[t] = held[triangles[t][0]] != 0 && held[triangles[t][1]] != 0 && held[triangles[t][2]] != 0;
  if (scene.bending == "morley" && scene.integrator != "newton")
    throw SceneError(scene.file, "model.bending",
                     "\"morley\" bending gives every shell edge an angle DOF, which integrator.type \"newton\" alone "
                     "integrates (this scene's is \"" + scene.integrator + "\"): use \"newton\", or \"patch\" or \"hinge\" bending");
  try {
    if (scene.bending == "morley") {
      parts.morley = physics::shells::add_morley_bending(model.system(), triangles, rest_state(model), plates, clamp);
      return;
    }
    if (scene.bending == "patch") {
      parts.patches = physics::shells::add_patch_bending(model.system(), triangles, rest_state(model), plates, clamp);
      return;
    }
    parts.hinges = &model.system().add<physics::shells::Hinges>();
    parts.hinges->add_interior_edges(triangles, rest_state(model), k_b);
  } catch (const physics::CellInputError& e) {
    // shell triangles restated as the mesh cells they came from (build_bodies names the file's cells)
    const auto mesh_cell = [&](const IndexedMessage::Ref& r) {
      if (r.kind != IndexedMessage::Ref::Kind::cell) return r;
      const physics::Index c = model.elements()[parts.element_of_membrane[r.index]].mesh_cell;
      return IndexedMessage::Ref{r.kind, static_cast<std::uint32_t>(c)};
    };
    throw physics::CellInputError("shell triangles", e.message().renumbered(mesh_cell));
  } catch (const physics::InputError& e) {
    throw SceneError(scene.file, "meshes", e.what());
  }
  parts.hinge_corners = hinge_corners(*parts.hinges, triangles);
}

void add_solids(const std::vector<physics::MaterialParams>& materials, const IndexedMesh& mesh, const std::vector<CellModel>& models,
                physics::MssModel<3>& model, const Scene& scene, ContinuumParts& parts) {
  for (Index e = 0; e < model.elements().size(); ++e) {
    const auto& el = model.elements()[e];
    if (!el.alive || models[el.mesh_cell] != CellModel::solid) continue;
    if (!parts.tets)
      parts.tets = &model.system().add<physics::solids::Tets>(scene.law == "stvk" ? physics::solids::TetLaw::stvk
                                                                                  : physics::solids::TetLaw::stable_neo_hookean);
    physics::solids::TetPositions X;
    const auto nodes = corner_nodes<4>(model, mesh.cell(el.mesh_cell), X);
    const auto& mat = materials[el.material];
    parts.tets->add(nodes, X, mat.young, mat.poisson);
    parts.element_of_tet.push_back(e);
  }
}

}  // namespace

void apply_rod_sections(const Scene& scene, const IndexedMesh& mesh, const std::vector<CellModel>& models, const std::vector<int>& groups,
                        std::vector<physics::MaterialParams>& materials, std::vector<std::uint32_t>& material_of_cell) {
  std::map<std::pair<std::uint32_t, int>, std::uint32_t> copy;  // (material, group) -> its copy
  for (std::uint32_t c = 0; c < mesh.num_cells(); ++c) {
    if (models[c] != CellModel::rod) continue;
    const int g = groups[c];
    if (g < 0 || scene.model_groups[static_cast<std::size_t>(g)].semi_axes[0] <= 0) continue;
    const auto [it, added] = copy.try_emplace({material_of_cell[c], g}, static_cast<std::uint32_t>(materials.size()));
    if (added) {
      physics::MaterialParams m = materials[material_of_cell[c]];
      const auto& axes = scene.model_groups[static_cast<std::size_t>(g)].semi_axes;
      m.area = std::numbers::pi * axes[0] * axes[1];
      materials.push_back(m);
    }
    material_of_cell[c] = it->second;
  }
}

ContinuumParts build_continuum(const Scene& scene, const std::vector<physics::MaterialParams>& materials, const IndexedMesh& mesh,
                               const std::vector<CellModel>& models, const std::vector<int>& groups, physics::MssModel<3>& model,
                               std::span<const std::uint8_t> held) {
  if (!held.empty() && held.size() != model.nodes().size())
    throw physics::InputError("build_continuum: " + std::to_string(held.size()) + " held flags for " +
                              std::to_string(model.nodes().size()) + " nodes");
  check_cuts(scene, models);
  drop_springs(scene, model);
  ContinuumParts parts;
  add_solids(materials, mesh, models, model, scene, parts);
  add_shells(materials, mesh, models, model, scene, held, parts);
  add_rods(scene, materials, mesh, models, groups, model, parts);
  // every edit of the model (a cut, a piercing) is followed before the model compacts its
  // particles, so that elements it removed are retired while their nodes still exist; the
  // listener keeps its own copy of the parts (term pointers and index tables, fixed from here)
  if (parts.tets || parts.membranes) model.after_edits([copy = parts, &model] { follow_cut(copy, model); });
  return parts;
}

void follow_cut(const ContinuumParts& parts, const physics::MssModel<3>& model) {
  // an element a piercing removed takes its term's element with it
  auto alive = [&](Index e) { return model.elements()[e].alive; };
  for (Index k = 0; k < parts.element_of_tet.size(); ++k) {
    if (!parts.tets->is_alive(k)) continue;
    if (!alive(parts.element_of_tet[k])) {
      parts.tets->retire_element(k);
      continue;
    }
    const std::vector<Index> nodes = model.element_nodes(parts.element_of_tet[k]);
    parts.tets->set_element_nodes(k, {nodes[0], nodes[1], nodes[2], nodes[3]});
  }
  std::vector<std::array<Index, 3>> tri(parts.element_of_membrane.size());
  for (Index k = 0; k < tri.size(); ++k) {
    if (!parts.membranes->is_alive(k)) continue;
    if (!alive(parts.element_of_membrane[k])) {
      parts.membranes->retire_element(k);
      continue;
    }
    const std::vector<Index> nodes = model.element_nodes(parts.element_of_membrane[k]);
    tri[k] = {nodes[0], nodes[1], nodes[2]};
    parts.membranes->set_element_nodes(k, tri[k]);
  }
  for (Index h = 0; h < parts.hinge_corners.size(); ++h) {
    if (!parts.hinges->is_alive(h)) continue;
    const HingeCorners& c = parts.hinge_corners[h];
    if (!parts.membranes->is_alive(c.a) || !parts.membranes->is_alive(c.b)) {
      parts.hinges->retire_element(h);
      continue;
    }
    const auto& a = tri[c.a];
    const auto& b = tri[c.b];
    // the edge's two particles, as each triangle now has them: different copies mean the cut
    // ran along this edge, and the two faces no longer bend about a common hinge
    if (a[c.in_a[1]] != b[c.in_b[1]] || a[c.in_a[2]] != b[c.in_b[2]])
      parts.hinges->retire_element(h);
    else
      parts.hinges->set_element_nodes(h, {a[c.in_a[0]], a[c.in_a[1]], a[c.in_a[2]], b[c.in_b[0]]});
  }
}

RodOutput rod_output(const ContinuumParts& parts, const physics::MssModel<3>& model) {
  RodOutput out;
  out.m1.assign(model.nodes().size(), Point3{0, 0, 0});
  out.m2 = out.m1;
  if (!parts.rods) return out;
  // read through the const term: its non-const rod() forgets the last θ solve, and writing a
  // frame has no reason to cost the next force evaluation a twist solve (a no-op from a solved
  // θ: it stops at once, its Newton step below 1e-13)
  const physics::rods::Rods& rods = *parts.rods;
  const auto x = model.nodes().x();
  std::vector<std::uint8_t> done(model.nodes().size(), 0);
  for (Index r = 0; r < rods.num_rods(); ++r) {
    const physics::rods::Rod& rod = rods.rod(r);
    const std::span<const Index> nodes = rods.rod_nodes(r);
    out.chains.emplace_back(nodes.begin(), nodes.end());
    if (rod.closed()) out.chains.back().push_back(nodes.front());
    const physics::rods::Points p = rods.gather(r, x);
    const int edges = rod.num_edges(), n = static_cast<int>(nodes.size());
    for (int v = 0; v < n; ++v) {
      if (done[nodes[static_cast<std::size_t>(v)]] != 0) continue;
      // the edges meeting at vertex v: edge v - 1 (v + n - 1 on a closed rod) and edge v
      const int before = rod.closed() ? (v + n - 1) % n : v - 1, after = v < edges ? v : -1;
      Vec3d m1 = Vec3d::Zero(), t = Vec3d::Zero(), first = Vec3d::Zero();
      for (const int e : {before, after}) {
        if (e < 0) continue;
        const int next = (e + 1) % n;
        t += (p.col(next) - p.col(e)).normalized();
        m1 += rod.material_directors(p, e).first;
        if (first.isZero()) first = m1;
      }
      t.normalize();
      m1 -= m1.dot(t) * t;
      // two edges' directors half a turn apart cancel: the first edge's then
      if (!(m1.norm() > 1e-6)) m1 = first - first.dot(t) * t;
      m1.normalize();
      const Vec3d m2 = t.cross(m1);
      out.m1[nodes[static_cast<std::size_t>(v)]] = {m1.x(), m1.y(), m1.z()};
      out.m2[nodes[static_cast<std::size_t>(v)]] = {m2.x(), m2.y(), m2.z()};
      done[nodes[static_cast<std::size_t>(v)]] = 1;
    }
  }
  return out;
}

}  // namespace sewn::app
