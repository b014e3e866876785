// PodArray's mapped blocks: a freed one serves the next array of about its size, never one
// that would hold more than twice what it asked for.
#include <doctest/doctest.h>

#include <cstdint>

#include "sewn/cmap/detail/pod_array.hpp"

using sewn::detail::PodArray;

#if defined(__linux__)
TEST_CASE("pod array: a freed mapped block is reused, contents rewritten") {
  constexpr std::size_t n = (std::size_t{5} << 20) / 4 + 1000;  // a size no other test maps
  PodArray<std::uint32_t> src;
  src.resize(n - 10);
  for (std::size_t i = 0; i < src.size(); ++i) src[i] = static_cast<std::uint32_t>(i);
  const std::uint32_t* first = nullptr;
  {
    PodArray<std::uint32_t> a;
    a.resize(n, 7);
    first = a.data();
  }
  const PodArray<std::uint32_t> b(src);  // copies into the freed block
  CHECK(b.data() == first);
  CHECK(b.capacity() >= n);
  REQUIRE(b.size() == src.size());
  bool same = true;
  for (std::size_t i = 0; i < b.size(); ++i) same = same && b[i] == i;
  CHECK(same);
}

TEST_CASE("pod array: a freed block more than twice a request is not handed to it") {
  constexpr std::size_t big = (std::size_t{9} << 20) / 4 + 1000, small = (std::size_t{2} << 20) / 4;
  const std::uint32_t* freed = nullptr;
  {
    PodArray<std::uint32_t> a;
    a.resize(big);
    freed = a.data();
  }
  PodArray<std::uint32_t> b;
  b.resize(small);
  CHECK(b.data() != freed);
  CHECK(b.capacity() < 2 * small);
}
#endif
