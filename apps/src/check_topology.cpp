#include "sewn/apps/check_topology.hpp"

#include <sstream>

#include "sewn/cmap/build.hpp"

namespace sewn::app {

namespace {

template <int D>
void compute(const IndexedMesh& mesh, const std::string& source, MeshTopology& out) {
  CMap<D> map;
  BuildOptions opt;
  opt.source = source;
  const BuildResult built = build(map, mesh, opt);
  out.topology = topology(map, {built.vertex_of_dart});
  out.point_of_dart = built.vertex_of_dart;
  out.next_of_dart.assign(map.dart_capacity(), Dart::null_index);
  for (Dart d : map.darts()) out.next_of_dart[d.index()] = built.vertex_of_dart[map.beta(d, 1).index()];
}

const char* cell_name(int dim, int i) {
  static const char* names[] = {"vertices", "edges", "faces", "volumes"};
  return i == dim && dim == 2 ? "faces" : names[i];
}

std::string betti_str(const ComponentTopology& c, int dim) {
  std::string s = "(";
  for (int i = 0; i <= dim; ++i) s += (i ? ", " : "") + std::to_string(c.betti[static_cast<std::size_t>(i)]);
  return s + ")";
}

std::string where(const MeshTopology& t, const NonManifoldCell& c) {
  const std::uint32_t x = c.dart.index();
  if (c.dim == 0) return "vertex at point " + std::to_string(t.number(t.point_of_dart[x]));
  return "edge between points " + std::to_string(t.number(t.point_of_dart[x])) + " and " + std::to_string(t.number(t.next_of_dart[x]));
}

}  // namespace

MeshTopology mesh_topology(const IndexedMesh& mesh, const std::string& source) {
  MeshTopology out;
  const auto n = mesh.count_by_dimension();
  if (mesh.num_cells() == 0) {
    out.skipped = "the mesh has no cells";
  } else if (n[3] > 0 && n[1] == 0 && n[2] == 0) {
    out.dim = 3;
    compute<3>(mesh, source, out);
  } else if (n[2] > 0 && n[1] == 0 && n[3] == 0) {
    out.dim = 2;
    compute<2>(mesh, source, out);
  } else {
    out.skipped = "invariants are computed for meshes of volumes only or of surface cells only; this one has " +
                  std::to_string(n[3]) + " volumes, " + std::to_string(n[2]) + " surface cells and " + std::to_string(n[1]) +
                  " segments";
  }
  return out;
}

std::string topology_text(const MeshTopology& t, std::size_t max_items) {
  std::ostringstream os;
  if (t.dim == 0) {
    os << "  topology: not computed: " << t.skipped << "\n";
    return os.str();
  }
  const Topology& tp = t.topology;
  const int D = t.dim;
  os << "  topology (cells identified by their points): " << tp.components.size() << " component"
     << (tp.components.size() == 1 ? "" : "s") << ", χ = " << tp.total.euler << ", Betti numbers over Z/2 "
     << betti_str(tp.total, D) << ", " << (tp.orientable ? "orientable" : "not orientable") << ", "
     << tp.boundary.size() << " boundary component" << (tp.boundary.size() == 1 ? "" : "s") << "\n";
  for (std::size_t k = 0; k < tp.components.size() && k < max_items; ++k) {
    const auto& c = tp.components[k];
    os << "    component " << k << ": ";
    for (int i = D; i >= 0; --i) os << c.cells[static_cast<std::size_t>(i)] << " " << cell_name(D, i) << (i ? ", " : "");
    os << "; χ = " << c.euler << ", b = " << betti_str(c, D) << ", " << (c.orientable ? "orientable" : "not orientable");
    if (D == 2) os << ", genus " << c.genus << (c.orientable ? "" : " (cross-caps)");
    os << ", " << c.boundary_components << " boundary component" << (c.boundary_components == 1 ? "" : "s") << "\n";
  }
  if (tp.components.size() > max_items) os << "    ... and " << tp.components.size() - max_items << " more components\n";
  for (std::size_t k = 0; k < tp.boundary.size() && k < max_items; ++k) {
    const auto& b = tp.boundary[k];
    os << "    boundary " << k << " (component " << b.component << "): ";
    if (D == 3) {
      os << b.cells[2] << " faces, " << b.cells[1] << " edges, " << b.cells[0] << " vertices; χ = " << b.euler << ", ";
      if (!b.surface) os << "not a closed surface (pinched)\n";
      else os << (b.orientable ? "orientable, genus " : "not orientable, cross-caps ") << b.genus << "\n";
    } else {
      os << b.cells[1] << " edges, " << b.cells[0] << " vertices" << (b.euler == 0 ? " (a closed curve)" : "") << "\n";
    }
  }
  if (tp.boundary.size() > max_items) os << "    ... and " << tp.boundary.size() - max_items << " more boundary components\n";
  if (tp.nonmanifold.empty()) {
    os << "    manifold: every vertex and edge has a sphere or disc as its link\n";
  } else {
    os << "    non-manifold cells: " << tp.nonmanifold.size() << "\n";
    for (std::size_t k = 0; k < tp.nonmanifold.size() && k < max_items; ++k)
      os << "      " << where(t, tp.nonmanifold[k]) << ": " << tp.nonmanifold[k].why << "\n";
    if (tp.nonmanifold.size() > max_items) os << "      ... and " << tp.nonmanifold.size() - max_items << " more\n";
  }
  return os.str();
}

nlohmann::json topology_json(const MeshTopology& t) {
  using nlohmann::json;
  if (t.dim == 0) return json{{"skipped", t.skipped}};
  const Topology& tp = t.topology;
  const int D = t.dim;
  auto counts = [&](const auto& a, int n) {
    json j = json::array();
    for (int i = 0; i <= n; ++i) j.push_back(a[static_cast<std::size_t>(i)]);
    return j;
  };
  json comps = json::array();
  for (const auto& c : tp.components) {
    json j{{"cells", counts(c.cells, D)},
           {"euler", c.euler},
           {"betti", counts(c.betti, D)},
           {"orientable", c.orientable},
           {"boundary_components", c.boundary_components}};
    if (D == 2) j["genus"] = c.genus;
    comps.push_back(std::move(j));
  }
  json bnd = json::array();
  for (const auto& b : tp.boundary) {
    json j{{"component", b.component}, {"cells", counts(b.cells, D - 1)}, {"euler", b.euler}, {"orientable", b.orientable}};
    if (D == 3) {
      j["surface"] = b.surface;
      j["genus"] = b.genus;
    }
    bnd.push_back(std::move(j));
  }
  json nm = json::array();
  for (const auto& c : tp.nonmanifold) {
    json j{{"dim", c.dim}, {"why", c.why}};
    if (c.dim == 0) j["point"] = t.number(t.point_of_dart[c.dart.index()]);
    else j["points"] = {t.number(t.point_of_dart[c.dart.index()]), t.number(t.next_of_dart[c.dart.index()])};
    nm.push_back(std::move(j));
  }
  return json{{"dimension", D},       {"cells", counts(tp.total.cells, D)}, {"euler", tp.total.euler},
              {"betti", counts(tp.total.betti, D)}, {"orientable", tp.orientable}, {"components", comps},
              {"boundary", bnd},      {"nonmanifold", nm}};
}

}  // namespace sewn::app
