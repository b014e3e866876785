// Legacy VTK reader ("VTK File Formats", legacy format): DATASET UNSTRUCTURED_GRID, ASCII or
// BINARY (big-endian), file versions up to 5.1 (5.x stores cells as OFFSETS + CONNECTIVITY).

#include <algorithm>
#include <array>
#include <bit>
#include <cctype>
#include <cmath>
#include <cstring>
#include <optional>

#include "cursor.hpp"
#include "read_common.hpp"
#include "sewn/io/read.hpp"

namespace sewn::io {

namespace {

using detail::Cursor;

using detail::lower;

enum class Kind { signed_int, unsigned_int, real };
struct DType {
  Kind kind;
  std::size_t bytes;
};

std::optional<DType> dtype_of(const std::string& t) {
  if (t == "char" || t == "vtktypeint8" || t == "signed_char") return DType{Kind::signed_int, 1};
  if (t == "unsigned_char" || t == "vtktypeuint8") return DType{Kind::unsigned_int, 1};
  if (t == "short" || t == "vtktypeint16") return DType{Kind::signed_int, 2};
  if (t == "unsigned_short" || t == "vtktypeuint16") return DType{Kind::unsigned_int, 2};
  if (t == "int" || t == "vtktypeint32") return DType{Kind::signed_int, 4};
  if (t == "unsigned_int" || t == "vtktypeuint32") return DType{Kind::unsigned_int, 4};
  // VTK writes "long" with the writing machine's sizeof(long); 8 bytes on the 64-bit Unix
  // systems that write these files.
  if (t == "long" || t == "vtktypeint64" || t == "vtkidtype") return DType{Kind::signed_int, 8};
  if (t == "unsigned_long" || t == "vtktypeuint64") return DType{Kind::unsigned_int, 8};
  if (t == "float" || t == "vtktypefloat32") return DType{Kind::real, 4};
  if (t == "double" || t == "vtktypefloat64") return DType{Kind::real, 8};
  return std::nullopt;
}

struct VtkCellType {
  CellType type;
  int points;
  std::array<std::uint32_t, 8> order;  // VTK slot k takes file point order[k]
};

std::optional<VtkCellType> vtk_cell_type(std::int64_t t) {
  switch (t) {
    case 3: return VtkCellType{CellType::segment, 2, {0, 1}};
    case 5: return VtkCellType{CellType::triangle, 3, {0, 1, 2}};
    case 8: return VtkCellType{CellType::quad, 4, {0, 1, 3, 2}};  // pixel: lexicographic corners
    case 9: return VtkCellType{CellType::quad, 4, {0, 1, 2, 3}};
    case 10: return VtkCellType{CellType::tetrahedron, 4, {0, 1, 2, 3}};
    case 11: return VtkCellType{CellType::hexahedron, 8, {0, 1, 3, 2, 4, 5, 7, 6}};  // voxel
    case 12: return VtkCellType{CellType::hexahedron, 8, {0, 1, 2, 3, 4, 5, 6, 7}};
    case 13: return VtkCellType{CellType::prism, 6, {0, 1, 2, 3, 4, 5}};
    case 14: return VtkCellType{CellType::pyramid, 5, {0, 1, 2, 3, 4}};
    default: return std::nullopt;
  }
}

// A VTK array read as 64-bit integers or as doubles, whichever its type holds exactly.
struct Values {
  std::vector<std::int64_t> ints;
  std::vector<double> reals;
  bool integral = true;
};

class VtkReader {
 public:
  VtkReader(std::string_view bytes, const std::string& source, const ReadOptions& opt)
      : in_(bytes, source), opt_(opt) {}

  MeshFile run() {
    out_.format = MeshFormat::vtk_legacy;
    read_header();
    while (!in_.at_end()) {
      const std::string_view kw = in_.token("a dataset keyword (POINTS, CELLS, CELL_TYPES, CELL_DATA, POINT_DATA)");
      const std::string k = lower(kw);
      if (k == "points") {
        read_points();
      } else if (k == "cells") {
        read_cells();
      } else if (k == "cell_types") {
        read_cell_types();
      } else if (k == "cell_data") {
        read_attributes(true);
      } else if (k == "point_data") {
        read_attributes(false);
      } else if (k == "field") {
        skip_field();
      } else if (k == "metadata") {
        skip_metadata();
      } else {
        in_.fail_expected("a dataset keyword (POINTS, CELLS, CELL_TYPES, CELL_DATA, POINT_DATA)", kw);
      }
    }
    if (!have_points_) in_.fail_expected("a POINTS section", "");
    // A grid without cells is legal VTK but nothing to simulate, and requiring CELLS means a file
    // cut short after its POINTS is reported rather than read as an empty grid.
    if (!have_cells_) in_.fail_expected("a CELLS section", "");
    if (!have_types_) in_.fail_expected("a CELL_TYPES section after CELLS", "");
    if (!opt_.vtk_tag_array.empty() && !tag_found_)
      throw SemanticError(in_.source(), 0, "no CELL_DATA array named '" + opt_.vtk_tag_array + "' to use as cell tags");
    return std::move(out_);
  }

 private:
  void read_header() {
    const std::string_view first = in_.rest_of_line();
    const std::string l = lower(first);
    const std::string magic = "# vtk datafile version";
    if (l.compare(0, magic.size(), magic) != 0)
      in_.fail_expected("'# vtk DataFile Version x.y' (the first line of a legacy VTK file)", first);
    std::string v = l.substr(magic.size());
    v.erase(0, v.find_first_not_of(" \t"));
    v.erase(v.find_last_not_of(" \t\r") + 1);
    out_.version = v;
    const auto dot = v.find('.');
    const std::string major_s = v.substr(0, dot);
    if (major_s.empty() || major_s.size() > 3 || !std::all_of(major_s.begin(), major_s.end(), ::isdigit))
      in_.fail_expected("a version number after '# vtk DataFile Version'", v);
    major_ = std::stoi(major_s);
    if (major_ < 1 || major_ > 5)
      in_.fail_unsupported("legacy VTK file version " + v + " is not supported (Sewn reads 2.0 to 5.1)");
    (void)in_.rest_of_line();  // the title
    const std::string_view mode = in_.token("ASCII or BINARY");
    const std::string m = lower(mode);
    if (m == "binary") {
      binary_ = true;
    } else if (m != "ascii") {
      in_.fail_expected("ASCII or BINARY", mode);
    }
    const std::string_view ds = in_.token("DATASET");
    if (lower(ds) != "dataset") in_.fail_expected("DATASET", ds);
    const std::string_view kind = in_.token("a dataset type");
    if (lower(kind) != "unstructured_grid")
      in_.fail_unsupported("dataset type " + detail::printable(kind) + " is not supported (Sewn reads UNSTRUCTURED_GRID)");
    in_.end_line("the DATASET line");
  }

  DType read_dtype(const std::string& what) {
    const std::string_view t = in_.token("the data type of " + what);
    const std::string l = lower(t);
    if (l == "bit") in_.fail_unsupported("bit arrays are not supported (" + what + ")");
    const auto d = dtype_of(l);
    if (!d) in_.fail_expected("a VTK data type (int, float, double, ...) for " + what, t);
    return *d;
  }

  // Reads n values of type d. ASCII: one token each; BINARY: n big-endian items of d.bytes.
  Values read_values(std::uint64_t n, DType d, const std::string& what) {
    Values v;
    v.integral = d.kind != Kind::real;
    if (binary_) {
      in_.end_line(what + "'s header");
      if (n > in_.remaining() / d.bytes)
        throw ParseError(in_.source(), 0,
                         what + ": " + std::to_string(n) + " binary values of " + std::to_string(d.bytes) + " bytes",
                         "only " + std::to_string(in_.remaining()) + " bytes before the end of the file");
      const std::string_view raw = in_.raw(static_cast<std::size_t>(n * d.bytes), what);
      (v.integral ? v.ints.resize(n) : v.reals.resize(n));
      for (std::size_t i = 0; i < n; ++i) {
        std::uint64_t bits = 0;
        for (std::size_t b = 0; b < d.bytes; ++b) bits = (bits << 8) | static_cast<unsigned char>(raw[i * d.bytes + b]);
        if (d.kind == Kind::real) {
          if (d.bytes == 4) {
            v.reals[i] = static_cast<double>(std::bit_cast<float>(static_cast<std::uint32_t>(bits)));
          } else {
            v.reals[i] = std::bit_cast<double>(bits);
          }
        } else if (d.kind == Kind::signed_int) {
          const unsigned shift = static_cast<unsigned>(64 - 8 * d.bytes);
          v.ints[i] = shift == 0 ? static_cast<std::int64_t>(bits)
                                 : static_cast<std::int64_t>(bits << shift) >> shift;  // sign-extend
        } else {
          if (bits > static_cast<std::uint64_t>(INT64_MAX))
            throw SemanticError(in_.source(), 0, what + ": value " + std::to_string(bits) + " does not fit in 64 bits");
          v.ints[i] = static_cast<std::int64_t>(bits);
        }
      }
      return v;
    }
    const std::size_t r = detail::reservable(n, in_.remaining(), 2);
    if (v.integral) {
      v.ints.reserve(r);
      for (std::uint64_t i = 0; i < n; ++i) v.ints.push_back(in_.integer(what));
    } else {
      v.reals.reserve(r);
      for (std::uint64_t i = 0; i < n; ++i) v.reals.push_back(in_.real(what));
    }
    return v;
  }

  void read_points() {
    if (have_points_) in_.fail_semantic("a second POINTS section");
    have_points_ = true;
    const std::uint64_t n = in_.count("the number of points");
    const DType d = read_dtype("POINTS");
    if (d.kind != Kind::real) in_.fail_unsupported("integer point coordinates are not supported");
    const Values v = read_values(3 * n, d, "POINTS");
    out_.mesh.points.resize(n);
    for (std::size_t i = 0; i < n; ++i) {
      for (std::size_t k = 0; k < 3; ++k) {
        const double x = v.reals[3 * i + k];
        if (!std::isfinite(x))
          throw SemanticError(in_.source(), binary_ ? 0 : in_.line(),
                              "point " + std::to_string(i) + " has a non-finite coordinate");
        out_.mesh.points[i][k] = x;
      }
    }
  }

  void read_cells() {
    if (have_cells_) in_.fail_semantic("a second CELLS section");
    have_cells_ = true;
    cells_line_ = in_.line();
    const std::uint64_t a = in_.count("the number of cells", std::uint64_t{1} << 40);
    const std::uint64_t b = in_.count("the size of the cell list", std::uint64_t{1} << 40);
    if (major_ >= 5) {
      // CELLS <offsets> <connectivity>, then OFFSETS <type> ..., CONNECTIVITY <type> ...
      in_.end_line("the CELLS line");
      const std::string_view o = in_.token("OFFSETS");
      if (lower(o) != "offsets") in_.fail_expected("OFFSETS", o);
      const DType od = read_dtype("OFFSETS");
      if (od.kind == Kind::real) in_.fail_expected("an integer type for OFFSETS", "a real type");
      const Values off = read_values(a, od, "OFFSETS");
      const std::string_view c = in_.token("CONNECTIVITY");
      if (lower(c) != "connectivity") in_.fail_expected("CONNECTIVITY", c);
      const DType cd = read_dtype("CONNECTIVITY");
      if (cd.kind == Kind::real) in_.fail_expected("an integer type for CONNECTIVITY", "a real type");
      const Values conn = read_values(b, cd, "CONNECTIVITY");
      if (a == 0) {
        if (b != 0) in_.fail_semantic("CONNECTIVITY has entries but OFFSETS is empty");
        return;
      }
      if (off.ints[0] != 0) in_.fail_semantic("OFFSETS must start at 0, not " + std::to_string(off.ints[0]));
      for (std::size_t i = 0; i + 1 < a; ++i)
        if (off.ints[i + 1] < off.ints[i] || off.ints[i + 1] > static_cast<std::int64_t>(b))
          in_.fail_semantic("OFFSETS of cell " + std::to_string(i) + " (" + std::to_string(off.ints[i]) + ".." +
                            std::to_string(off.ints[i + 1]) + ") is not an increasing range within the " +
                            std::to_string(b) + " CONNECTIVITY entries");
      if (off.ints[a - 1] != static_cast<std::int64_t>(b))
        in_.fail_semantic("the last OFFSET is " + std::to_string(off.ints[a - 1]) + " but CONNECTIVITY has " +
                          std::to_string(b) + " entries");
      raw_off_ = off.ints;
      raw_conn_ = conn.ints;
      return;
    }
    // CELLS <cells> <size>, then per cell: <n> <id> ... (size integers in all)
    const Values list = read_values(b, DType{Kind::signed_int, 4}, "CELLS");
    if (a > b) in_.fail_semantic("CELLS declares " + std::to_string(a) + " cells in a list of only " + std::to_string(b) + " integers");
    raw_off_.assign(1, 0);
    raw_off_.reserve(static_cast<std::size_t>(a) + 1);
    raw_conn_.reserve(static_cast<std::size_t>(b - a));
    std::size_t pos = 0;
    for (std::size_t i = 0; i < a; ++i) {
      if (pos >= list.ints.size())
        in_.fail_semantic("CELLS declares " + std::to_string(a) + " cells but its " + std::to_string(b) +
                          " integers end within cell " + std::to_string(i));
      const std::int64_t np = list.ints[pos++];
      if (np < 0 || static_cast<std::uint64_t>(np) > list.ints.size() - pos)
        in_.fail_semantic("cell " + std::to_string(i) + " declares " + std::to_string(np) +
                          " points, more than the CELLS list has left");
      raw_conn_.insert(raw_conn_.end(), list.ints.begin() + static_cast<std::ptrdiff_t>(pos),
                       list.ints.begin() + static_cast<std::ptrdiff_t>(pos + static_cast<std::size_t>(np)));
      raw_off_.push_back(static_cast<std::int64_t>(raw_conn_.size()));
      pos += static_cast<std::size_t>(np);
    }
    if (pos != list.ints.size())
      in_.fail_semantic("CELLS declares a list of " + std::to_string(b) + " integers but its " + std::to_string(a) +
                        " cells use " + std::to_string(pos));
  }

  void read_cell_types() {
    if (!have_cells_) in_.fail_expected("CELLS before CELL_TYPES", "CELL_TYPES");
    if (have_types_) in_.fail_semantic("a second CELL_TYPES section");
    have_types_ = true;
    const std::size_t types_line = in_.line();
    const std::uint64_t n = in_.count("the number of cell types", std::uint64_t{1} << 40);
    const std::size_t ncells = raw_off_.empty() ? 0 : raw_off_.size() - 1;
    if (n != ncells)
      in_.fail_semantic("CELL_TYPES lists " + std::to_string(n) + " cells but CELLS has " + std::to_string(ncells));
    const Values t = read_values(n, DType{Kind::signed_int, 4}, "CELL_TYPES");
    out_.file_elements = n;
    file_to_mesh_.assign(n, -1);
    for (std::size_t i = 0; i < n; ++i) {
      const std::int64_t type = t.ints[i];
      const std::span<const std::int64_t> pts(raw_conn_.data() + raw_off_[i],
                                              static_cast<std::size_t>(raw_off_[i + 1] - raw_off_[i]));
      const std::string name = "cell " + std::to_string(i);
      if (type == 1 || type == 2) {  // vertex, poly-vertex: not a simulated element
        ++out_.skipped_points;
        continue;
      }
      const auto ct = vtk_cell_type(type);
      if (!ct) {
        if ((type >= 4 && type <= 7) || (type >= 15 && type <= 100))
          in_.fail_unsupported(name + " has VTK type " + std::to_string(type) +
                                   ", which Sewn does not read (linear types 3, 5, 8-14 only)",
                               types_line);
        in_.fail_semantic(name + " has unknown VTK cell type " + std::to_string(type), types_line);
      }
      if (pts.size() != static_cast<std::size_t>(ct->points))
        in_.fail_semantic(name + " is a " + to_string(ct->type) + " (VTK type " + std::to_string(type) + ") but lists " +
                          std::to_string(pts.size()) + " points instead of " + std::to_string(ct->points),
                          cells_line_);
      std::array<std::uint32_t, 8> v{};
      for (std::size_t k = 0; k < pts.size(); ++k) {
        const std::int64_t p = pts[ct->order[k]];
        if (p < 0 || static_cast<std::uint64_t>(p) >= out_.mesh.points.size())
          in_.fail_semantic(name + " refers to point " + std::to_string(p) + " but there are " +
                                std::to_string(out_.mesh.points.size()) + " points",
                            cells_line_);
        v[k] = static_cast<std::uint32_t>(p);
        for (std::size_t l = 0; l < k; ++l)
          if (v[l] == v[k]) in_.fail_semantic(name + " uses point " + std::to_string(p) + " twice", cells_line_);
      }
      file_to_mesh_[i] = static_cast<std::int64_t>(
          out_.mesh.add_cell(ct->type, std::span<const std::uint32_t>(v.data(), pts.size())));
    }
    raw_off_ = {};
    raw_conn_ = {};
  }

  // POINT_DATA / CELL_DATA: attribute arrays until the next dataset keyword.
  void read_attributes(bool cells) {
    const std::string section = cells ? "CELL_DATA" : "POINT_DATA";
    const std::uint64_t n = in_.count("the number of " + std::string(cells ? "cells" : "points") + " in " + section,
                                      std::uint64_t{1} << 40);
    if (cells && (!have_types_ || n != file_to_mesh_.size()))
      in_.fail_semantic("CELL_DATA is for " + std::to_string(n) + " cells but the grid has " +
                        std::to_string(file_to_mesh_.size()));
    if (!cells && (!have_points_ || n != out_.mesh.points.size()))
      in_.fail_semantic("POINT_DATA is for " + std::to_string(n) + " points but the grid has " +
                        std::to_string(out_.mesh.points.size()));
    while (const auto next = in_.peek()) {
      const std::string k = lower(*next);
      if (k == "points" || k == "cells" || k == "cell_types" || k == "cell_data" || k == "point_data") return;
      (void)in_.token("an attribute keyword");
      if (k == "scalars") {
        const std::string name(in_.token("the name of a SCALARS array"));
        const DType d = read_dtype("SCALARS " + name);
        std::uint64_t comps = 1;
        if (in_.peek_on_line()) {
          comps = in_.count("the number of components of SCALARS " + name, 4);
          if (comps == 0) in_.fail_semantic("SCALARS " + name + " has 0 components");
        }
        in_.end_line("SCALARS " + name);
        // The format requires a LOOKUP_TABLE line; in ASCII files a missing one is tolerated.
        if (binary_ || (in_.peek() && lower(*in_.peek()) == "lookup_table")) {
          const std::string_view lt = in_.token("LOOKUP_TABLE");
          if (lower(lt) != "lookup_table") in_.fail_expected("LOOKUP_TABLE after SCALARS " + name, lt);
          (void)in_.token("the name of a lookup table");
        }
        const Values v = read_values(n * comps, d, "SCALARS " + name);
        if (cells && comps == 1) consider_tag(name, v);
      } else if (k == "color_scalars") {
        const std::string name(in_.token("the name of a COLOR_SCALARS array"));
        const std::uint64_t m = in_.count("the number of values of COLOR_SCALARS " + name, 4);
        (void)read_values(n * m, binary_ ? DType{Kind::unsigned_int, 1} : DType{Kind::real, 4}, "COLOR_SCALARS " + name);
      } else if (k == "lookup_table") {
        (void)in_.token("the name of a LOOKUP_TABLE");
        const std::uint64_t m = in_.count("the size of a LOOKUP_TABLE");
        (void)read_values(4 * m, binary_ ? DType{Kind::unsigned_int, 1} : DType{Kind::real, 4}, "LOOKUP_TABLE");
      } else if (k == "vectors" || k == "normals" || k == "tensors" || k == "tensors6") {
        const std::string name(in_.token("the name of an attribute array"));
        const DType d = read_dtype(k + " " + name);
        const std::uint64_t comps = k == "tensors" ? 9 : k == "tensors6" ? 6 : 3;
        (void)read_values(n * comps, d, name);
      } else if (k == "texture_coordinates") {
        const std::string name(in_.token("the name of a TEXTURE_COORDINATES array"));
        const std::uint64_t dim = in_.count("the dimension of TEXTURE_COORDINATES " + name, 3);
        const DType d = read_dtype("TEXTURE_COORDINATES " + name);
        (void)read_values(n * dim, d, name);
      } else if (k == "global_ids" || k == "pedigree_ids") {
        const std::string name(in_.token("the name of an id array"));
        const DType d = read_dtype(name);
        (void)read_values(n, d, name);
      } else if (k == "field") {
        read_field(cells ? n : 0, cells);
      } else if (k == "metadata") {
        skip_metadata();
      } else {
        in_.fail_expected("an attribute keyword (SCALARS, VECTORS, FIELD, ...) in " + section, *next);
      }
    }
  }

  void skip_field() { read_field(0, false); }

  // FIELD <name> <arrays>, each "<name> <components> <tuples> <type>" then its values.
  void read_field(std::uint64_t cells, bool cell_data) {
    (void)in_.token("the name of a FIELD");
    const std::uint64_t arrays = in_.count("the number of FIELD arrays");
    for (std::uint64_t i = 0; i < arrays; ++i) {
      const std::string name(in_.token("the name of a FIELD array"));
      if (name == "NULL_ARRAY") continue;
      const std::uint64_t comps = in_.count("the number of components of " + name, 1u << 16);
      const std::uint64_t tuples = in_.count("the number of tuples of " + name, std::uint64_t{1} << 40);
      if (tuples != 0 && comps > (std::uint64_t{1} << 48) / tuples) in_.fail_semantic(name + " is too large");
      if (const auto t = in_.peek(); t && (lower(*t) == "string" || lower(*t) == "utf8_string")) {
        (void)in_.token("the data type of " + name);
        skip_strings(comps * tuples, name);
      } else {
        const DType d = read_dtype(name);
        const Values v = read_values(comps * tuples, d, name);
        if (cell_data && comps == 1 && tuples == cells) consider_tag(name, v);
      }
      if (const auto t = in_.peek(); t && lower(*t) == "metadata") {
        (void)in_.token("METADATA");
        skip_metadata();
      }
    }
  }

  // A string array (VTK writes them in FIELD data: a file's notes, ParaView's names). ASCII: one
  // percent-encoded string per line, possibly empty. BINARY: each string's length in 1, 2, 4 or
  // 8 big-endian bytes whose top two bits say which (11, 10, 01, 00), then its bytes.
  void skip_strings(std::uint64_t n, const std::string& name) {
    in_.end_line(name + "'s header");
    for (std::uint64_t i = 0; i < n; ++i) {
      if (in_.remaining() == 0) in_.fail_expected_here("string " + std::to_string(i) + " of " + std::to_string(n) + " of " + name);
      if (!binary_) {
        (void)in_.rest_of_line();
        continue;
      }
      const auto first = static_cast<unsigned char>(in_.raw(1, "the length of a string of " + name)[0]);
      const std::size_t bytes = std::size_t{1} << (3 - (first >> 6));  // 11: 1, 10: 2, 01: 4, 00: 8
      std::uint64_t length = first & 0x3fu;
      if (bytes > 1)
        for (const char c : in_.raw(bytes - 1, "the length of a string of " + name)) length = (length << 8) | static_cast<unsigned char>(c);
      if (length > in_.remaining())
        in_.fail_semantic("string " + std::to_string(i) + " of " + name + " is " + std::to_string(length) + " bytes long, past the end of the file");
      (void)in_.raw(static_cast<std::size_t>(length), "a string of " + name);
    }
  }

  // METADATA blocks (component names, information keys) end at an empty line.
  void skip_metadata() {
    (void)in_.rest_of_line();
    while (in_.remaining() > 0) {
      const std::string_view l = in_.rest_of_line();
      if (l.find_first_not_of(" \t\r") == std::string_view::npos) return;
    }
  }

  void consider_tag(const std::string& name, const Values& v) {
    if (tag_found_) return;
    if (opt_.vtk_tag_array.empty() ? !v.integral : name != opt_.vtk_tag_array) return;
    tag_found_ = true;
    for (std::size_t i = 0; i < file_to_mesh_.size(); ++i) {
      if (file_to_mesh_[i] < 0) continue;
      std::int64_t t = 0;
      if (v.integral) {
        t = v.ints[i];
      } else {
        const double x = v.reals[i];
        if (!(std::floor(x) == x) || std::abs(x) > 2147483647.0)
          in_.fail_semantic("cell tag array '" + name + "' holds " + std::to_string(x) + " for cell " + std::to_string(i) +
                            ", not an integer");
        t = static_cast<std::int64_t>(x);
      }
      out_.mesh.tags[static_cast<std::size_t>(file_to_mesh_[i])] =
          detail::to_tag(in_, t, "the tag of cell " + std::to_string(i) + " in '" + name + "'");
    }
  }

  Cursor in_;
  const ReadOptions& opt_;
  MeshFile out_;
  int major_ = 0;
  bool binary_ = false;
  bool have_points_ = false;
  bool have_cells_ = false;
  bool have_types_ = false;
  bool tag_found_ = false;
  std::size_t cells_line_ = 0;  // problems found in a cell's point list are reported here
  std::vector<std::int64_t> raw_off_;   // CELLS as read: offsets into raw_conn_
  std::vector<std::int64_t> raw_conn_;
  std::vector<std::int64_t> file_to_mesh_;  // file cell -> mesh cell, -1 when skipped
};

}  // namespace

MeshFile parse_vtk(std::string_view bytes, const std::string& source, const ReadOptions& opt) {
  return VtkReader(bytes, source, opt).run();
}

MeshFile read_vtk(const std::filesystem::path& path, const ReadOptions& opt) {
  const std::string bytes = detail::slurp(path);
  return parse_vtk(bytes, path.string(), opt);
}

}  // namespace sewn::io
