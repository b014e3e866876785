// Property-based test of the topology invariants: seeded random sequences of every map operation
// (sew, unsew, unsew of several facets at once as a cut does, insertions of vertices in edges and
// faces, edges and dangling edges in faces, faces in volumes and in holes, removals, contractions,
// new cells) on 2- and 3-maps. After each: validate(); the Betti numbers of topology() against an
// independent computation (cells found through the public traversal API, ranks by dense Gaussian
// elimination over GF(2)); b0 against count_components(), χ against euler_characteristic() and
// Σ(-1)^i b_i; the orientation found against every sew; and what each operation must do:
// insertions keep every Betti number, so do removals between two distinct cells and contractions
// of an edge between two distinct vertices, and a new closed cell adds one component; sewing or
// unsewing one facet whose boundary cells stay as they were (only the facet count changes) moves
// exactly one Betti number by one, b_{D-1} or b_D (see Expect::facet_unsewn: χ does not stay,
// as issue 18 first stated, since a crack inside a body adds a b_{D-1}). The map
// carries a per-dart tag (DartInfo), unique to each dart, checked after every operation against
// a model kept here: a surviving dart keeps its tag, an erased dart's tag is gone (a slot reused
// later starts from 0), a built dart starts from 0, and each dart an insertion makes holds the
// tag of the dart the header's rule names. The seed, step and operation are printed on failure
// so the sequence replays.
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

namespace test_topology_random {

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
  CMap<D, DartInfo<std::uint64_t>> m;
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
  //
  // Unsewing a facet f whose boundary cells are not split (only the facet count grows by one):
  // the map before is, over Z/2, the map after with one D-cell e attached, ∂e = f1 + f2 (the two
  // copies of f share their boundary, so f1 + f2 is a cycle, and the pair (e, f1 + f2) collapses
  // back to f). Attaching a D-cell either fills a (D-1)-cycle (b_{D-1} one less) or closes a
  // D-cycle (b_D one more), nothing else. So the unsew raises b_{D-1} by one or lowers b_D by
  // one, and a sew that only merges two facets does the reverse. (A crack inside a ball adds a
  // b2: χ changes, against issue 18's first statement that unsewing one facet keeps χ.)
  enum class Expect { keep, add_component, keep_if_merged, facet_unsewn, facet_sewn, any };
  int merged_i = 0, merged_j = 0;

  struct Op {
    const char* name;
    std::function<Expect()> run;  // throws nothing; returns any when it did not apply
  };
  std::vector<Op> ops;
  Expect skipped = Expect::any;
  bool applied = false;

  // Per-dart tags. tag_model[slot]: the tag the live dart in that slot must hold, 0 for a slot
  // with no dart. An operation that makes darts says which tags they may hold (new_tags) and
  // how many it makes (new_count, -1: any); a dart it makes that the rule does not allow fails.
  std::vector<std::uint64_t> tag_model;
  std::uint64_t next_tag = 1;
  std::function<std::vector<std::uint64_t>(Dart)> new_tags;
  std::int64_t new_count = -1;
  std::int64_t tag_checks = 0;
  std::uint64_t model_tag(Dart d) const { return d.index() < tag_model.size() ? tag_model[d.index()] : 0; }
  // Builders and make_*: new darts start from the default value.
  void expect_default_tags() {
    new_tags = [](Dart) { return std::vector<std::uint64_t>{0}; };
    new_count = -1;
  }
  // Insertions into the face of d: darts on d's side copy d, those on β3(d)'s side copy β3(d)
  // (D = 3); `side` finds the side of a new dart.
  void expect_face_copies(Dart d, std::int64_t count) {
    const std::uint64_t td = model_tag(d);
    const Dart d3 = D == 3 ? m.beta(d, D) : null_dart;
    const std::uint64_t t3 = d3 ? model_tag(d3) : 0;
    new_tags = [this, d, d3, td, t3](Dart x) {
      if (!d3) return std::vector<std::uint64_t>{td};
      const bool near = m.template same_cell<D>(x, d), far = m.template same_cell<D>(x, d3);
      if (near && far) return std::vector<std::uint64_t>{td, t3};  // a volume sewn to itself
      return std::vector<std::uint64_t>{near ? td : t3};
    };
    new_count = d3 ? 2 * count : count;
  }
  // Faces inserted along path: the new darts β2(path[i]) (and, for a face in a volume, its β3
  // partner) copy path[i]. Called after the insertion, which is what makes β2(path[i]) new.
  void expect_path_copies(const std::vector<Dart>& path, int per_dart) {
    std::vector<std::pair<std::uint32_t, std::uint64_t>> want;
    for (Dart d : path) {
      const Dart p = m.beta(d, 2);
      want.emplace_back(p.index(), model_tag(d));
      if (per_dart == 2) want.emplace_back(m.beta(p, 3).index(), model_tag(d));
    }
    new_tags = [want](Dart x) {
      for (const auto& w : want)
        if (w.first == x.index()) return std::vector<std::uint64_t>{w.second};
      return std::vector<std::uint64_t>{};  // not a dart the rule makes
    };
    new_count = static_cast<std::int64_t>(want.size());
  }
  // Checks every live dart against the model, then gives the new darts fresh tags and forgets
  // the erased ones.
  void check_tags() {
    tag_model.resize(m.dart_capacity(), 0);
    std::int64_t made = 0;
    for (std::uint32_t x = 0; x < tag_model.size(); ++x)
      if (!m.is_alive(Dart(x))) tag_model[x] = 0;
    for (Dart x : m.darts()) {
      const std::uint64_t have = m.info(x);
      if (const std::uint64_t want = tag_model[x.index()]; want != 0) {
        INFO("dart ", x.index());
        CHECK(have == want);
        continue;
      }
      ++made;
      const std::vector<std::uint64_t> allowed = new_tags ? new_tags(x) : std::vector<std::uint64_t>{0};
      INFO("new dart ", x.index(), " holds tag ", have);
      CHECK(std::find(allowed.begin(), allowed.end(), have) != allowed.end());
    }
    if (new_count >= 0) CHECK(made == new_count);
    for (Dart x : m.darts())
      if (tag_model[x.index()] == 0) m.info(x) = tag_model[x.index()] = next_tag++;
    ++tag_checks;
    new_tags = nullptr;
    new_count = 0;  // an operation that makes darts says so
  }

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
                     const Dart d = random_dart();
                     const auto edge = m.template cell<1>(d);
                     m.insert_vertex_in_edge(d);
                     // each new dart follows the dart it was split from in its face
                     new_tags = [this](Dart x) { return std::vector<std::uint64_t>{model_tag(m.beta(x, 0))}; };
                     new_count = static_cast<std::int64_t>(edge.size());
                     return done(Expect::keep);
                   }});
    ops.push_back({"insert_edge_in_face", [=, this] {
                     if (m.num_darts() > max_darts) return skip();
                     const Dart a = random_dart();
                     const auto cyc = face_cycle(a);
                     if (cyc.size() < 2) return skip();
                     expect_face_copies(a, 2);
                     m.insert_edge_in_face(a, cyc[1 + uniform(static_cast<std::uint32_t>(cyc.size() - 1))]);
                     return done(Expect::keep);
                   }});
    ops.push_back({"insert_vertex_in_face", [=, this] {
                     if (m.num_darts() > max_darts) return skip();
                     const Dart d = random_dart();
                     if (!m.is_insertable_vertex_in_face(d)) return skip();
                     expect_face_copies(d, 2 * static_cast<std::int64_t>(face_cycle(d).size()));
                     m.insert_vertex_in_face(d);
                     return done(Expect::keep);
                   }});
    ops.push_back({"insert_dangling_edge_in_face", [=, this] {
                     if (m.num_darts() > max_darts) return skip();
                     const Dart d = random_dart();
                     if (!m.is_insertable_dangling_edge_in_face(d)) return skip();
                     expect_face_copies(d, 2);
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
                     return done(Expect::facet_unsewn);
                   }});
    ops.push_back({"sew<D>", [=, this] {
                     const Dart a = random_dart_where([&](Dart x) { return m.is_free(x, D); });
                     if (!a) return skip();
                     for (int t = 0; t < 30; ++t) {
                       const Dart b = random_dart();
                       if (b != a && m.template is_sewable<D>(a, b)) {
                         m.template sew<D>(a, b);
                         return done(Expect::facet_sewn);
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
                     expect_default_tags();
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
                         check_tags();  // the removal's erased slots may be reused next
                         m.insert_face_in_hole(ring);
                         expect_path_copies(ring, 1);
                         return done(Expect::keep);
                       }
                       // the face was all that held a vertex, an edge or the volume together
                       // (a pinch): the map split it, and the hole has several rings, each closed
                       // by a face of its own
                       check_tags();
                       std::vector<Dart> closed;
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
                         closed.insert(closed.end(), sub.begin(), sub.end());
                       }
                       expect_path_copies(closed, 1);
                       return done(Expect::any);
                     }});
    if constexpr (D == 3)
      ops.push_back({"insert_face_in_volume", [=, this] {
                       if (m.num_darts() > max_darts) return skip();
                       const auto cyc = face_cycle(random_dart());
                       if (!m.is_insertable_face_in_volume(cyc)) return skip();
                       m.insert_face_in_volume(cyc);
                       expect_path_copies(cyc, 2);
                       return done(Expect::keep);
                     }});
  }

  B cells_before{};
  std::int64_t pinched = 0, kept = 0, facet_moves = 0;
  Topology last;  // after the previous step
  void check(unsigned seed, std::int64_t step, const char* op, Expect expect, const B& before, bool with_oracle) {
    const std::string what = std::string(op) + ", Betti before " + str(before);
    INFO("seed ", seed, ", step ", step, ", after ", what);
    const auto report = m.validate();
    REQUIRE_MESSAGE(report.ok(), report.str());
    check_tags();
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
    if (expect == Expect::facet_unsewn || expect == Expect::facet_sewn) {
      const std::int64_t s = expect == Expect::facet_unsewn ? 1 : -1;
      B only_facet = cells_before;
      only_facet[D - 1] += s;
      if (t.total.cells == only_facet) {
        ++facet_moves;
        B crack = before, hole = before;  // for an unsew: a (D-1)-cycle more, or a D-cycle less
        crack[D - 1] += s;
        hole[D] -= s;
        CHECK((b == crack || b == hole));
      }
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
        expect_default_tags();
        check_tags();
        last = topology(m, {{}, false});
      }
      const B before = last.total.betti;
      cells_before = last.total.cells;
      Op& op = ops[uniform(static_cast<std::uint32_t>(ops.size()))];
      new_tags = nullptr;
      new_count = 0;
      const Expect e = op.run();
      if (!applied) continue;
      ++ops_applied;
      check(seed, s, op.name, e, before, s % 8 == 0);
    }
  }
};

}  // namespace

TEST_CASE("random operation sequences keep the invariants they must (2-maps)") {
  std::int64_t total = 0, kept = 0, pinched = 0, tag_checks = 0, facet_moves = 0;
  for (unsigned seed : {11u, 12u, 13u, 14u, 15u}) {
    Driver<2> d(seed, 200);
    d.run(seed, 18500);
    total += d.ops_applied;
    tag_checks += d.tag_checks;
    kept += d.kept;
    pinched += d.pinched;
    facet_moves += d.facet_moves;
  }
  MESSAGE("2-map operations applied: ", total, ", of which ", kept, " had to keep every Betti number; ", pinched,
          " removals or contractions pinched; ", facet_moves, " sews or unsews of one facet moved one Betti number");
  CHECK(total >= 50000);
  CHECK(tag_checks >= total);  // the per-dart tags were checked after every operation
  CHECK(kept >= total / 4);
  CHECK(facet_moves > 0);
}

TEST_CASE("random operation sequences keep the invariants they must (3-maps)") {
  std::int64_t total = 0, kept = 0, pinched = 0, tag_checks = 0, facet_moves = 0;
  for (unsigned seed : {21u, 22u, 23u, 24u, 25u}) {
    Driver<3> d(seed, 300);
    d.run(seed, 23000);
    total += d.ops_applied;
    tag_checks += d.tag_checks;
    kept += d.kept;
    pinched += d.pinched;
    facet_moves += d.facet_moves;
  }
  MESSAGE("3-map operations applied: ", total, ", of which ", kept, " had to keep every Betti number; ", pinched,
          " removals or contractions pinched; ", facet_moves, " sews or unsews of one facet moved one Betti number");
  CHECK(total >= 50000);
  CHECK(tag_checks >= total);  // the per-dart tags were checked after every operation
  CHECK(kept >= total / 4);
  CHECK(facet_moves > 0);
}

namespace {

// Every D-sewn facet of m in turn: unsewn, then sewn back. When the unsew changes no count but
// the facet count (its boundary cells stay shared), one Betti number moves by one, b_{D-1} up or
// b_D down (see Driver::Expect); sewing it back restores the counts and the Betti numbers.
// Returns how many facets were of that kind.
template <int D>
int unsew_and_sew_back_every_facet(CMap<D>& m) {
  std::vector<Dart> facets;
  for (Dart d : m.template cells<D - 1>())
    if (!m.is_free(d, D)) facets.push_back(d);
  const Topology t0 = topology(m, {{}, false});
  int moved = 0;
  for (Dart d : facets) {
    INFO("facet of dart ", d.index());
    const Dart partner = m.beta(d, D);
    m.template unsew<D>(d);
    REQUIRE(m.validate().ok());
    const Topology t = topology(m, {{}, false});
    B only_facet = t0.total.cells;
    ++only_facet[D - 1];
    if (t.total.cells == only_facet) {
      ++moved;
      B crack = t0.total.betti, hole = t0.total.betti;
      ++crack[D - 1];
      --hole[D];
      const std::string got = str(t.total.betti), was = str(t0.total.betti);
      INFO("Betti numbers ", was, " became ", got);
      CHECK((t.total.betti == crack || t.total.betti == hole));
    }
    REQUIRE(m.template is_sewable<D>(d, partner));
    m.template sew<D>(d, partner);
    REQUIRE(m.validate().ok());
    const Topology back = topology(m, {{}, false});
    CHECK(back.total.cells == t0.total.cells);
    CHECK(back.total.betti == t0.total.betti);
  }
  return moved;
}

TEST_CASE("unsewing one facet whose boundary stays shared moves b_{D-1} up or b_D down, not chi") {
  SUBCASE("quads: a 4 x 4 grid (cracks) and the surface of a cube (a slit opens the sphere)") {
    CMap<2> grid;
    build(grid, quad_grid(4, 4));
    CHECK(unsew_and_sew_back_every_facet(grid) == 12);  // the edges between two of the 3 x 3 inner vertices
    IndexedMesh cube;
    cube.points.resize(8);
    for (auto f : cell_faces(CellType::hexahedron)) cube.add_cell(CellType::quad, {f[0], f[1], f[2], f[3]});
    CMap<2> sphere;
    build(sphere, cube);
    REQUIRE(topology(sphere).total.betti == B{1, 0, 1, 0});
    CHECK(unsew_and_sew_back_every_facet(sphere) == 12);
  }
  SUBCASE("hexahedra and tetrahedra") {
    CMap<3> hex;
    build(hex, hex_grid(3, 3, 3));
    CHECK(unsew_and_sew_back_every_facet(hex) > 0);
    CMap<3> tet;
    build(tet, tet_grid(2, 2, 2, TetSplit::kuhn6));
    CHECK(unsew_and_sew_back_every_facet(tet) > 0);
  }
}

}  // namespace

}  // namespace test_topology_random
