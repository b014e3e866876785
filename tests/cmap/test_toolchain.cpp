// The compiler must pass small aggregates intact. GCC 12 with AVX-512 (-march=native on such a
// machine) vectorises the construction of a 4-element std::array argument into a broadcast of
// its first element: record({1, 1, 0, 0}, ...) sees {1, 1, 1, 1}. The build turns that
// vectoriser off (cmake/SewnCompileOptions.cmake); this test fails if it is on again.
#include <array>
#include <cstdint>

#include <doctest/doctest.h>

namespace {

using Quad = std::array<std::int64_t, 4>;

void record(Quad q, std::int64_t c, std::int64_t* out) {
  for (int i = 0; i < 4; ++i) out[i] = q[i];
  out[4] = c;
}

}  // namespace

TEST_CASE("toolchain: a 4-element array argument arrives as written") {
  std::int64_t out[5] = {};
  volatile int offset = 0;  // keeps the call from being folded away entirely
  record({1, 1, 0, 0}, 1, out + offset);
  CHECK(out[0] == 1);
  CHECK(out[1] == 1);
  CHECK(out[2] == 0);
  CHECK(out[3] == 0);
  CHECK(out[4] == 1);
}
