// is_insertable_face_in_volume decides the usual path by turning around the path's vertices
// inside the volume and walks the whole volume otherwise: both ways must give the answer of the
// definition (darts of one volume, each ending where the next starts, distinct edges), checked
// here against that definition written out on every short path of small maps, including a
// volume with 2-free darts (an open box), where the turns stop and the walk decides.
#include <doctest/doctest.h>

#include <algorithm>
#include <array>
#include <cstdint>
#include <random>
#include <span>
#include <vector>

#include "sewn/cmap/build.hpp"
#include "sewn/cmap/cmap.hpp"
#include "sewn/cmap/mesh.hpp"

namespace test_face_path {
namespace {

using Map = sewn::CMap<3>;
using sewn::Dart;

// The definition, from cell walks only.
bool insertable_by_definition(const Map& m, std::span<const Dart> path) {
  if (path.empty()) return false;
  const auto vol = m.cell<3>(path[0]);
  for (std::size_t k = 0; k < path.size(); ++k) {
    if (std::find(vol.begin(), vol.end(), path[k]) == vol.end()) return false;
    const Dart end = m.beta(path[k], 1);
    if (end.is_null() || !m.same_cell<0>(end, path[(k + 1) % path.size()])) return false;
    for (std::size_t l = 0; l < k; ++l)
      if (m.same_cell<1>(path[l], path[k])) return false;
  }
  return true;
}

std::vector<Dart> darts_of(const Map& m) {
  std::vector<Dart> all;
  for (std::uint32_t i = 0; i < m.dart_capacity(); ++i)
    if (m.is_alive(Dart(i))) all.emplace_back(i);
  return all;
}

// Every path of 3 darts and a seeded sample of 4-dart paths; returns how many were insertable.
int compare_all(const Map& m) {
  const std::vector<Dart> all = darts_of(m);
  int yes = 0;
  for (Dart a : all)
    for (Dart b : all)
      for (Dart c : all) {
        const std::array<Dart, 3> p{a, b, c};
        const bool want = insertable_by_definition(m, p);
        REQUIRE(m.is_insertable_face_in_volume(p) == want);
        yes += want;
      }
  std::mt19937 rng(13);
  std::uniform_int_distribution<std::size_t> pick(0, all.size() - 1);
  for (int t = 0; t < 20000; ++t) {
    // a walk along β1-then-turn steps, so that many samples are chains
    std::array<Dart, 4> p{all[pick(rng)]};
    for (std::size_t k = 1; k < 4; ++k) {
      Dart next = m.beta(p[k - 1], 1);
      for (std::size_t turns = pick(rng) % 3; turns > 0 && next && m.beta(next, 2); --turns) next = m.beta(next, 2, 1);
      p[k] = (next && pick(rng) % 8 != 0) ? next : all[pick(rng)];
    }
    const bool want = insertable_by_definition(m, p);
    REQUIRE(m.is_insertable_face_in_volume(p) == want);
    yes += want;
  }
  return yes;
}

TEST_CASE("a face path in a volume: the turning check agrees with the definition") {
  SUBCASE("two hexahedra sewn along a face") {
    Map m;
    (void)sewn::build(m, sewn::hex_grid(2, 1, 1));
    CHECK(compare_all(m) > 0);
  }
  SUBCASE("an open box: 2-free darts around its opening") {
    Map m;
    const Dart lid = m.make_hexahedron();
    for (Dart x : m.cell<2>(lid)) m.unsew<2>(x);  // the lid falls off: a box and a loose quad
    const std::vector<Dart> all = darts_of(m);
    REQUIRE(std::count_if(all.begin(), all.end(), [&](Dart x) { return m.is_free(x, 2); }) == 8);
    CHECK(compare_all(m) > 0);
  }
}

}  // namespace
}  // namespace test_face_path
