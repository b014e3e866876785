// PodArray's mapped blocks: a freed one serves the next arrays that fit in it, each given just
// what it asked for; a mapped array grows by a quarter, in place over a kept block right after
// it; freed neighbours join.
#include <doctest/doctest.h>

#include <cstdint>

#if defined(__linux__)
#include <sys/mman.h>
#endif

#include "sewn/cmap/detail/pod_array.hpp"

using sewn::detail::PodArray;

#if defined(__linux__)
namespace {
// The capacity of a mapped array of n 4-byte elements: whole pages.
std::size_t whole_pages(std::size_t n) { return (n * 4 + 4095) / 4096 * 4096 / 4; }
}  // namespace

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
  CHECK(b.capacity() == whole_pages(src.size()));
  REQUIRE(b.size() == src.size());
  bool same = true;
  for (std::size_t i = 0; i < b.size(); ++i) same = same && b[i] == i;
  CHECK(same);
}

// Sizes from here on are larger than the blocks the tests above free, which would otherwise be
// preferred as smaller fits.
TEST_CASE("pod array: a kept block serves a smaller request from its front, the rest the next") {
  constexpr std::size_t freed_n = (std::size_t{13} << 20) / 4 + 3000, want = (std::size_t{11} << 20) / 4 + 3000;
  const std::uint32_t* freed = nullptr;
  {
    PodArray<std::uint32_t> a;
    a.resize(freed_n, 1);
    freed = a.data();
  }
  PodArray<std::uint32_t> b;
  b.reserve(want);
  CHECK(b.data() == freed);
  CHECK(b.capacity() == whole_pages(want));
  b.resize(want, 2);  // the kept pages are writable and hold what is written
  CHECK(b[0] == 2);
  CHECK(b[want - 1] == 2);
  PodArray<std::uint32_t> c;
  c.reserve(whole_pages(freed_n) - whole_pages(want));
  CHECK(c.data() == freed + whole_pages(want));
}

TEST_CASE("pod array: freed neighbours join, and an array grows in place over a kept block after it") {
  constexpr std::size_t whole = (std::size_t{48} << 20) / 4, front = (std::size_t{16} << 20) / 4;
  const std::uint32_t* base = nullptr;
  {
    PodArray<std::uint32_t> a;
    a.resize(whole, 1);
    base = a.data();
  }
  {
    PodArray<std::uint32_t> x, y;  // the front of the kept block, then the front of its rest
    x.reserve(front);
    y.reserve(front);
    CHECK(x.data() == base);
    CHECK(y.data() == base + front);
  }  // x and y join what is left of the block
  PodArray<std::uint32_t> z;
  z.reserve(whole);
  CHECK(z.data() == base);
  z.shrink_to_fit();  // empty: the whole block is kept again
  PodArray<std::uint32_t> g;
  g.reserve(front);
  REQUIRE(g.data() == base);
  for (std::size_t i = 0; i < 2 * front; ++i) g.push_back(static_cast<std::uint32_t>(i));
  CHECK(g.data() == base);
  CHECK(g.capacity() < 2 * front + 2 * front / 4);
  bool kept = true;
  for (std::size_t i = 0; i < g.size(); ++i) kept = kept && g[i] == i;
  CHECK(kept);
}

TEST_CASE("pod array: kept ranges of two mappings are neither joined nor extended across") {
  // mremap moves one mapping and fails on a range across two: ranges are tagged with the
  // mapping they lie in. One mapping stands for two here, its halves tagged apart.
  constexpr std::size_t half = std::size_t{4} << 12;
  char* r = static_cast<char*>(mmap(nullptr, 2 * half, PROT_READ | PROT_WRITE, MAP_PRIVATE | MAP_ANONYMOUS, -1, 0));
  REQUIRE(r != MAP_FAILED);
  void* other = r + half;  // the tag of the second half
  auto& kept = sewn::detail::MappedBlocks::instance();
  kept.give(r, half, r);
  kept.give(r + half, half, other);
  CHECK(!kept.take_at(r + half, half, r));  // the array ending at r + half may not extend over it
  CHECK(!kept.take_at(r, 2 * half, r));     // not joined: the first range is half long
  CHECK(kept.take_at(r, half, r));
  CHECK(kept.take_at(r + half, half, other));
  // with one tag the halves join
  kept.give(r, half, r);
  kept.give(r + half, half, r);
  CHECK(kept.take_at(r, 2 * half, r));
  munmap(r, 2 * half);
}

TEST_CASE("pod array: a mapped array grows by a quarter, a heap one doubles") {
  PodArray<std::uint32_t> a;
  std::size_t heap_growths = 0, mapped_growths = 0;
  for (std::size_t i = 0; i < (std::size_t{3} << 20) / 4 + 100; ++i) {
    const std::size_t before = a.capacity();
    a.push_back(static_cast<std::uint32_t>(i));
    if (a.capacity() == before || before < 8) continue;
    if (before * 4 < (std::size_t{256} << 10)) {
      if (a.capacity() * 4 < (std::size_t{256} << 10)) {
        CHECK(a.capacity() == 2 * before);
        ++heap_growths;
      }
    } else {
      CHECK(a.capacity() == whole_pages(before + before / 4));
      ++mapped_growths;
    }
  }
  CHECK(heap_growths > 0);
  CHECK(mapped_growths >= 4);
  bool kept = true;
  for (std::size_t i = 0; i < a.size(); ++i) kept = kept && a[i] == i;
  CHECK(kept);
}
#endif
