// Gmsh MSH reader, versions 2.x and 4.1, ASCII and binary (Gmsh reference manual, "MSH file
// format").

#include <algorithm>
#include <array>
#include <bit>
#include <charconv>
#include <cstring>
#include <map>
#include <limits>
#include <optional>
#include <set>
#include <unordered_map>
#include <tuple>
#include <vector>

#include "cursor.hpp"
#include "read_common.hpp"
#include "sewn/io/read.hpp"

namespace sewn::io {

namespace {

using detail::Cursor;

constexpr int gmsh_point = 15;

struct GmshType {
  CellType type;
  int nodes;
};

// Linear types only; the point type is handled apart because it is skipped.
std::optional<GmshType> linear_type(std::int64_t t) {
  switch (t) {
    case 1: return GmshType{CellType::segment, 2};
    case 2: return GmshType{CellType::triangle, 3};
    case 3: return GmshType{CellType::quad, 4};
    case 4: return GmshType{CellType::tetrahedron, 4};
    case 5: return GmshType{CellType::hexahedron, 8};
    case 6: return GmshType{CellType::prism, 6};
    case 7: return GmshType{CellType::pyramid, 5};
    default: return std::nullopt;
  }
}

// Gmsh numbers element types up to 140 or so; those it defines beyond the linear ones are
// higher-order or special (polygons, trihedra), which Sewn does not model: a clear "unsupported"
// beats "unknown" for them.
const char* higher_order_name(std::int64_t t) {
  switch (t) {
    case 8: return "3-node second-order line";
    case 9: return "6-node second-order triangle";
    case 10: return "9-node second-order quadrangle";
    case 11: return "10-node second-order tetrahedron";
    case 12: return "27-node second-order hexahedron";
    case 13: return "18-node second-order prism";
    case 14: return "14-node second-order pyramid";
    case 16: return "8-node second-order quadrangle";
    case 17: return "20-node second-order hexahedron";
    case 18: return "15-node second-order prism";
    case 19: return "13-node second-order pyramid";
    default: return t >= 20 && t <= 140 ? "higher-order or special" : nullptr;
  }
}

// Gmsh's prism has its first triangle (0,1,2) turning towards the second (u × v = w); VTK's
// wedge has it turning away (vtkWedge: "normal points outward"). Hexahedra, pyramids,
// tetrahedra and the 2D types number their vertices identically in both.
constexpr std::array<std::uint32_t, 6> prism_to_vtk{0, 2, 1, 3, 5, 4};

// The values of a section's data: tokens in an ASCII file; in a binary one fixed-width fields
// in the writer's byte order (a C int of 4 bytes, a size_t of the header's data size, a double
// of 8), with the section headers and $PhysicalNames still text. The reader's grammar is
// written once against these calls: the two encodings lay out the same values in the same
// order, except MSH 2's binary $Elements (read_elements2_binary).
class MshData {
 public:
  explicit MshData(Cursor& in) : in_(in) {}

  void set_binary(int size_bytes, bool swap, bool v4) {
    binary_ = true;
    size_bytes_ = size_bytes;
    swap_ = swap;
    v4_ = v4;
  }
  [[nodiscard]] bool binary() const { return binary_; }

  /// A C int.
  std::int64_t integer(std::string_view what) { return binary_ ? fixed<std::int32_t>(what) : in_.integer(what); }
  /// A size_t (node and element tag ranges).
  std::int64_t size(std::string_view what) {
    if (!binary_) return in_.integer(what);
    const std::uint64_t v = size_bytes_ == 4 ? fixed<std::uint32_t>(what) : fixed<std::uint64_t>(what);
    if (v > static_cast<std::uint64_t>(std::numeric_limits<std::int64_t>::max()))
      in_.fail_semantic(std::string(what) + " " + std::to_string(v) + " does not fit in 63 bits");
    return static_cast<std::int64_t>(v);
  }
  /// A node or element tag: a size_t in MSH 4.1, an int in MSH 2.
  std::int64_t tag(std::string_view what) { return v4_ ? size(what) : integer(what); }
  /// A count (a size_t in binary) no larger than max.
  std::uint64_t count(std::string_view what, std::uint64_t max = std::numeric_limits<std::uint32_t>::max()) {
    if (!binary_) return in_.count(what, max);
    const auto v = static_cast<std::uint64_t>(size(what));
    if (v > max) in_.fail_semantic(std::string(what) + " " + std::to_string(v) + " is larger than " + std::to_string(max));
    return v;
  }
  double real(std::string_view what) { return binary_ ? fixed<double>(what) : in_.real(what); }
  /// The end of a record's line in an ASCII file; nothing in a binary one.
  void end_line(std::string_view after) {
    if (!binary_) in_.end_line(after);
  }
  [[noreturn]] void fail_semantic(const std::string& reason) const { in_.fail_semantic(reason); }

 private:
  template <class T>
  T fixed(std::string_view what) {
    const std::string_view bytes = in_.raw(sizeof(T), what);
    std::array<unsigned char, sizeof(T)> b{};
    std::memcpy(b.data(), bytes.data(), sizeof(T));
    if (swap_) std::reverse(b.begin(), b.end());
    return std::bit_cast<T>(b);
  }

  Cursor& in_;
  bool binary_ = false;
  bool swap_ = false;
  bool v4_ = false;
  int size_bytes_ = 8;
};

class GmshReader {
 public:
  GmshReader(std::string_view text, const std::string& source) : in_(text, source) {}

  MeshFile run() {
    out_.format = MeshFormat::gmsh;
    read_header();
    while (!in_.at_end()) {
      const std::string_view name = in_.token("a section header such as $Nodes");
      if (name.empty() || name[0] != '$') in_.fail_expected("a section header such as $Nodes", name);
      const std::size_t line = in_.line();
      // MSH 4.1 binary: the data of these sections starts on the line after the header
      if (data_.binary() && v4_ && (name == "$Entities" || name == "$Nodes" || name == "$Elements"))
        in_.end_line(std::string(name));
      if (name == "$PhysicalNames") {
        read_physical_names();
        in_.expect("$EndPhysicalNames");
      } else if (name == "$Entities" && v4_) {
        read_entities();
        in_.expect("$EndEntities");
      } else if (name == "$PartitionedEntities") {
        in_.fail_unsupported("partitioned meshes ($PartitionedEntities) are not supported; save the mesh unpartitioned");
      } else if (name == "$Nodes") {
        if (have_nodes_) in_.fail_semantic("a second $Nodes section");
        v4_ ? read_nodes4() : read_nodes2();
        have_nodes_ = true;
      } else if (name == "$Elements") {
        if (have_elements_) in_.fail_semantic("a second $Elements section");
        if (!have_nodes_) in_.fail_expected("the $Nodes section before $Elements", name);
        v4_ ? read_elements4() : read_elements2();
        have_elements_ = true;
      } else {
        skip_section(name, line);
      }
    }
    if (!have_nodes_) in_.fail_expected("a $Nodes section", "");
    if (!have_elements_) in_.fail_expected("an $Elements section", "");
    if (!v4_) merge_group_repeats();
    if (have_entities_) warn_unsaved_entities();
    return std::move(out_);
  }

 private:
  void read_header() {
    const std::string_view first = in_.token("'$MeshFormat'");
    if (first == "$NOD" || first == "$NOE")
      in_.fail_unsupported("MSH version 1 is not supported; re-export the mesh as MSH 4.1 or 2.2");
    if (first != "$MeshFormat") in_.fail_expected("'$MeshFormat' (the first line of a Gmsh .msh file)", first);
    const std::string_view version = in_.token("the MSH version number");
    out_.version = std::string(version);
    if (version == "4.1") {
      v4_ = true;
    } else if (version == "2" || version == "2.0" || version == "2.1" || version == "2.2") {
      v4_ = false;
    } else {
      double number = 0;
      const auto [end, ec] = std::from_chars(version.data(), version.data() + version.size(), number);
      if (ec != std::errc() || end != version.data() + version.size())
        in_.fail_expected("the MSH version number", version);
      in_.fail_unsupported("MSH version " + detail::printable(version) +
                           " is not supported (Sewn reads 2.2 and 4.1); re-export with -format msh41 or msh22");
    }
    const std::int64_t file_type = in_.integer("the MSH file type (0 = ASCII, 1 = binary)");
    if (file_type != 0 && file_type != 1) in_.fail_expected("the MSH file type 0 (ASCII) or 1 (binary)", std::to_string(file_type));
    const std::int64_t data_size = in_.integer("the MSH data size");
    in_.end_line("the MSH format line");
    if (file_type == 1) read_byte_order(data_size);
    in_.expect("$EndMeshFormat");
  }

  // A binary file's header line is followed by the int 1 in the writer's byte order.
  void read_byte_order(std::int64_t data_size) {
    if (data_size != 4 && data_size != 8)
      in_.fail_unsupported("a binary MSH file with data size " + std::to_string(data_size) + " (Sewn reads size_t of 4 or 8 bytes)");
    const std::string_view one = in_.raw(4, "the binary MSH file's integer 1 (its byte order)");
    std::int32_t native = 0;
    std::memcpy(&native, one.data(), 4);
    if (native != 1 && native != 0x01000000)
      in_.fail_semantic("the binary MSH file's byte-order check reads " + std::to_string(native) + ", not 1 in either byte order");
    data_.set_binary(static_cast<int>(data_size), native != 1, v4_);
  }

  // Sections Sewn does not use ($NodeData, $Periodic, $Comments, ...) are passed over whole.
  void skip_section(std::string_view name, std::size_t line) {
    const std::string end = std::string("$End") + std::string(name.substr(1));
    in_.skip_line();
    while (!in_.at_end()) {
      const std::string_view l = in_.rest_of_line();
      const auto b = l.find_first_not_of(" \t");
      if (b != std::string_view::npos && l.substr(b, end.size()) == end &&
          l.find_first_not_of(" \t\r", b + end.size()) == std::string_view::npos)
        return;
    }
    in_.fail_expected("'" + end + "' closing the section opened on line " + std::to_string(line), "");
  }

  void read_physical_names() {
    const std::uint64_t n = in_.count("the number of physical names");
    in_.end_line("the number of physical names");
    for (std::uint64_t i = 0; i < n; ++i) {
      TagName t;
      const std::int64_t dim = in_.integer("the dimension of a physical name");
      if (dim < 0 || dim > 3) in_.fail_semantic("physical name dimension " + std::to_string(dim) + " is not 0..3");
      t.dimension = static_cast<int>(dim);
      t.tag = detail::to_tag(in_, in_.integer("a physical tag"), "physical tag");
      std::string_view rest = in_.rest_of_line();
      const auto a = rest.find('"');
      const auto b = rest.rfind('"');
      if (a == std::string_view::npos || b == a) in_.fail_expected("a physical name in double quotes", rest);
      t.name = std::string(rest.substr(a + 1, b - a - 1));
      out_.tag_names.push_back(std::move(t));
    }
  }

  // Once a physical group is defined, Gmsh saves only the elements of physical groups (unless
  // Mesh.SaveAll = 1): a volume left out of every Physical Volume vanishes from the file, and a
  // solid meshed with -3 but given only boundary groups arrives as a few loose surfaces. The
  // entities of the top dimension that are in no group and have no elements say so.
  void warn_unsaved_entities() {
    const bool grouped = std::any_of(entity_phys_.begin(), entity_phys_.end(), [](const auto& e) { return e.second != 0; });
    int top = -1;
    for (const auto& e : entity_phys_) top = std::max(top, e.first.first);
    if (!grouped || top < 1) return;
    std::vector<std::int64_t> unsaved;
    for (const auto& e : entity_phys_)
      if (e.first.first == top && e.second == 0 && !entity_with_elements_.count(e.first)) unsaved.push_back(e.first.second);
    if (unsaved.empty()) return;
    static const char* kinds[] = {"", "curve", "surface", "volume"};
    static const char* groups[] = {"", "Physical Curve", "Physical Surface", "Physical Volume"};
    const bool one = unsaved.size() == 1;
    std::string list;
    for (std::size_t i = 0; i < unsaved.size() && i < 5; ++i) list += (i > 0 ? ", " : "") + std::to_string(unsaved[i]);
    if (unsaved.size() > 5) list += ", ...";
    out_.warnings.push_back(in_.source() + ": Gmsh saved only the elements of physical groups, and " + kinds[top] + (one ? " " : "s ") +
                            list + " of the geometry " + (one ? "belongs to none: its elements, if it was" : "belong to none: their elements, if they were") +
                            " meshed, are not in the file. Add " + (one ? "it" : "them") + " to a " + groups[top] +
                            ", or save with Mesh.SaveAll = 1");
  }

  // Physical tags per entity, so that 4.1 element blocks can be tagged.
  void read_entities() {
    std::array<std::uint64_t, 4> n{};
    for (auto& c : n) c = data_.count("the number of entities of each dimension");
    data_.end_line("the entity counts");
    have_entities_ = true;
    for (int dim = 0; dim < 4; ++dim) {
      for (std::uint64_t i = 0; i < n[static_cast<std::size_t>(dim)]; ++i) {
        const std::int64_t tag = data_.integer("an entity tag");
        const int reals = dim == 0 ? 3 : 6;  // a point's coordinates or a bounding box
        for (int k = 0; k < reals; ++k) (void)data_.real("an entity coordinate");
        const std::uint64_t nphys = data_.count("the number of physical tags of an entity");
        std::int32_t phys = 0;
        for (std::uint64_t k = 0; k < nphys; ++k) {
          const std::int32_t p = detail::to_tag(in_, data_.integer("a physical tag"), "physical tag");
          if (k == 0) phys = p;
        }
        if (dim > 0) {
          const std::uint64_t nb = data_.count("the number of bounding entities");
          for (std::uint64_t k = 0; k < nb; ++k) (void)data_.integer("a bounding entity tag");
        }
        data_.end_line("entity " + std::to_string(tag));
        if (!entity_phys_.emplace(std::make_pair(dim, tag), phys).second)
          in_.fail_semantic("entity " + std::to_string(tag) + " of dimension " + std::to_string(dim) + " is declared twice");
      }
    }
  }

  void read_nodes2() {
    const std::uint64_t n = in_.count("the number of nodes");
    in_.end_line("the number of nodes");  // text in binary files too
    out_.mesh.points.reserve(detail::reservable(n, in_.remaining(), 8));
    node_index_.reserve(detail::reservable(n, in_.remaining(), 8));
    for (std::uint64_t i = 0; i < n; ++i) {
      const std::int64_t tag = data_.tag("a node number (node " + std::to_string(i + 1) + " of " + std::to_string(n) + ")");
      const std::string name = "node " + std::to_string(tag);
      if (!node_index_.emplace(tag, out_.mesh.num_points()).second) in_.fail_semantic(name + " is defined twice");
      out_.mesh.points.push_back(detail::read_point(data_, 3, name));
      out_.node_tags.push_back(tag);
      data_.end_line(name + "'s coordinates");
    }
    expect_end("$EndNodes", std::to_string(n) + " nodes");
  }

  void read_nodes4() {
    const std::uint64_t blocks = data_.count("the number of node blocks");
    const std::uint64_t n = data_.count("the number of nodes");
    const std::int64_t min_tag = data_.size("the smallest node tag");
    const std::int64_t max_tag = data_.size("the largest node tag");
    data_.end_line("the $Nodes header");
    out_.mesh.points.reserve(detail::reservable(n, in_.remaining(), 8));
    node_index_.reserve(detail::reservable(n, in_.remaining(), 8));
    std::vector<std::int64_t> tags;
    for (std::uint64_t b = 0; b < blocks; ++b) {
      const std::int64_t dim = data_.integer("the entity dimension of a node block");
      if (dim < 0 || dim > 3) in_.fail_semantic("node block entity dimension " + std::to_string(dim) + " is not 0..3");
      (void)data_.integer("the entity tag of a node block");
      const std::int64_t parametric = data_.integer("the parametric flag of a node block (0 or 1)");
      if (parametric != 0 && parametric != 1) in_.fail_expected("the parametric flag 0 or 1", std::to_string(parametric));
      const std::uint64_t m = data_.count("the number of nodes in a block");
      data_.end_line("the node block header");
      if (out_.mesh.points.size() + m > n)
        in_.fail_semantic("node blocks hold more nodes than the " + std::to_string(n) + " the $Nodes header declares");
      tags.clear();
      tags.reserve(detail::reservable(m, in_.remaining(), 2));
      for (std::uint64_t i = 0; i < m; ++i) {
        const std::int64_t tag = data_.tag("a node tag");
        if (tag < min_tag || tag > max_tag)
          in_.fail_semantic("node tag " + std::to_string(tag) + " is outside the range " + std::to_string(min_tag) +
                            ".." + std::to_string(max_tag) + " the $Nodes header declares");
        data_.end_line("node tag " + std::to_string(tag));
        tags.push_back(tag);
      }
      for (const std::int64_t tag : tags) {
        const std::string name = "node " + std::to_string(tag);
        if (!node_index_.emplace(tag, out_.mesh.num_points()).second) in_.fail_semantic(name + " is defined twice");
        out_.mesh.points.push_back(detail::read_point(data_, 3, name));
        out_.node_tags.push_back(tag);
        for (std::int64_t k = 0; k < dim * parametric; ++k) (void)data_.real("a parametric coordinate of " + name);
        data_.end_line(name + "'s coordinates");
      }
    }
    if (out_.mesh.points.size() != n)
      in_.fail_semantic("the $Nodes header declares " + std::to_string(n) + " nodes but its blocks hold " +
                        std::to_string(out_.mesh.points.size()));
    expect_end("$EndNodes", std::to_string(blocks) + " node blocks");
  }

  // Reads an element's node tags, checks them and appends the cell (VTK order).
  void add_element(std::int64_t id, std::int64_t type, std::int32_t tag, std::int64_t entity, int dim) {
    const std::string name = "element " + std::to_string(id);
    if (type == gmsh_point) {
      (void)node_of(data_.tag("the node of point " + name), name);
      ++out_.skipped_points;
      data_.end_line(name);
      return;
    }
    const auto gt = linear_type(type);
    check_type(type, name);
    std::array<std::uint32_t, 8> v{};
    std::array<std::int64_t, 8> tags{};
    for (std::size_t k = 0; k < static_cast<std::size_t>(gt->nodes); ++k) {
      tags[k] = data_.tag("node " + std::to_string(k + 1) + " of " + name);
      v[k] = node_of(tags[k], name);
      for (std::size_t l = 0; l < k; ++l)
        if (tags[l] == tags[k]) in_.fail_semantic(name + " uses node " + std::to_string(tags[k]) + " twice");
    }
    data_.end_line(name + " (a " + std::string(to_string(gt->type)) + " has " + std::to_string(gt->nodes) + " nodes)");
    if (gt->type == CellType::prism) {
      const auto g = v;
      for (std::size_t k = 0; k < 6; ++k) v[k] = g[prism_to_vtk[k]];
    }
    out_.mesh.add_cell(gt->type, std::span<const std::uint32_t>(v.data(), static_cast<std::size_t>(gt->nodes)), tag);
    entity_.push_back({dim, entity});
    out_.element_tags.push_back(id);
  }

  void check_type(std::int64_t type, const std::string& name) {
    if (linear_type(type) || type == gmsh_point) return;
    if (const char* ho = higher_order_name(type))
      in_.fail_unsupported(name + " has Gmsh type " + std::to_string(type) + " (" + ho +
                           "); Sewn reads linear elements only: mesh with Mesh.ElementOrder = 1");
    in_.fail_semantic(name + " has unknown Gmsh element type " + std::to_string(type));
  }

  std::uint32_t node_of(std::int64_t tag, const std::string& element) {
    const auto it = node_index_.find(tag);
    if (it == node_index_.end())
      in_.fail_semantic(element + " refers to node " + std::to_string(tag) + ", which $Nodes does not define");
    return it->second;
  }

  void read_elements2() {
    const std::uint64_t n = in_.count("the number of elements");
    in_.end_line("the number of elements");
    out_.file_elements = n;
    reserve_cells(n, 10);
    if (data_.binary()) {
      read_elements2_binary(n);
      return;
    }
    for (std::uint64_t i = 0; i < n; ++i) {
      const std::int64_t id = in_.integer("an element number (element " + std::to_string(i + 1) + " of " + std::to_string(n) + ")");
      const std::string name = "element " + std::to_string(id);
      const std::int64_t type = in_.integer("the type of " + name);
      check_type(type, name);
      const std::uint64_t ntags = in_.count("the number of tags of " + name);
      std::int32_t phys = 0;
      std::int64_t entity = 0;
      for (std::uint64_t k = 0; k < ntags; ++k) {
        const std::int64_t t = in_.integer("a tag of " + name);
        if (k == 0) phys = detail::to_tag(in_, t, "the physical tag of " + name);
        if (k == 1) entity = t;
      }
      add_element(id, type, phys, entity, type == gmsh_point ? 0 : cell_dimension(linear_type(type)->type));
    }
    expect_end("$EndElements", std::to_string(n) + " elements");
  }
  // MSH 2 binary: groups of elements of one type and tag count, each group after a header of
  // three ints (type, elements in the group, tags per element); an element is its number, its
  // tags, its nodes, all ints.
  void read_elements2_binary(std::uint64_t n) {
    std::uint64_t seen = 0;
    while (seen < n) {
      const std::int64_t type = data_.integer("the element type of a binary element group");
      check_type(type, "a binary element group");
      const std::int64_t m = data_.integer("the number of elements in a binary element group");
      const std::int64_t ntags = data_.integer("the number of tags of a binary element group");
      if (m <= 0 || static_cast<std::uint64_t>(m) > n - seen)
        data_.fail_semantic("a binary element group of " + std::to_string(m) + " elements after " + std::to_string(seen) +
                            " of the " + std::to_string(n) + " the $Elements header declares");
      if (ntags < 0 || ntags > 64) data_.fail_semantic("a binary element group with " + std::to_string(ntags) + " tags per element");
      for (std::int64_t i = 0; i < m; ++i) {
        const std::int64_t id = data_.integer("an element number");
        std::int32_t phys = 0;
        std::int64_t entity = 0;
        for (std::int64_t k = 0; k < ntags; ++k) {
          const std::int64_t t = data_.integer("a tag of element " + std::to_string(id));
          if (k == 0) phys = detail::to_tag(in_, t, "the physical tag of element " + std::to_string(id));
          if (k == 1) entity = t;
        }
        add_element(id, type, phys, entity, type == gmsh_point ? 0 : cell_dimension(linear_type(type)->type));
      }
      seen += static_cast<std::uint64_t>(m);
    }
    expect_end("$EndElements", std::to_string(n) + " elements");
  }


  void read_elements4() {
    const std::uint64_t blocks = data_.count("the number of element blocks");
    const std::uint64_t n = data_.count("the number of elements");
    (void)data_.size("the smallest element tag");
    (void)data_.size("the largest element tag");
    data_.end_line("the $Elements header");
    out_.file_elements = n;
    reserve_cells(n, 6);
    std::uint64_t seen = 0;
    for (std::uint64_t b = 0; b < blocks; ++b) {
      const std::int64_t dim = data_.integer("the entity dimension of an element block");
      if (dim < 0 || dim > 3) in_.fail_semantic("element block entity dimension " + std::to_string(dim) + " is not 0..3");
      const std::int64_t entity = data_.integer("the entity tag of an element block");
      const std::int64_t type = data_.integer("the element type of a block");
      check_type(type, "an element block (entity " + std::to_string(entity) + ")");
      const std::uint64_t m = data_.count("the number of elements in a block");
      data_.end_line("the element block header");
      const int type_dim = type == gmsh_point ? 0 : cell_dimension(linear_type(type)->type);
      if (type_dim != dim)
        in_.fail_semantic("an element block of entity dimension " + std::to_string(dim) + " holds elements of dimension " +
                          std::to_string(type_dim));
      std::int32_t phys = 0;
      if (have_entities_) {
        const auto it = entity_phys_.find({static_cast<int>(dim), entity});
        if (it == entity_phys_.end())
          in_.fail_semantic("an element block refers to entity " + std::to_string(entity) + " of dimension " +
                            std::to_string(dim) + ", which $Entities does not declare");
        phys = it->second;
      }
      if (m > 0) entity_with_elements_.insert({static_cast<int>(dim), entity});
      if (seen + m > n)
        in_.fail_semantic("element blocks hold more elements than the " + std::to_string(n) +
                          " the $Elements header declares");
      seen += m;
      for (std::uint64_t i = 0; i < m; ++i) {
        const std::int64_t id = data_.tag("an element tag");
        add_element(id, type, phys, entity, type_dim);
      }
    }
    if (seen != n)
      in_.fail_semantic("the $Elements header declares " + std::to_string(n) + " elements but its blocks hold " +
                        std::to_string(seen));
    expect_end("$EndElements", std::to_string(blocks) + " element blocks");
  }

  void reserve_cells(std::uint64_t n, std::size_t min_bytes) {
    const std::size_t r = detail::reservable(n, in_.remaining(), min_bytes);
    out_.mesh.types.reserve(r);
    out_.mesh.tags.reserve(r);
    out_.mesh.offsets.reserve(r + 1);
    out_.mesh.conn.reserve(4 * r);
    entity_.reserve(r);
  }

  void expect_end(const char* end, const std::string& declared) {
    const std::string_view t = in_.token(end);
    if (t != end) in_.fail_expected(std::string("'") + end + "' after the " + declared + " the section declares", t);
  }

  // MSH 2 writes an element once for each physical group that contains its entity; 4.1 writes it
  // once. Merging the repeats (same entity, type and nodes; the first group is kept as tag) makes
  // both versions of one mesh load alike.
  void merge_group_repeats() {
    IndexedMesh& m = out_.mesh;
    std::map<std::pair<int, std::int64_t>, std::set<std::int32_t>> groups;
    for (std::uint32_t c = 0; c < m.num_cells(); ++c) groups[entity_[c]].insert(m.tags[c]);
    std::set<std::pair<int, std::int64_t>> repeated;
    for (const auto& [e, g] : groups)
      if (g.size() > 1) repeated.insert(e);
    if (repeated.empty()) return;
    std::map<std::tuple<int, std::int64_t, CellType, std::vector<std::uint32_t>>, std::uint32_t> first;
    IndexedMesh kept;
    kept.points = std::move(m.points);
    std::vector<std::int64_t> kept_tags;
    for (std::uint32_t c = 0; c < m.num_cells(); ++c) {
      const auto v = m.cell(c);
      if (repeated.count(entity_[c])) {
        const auto key = std::make_tuple(entity_[c].first, entity_[c].second, m.types[c],
                                         std::vector<std::uint32_t>(v.begin(), v.end()));
        if (!first.emplace(key, c).second) continue;
      }
      kept.add_cell(m.types[c], v, m.tags[c]);
      kept_tags.push_back(out_.element_tags[c]);
    }
    m = std::move(kept);
    out_.element_tags = std::move(kept_tags);
  }

  Cursor in_;
  MshData data_{in_};
  MeshFile out_;
  bool v4_ = false;
  bool have_nodes_ = false;
  bool have_elements_ = false;
  bool have_entities_ = false;
  std::unordered_map<std::int64_t, std::uint32_t> node_index_;
  std::map<std::pair<int, std::int64_t>, std::int32_t> entity_phys_;  // 0: in no physical group
  std::set<std::pair<int, std::int64_t>> entity_with_elements_;
  std::vector<std::pair<int, std::int64_t>> entity_;  // per cell: (dimension, entity tag)
};

}  // namespace

MeshFile parse_gmsh(std::string_view text, const std::string& source) { return GmshReader(text, source).run(); }

MeshFile read_gmsh(const std::filesystem::path& path) {
  const std::string text = detail::slurp(path);
  return parse_gmsh(text, path.string());
}

}  // namespace sewn::io
