#include <algorithm>
#include <cctype>
#include <string>

#include "cursor.hpp"
#include "read_common.hpp"
#include "sewn/io/read.hpp"

namespace sewn::io {

const char* to_string(MeshFormat f) {
  switch (f) {
    case MeshFormat::gmsh: return "Gmsh MSH";
    case MeshFormat::medit: return "MEDIT";
    case MeshFormat::vtk_legacy: return "legacy VTK";
  }
  return "?";
}

namespace {

using detail::lower;

// The first word of the file, skipping blank space and MEDIT '#' comment lines.
std::string first_word(std::string_view bytes) {
  std::size_t p = 0;
  while (p < bytes.size()) {
    const char c = bytes[p];
    if (c == '#') {
      // "# vtk DataFile" is a header, not a comment
      if (lower(bytes.substr(p, 6)) == "# vtk ") return "# vtk";
      while (p < bytes.size() && bytes[p] != '\n') ++p;
    } else if (std::isspace(static_cast<unsigned char>(c)) != 0) {
      ++p;
    } else {
      break;
    }
  }
  std::size_t e = p;
  while (e < bytes.size() && std::isspace(static_cast<unsigned char>(bytes[e])) == 0) ++e;
  return lower(bytes.substr(p, std::min<std::size_t>(e - p, 64)));
}

// What to do with the files of other tools that users bring as meshes.
std::string format_hint(const std::string& ext) {
  if (ext == ".node" || ext == ".ele" || ext == ".face" || ext == ".smesh" || ext == ".poly")
    return " (tetgen's own format: run tetgen with -g to write a MEDIT .mesh)";
  if (ext == ".off" || ext == ".obj" || ext == ".stl" || ext == ".ply")
    return " (a surface: a scene's mesh of type \"surface\" voxelizes a closed OFF, OBJ or STL surface, or mesh its "
           "inside with gmsh or tetgen)";
  return "";
}

}  // namespace

MeshFile read_mesh_file(const std::filesystem::path& path, const ReadOptions& opt) {
  const std::string bytes = detail::slurp(path);
  const std::string name = path.string();
  if (bytes.find_first_not_of(" \t\r\n") == std::string::npos) throw ParseError(name, 1, "a mesh", "");
  const std::string w = first_word(bytes);
  if (w == "$meshformat" || w == "$nod") return parse_gmsh(bytes, name);
  if (w == "# vtk") return parse_vtk(bytes, name, opt);
  if (w == "meshversionformatted") return parse_medit(bytes, name);
  const std::string ext = lower(path.extension().string());
  if (ext == ".msh") return parse_gmsh(bytes, name);
  if (ext == ".vtk") return parse_vtk(bytes, name, opt);
  if (ext == ".mesh") return parse_medit(bytes, name);
  if (ext == ".meshb") throw UnsupportedError(name, 0, "binary MEDIT (.meshb) files are not supported");
  throw UnsupportedError(name, 0,
                         "not a recognised mesh file: expected a Gmsh .msh, MEDIT .mesh or legacy VTK .vtk file, found '" +
                             detail::printable(w) + "' at its start" + format_hint(ext));
}

std::int64_t MeshFile::point_number(std::uint32_t p) const {
  if (!node_tags.empty()) return node_tags[p];
  return format == MeshFormat::medit ? std::int64_t{p} + 1 : std::int64_t{p};
}

std::vector<std::int64_t> MeshFile::point_numbers() const {
  std::vector<std::int64_t> out(mesh.num_points());
  for (std::uint32_t p = 0; p < mesh.num_points(); ++p) out[p] = point_number(p);
  return out;
}

IndexedMesh read_mesh(const std::filesystem::path& path, const ReadOptions& opt) {
  return read_mesh_file(path, opt).mesh;
}

}  // namespace sewn::io
