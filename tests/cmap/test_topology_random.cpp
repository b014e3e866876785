// Property-based test of the topology invariants: seeded random sequences of every map operation
// (sew, unsew, unsew of several facets at once as a cut does, insertions of vertices in edges and
// faces, edges and dangling edges in faces, faces in volumes and in holes, removals, contractions,
// new cells) on 2- and 3-maps. After each: validate(); the Betti numbers of topology() against an
// independent computation (cells found through the public traversal API, ranks by dense Gaussian
// elimination over GF(2)); b0 against count_components(), χ against euler_characteristic() and
// Σ(-1)^i b_i; the orientation found against every sew; and what each operation must do:
// insertions keep every Betti number, so do removals between two distinct cells and contractions
// of an edge between two distinct vertices, and a new closed cell adds one component. The seed,
// step and operation are printed on failure so the sequence replays.
#include <doctest/doctest.h>

#include <algorithm>
#include <array>
#include <cstdint>
#include <functional>
#include <random>
#include <string>
#include <vector>

#include "check.hpp"
#include "sewn/cmap/build.hpp"
#include "sewn/cmap/cmap.hpp"
#include "sewn/cmap/topology.hpp"

using namespace sewn;

namespace {

using B = std::array<std::int64_t, 4>;

using test::str;

// Rank over GF(2) of a dense matrix given as columns of bits.
std::int64_t dense_rank(std::vector<std::vector<std::uint64_t>> cols) {
  std::int64_t rank = 0;
  if (cols.empty()) return 0;
  const std::size_t words = cols[0].size();
  for (std::size_t bit = 0; bit < words * 64; ++bit) {
    const std::size_t w = bit / 64;
    const std::uint64_t m = std::uint64_t{1} << (bit % 64);
    std::size_t p = static_cast<std::size_t>(rank);
    while (p < cols.size() && (cols[p][w] & m) == 0) ++p;
    if (p == cols.size()) continue;
    std::swap(cols[p], cols[static_cast<std::size_t>(rank)]);
    const auto& piv = cols[static_cast<std::size_t>(rank)];
    for (std::size_t j = 0; j < cols.size(); ++j)
      if (j != static_cast<std::size_t>(rank) && (cols[j][w] & m) != 0)
        for (std::size_t k = 0; k < words; ++k) cols[j][k] ^= piv[k];
    ++rank;
  }
  return rank;
}

// Betti numbers of the map's own cell complex, from the definition in topology.hpp written
// again with the public traversal API: cells by cells<I>() / cell<I>(), boundaries by walking
// one copy of each cell, incidences counted mod 2 by toggling bits.
template <class Map>
B oracle_betti(const Map& m) {
  constexpr int D = Map::dimension;
  std::array<std::vector<std::uint32_t>, D + 1> id;
  std::array<std::uint32_t, D + 1> n{};
  [&]<int... I>(std::integer_sequence<int, I...>) {
    (
        [&] {
          id[I].assign(m.dart_capacity(), 0);
          for (Dart d : m.template cells<I>()) {
            for (Dart x : m.template cell<I>(d)) id[I][x.index()] = n[I];
            ++n[I];
          }
        }(),
        ...);
  }(std::make_integer_sequence<int, D + 1>{});
  auto column = [&](std::uint32_t rows) { return std::vector<std::uint64_t>(rows / 64 + 1, 0); };
  auto toggle = [](std::vector<std::uint64_t>& c, std::uint32_t r) { c[r / 64] ^= std::uint64_t{1} << (r % 64); };
  std::array<std::vector<std::vector<std::uint64_t>>, D + 1> bd;
  for (Dart d : m.template cells<1>()) {
    auto c = column(n[0]);
    toggle(c, id[0][d.index()]);
    toggle(c, id[0][m.beta(d, 1).index()]);
    bd[1].push_back(std::move(c));
  }
  for (Dart d : m.template cells<2>()) {
    auto c = column(n[1]);
    for (Dart x : m.template orbit<1>(d)) toggle(c, id[1][x.index()]);
    bd[2].push_back(std::move(c));
  }
  if constexpr (D == 3) {
    for (Dart d : m.template cells<3>()) {
      auto c = column(n[2]);
      for (Dart x : m.template orbit<1, 2>(d)) {
        bool smallest = true;
        for (Dart y : m.template orbit<1>(x)) smallest = smallest && y >= x;
        if (smallest) toggle(c, id[2][x.index()]);
      }
      bd[3].push_back(std::move(c));
    }
  }
  std::array<std::int64_t, D + 2> rank{};
  for (int i = 1; i <= D; ++i) rank[static_cast<std::size_t>(i)] = dense_rank(bd[static_cast<std::size_t>(i)]);
  B b{};
  for (int i = 0; i <= D; ++i)
    b[static_cast<std::size_t>(i)] = n[static_cast<std::size_t>(i)] - rank[static_cast<std::size_t>(i)] - rank[static_cast<std::size_t>(i) + 1];
  return b;
}

template <int D>
struct Driver {
  CMap<D> m;
  std::mt19937 rng;
  std::uint32_t max_darts;
  std::int64_t ops_applied = 0;

  Driver(unsigned seed, std::uint32_t max) : rng(seed), max_darts(max) {}

  std::uint32_t uniform(std::uint32_t k) { return std::uniform_int_distribution<std::uint32_t>(0, k - 1)(rng); }
  Dart random_dart() {
    if (m.num_darts() == 0) return null_dart;
    for (;;)
      if (const Dart d(uniform(m.dart_capacity())); m.is_alive(d)) return d;
  }
  template <class P>
  Dart random_dart_where(P pred) {
    for (int t = 0; t < 30; ++t)
      if (const Dart d = random_dart(); d && pred(d)) return d;
    return null_dart;
  }
  std::vector<Dart> face_cycle(Dart a) {
    std::vector<Dart> c;
    Dart x = a;
    do {
      c.push_back(x);
      x = m.beta(x, 1);
    } while (x != a);
    return c;
  }

  // What an operation promises: every Betti number kept, or one more component. A removal or
  // contraction keeps them when the map makes of it what the cell complex does: one i-cell goes
  // and two cells around it become one (counts[i] and counts[j] one less, the other counts as
  // they were). When the cells around would be pinched (two faces left meeting at a single
  // vertex of a 2-map, say), the map splits them instead: no promise then.
  enum class Expect { keep, add_component, keep_if_merged, any };
  int merged_i = 0, merged_j = 0;

  struct Op {
    const char* name;
    std::function<Expect()> run;  // throws nothing; returns any when it did not apply
  };
  std::vector<Op> ops;
  Expect skipped = Expect::any;
  bool applied = false;

  void install() {
    auto done = [this](Expect e) {
      applied = true;
      return e;
    };
    auto skip = [this] {
      applied = false;
      return Expect::any;
    };
    ops.push_back({"insert_vertex_in_edge", [=, this] {
                     if (m.num_darts() > max_darts) return skip();
                     m.insert_vertex_in_edge(random_dart());
                     return done(Expect::keep);
                   }});
    ops.push_back({"insert_edge_in_face", [=, this] {
                     if (m.num_darts() > max_darts) return skip();
                     const Dart a = random_dart();
                     const auto cyc = face_cycle(a);
                     if (cyc.size() < 2) return skip();
                     m.insert_edge_in_face(a, cyc[1 + uniform(static_cast<std::uint32_t>(cyc.size() - 1))]);
                     return done(Expect::keep);
                   }});
    ops.push_back({"insert_vertex_in_face", [=, this] {
                     if (m.num_darts() > max_darts) return skip();
                     const Dart d = random_dart();
                     if (!m.is_insertable_vertex_in_face(d)) return skip();
                     m.insert_vertex_in_face(d);
                     return done(Expect::keep);
                   }});
    ops.push_back({"insert_dangling_edge_in_face", [=, this] {
                     if (m.num_darts() > max_darts) return skip();
                     const Dart d = random_dart();
                     if (!m.is_insertable_dangling_edge_in_face(d)) return skip();
                     m.insert_dangling_edge_in_face(d);
                     return done(Expect::keep);
                   }});
    ops.push_back({"remove_cell<0>", [=, this] {
                     const Dart d = random_dart_where([&](Dart x) { return m.template is_removable<0>(x); });
                     if (!d) return skip();
                     // a vertex between two distinct edges: the space does not change
                     const bool two = !m.template same_cell<1>(d, m.beta(d, 0));
                     m.template remove_cell<0>(d);
                     merged_i = 0;
                     merged_j = 1;
                     return done(two ? Expect::keep_if_merged : Expect::any);
                   }});
    ops.push_back({"remove_cell<D-1>", [=, this] {
                     // a facet between two distinct top cells (a boundary facet would open its cell)
                     const Dart d = random_dart_where([&](Dart x) {
                       return !m.is_free(x, D) && !m.template same_cell<D>(x, m.beta(x, D)) && m.template is_removable<D - 1>(x);
                     });
                     if (!d) return skip();
                     m.template remove_cell<D - 1>(d);
                     merged_i = D - 1;
                     merged_j = D;
                     return done(Expect::keep_if_merged);
                   }});
    ops.push_back({"contract_cell<1>", [=, this] {
                     const Dart d = random_dart_where([&](Dart x) {
                       return m.template is_contractible<1>(x) && m.beta(x, 1) != x && !m.template same_cell<0>(x, m.beta(x, 1));
                     });
                     if (!d) return skip();
                     m.template contract_cell<1>(d);
                     merged_i = 0;
                     merged_j = 1;
                     return done(Expect::keep_if_merged);
                   }});
    ops.push_back({"contract_cell<2>", [=, this] {
                     const Dart d = random_dart_where([&](Dart x) { return m.template is_contractible<2>(x); });
                     if (!d) return skip();
                     m.template contract_cell<2>(d);
                     return done(Expect::any);
                   }});
    ops.push_back({"unsew<D>", [=, this] {
                     const Dart d = random_dart_where([&](Dart x) { return !m.is_free(x, D); });
                     if (!d) return skip();
                     m.template unsew<D>(d);
                     return done(Expect::any);
                   }});
    ops.push_back({"sew<D>", [=, this] {
                     const Dart a = random_dart_where([&](Dart x) { return m.is_free(x, D); });
                     if (!a) return skip();
                     for (int t = 0; t < 30; ++t) {
                       const Dart b = random_dart();
                       if (b != a && m.template is_sewable<D>(a, b)) {
                         m.template sew<D>(a, b);
                         return done(Expect::any);
                       }
                     }
                     return skip();
                   }});
    ops.push_back({"cut (unsew_all<D>)", [=, this] {
                     std::vector<Dart> facets;
                     for (int k = 0; k < 4; ++k)
                       if (const Dart d = random_dart_where([&](Dart x) { return !m.is_free(x, D); })) facets.push_back(d);
                     if (facets.empty()) return skip();
                     m.template unsew_all<D>(facets);
                     return done(Expect::any);
                   }});
    ops.push_back({"new cell", [=, this] {
                     if (m.num_darts() > max_darts) return skip();
                     if constexpr (D == 2) m.make_polygon(3 + uniform(3));
                     else if (uniform(2) == 0) m.make_tetrahedron();
                     else m.make_hexahedron();
                     return done(Expect::add_component);
                   }});
    if constexpr (D == 3)
      ops.push_back({"remove a boundary face, insert_face_in_hole", [=, this] {
                       // the hole's ring is the faces' β2 partners, in reverse order
                       const Dart f = random_dart_where([&](Dart x) { return m.is_free(x, 3); });
                       if (!f) return skip();
                       std::vector<Dart> ring;
                       for (Dart x : face_cycle(f)) {
                         const Dart r = m.beta(x, 2);
                         if (m.template same_cell<2>(r, f) || std::find(ring.begin(), ring.end(), r) != ring.end()) return skip();
                         ring.insert(ring.begin(), r);
                       }
                       auto expected = m.count_all();
                       --expected[2];
                       m.template remove_cell<2>(f);
                       if (m.count_all() == expected) {
                         if (!m.is_insertable_face_in_hole(ring)) {
                           std::string why;
                           for (std::size_t k = 0; k < ring.size(); ++k) {
                             const Dart r = ring[k];
                             why += " r" + std::to_string(r.index()) + (m.is_alive(r) ? "" : " dead") +
                                    (m.is_alive(r) && !m.is_free(r, 2) ? " sewn" : "");
                             if (m.is_alive(r) && !m.template same_cell<0>(m.beta(r, 1), ring[(k + 1) % ring.size()])) why += " vertex";
                             if (m.is_alive(r) && !m.template same_cell<3>(r, ring[0])) why += " volume";
                           }
                           FAIL("the ring left by removing a boundary face cannot be closed:", why);
                         }
                         m.insert_face_in_hole(ring);
                         return done(Expect::keep);
                       }
                       // the face was all that held a vertex, an edge or the volume together
                       // (a pinch): the map split it, and the hole has several rings, each closed
                       // by a face of its own
                       for (Dart r : ring) {
                         if (!m.is_free(r, 2)) continue;
                         std::vector<Dart> sub;
                         Dart x = r;
                         do {
                           sub.push_back(x);
                           Dart y = m.beta(x, 1);
                           while (m.beta(y, 2)) y = m.beta(y, 2, 1);
                           x = y;
                         } while (x != r && sub.size() <= ring.size());
                         if (!m.is_insertable_face_in_hole(sub)) FAIL("a ring of a pinched hole cannot be closed");
                         m.insert_face_in_hole(sub);
                       }
                       return done(Expect::any);
                     }});
    if constexpr (D == 3)
      ops.push_back({"insert_face_in_volume", [=, this] {
                       if (m.num_darts() > max_darts) return skip();
                       const auto cyc = face_cycle(random_dart());
                       if (!m.is_insertable_face_in_volume(cyc)) return skip();
                       m.insert_face_in_volume(cyc);
                       return done(Expect::keep);
                     }});
  }

  B cells_before{};
  std::int64_t pinched = 0, kept = 0;
  Topology last;  // after the previous step
  void check(unsigned seed, std::int64_t step, const char* op, Expect expect, const B& before, bool with_oracle) {
    const std::string what = std::string(op) + ", Betti before " + str(before);
    INFO("seed ", seed, ", step ", step, ", after ", what);
    const auto report = m.validate();
    REQUIRE_MESSAGE(report.ok(), report.str());
    last = topology(m, {{}, false});
    const Topology& t = last;
    const B& b = t.total.betti;
    CHECK(b[0] == static_cast<std::int64_t>(m.count_components()));
    CHECK(t.total.euler == m.euler_characteristic());
    std::int64_t alt = 0;
    for (int i = 0; i <= D; ++i) alt += (i % 2 == 0 ? 1 : -1) * b[static_cast<std::size_t>(i)];
    CHECK(alt == t.total.euler);
    CHECK(std::all_of(b.begin(), b.end(), [](std::int64_t v) { return v >= 0; }));
    const std::string now = str(b) + " cells " + str(t.total.cells) + " before " + str(cells_before);
    INFO("Betti now ", now);
    if (expect == Expect::keep_if_merged) {
      B merged = cells_before;
      --merged[static_cast<std::size_t>(merged_i)];
      --merged[static_cast<std::size_t>(merged_j)];
      if (t.total.cells == merged) expect = Expect::keep;
      else ++pinched;
    }
    if (expect == Expect::keep) {
      ++kept;
      CHECK(b == before);
    }
    if (expect == Expect::add_component) {
      B more = before;
      ++more[0];
      CHECK(b == more);
    }
    // a map is orientable, and the orientation found agrees with every sew
    CHECK(t.orientable);
    std::uint32_t disagree = 0;
    for (Dart x : m.darts())
      if (const Dart y = m.beta(x, D))
        disagree += t.orientation[t.cell_of_dart[D][x.index()]] != t.orientation[t.cell_of_dart[D][y.index()]] ? 1u : 0u;
    CHECK(disagree == 0);
    if (with_oracle) CHECK(b == oracle_betti(m));
  }

  void run(unsigned seed, std::int64_t steps) {
    install();
    last = topology(m, {{}, false});
    for (std::int64_t s = 0; s < steps; ++s) {
      if (m.num_darts() == 0) {
        if constexpr (D == 2) build(m, quad_grid(2 + uniform(2), 2));
        else build(m, hex_grid(2, 1 + uniform(2), 1));
        last = topology(m, {{}, false});
      }
      const B before = last.total.betti;
      cells_before = last.total.cells;
      Op& op = ops[uniform(static_cast<std::uint32_t>(ops.size()))];
      const Expect e = op.run();
      if (!applied) continue;
      ++ops_applied;
      check(seed, s, op.name, e, before, s % 8 == 0);
    }
  }
};

}  // namespace

TEST_CASE("random operation sequences keep the invariants they must (2-maps)") {
  std::int64_t total = 0, kept = 0, pinched = 0;
  for (unsigned seed : {11u, 12u, 13u, 14u, 15u}) {
    Driver<2> d(seed, 200);
    d.run(seed, 18500);
    total += d.ops_applied;
    kept += d.kept;
    pinched += d.pinched;
  }
  MESSAGE("2-map operations applied: ", total, ", of which ", kept, " had to keep every Betti number; ", pinched,
          " removals or contractions pinched");
  CHECK(total >= 50000);
  CHECK(kept >= total / 4);
}

TEST_CASE("random operation sequences keep the invariants they must (3-maps)") {
  std::int64_t total = 0, kept = 0, pinched = 0;
  for (unsigned seed : {21u, 22u, 23u, 24u, 25u}) {
    Driver<3> d(seed, 300);
    d.run(seed, 23000);
    total += d.ops_applied;
    kept += d.kept;
    pinched += d.pinched;
  }
  MESSAGE("3-map operations applied: ", total, ", of which ", kept, " had to keep every Betti number; ", pinched,
          " removals or contractions pinched");
  CHECK(total >= 50000);
  CHECK(kept >= total / 4);
}
