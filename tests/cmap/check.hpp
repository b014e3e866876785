#pragma once
// Test helpers: an independent cell recount and the per-step validity check.

#include <doctest/doctest.h>

#include <array>
#include <cstdint>
#include <string>
#include <utility>
#include <vector>

#include "sewn/cmap/cmap.hpp"

namespace sewn::test {

// Four numbers (Betti numbers or cell counts by dimension) as one line, for failure messages.
inline std::string str(const std::array<std::int64_t, 4>& b) {
  return std::to_string(b[0]) + " " + std::to_string(b[1]) + " " + std::to_string(b[2]) + " " + std::to_string(b[3]);
}

// Gives every cell of every dimension with attributes its own attribute, numbered 0, 1, 2, ...
template <class M>
void label_all_cells(M& m) {
  int next = 0;
  auto label = [&](auto k) {
    constexpr int I = decltype(k)::value;
    if constexpr (M::template has_attribute<I>) m.template create_attributes<I>([&](Dart) { return next++; });
  };
  [&]<int... I>(std::integer_sequence<int, I...>) {
    (label(std::integral_constant<int, I>{}), ...);
  }(std::make_integer_sequence<int, M::dimension + 1>{});
}

// Neighbours of dart x in the orbit of its i-cell, written out by hand from the definition of
// cells in a combinatorial map (not shared with the library): for i ≥ 1 every βj (j ≠ i, β0
// with β1), for i = 0 the compositions β1∘βj, βj∘β0 and βk∘βj (j ≠ k ≥ 2). A fixed array, not a
// vector: the randomized tests call this for every dart after every operation, and a heap
// allocation each time made the allocator most of their cost (most of all under ASan).
template <class Map>
struct OrbitNeighbours {
  std::array<Dart, (Map::dimension + 1) * (Map::dimension + 1)> dart{};
  int size = 0;
  void push(Dart y) {
    if (y) dart[static_cast<std::size_t>(size++)] = y;
  }
  const Dart* begin() const { return dart.data(); }
  const Dart* end() const { return dart.data() + size; }
};

template <class Map>
OrbitNeighbours<Map> orbit_neighbours(const Map& m, Dart x, int i) {
  constexpr int D = Map::dimension;
  OrbitNeighbours<Map> out;
  if (i == 0) {
    for (int j = 2; j <= D; ++j) {
      if (Dart y = m.beta(x, j)) {
        out.push(m.beta(y, 1));
        for (int k = 2; k <= D; ++k)
          if (k != j) out.push(m.beta(y, k));
      }
      if (Dart y = m.beta(x, 0)) out.push(m.beta(y, j));
    }
  } else {
    for (int j = 0; j <= D; ++j) {
      if (j == i || (i == 1 && j == 0)) continue;
      out.push(m.beta(x, j));
    }
  }
  return out;
}

// Visits the i-cell of `start` (marking its darts in `seen`) and calls f on each of its darts.
// `stack` is the caller's, reused from cell to cell.
template <class Map, class F>
void visit_orbit(const Map& m, Dart start, int i, std::vector<char>& seen, std::vector<Dart>& stack, F&& f) {
  stack.assign(1, start);
  seen[start.index()] = 1;
  while (!stack.empty()) {
    const Dart x = stack.back();
    stack.pop_back();
    f(x);
    for (Dart y : orbit_neighbours(m, x, i))
      if (!seen[y.index()]) {
        seen[y.index()] = 1;
        stack.push_back(y);
      }
  }
}

// Number of i-cells for i = 0..D by graph search with a plain visited array.
template <class Map>
std::array<std::uint32_t, Map::dimension + 1> recount(const Map& m) {
  constexpr int D = Map::dimension;
  std::array<std::uint32_t, D + 1> n{};
  const std::uint32_t cap = m.dart_capacity();
  std::vector<char> seen;
  std::vector<Dart> stack;
  for (int i = 0; i <= D; ++i) {
    seen.assign(cap, 0);
    for (std::uint32_t s = 0; s < cap; ++s) {
      if (!m.is_alive(Dart(s)) || seen[s]) continue;
      ++n[static_cast<std::size_t>(i)];
      visit_orbit(m, Dart(s), i, seen, stack, [](Dart) {});
    }
  }
  return n;
}

// What cells<i>() yields, against the independent search: one dart per cell, each the smallest
// of its cell, as many as `ref` counts. Empty if so, else the first problem found.
template <class Map>
std::string check_iteration(const Map& m, const std::array<std::uint32_t, Map::dimension + 1>& ref) {
  constexpr int D = Map::dimension;
  std::string problem;
  std::vector<char> seen;
  std::vector<Dart> stack;
  auto one = [&](auto k) {
    constexpr int I = decltype(k)::value;
    if (!problem.empty()) return;
    seen.assign(m.dart_capacity(), 0);
    std::uint32_t n = 0;
    for (Dart d : m.template cells<I>()) {
      ++n;
      if (seen[d.index()]) {
        problem = "cells<" + std::to_string(I) + ">() yields two darts of one cell";
        return;
      }
      bool smallest = true;
      visit_orbit(m, d, I, seen, stack, [&](Dart x) { smallest = smallest && !(x < d); });
      if (!smallest) {
        problem = "cells<" + std::to_string(I) + ">() yields a dart that is not the smallest of its cell";
        return;
      }
    }
    if (n != ref[I]) problem = "cells<" + std::to_string(I) + ">() yields " + std::to_string(n) + " cells, not " + std::to_string(ref[I]);
  };
  [&]<int... I>(std::integer_sequence<int, I...>) {
    (one(std::integral_constant<int, I>{}), ...);
  }(std::make_integer_sequence<int, D + 1>{});
  return problem;
}

// validate() is clean, the map's own counts agree with the independent recount, cells<i>()
// yields the smallest dart of each cell, and no mark is left reserved. Returns the counts.
template <class Map>
std::array<std::uint32_t, Map::dimension + 1> check_map(const Map& m) {
  const auto report = m.validate();
  INFO(report.str());
  CHECK(report.ok());
  const auto own = m.count_all();
  const auto ref = recount(m);
  for (int i = 0; i <= Map::dimension; ++i) {
    INFO("dimension " << i);
    CHECK(own[static_cast<std::size_t>(i)] == ref[static_cast<std::size_t>(i)]);
  }
  const std::string iteration = check_iteration(m, ref);
  INFO(iteration);
  CHECK(iteration.empty());
  CHECK(m.num_reserved_marks() == 0);
  return own;
}

template <std::size_t N>
std::array<std::uint32_t, N> counts(std::initializer_list<std::uint32_t> v) {
  std::array<std::uint32_t, N> a{};
  std::size_t k = 0;
  for (auto x : v) {
    REQUIRE(k < N);
    a[k++] = x;
  }
  return a;
}

}  // namespace sewn::test
