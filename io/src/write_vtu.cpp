// VTU and PVD writers ("VTK File Formats", XML formats: UnstructuredGrid and Collection).

#include <bit>
#include <cerrno>
#include <charconv>
#include <cmath>
#include <cstring>
#include <sstream>
#include <stdexcept>

#include "sewn/io/atomic_file.hpp"
#include "sewn/io/write.hpp"

namespace sewn::io {

std::string format_double(double x) {
  if (std::isnan(x)) return "nan";
  if (std::isinf(x)) return x > 0 ? "inf" : "-inf";
  char buf[32];
  const auto r = std::to_chars(buf, buf + sizeof buf, x);
  return {buf, r.ptr};
}

std::uint8_t vtk_cell_type(CellType t) {
  switch (t) {
    case CellType::segment: return 3;
    case CellType::triangle: return 5;
    case CellType::quad: return 9;
    case CellType::tetrahedron: return 10;
    case CellType::hexahedron: return 12;
    case CellType::prism: return 13;
    case CellType::pyramid: return 14;
  }
  return 0;
}

std::size_t DataArray::tuples() const {
  const std::size_t n = std::visit([](const auto& s) { return s.size(); }, values);
  if (std::holds_alternative<std::span<const Point3>>(values)) return n;
  return components > 0 ? n / static_cast<std::size_t>(components) : 0;
}

namespace {

std::string xml_escape(const std::string& s) {
  std::string r;
  for (char c : s) {
    switch (c) {
      case '&': r += "&amp;"; break;
      case '<': r += "&lt;"; break;
      case '>': r += "&gt;"; break;
      case '"': r += "&quot;"; break;
      case '\'': r += "&apos;"; break;
      default: r += c;
    }
  }
  return r;
}

void base64(std::string& out, const unsigned char* data, std::size_t n) {
  static constexpr char table[] = "ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
  std::size_t i = 0;
  for (; i + 3 <= n; i += 3) {
    const std::uint32_t w = (std::uint32_t{data[i]} << 16) | (std::uint32_t{data[i + 1]} << 8) | data[i + 2];
    out += table[(w >> 18) & 63];
    out += table[(w >> 12) & 63];
    out += table[(w >> 6) & 63];
    out += table[w & 63];
  }
  if (i < n) {
    const std::uint32_t w = (std::uint32_t{data[i]} << 16) | (i + 1 < n ? std::uint32_t{data[i + 1]} << 8 : 0u);
    out += table[(w >> 18) & 63];
    out += table[(w >> 12) & 63];
    out += i + 1 < n ? table[(w >> 6) & 63] : '=';
    out += '=';
  }
}

template <class T>
const char* vtk_type_name() {
  if constexpr (std::is_same_v<T, double>) return "Float64";
  if constexpr (std::is_same_v<T, std::int32_t>) return "Int32";
  if constexpr (std::is_same_v<T, std::int64_t>) return "Int64";
  if constexpr (std::is_same_v<T, std::uint8_t>) return "UInt8";
}

// One <DataArray> element holding `values` (flat, `components` per tuple).
template <class T>
void data_array(std::string& out, const std::string& name, int components, std::span<const T> values, VtuEncoding enc) {
  out += "        <DataArray type=\"";
  out += vtk_type_name<T>();
  out += "\" Name=\"" + xml_escape(name) + "\"";
  if (components != 1) out += " NumberOfComponents=\"" + std::to_string(components) + "\"";
  out += enc == VtuEncoding::ascii ? " format=\"ascii\">\n          " : " format=\"binary\">\n          ";
  if (enc == VtuEncoding::ascii) {
    for (std::size_t i = 0; i < values.size(); ++i) {
      if (i) out += (i % 12 == 0) ? "\n          " : " ";
      if constexpr (std::is_same_v<T, double>) {
        out += format_double(values[i]);
      } else {
        out += std::to_string(values[i]);
      }
    }
  } else {
    // one base64 stream of the byte count (UInt64, as header_type declares) followed by the data
    const std::uint64_t bytes = values.size() * sizeof(T);
    std::string raw(sizeof bytes + bytes, '\0');
    std::memcpy(raw.data(), &bytes, sizeof bytes);
    if (bytes) std::memcpy(raw.data() + sizeof bytes, values.data(), bytes);
    base64(out, reinterpret_cast<const unsigned char*>(raw.data()), raw.size());
  }
  out += "\n        </DataArray>\n";
}

void user_array(std::string& out, const DataArray& a, VtuEncoding enc) {
  std::visit(
      [&](const auto& s) {
        using S = std::decay_t<decltype(s)>;
        if constexpr (std::is_same_v<S, std::span<const Point3>>) {
          data_array<double>(out, a.name, 3, std::span<const double>(s.empty() ? nullptr : s.data()->data(), 3 * s.size()),
                             enc);
        } else {
          data_array<typename S::value_type>(out, a.name, a.components, std::span<const typename S::value_type>(s), enc);
        }
      },
      a.values);
}

void check_arrays(std::span<const DataArray> arrays, std::size_t tuples, const char* where) {
  for (const auto& a : arrays) {
    const std::size_t n = std::visit([](const auto& s) { return s.size(); }, a.values);
    const bool is_point3 = std::holds_alternative<std::span<const Point3>>(a.values);
    if (!is_point3 && (a.components < 1 || n % static_cast<std::size_t>(a.components) != 0))
      throw std::invalid_argument("write_vtu: " + std::string(where) + " array '" + a.name + "' has " +
                                  std::to_string(n) + " values, not a multiple of its " + std::to_string(a.components) +
                                  " components");
    if (a.tuples() != tuples)
      throw std::invalid_argument("write_vtu: " + std::string(where) + " array '" + a.name + "' has " +
                                  std::to_string(a.tuples()) + " tuples but there are " + std::to_string(tuples) + " " +
                                  where + "s");
  }
}

}  // namespace

void write_vtu(const std::filesystem::path& path, std::span<const Point3> points, CellsView cells,
               std::span<const DataArray> point_data, std::span<const DataArray> cell_data, const VtuOptions& opt) {
  const std::size_t nc = cells.size();
  if (cells.offsets.size() != nc + 1 || cells.offsets[0] != 0 || cells.offsets[nc] != cells.conn.size())
    throw std::invalid_argument("write_vtu: cell offsets do not match the cell types and connectivity");
  if (!cells.poly_line.empty() && cells.poly_line.size() != nc)
    throw std::invalid_argument("write_vtu: " + std::to_string(cells.poly_line.size()) + " poly-line flags for " + std::to_string(nc) +
                                " cells");
  for (std::size_t c = 0; c < cells.poly_line.size(); ++c)
    if (cells.poly_line[c] != 0 && (cells.types[c] != CellType::segment || cells.offsets[c + 1] < cells.offsets[c] + 2))
      throw std::invalid_argument("write_vtu: cell " + std::to_string(c) + " is flagged a poly-line but is not a segment chain of two or more points");
  for (const std::uint32_t v : cells.conn)
    if (v >= points.size())
      throw std::invalid_argument("write_vtu: a cell refers to point " + std::to_string(v) + " but there are " +
                                  std::to_string(points.size()) + " points");
  check_arrays(point_data, points.size(), "point");
  check_arrays(cell_data, nc, "cell");

  std::string out;
  out.reserve(64 * (points.size() + nc) + 1024);
  out += "<?xml version=\"1.0\"?>\n<VTKFile type=\"UnstructuredGrid\" version=\"1.0\" byte_order=\"";
  out += std::endian::native == std::endian::little ? "LittleEndian" : "BigEndian";
  out += "\" header_type=\"UInt64\">\n  <UnstructuredGrid>\n    <Piece NumberOfPoints=\"" +
         std::to_string(points.size()) + "\" NumberOfCells=\"" + std::to_string(nc) + "\">\n";
  out += "      <Points>\n";
  data_array<double>(out, "Points", 3,
                     std::span<const double>(points.empty() ? nullptr : points.data()->data(), 3 * points.size()),
                     opt.encoding);
  out += "      </Points>\n      <Cells>\n";
  const std::vector<std::int64_t> conn(cells.conn.begin(), cells.conn.end());
  const std::vector<std::int64_t> offsets(cells.offsets.begin() + 1, cells.offsets.end());  // VTU: cell ends
  std::vector<std::uint8_t> types(nc);
  constexpr std::uint8_t vtk_poly_line = 4;
  for (std::size_t c = 0; c < nc; ++c)
    types[c] = !cells.poly_line.empty() && cells.poly_line[c] != 0 ? vtk_poly_line : vtk_cell_type(cells.types[c]);
  data_array<std::int64_t>(out, "connectivity", 1, conn, opt.encoding);
  data_array<std::int64_t>(out, "offsets", 1, offsets, opt.encoding);
  data_array<std::uint8_t>(out, "types", 1, types, opt.encoding);
  out += "      </Cells>\n";
  out += "      <PointData>\n";
  for (const auto& a : point_data) user_array(out, a, opt.encoding);
  out += "      </PointData>\n      <CellData>\n";
  for (const auto& a : cell_data) user_array(out, a, opt.encoding);
  out += "      </CellData>\n    </Piece>\n  </UnstructuredGrid>\n</VTKFile>\n";
  write_file_atomically(path, out);
}

void write_vtu(const std::filesystem::path& path, const IndexedMesh& mesh, std::span<const DataArray> point_data,
               std::span<const DataArray> cell_data, const VtuOptions& opt) {
  write_vtu(path, mesh.points, CellsView::of(mesh), point_data, cell_data, opt);
}

PvdWriter::PvdWriter(std::filesystem::path path) : path_(std::move(path)) { flush(); }

PvdWriter::PvdWriter(std::filesystem::path path, std::vector<std::pair<double, std::string>> frames)
    : path_(std::move(path)), entries_(std::move(frames)) {
  flush();
}

void PvdWriter::add(double time, const std::filesystem::path& vtu) {
  if (!std::isfinite(time)) throw std::invalid_argument("PvdWriter::add: the time of a frame must be finite");
  // ParaView resolves file names against the .pvd's folder
  const auto dir = std::filesystem::absolute(path_).parent_path();
  const auto rel = std::filesystem::absolute(vtu).lexically_proximate(dir);
  entries_.emplace_back(time, rel.generic_string());
  flush();
}

void PvdWriter::flush() const {
  std::string out = "<?xml version=\"1.0\"?>\n<VTKFile type=\"Collection\" version=\"0.1\">\n  <Collection>\n";
  for (const auto& [t, file] : entries_)
    out += "    <DataSet timestep=\"" + format_double(t) + "\" group=\"\" part=\"0\" file=\"" + xml_escape(file) + "\"/>\n";
  out += "  </Collection>\n</VTKFile>\n";
  write_file_atomically(path_, out);
}

}  // namespace sewn::io
