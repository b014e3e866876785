// Randomized, seeded operation sequences on 2D and 3D maps. After every operation: validate(),
// the map's counts against an independent breadth-first recount, one attribute per cell, and
// hook sanity. 50 000 operations per dimension; the seed is printed on failure.
#include <doctest/doctest.h>

#include <array>
#include <functional>
#include <map>
#include <random>
#include <string>
#include <vector>

#include "check.hpp"
#include "sewn/cmap/build.hpp"
#include "sewn/cmap/cmap.hpp"

namespace test_random {

using namespace sewn;

namespace {

template <class M>
struct Fuzzer {
  M m;
  std::mt19937 rng;
  int next_label = 0;
  std::map<std::string, std::array<int, 2>> tally;  // op -> {applied, skipped}
  int splits = 0, merges = 0;

  explicit Fuzzer(unsigned seed) : rng(seed) {
    auto install = [&](auto k) {
      constexpr int I = decltype(k)::value;
      m.template on_split<I>([this](AttrId<I> a, AttrId<I> b) {
        if (m.value(a) != m.value(b)) FAIL_CHECK("on_split: the copy does not hold the original's value");
        ++splits;
      });
      m.template on_merge<I>([this](AttrId<I> a, AttrId<I> b) {
        if (a == b) FAIL_CHECK("on_merge called with one attribute twice");
        ++merges;
      });
    };
    [&]<int... I>(std::integer_sequence<int, I...>) {
      (install(std::integral_constant<int, I>{}), ...);
    }(std::make_integer_sequence<int, M::dimension + 1>{});
  }

  std::uint32_t uniform(std::uint32_t n) { return std::uniform_int_distribution<std::uint32_t>(0, n - 1)(rng); }

  Dart random_dart() {
    if (m.num_darts() == 0) return null_dart;
    for (;;) {
      const Dart d(uniform(m.dart_capacity()));
      if (m.is_alive(d)) return d;
    }
  }
  // A random dart satisfying pred, or null after a few tries.
  template <class P>
  Dart random_dart_where(P pred) {
    for (int t = 0; t < 30; ++t) {
      const Dart d = random_dart();
      if (d && pred(d)) return d;
    }
    return null_dart;
  }

  void label_new_cells() {
    auto label = [&](auto k) {
      constexpr int I = decltype(k)::value;
      m.template create_attributes<I>([&](Dart) { return next_label++; });
    };
    [&]<int... I>(std::integer_sequence<int, I...>) {
      (label(std::integral_constant<int, I>{}), ...);
    }(std::make_integer_sequence<int, M::dimension + 1>{});
  }

  // Returns a description of the first problem found, or an empty string.
  std::string check() {
    const auto report = m.validate();
    if (!report.ok()) return report.str(5);
    const auto own = m.count_all();
    const auto ref = sewn::test::recount(m);
    if (own != ref) return "count_all() differs from the independent recount";
    if (std::string e = sewn::test::check_iteration(m, ref); !e.empty()) return e;
    if (m.num_reserved_marks() != 0) return "a mark is still reserved";
    label_new_cells();
    bool ok = true;
    auto per_cell = [&](auto k) {
      constexpr int I = decltype(k)::value;
      if (m.template num_attributes<I>() != own[I]) ok = false;
    };
    [&]<int... I>(std::integer_sequence<int, I...>) {
      (per_cell(std::integral_constant<int, I>{}), ...);
    }(std::make_integer_sequence<int, M::dimension + 1>{});
    return ok ? std::string() : "not exactly one attribute per cell";
  }

  // Small maps keep each step cheap and make degenerate configurations (loops, folded cells,
  // one-edge faces) frequent: the cases where topological operations usually break.
  void run(int steps, const std::vector<std::pair<std::string, std::function<bool()>>>& ops,
           const std::function<void()>& refill, const std::function<void()>& shrink, unsigned seed, std::uint32_t max_darts) {
    std::uint32_t largest = 0;
    for (int step = 0; step < steps; ++step) {
      if (m.num_darts() < 24) refill();
      while (m.num_darts() > max_darts) shrink();
      largest = std::max(largest, m.num_darts());
      auto& [name, op] = ops[uniform(static_cast<std::uint32_t>(ops.size()))];
      const bool applied = op();
      ++tally[name][applied ? 0 : 1];
      const std::string problem = check();
      if (!problem.empty()) {
        FAIL("seed " << seed << ", step " << step << ", after " << name << ": " << problem);
      }
    }
    MESSAGE("largest map: " << largest << " darts");
  }
};

template <class M>
std::vector<Dart> face_cycle(const M& m, Dart d) {
  std::vector<Dart> out{d};
  for (Dart x = m.beta(d, 1); x && x != d; x = m.beta(x, 1)) {
    out.push_back(x);
    if (out.size() > m.num_darts()) return {};
  }
  if (!m.beta(out.back(), 1)) return {};  // open
  return out;
}

void report(const std::map<std::string, std::array<int, 2>>& tally, int min_applied) {
  for (const auto& entry : tally) {
    const std::string& name = entry.first;  // INFO cannot take bindings (clang 14)
    const std::array<int, 2>& t = entry.second;
    INFO("operation " << name << " applied " << t[0] << " times, skipped " << t[1]);
    CHECK(t[0] >= min_applied);  // every operation really ran: the test cannot pass by skipping
  }
}

}  // namespace

TEST_CASE("randomized operation sequences on a 2-map") {
  const unsigned seed = 20131;
  Fuzzer<CMap<2, int, int, int>> f(seed);
  auto& m = f.m;
  auto refill = [&] {
    build(m, quad_grid(3, 3));
    f.label_new_cells();
  };
  std::vector<std::pair<std::string, std::function<bool()>>> ops = {
      {"insert_vertex_in_edge", [&] { return bool(m.insert_vertex_in_edge(f.random_dart())); }},
      {"insert_vertex_in_edge with a value", [&] { return bool(m.insert_vertex_in_edge(f.random_dart(), f.next_label++)); }},
      {"insert_edge_in_face",
       [&] {
         const Dart a = f.random_dart();
         const auto cyc = face_cycle(m, a);
         if (cyc.size() < 2) return false;
         const Dart b = cyc[1 + f.uniform(static_cast<std::uint32_t>(cyc.size() - 1))];
         m.insert_edge_in_face(a, b);
         return true;
       }},
      {"remove_vertex",
       [&] {
         const Dart d = f.random_dart_where([&](Dart x) { return m.is_removable<0>(x); });
         if (!d) return false;
         m.remove_cell<0>(d);
         return true;
       }},
      {"remove_edge",
       [&] {
         const Dart d = f.random_dart();
         if (!m.is_removable<1>(d)) return false;
         m.remove_cell<1>(d);
         return true;
       }},
      {"remove_face",
       [&] {
         m.remove_cell<2>(f.random_dart());
         return true;
       }},
      {"contract_edge",
       [&] {
         const Dart d = f.random_dart_where([&](Dart x) { return m.is_contractible<1>(x); });
         if (!d) return false;
         m.contract_cell<1>(d);
         return true;
       }},
      {"contract_face",
       [&] {
         const Dart d = f.random_dart_where([&](Dart x) { return m.is_contractible<2>(x); });
         if (!d) return false;
         m.contract_cell<2>(d);
         return true;
       }},
      {"unsew2",
       [&] {
         const Dart d = f.random_dart_where([&](Dart x) { return !m.is_free(x, 2); });
         if (!d) return false;
         m.unsew<2>(d);
         return true;
       }},
      {"sew2",
       [&] {
         const Dart a = f.random_dart_where([&](Dart x) { return m.is_free(x, 2); });
         const Dart b = f.random_dart_where([&](Dart x) { return x != a && m.is_free(x, 2); });
         if (!a || !b || !m.is_sewable<2>(a, b)) return false;
         m.sew<2>(a, b);
         return true;
       }},
      {"make_polygon",
       [&] {
         m.make_polygon(1 + f.uniform(5));
         return true;
       }},
  };
  auto shrink = [&] { m.remove_cell<2>(f.random_dart()); };
  f.run(50000, ops, refill, shrink, seed, 400);
  report(f.tally, 500);
  CHECK(f.splits > 1000);
  CHECK(f.merges > 1000);
}

TEST_CASE("randomized operation sequences on a 3-map") {
  const unsigned seed = 20132;
  Fuzzer<CMap<3, int, int, int, int>> f(seed);
  auto& m = f.m;
  auto refill = [&] {
    build(m, hex_grid(2, 2, 1));
    f.label_new_cells();
  };
  std::vector<std::pair<std::string, std::function<bool()>>> ops = {
      {"insert_vertex_in_edge", [&] { return bool(m.insert_vertex_in_edge(f.random_dart())); }},
      {"insert_vertex_in_edge with a value", [&] { return bool(m.insert_vertex_in_edge(f.random_dart(), f.next_label++)); }},
      {"insert_edge_in_face",
       [&] {
         const Dart a = f.random_dart();
         const auto cyc = face_cycle(m, a);
         if (cyc.size() < 2) return false;
         const Dart b = cyc[1 + f.uniform(static_cast<std::uint32_t>(cyc.size() - 1))];
         m.insert_edge_in_face(a, b);
         return true;
       }},
      {"insert_face_in_volume",
       [&] {
         const auto cyc = face_cycle(m, f.random_dart());
         if (cyc.empty() || !m.is_insertable_face_in_volume(cyc)) return false;
         m.insert_face_in_volume(cyc);
         return true;
       }},
      {"unsew3",
       [&] {
         const Dart d = f.random_dart_where([&](Dart x) { return !m.is_free(x, 3); });
         if (!d) return false;
         m.unsew<3>(d);
         return true;
       }},
      {"sew3",
       [&] {
         const Dart a = f.random_dart_where([&](Dart x) { return m.is_free(x, 3); });
         if (!a) return false;
         const Dart b = f.random_dart_where([&](Dart x) { return m.is_sewable<3>(a, x); });
         if (!b) return false;
         m.sew<3>(a, b);
         return true;
       }},
      {"unsew2",
       [&] {
         const Dart d = f.random_dart_where([&](Dart x) { return !m.is_free(x, 2); });
         if (!d) return false;
         m.unsew<2>(d);
         return true;
       }},
      {"remove_vertex",
       [&] {
         const Dart d = f.random_dart_where([&](Dart x) { return m.is_removable<0>(x); });
         if (!d) return false;
         m.remove_cell<0>(d);
         return true;
       }},
      {"remove_edge",
       [&] {
         const Dart d = f.random_dart_where([&](Dart x) { return m.is_removable<1>(x); });
         if (!d) return false;
         m.remove_cell<1>(d);
         return true;
       }},
      {"remove_face",
       [&] {
         const Dart d = f.random_dart_where([&](Dart x) { return m.is_removable<2>(x); });
         if (!d) return false;
         m.remove_cell<2>(d);
         return true;
       }},
      {"remove_volume",
       [&] {
         if (f.uniform(4) != 0) return false;  // rarer: it empties the map quickly
         m.remove_cell<3>(f.random_dart());
         return true;
       }},
      {"contract_edge",
       [&] {
         const Dart d = f.random_dart_where([&](Dart x) { return m.is_contractible<1>(x); });
         if (!d) return false;
         m.contract_cell<1>(d);
         return true;
       }},
      {"contract_face",
       [&] {
         const Dart d = f.random_dart_where([&](Dart x) { return m.is_contractible<2>(x); });
         if (!d) return false;
         m.contract_cell<2>(d);
         return true;
       }},
      {"contract_volume",
       [&] {
         const Dart d = f.random_dart_where([&](Dart x) { return m.is_contractible<3>(x); });
         if (!d) return false;
         m.contract_cell<3>(d);
         return true;
       }},
      {"make_polyhedron",
       [&] {
         if (f.uniform(2) == 0)
           m.make_tetrahedron();
         else
           m.make_hexahedron();
         return true;
       }},
  };
  auto shrink = [&] { m.remove_cell<3>(f.random_dart()); };
  f.run(50000, ops, refill, shrink, seed, 300);
  report(f.tally, 200);
  CHECK(f.splits > 1000);
  CHECK(f.merges > 1000);
}

}  // namespace test_random
