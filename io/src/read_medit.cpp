// MEDIT .mesh reader, ASCII (P. Frey, "MEDIT: an interactive mesh visualization software",
// INRIA RT-0253, and libMeshb's keyword list). The format is free-form: tokens separated by any
// blank space, '#' starts a comment, keywords are case-insensitive, indices are 1-based.

#include <algorithm>
#include <array>
#include <cctype>

#include "cursor.hpp"
#include "read_common.hpp"
#include "sewn/io/read.hpp"

namespace sewn::io {

namespace {

using detail::Cursor;

using detail::lower;

struct CellKeyword {
  const char* name;
  CellType type;
};
// Vertex orders are taken as they are: MEDIT's tetrahedra and hexahedra number their vertices
// as VTK does (Gmsh's MEDIT export, checked by the round-trip test, yields positive cells).
constexpr std::array<CellKeyword, 6> cell_keywords{{{"edges", CellType::segment},
                                                    {"triangles", CellType::triangle},
                                                    {"quadrilaterals", CellType::quad},
                                                    {"tetrahedra", CellType::tetrahedron},
                                                    {"hexahedra", CellType::hexahedron},
                                                    {"hexaedra", CellType::hexahedron}}};

// Keywords whose records Sewn does not need but can step over: integers per record, plus
// `reals_per_dim` reals times the space dimension.
struct SkipKeyword {
  const char* name;
  int integers;
  int reals_per_dim;
};
constexpr std::array<SkipKeyword, 14> skip_keywords{{{"corners", 1, 0},
                                                     {"ridges", 1, 0},
                                                     {"requiredvertices", 1, 0},
                                                     {"requirededges", 1, 0},
                                                     {"requiredtriangles", 1, 0},
                                                     {"requiredquadrilaterals", 1, 0},
                                                     {"requiredtetrahedra", 1, 0},
                                                     {"requiredhexahedra", 1, 0},
                                                     {"normals", 0, 1},
                                                     {"tangents", 0, 1},
                                                     {"normalatvertices", 2, 0},
                                                     {"normalattrianglevertices", 3, 0},
                                                     {"normalatquadrilateralvertices", 3, 0},
                                                     {"tangentatvertices", 2, 0}}};

class MeditReader {
 public:
  MeditReader(std::string_view text, const std::string& source) : in_(text, source, '#') {}

  MeshFile run() {
    out_.format = MeshFormat::medit;
    const std::string_view first = in_.token("'MeshVersionFormatted'");
    if (lower(first) != "meshversionformatted")
      in_.fail_expected("'MeshVersionFormatted' (the first keyword of a MEDIT .mesh file)", first);
    const std::int64_t version = in_.integer("the MEDIT format version");
    if (version < 1 || version > 4) in_.fail_unsupported("MEDIT format version " + std::to_string(version) + " is not supported");
    out_.version = std::to_string(version);
    // 'End' is required: MEDIT files carry no total counts, so it is the only sign that a file
    // was not cut short between two sections.
    for (;;) {
      if (in_.at_end()) in_.fail_expected_here("a MEDIT keyword or 'End' (the file may be truncated)");
      const std::string_view kw = in_.token("a MEDIT keyword");
      const std::string k = lower(kw);
      if (k == "end") break;
      if (k == "dimension") {
        read_dimension();
      } else if (k == "vertices") {
        read_vertices();
      } else if (const auto* c = find_cell(k)) {
        read_cells(kw, c->type);
      } else if (const auto* s = find_skip(k)) {
        skip_records(kw, *s);
      } else if (k == "prisms" || k == "pyramids" || k == "pentahedra") {
        in_.fail_unsupported(std::string(kw) + " are not supported in MEDIT files (their vertex order is not standardised)");
      } else if (!kw.empty() && (std::isalpha(static_cast<unsigned char>(kw[0])) != 0)) {
        in_.fail_unsupported("unknown MEDIT keyword '" + detail::printable(kw) + "'");
      } else {
        in_.fail_expected("a MEDIT keyword", kw);
      }
    }
    if (!have_vertices_) in_.fail_expected("a 'Vertices' section", "");
    return std::move(out_);
  }

 private:
  static const CellKeyword* find_cell(const std::string& k) {
    for (const auto& c : cell_keywords)
      if (k == c.name) return &c;
    return nullptr;
  }
  static const SkipKeyword* find_skip(const std::string& k) {
    for (const auto& s : skip_keywords)
      if (k == s.name) return &s;
    return nullptr;
  }

  void read_dimension() {
    if (have_vertices_) in_.fail_semantic("'Dimension' comes after 'Vertices'");
    const std::int64_t d = in_.integer("the space dimension");
    if (d != 2 && d != 3) in_.fail_semantic("space dimension " + std::to_string(d) + " is not 2 or 3");
    dim_ = static_cast<int>(d);
    have_dimension_ = true;
  }

  void read_vertices() {
    if (!have_dimension_) in_.fail_expected("'Dimension' before 'Vertices'", "Vertices");
    if (have_vertices_) in_.fail_semantic("a second 'Vertices' section");
    have_vertices_ = true;
    const std::uint64_t n = in_.count("the number of vertices");
    out_.mesh.points.reserve(detail::reservable(n, in_.remaining(), 2 * static_cast<std::size_t>(dim_) + 2));
    for (std::uint64_t i = 0; i < n; ++i) {
      const std::string name = "vertex " + std::to_string(i + 1);
      out_.mesh.points.push_back(detail::read_point(in_, dim_, name));
      (void)in_.integer("the reference of " + name);
    }
  }

  void read_cells(std::string_view kw, CellType type) {
    if (!have_vertices_) in_.fail_expected("'Vertices' before '" + std::string(kw) + "'", kw);
    const std::uint64_t n = in_.count("the number of " + std::string(kw));
    out_.file_elements += n;
    const int nv = cell_vertex_count(type);
    const std::size_t r = detail::reservable(n, in_.remaining(), 2 * static_cast<std::size_t>(nv) + 2);
    out_.mesh.types.reserve(out_.mesh.types.size() + r);
    out_.mesh.conn.reserve(out_.mesh.conn.size() + r * static_cast<std::size_t>(nv));
    std::array<std::uint32_t, 8> v{};
    for (std::uint64_t i = 0; i < n; ++i) {
      const std::string name = std::string(kw) + " entry " + std::to_string(i + 1);
      for (std::size_t k = 0; k < static_cast<std::size_t>(nv); ++k) {
        const std::int64_t idx = in_.integer("vertex " + std::to_string(k + 1) + " of " + name);
        if (idx < 1 || static_cast<std::uint64_t>(idx) > out_.mesh.points.size())
          in_.fail_semantic(name + " refers to vertex " + std::to_string(idx) + " but the vertices are numbered 1.." +
                            std::to_string(out_.mesh.points.size()));
        v[k] = static_cast<std::uint32_t>(idx - 1);
        for (std::size_t l = 0; l < k; ++l)
          if (v[l] == v[k]) in_.fail_semantic(name + " uses vertex " + std::to_string(idx) + " twice");
      }
      const std::int32_t ref = detail::to_tag(in_, in_.integer("the reference of " + name), "the reference of " + name);
      out_.mesh.add_cell(type, std::span<const std::uint32_t>(v.data(), static_cast<std::size_t>(nv)), ref);
    }
  }

  void skip_records(std::string_view kw, const SkipKeyword& s) {
    const std::uint64_t n = in_.count("the number of " + std::string(kw));
    for (std::uint64_t i = 0; i < n; ++i) {
      for (int k = 0; k < s.integers; ++k) (void)in_.integer("an integer of " + std::string(kw));
      for (int k = 0; k < s.reals_per_dim * dim_; ++k) (void)in_.real("a real of " + std::string(kw));
    }
  }

  Cursor in_;
  MeshFile out_;
  int dim_ = 3;
  bool have_dimension_ = false;
  bool have_vertices_ = false;
};

}  // namespace

MeshFile parse_medit(std::string_view text, const std::string& source) { return MeditReader(text, source).run(); }

MeshFile read_medit(const std::filesystem::path& path) {
  const std::string text = detail::slurp(path);
  return parse_medit(text, path.string());
}

}  // namespace sewn::io
