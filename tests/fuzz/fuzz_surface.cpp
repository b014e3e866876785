// libFuzzer target for the surface readers (io/surface.hpp), the format's fallback chosen at
// compile time by SEWN_FUZZ_FORMAT (1 OFF, 2 OBJ, 3 STL, ASCII or binary): the input is named
// fuzz-input.off/.obj/.stl, so content that identifies another format is read as that one, as
// read_surface does. Contract: every input is read or refused with an IoError naming the
// source; what was read is a surface the voxelizer may index without checks.
#include <cstddef>
#include <cstdint>
#include <string>
#include <string_view>

#include "fuzz_check.hpp"
#include "sewn/io/surface.hpp"

namespace {

#if SEWN_FUZZ_FORMAT == 1
const std::string source = "fuzz-input.off";
#elif SEWN_FUZZ_FORMAT == 2
const std::string source = "fuzz-input.obj";
#elif SEWN_FUZZ_FORMAT == 3
const std::string source = "fuzz-input.stl";
#else
#error "SEWN_FUZZ_FORMAT must be 1 (OFF), 2 (OBJ) or 3 (STL)"
#endif

[[noreturn]] void finding(const char* what) { sewn::fuzz::finding("fuzz_surface", what); }

// At least one triangle, three distinct corners each naming a point, finite coordinates.
void check_read(const sewn::io::Surface& s) {
  if (s.triangles.empty()) finding("a surface without triangles was read");
  for (const auto& t : s.triangles) {
    for (const auto v : t)
      if (v >= s.points.size()) finding("a triangle names a point that does not exist");
    if (t[0] == t[1] || t[1] == t[2] || t[2] == t[0]) finding("a triangle repeats a corner");
  }
  sewn::fuzz::check_finite("fuzz_surface", s.points);
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::string_view bytes(reinterpret_cast<const char*>(data), size);
  sewn::fuzz::read_or_refusal("fuzz_surface", source, [&] { return sewn::io::parse_surface(bytes, source); }, check_read);
  return 0;
}
