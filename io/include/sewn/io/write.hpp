#pragma once
// Output for ParaView and for plots: one VTU (VTK XML UnstructuredGrid) file per frame, a PVD
// series index that is rewritten after each frame (so a run cut short is still readable), and
// per-frame CSV rows.
//
//   sewn::io::PvdWriter series("out/run.pvd");
//   const sewn::io::DataArray pd[] = {sewn::io::DataArray::vectors("velocity", v),
//                                     sewn::io::DataArray::scalars("fixed", fixed_flags)};
//   sewn::io::write_vtu("out/run_0007.vtu", x, sewn::io::CellsView::of(mesh), pd, {});
//   series.add(t, "out/run_0007.vtu");
//
// Files are written to a temporary name and renamed into place, so a reader never sees half a
// file. Every I/O failure throws FileError; a caller mistake (an array of the wrong length)
// throws std::invalid_argument.

#include <cstdint>
#include <filesystem>
#include <fstream>
#include <initializer_list>
#include <span>
#include <string>
#include <utility>
#include <variant>
#include <vector>

#include "sewn/cmap/mesh.hpp"
#include "sewn/io/errors.hpp"

namespace sewn::io {

/// Cells without their points (types, offsets, connectivity as in IndexedMesh), so one cell set
/// can be written with the positions of each frame.
struct CellsView {
  std::span<const CellType> types;
  std::span<const std::uint32_t> offsets;  ///< types.size() + 1 entries, offsets[0] = 0
  std::span<const std::uint32_t> conn;
  /// Empty, or per cell: non-zero for a VTK poly-line (type 4) through all of the cell's points
  /// in order (its type must be segment; two or more points), such as a whole rod.
  std::span<const std::uint8_t> poly_line = {};
  /// The cells of an IndexedMesh (which must outlive the view).
  static CellsView of(const IndexedMesh& m) { return {m.types, m.offsets, m.conn}; }
  /// Number of cells.
  [[nodiscard]] std::size_t size() const { return types.size(); }
};

/// VTK's number for a cell type (3 line, 5 triangle, 9 quad, 10 tetra, 12 hexahedron, 13 wedge,
/// 14 pyramid).
std::uint8_t vtk_cell_type(CellType t);

/// A named per-point or per-cell array, not owning its values. `components` values per tuple
/// for double and integer arrays; Point3 arrays have 3.
struct DataArray {
  using Values = std::variant<std::span<const double>, std::span<const Point3>, std::span<const std::int32_t>,
                              std::span<const std::uint8_t>>;
  std::string name;
  Values values;
  int components = 1;

  /// One double per point or cell (written as Float64).
  static DataArray scalars(std::string n, std::span<const double> v) { return {std::move(n), v, 1}; }
  /// One 3-vector per point or cell (Float64, 3 components): velocity, force, displacement.
  static DataArray vectors(std::string n, std::span<const Point3> v) { return {std::move(n), v, 3}; }
  /// One 32-bit integer per point or cell (Int32): material id, refinement level, cell type.
  static DataArray ints(std::string n, std::span<const std::int32_t> v) { return {std::move(n), v, 1}; }
  /// One byte per point or cell (UInt8): fixed flags, masks.
  static DataArray flags(std::string n, std::span<const std::uint8_t> v) { return {std::move(n), v, 1}; }
  /// Number of tuples (values / components).
  [[nodiscard]] std::size_t tuples() const;
};

enum class VtuEncoding {
  ascii,   ///< human-readable text, shortest round-trip decimal form of each value
  base64,  ///< VTK "binary" inline format: base64 of (64-bit byte count + native-endian data)
};

struct VtuOptions {
  VtuEncoding encoding = VtuEncoding::base64;
};

/// Writes one frame as a VTU file. Every point array needs points.size() tuples and every cell
/// array cells.size() tuples (std::invalid_argument otherwise, naming the array); cell indices
/// must be < points.size(). Throws FileError if the file cannot be written.
void write_vtu(const std::filesystem::path& path, std::span<const Point3> points, CellsView cells,
               std::span<const DataArray> point_data = {}, std::span<const DataArray> cell_data = {},
               const VtuOptions& opt = {});
/// The same with the mesh's own points.
void write_vtu(const std::filesystem::path& path, const IndexedMesh& mesh, std::span<const DataArray> point_data = {},
               std::span<const DataArray> cell_data = {}, const VtuOptions& opt = {});

/// A ParaView series (.pvd): time step -> VTU file. The index file is rewritten, whole and
/// atomically, by the constructor (empty series) and by every add().
class PvdWriter {
 public:
  /// Starts an empty series at `path` (overwriting an old one). Throws FileError.
  explicit PvdWriter(std::filesystem::path path);
  /// Continues a series whose first frames are `frames` (time, file relative to the .pvd's
  /// folder), as a run resumed from a checkpoint does: writes them at once. Throws FileError.
  PvdWriter(std::filesystem::path path, std::vector<std::pair<double, std::string>> frames);
  /// Records `vtu` (stored relative to the .pvd's folder) at time `time`. Throws FileError.
  void add(double time, const std::filesystem::path& vtu);
  /// The .pvd file.
  [[nodiscard]] const std::filesystem::path& path() const { return path_; }
  /// Frames recorded so far.
  [[nodiscard]] std::size_t size() const { return entries_.size(); }
  /// The frames recorded so far, as (time, file relative to the .pvd's folder).
  [[nodiscard]] const std::vector<std::pair<double, std::string>>& frames() const { return entries_; }

 private:
  void flush() const;
  std::filesystem::path path_;
  std::vector<std::pair<double, std::string>> entries_;
};

/// A CSV file of numeric rows under a header line. Values are written in the shortest form that
/// reads back to the same double (nan and inf as such). The file is only ever replaced whole
/// (written aside and renamed), so a reader never sees half a row: after every row while it is
/// under 64 KiB (about 250 rows of 15 columns), then each time it has doubled since it was last
/// written, and by flush() and the destructor, so the whole cost stays linear in its size.
class CsvWriter {
 public:
  /// Creates the file with the header (names quoted when they need it). Throws FileError.
  CsvWriter(const std::filesystem::path& path, std::vector<std::string> columns);
  /// Writes the rows not yet on disk; errors are swallowed here (call flush() to see them).
  ~CsvWriter();
  CsvWriter(const CsvWriter&) = delete;
  CsvWriter& operator=(const CsvWriter&) = delete;
  /// Appends a row; std::invalid_argument unless it has one value per column; FileError on I/O
  /// (the file then keeps the rows it had).
  void row(std::span<const double> values);
  /// row() for a braced list of values.
  void row(std::initializer_list<double> values) { row(std::span<const double>(values.begin(), values.size())); }
  /// Puts every row so far on disk. Throws FileError.
  void flush();
  /// Number of columns (values each row must have).
  [[nodiscard]] std::size_t columns() const { return columns_.size(); }

 private:
  std::filesystem::path path_;
  std::vector<std::string> columns_;
  std::string content_;        // the whole file
  std::size_t written_ = 0;    // bytes of content_ on disk
};

/// The shortest decimal form of x that reads back exactly ("nan", "inf", "-inf" if not finite).
std::string format_double(double x);

}  // namespace sewn::io
