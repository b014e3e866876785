// libFuzzer target for one mesh reader, chosen at compile time by SEWN_FUZZ_FORMAT
// (1 Gmsh MSH, 2 MEDIT, 3 legacy VTK). The contract under test (io/read.hpp): every input is
// either read or refused with an IoError whose message names the source; any other exception,
// a crash, a sanitizer report, a hang or an allocation past libFuzzer's -malloc_limit_mb is a
// finding. A result that was read must also be self-consistent, since the tool goes on to
// build a map from it.
#include <cstddef>
#include <cstdint>
#include <string>
#include <string_view>

#include "fuzz_check.hpp"
#include "sewn/io/read.hpp"

namespace {

const std::string source = "fuzz-input";

[[noreturn]] void finding(const char* what) { sewn::fuzz::finding("fuzz_reader", what); }

sewn::io::MeshFile parse(std::string_view bytes) {
#if SEWN_FUZZ_FORMAT == 1
  return sewn::io::parse_gmsh(bytes, source);
#elif SEWN_FUZZ_FORMAT == 2
  return sewn::io::parse_medit(bytes, source);
#elif SEWN_FUZZ_FORMAT == 3
  return sewn::io::parse_vtk(bytes, source);
#else
#error "SEWN_FUZZ_FORMAT must be 1 (gmsh), 2 (medit) or 3 (vtk)"
#endif
}

// What a caller may rely on after a successful read: offsets frame conn, one type and tag per
// cell, as many vertices as its type has, every vertex index names a point, finite coordinates.
void check_read(const sewn::IndexedMesh& m) {
  const std::size_t cells = m.types.size();
  if (m.tags.size() != cells) finding("tags and types differ in length");
  if (m.offsets.size() != cells + 1) finding("offsets do not frame the cells");
  if (m.offsets.front() != 0 || m.offsets.back() != m.conn.size()) finding("offsets do not span conn");
  for (std::size_t c = 0; c < cells; ++c)
    if (m.offsets[c] > m.offsets[c + 1] ||
        m.offsets[c + 1] - m.offsets[c] != static_cast<std::uint32_t>(sewn::cell_vertex_count(m.types[c])))
      finding("a cell's vertex count does not match its type");
  for (const auto v : m.conn)
    if (v >= m.points.size()) finding("a cell names a point that does not exist");
  sewn::fuzz::check_finite("fuzz_reader", m.points);
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::string_view bytes(reinterpret_cast<const char*>(data), size);
  sewn::fuzz::read_or_refusal(
      "fuzz_reader", source, [&] { return parse(bytes); }, [](const sewn::io::MeshFile& f) { check_read(f.mesh); });
  return 0;
}
