#include "sewn/io/write_gmsh.hpp"

#include <cstdio>
#include <stdexcept>

#include "sewn/io/atomic_file.hpp"

namespace sewn::io {

namespace {

// Gmsh's element type numbers (first order).
int gmsh_type(CellType t) {
  switch (t) {
    case CellType::segment: return 1;
    case CellType::triangle: return 2;
    case CellType::quad: return 3;
    case CellType::tetrahedron: return 4;
    case CellType::hexahedron: return 5;
    case CellType::prism: return 6;
    case CellType::pyramid: return 7;
  }
  return 0;
}

}  // namespace

std::string gmsh_text(const IndexedMesh& mesh, std::span<const TagName> names) {
  std::string s = "$MeshFormat\n2.2 0 8\n$EndMeshFormat\n";
  char buf[160];
  if (!names.empty()) {
    s.append("$PhysicalNames\n").append(std::to_string(names.size())).append("\n");
    for (const TagName& n : names) {
      if (n.name.find_first_of("\"\n\r") != std::string::npos)
        throw std::invalid_argument("gmsh physical name '" + n.name + "' holds a quote or a line break");
      // appended piecewise: g++ 12 warns falsely (-Wrestrict) on a chain of string + string
      s.append(std::to_string(n.dimension)).append(" ").append(std::to_string(n.tag)).append(" \"");
      s.append(n.name).append("\"\n");
    }
    s += "$EndPhysicalNames\n";
  }
  s.append("$Nodes\n").append(std::to_string(mesh.num_points())).append("\n");
  for (std::uint32_t p = 0; p < mesh.num_points(); ++p) {
    const Point3& x = mesh.points[p];
    std::snprintf(buf, sizeof buf, "%u %.17g %.17g %.17g\n", p + 1, x[0], x[1], x[2]);
    s += buf;
  }
  s.append("$EndNodes\n$Elements\n").append(std::to_string(mesh.num_cells())).append("\n");
  for (std::uint32_t c = 0; c < mesh.num_cells(); ++c) {
    const std::int32_t tag = c < mesh.tags.size() ? mesh.tags[c] : 0;
    std::snprintf(buf, sizeof buf, "%u %d 2 %d %d", c + 1, gmsh_type(mesh.types[c]), tag, tag);
    s += buf;
    for (const std::uint32_t v : mesh.cell(c)) {
      std::snprintf(buf, sizeof buf, " %u", v + 1);
      s += buf;
    }
    s += '\n';
  }
  s += "$EndElements\n";
  return s;
}

void write_gmsh(const std::filesystem::path& path, const IndexedMesh& mesh, std::span<const TagName> names) {
  write_file_atomically(path, gmsh_text(mesh, names));
}

}  // namespace sewn::io
