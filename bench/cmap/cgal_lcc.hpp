#pragma once
// The cmap suite, CGAL's side: the same cases as ours.cpp run on CGAL's
// Linear_cell_complex_for_combinatorial_map<D> (default items: a point in each vertex
// attribute, no other attribute). Included by one translation unit per dimension, so that the
// two slow CGAL instantiations compile in parallel and never in our own benchmark's unit.
//
// How each operation is matched with ours:
//   build        CGAL's Linear_cell_complex_incremental_builder_3 (one vertex attribute per
//                mesh point, faces added per volume, 2- and 3-sewing found by the builder). It is
//                CGAL's fastest path we know: make_hexahedron from points + sew3_same_facets()
//                was slower when we tried it (it matches faces through std::maps keyed by
//                points) and leaves 8 vertex attributes per hexahedron allocated, 7 of them
//                freed by the merges; CGAL 5.5 has no sew2_same_edges for 2D.
//   iterate      one_dart_per_cell<i>(), using each dart's address as ours uses its index.
//   count_all    count_all_cells().
//   split edges  insert_barycenter_in_cell<1>, which computes the midpoint and gives the new
//                vertex an attribute holding it, as ours gives its vertex a node and position.
//   split faces  insert_cell_1_in_cell_2(d, β1β1(d)), as ours insert_edge_in_face(d, β1β1(d)).
//   unsew plane  unsew<3> on one dart per face of the middle plane; CGAL copies the point of
//                every vertex the cut splits, as our split hook copies the position.
//   validate     is_valid() (combinatorial checks plus "every dart has a vertex attribute").
//   vertex in faces    insert_barycenter_in_cell<2> (insert_cell_0_in_cell_2 plus the point), as
//                ours insert_vertex_in_face plus a node at the barycentre.
//   dangling edges     insert_dangling_cell_1_in_cell_2(d, point of d) on every boundary face,
//                as ours insert_dangling_edge_in_face plus a node at that point (on a 3-sewn
//                face CGAL 5.5.1 gives the point to a wrong dart: is_valid() fails).
//   close holes  insert_cell_2_in_cell_3 on the ring of 2-free darts each removed top face
//                left (the removals untimed), as ours insert_face_in_hole; each iteration
//                reopens the holes on the same maps instead of copying them (closing them takes
//                microseconds, copying a grid milliseconds), in copies_for_holes(n) copies of
//                the grid per timing, so that pausing the clock weighs little on either side.
// Operations that change the map run on a copy of a prototype made before the clock restarts,
// and the darts they apply to are collected on that copy, also untimed.

#include <CGAL/Linear_cell_complex_for_combinatorial_map.h>
#include <CGAL/Linear_cell_complex_incremental_builder.h>
#include <CGAL/version.h>

#include <cstdint>
#include <map>
#include <memory>
#include <string>
#include <utility>
#include <vector>

#include "grids.hpp"

namespace sewn::bench::cmap::cgal {

template <int D>
using Lcc = CGAL::Linear_cell_complex_for_combinatorial_map<D>;

template <int D>
std::string peer_name() {
  return "CGAL " CGAL_VERSION_STR " Linear_cell_complex_for_combinatorial_map<" + std::to_string(D) + ">";
}

template <int D>
struct Peer {
  using Map = Lcc<D>;
  using DartHandle = typename Map::Dart_handle;
  Map lcc;

  explicit Peer(const IndexedMesh& mesh) {
    CGAL::Linear_cell_complex_incremental_builder_3<Map> builder(lcc);
    for (const Point3& p : mesh.points) {
      if constexpr (D == 3)
        builder.add_vertex(typename Map::Point(p[0], p[1], p[2]));
      else
        builder.add_vertex(typename Map::Point(p[0], p[1]));
    }
    auto add_face = [&](auto&& local, std::span<const std::uint32_t> v) {
      builder.begin_facet();
      for (std::uint32_t l : local) builder.add_vertex_to_facet(v[l]);
      builder.end_facet();
    };
    if constexpr (D == 3) {
      for (std::uint32_t c = 0; c < mesh.num_cells(); ++c) {
        builder.begin_surface();
        for (auto face : cell_faces(mesh.types[c])) add_face(face, mesh.cell(c));
        builder.end_surface();
      }
    } else {
      // a 2D complex is one surface; the quads are added with their points in mesh order
      static constexpr std::uint32_t quad[4] = {0, 1, 2, 3};
      builder.begin_surface();
      for (std::uint32_t c = 0; c < mesh.num_cells(); ++c) add_face(quad, mesh.cell(c));
      builder.end_surface();
    }
  }

  // Heap bytes of the map: the dart container and the vertex-attribute container (which holds
  // the points) at capacity, times their element sizes. Each Compact_container block also holds
  // two sentinel elements and the container a vector of block pointers: with block sizes
  // growing by 16, that is under 0.1% at these sizes, and is left out. The marks live in the
  // darts (a bitset each) and the map object's arrays, so nothing else is on the heap.
  [[nodiscard]] double bytes_per_dart() const {
    const std::size_t bytes = lcc.darts().capacity() * sizeof(typename Map::Dart) +
                              lcc.template attributes<0>().capacity() * sizeof(typename Map::Vertex_attribute);
    return static_cast<double>(bytes) / static_cast<double>(lcc.number_of_darts());
  }

  [[nodiscard]] Counts counts() const {
    Counts c;
    c.darts = lcc.number_of_darts();
    const std::vector<unsigned> n = lcc.count_all_cells();
    for (int i = 0; i <= D; ++i) c.cells[static_cast<std::size_t>(i)] = n[static_cast<std::size_t>(i)];
    return c;
  }

  // Empty if the map is valid, has the expected counts and one vertex attribute per vertex.
  [[nodiscard]] std::string check(const Counts& want) const {
    if (!lcc.is_valid()) return "is_valid() is false";
    if (std::string e = mismatch("cell counts", want, counts()); !e.empty()) return e;
    const std::uint64_t points = lcc.template number_of_attributes<0>();
    if (points != want.cells[0])
      return "expected " + std::to_string(want.cells[0]) + " vertex attributes, got " + std::to_string(points);
    return {};
  }

  template <int I>
  std::vector<DartHandle> one_dart_per_cell() {
    std::vector<DartHandle> out;
    for (auto& d : lcc.template one_dart_per_cell<I>()) out.push_back(lcc.darts().iterator_to(d));
    return out;
  }

  // One dart per 3-sewn face whose vertices all lie in the middle plane (D = 3).
  std::vector<DartHandle> middle_plane_faces(std::uint32_t n) { return faces_in_plane(middle_plane_z(n), false); }

  // One dart per face, 3-sewn or 3-free as `free` says, whose vertices all lie in plane z.
  std::vector<DartHandle> faces_in_plane(double z, bool free) {
    std::vector<DartHandle> out;
    for (DartHandle d : one_dart_per_cell<2>()) {
      if (lcc.template is_free<3>(d) != free) continue;
      bool in_plane = true;
      DartHandle x = d;
      do {
        in_plane = in_plane && lcc.point(x).z() == z;
        x = lcc.next(x);
      } while (x != d);
      if (in_plane) out.push_back(d);
    }
    return out;
  }
};

template <int D>
Peer<D>& proto(std::uint32_t n) {
  static std::map<std::uint32_t, std::unique_ptr<Peer<D>>> made;
  auto& p = made[n];
  if (!p) p = std::make_unique<Peer<D>>(grid_mesh(D, n));
  return *p;
}

template <int D>
void check_once(benchmark::State& state, const std::string& key, const Peer<D>& work, const Counts& want) {
  if (!first_time(key)) return;
  if (std::string e = work.check(want); !e.empty()) state.SkipWithError(e.c_str());
}

// Runs op(work, darts) timed on a fresh copy of the prototype, darts = collect(work) untimed.
template <int D, class Collect, class Op>
std::unique_ptr<Peer<D>> on_fresh_copies(benchmark::State& state, std::uint32_t n, Collect collect, Op op) {
  const Peer<D>& p = proto<D>(n);
  std::unique_ptr<Peer<D>> work;
  std::vector<typename Peer<D>::DartHandle> darts;
  for (auto _ : state) {
    {
      const Untimed untimed(state);
      work.reset();
      work = std::make_unique<Peer<D>>(p);
      darts = collect(*work);
    }
    op(work->lcc, darts);
  }
  return work;
}

template <int D>
void bench_build(benchmark::State& state, std::uint32_t n, const std::string& key) {
  const IndexedMesh& mesh = grid_mesh(D, n);
  std::unique_ptr<Peer<D>> work;
  for (auto _ : state) {
    {
      const Untimed untimed(state);
      work.reset();
    }
    work = std::make_unique<Peer<D>>(mesh);
  }
  state.counters["bytes/dart"] = work->bytes_per_dart();
  check_once(state, key, *work, built_counts(D, n));
}

template <int D, int I>
void bench_iterate(benchmark::State& state, std::uint32_t n) {
  auto& lcc = proto<D>(n).lcc;
  std::uint64_t cells = 0, sum = 0;
  for (auto _ : state) {
    cells = 0;
    for (auto& d : lcc.template one_dart_per_cell<I>()) {
      sum += reinterpret_cast<std::uintptr_t>(&d);
      ++cells;
    }
    benchmark::DoNotOptimize(sum);
  }
  const std::uint64_t want = built_counts(D, n).cells[I];
  if (cells != want)
    state.SkipWithError(("expected " + std::to_string(want) + " cells, iterated " + std::to_string(cells)).c_str());
}

template <int D>
void bench_count_all(benchmark::State& state, std::uint32_t n) {
  auto& lcc = proto<D>(n).lcc;
  std::vector<unsigned> got;
  for (auto _ : state) {
    got = lcc.count_all_cells();
    benchmark::DoNotOptimize(got.data());
  }
  Counts c = built_counts(D, n);
  for (int i = 0; i <= D; ++i) c.cells[static_cast<std::size_t>(i)] = got[static_cast<std::size_t>(i)];
  if (std::string e = mismatch("count_all_cells", built_counts(D, n), c); !e.empty()) state.SkipWithError(e.c_str());
}

template <int D>
void bench_validate(benchmark::State& state, std::uint32_t n) {
  auto& lcc = proto<D>(n).lcc;
  bool ok = false;
  for (auto _ : state) {
    ok = lcc.is_valid();
    benchmark::DoNotOptimize(ok);
  }
  if (!ok) state.SkipWithError("is_valid() reports a valid map as invalid");
}

template <int D>
void bench_split_edges(benchmark::State& state, std::uint32_t n, const std::string& key) {
  auto work = on_fresh_copies<D>(
      state, n, [](Peer<D>& w) { return w.template one_dart_per_cell<1>(); },
      [](Lcc<D>& lcc, const auto& edges) {
        for (auto d : edges) lcc.template insert_barycenter_in_cell<1>(d);
      });
  check_once(state, key, *work, after_vertex_in_every_edge(built_counts(D, n)));
}

template <int D>
  requires(D == 2)
void bench_split_faces(benchmark::State& state, std::uint32_t n, const std::string& key) {
  auto work = on_fresh_copies<D>(
      state, n, [](Peer<D>& w) { return w.template one_dart_per_cell<2>(); },
      [](Lcc<D>& lcc, const auto& faces) {
        for (auto d : faces) lcc.insert_cell_1_in_cell_2(d, lcc.template beta<1, 1>(d));
      });
  check_once(state, key, *work, after_edge_in_every_face(quad_counts(n)));
}

template <int D>
  requires(D == 3)
void bench_unsew_plane(benchmark::State& state, std::uint32_t n, const std::string& key) {
  std::size_t found = 0;
  auto work = on_fresh_copies<D>(
      state, n,
      [&](Peer<D>& w) {
        auto faces = w.middle_plane_faces(n);
        found = faces.size();
        return faces;
      },
      [](Lcc<D>& lcc, const auto& faces) {
        for (auto d : faces) lcc.template unsew<3>(d);
      });
  if (found != std::uint64_t{n} * n)
    state.SkipWithError(("found " + std::to_string(found) + " faces in the middle plane").c_str());
  else
    check_once(state, key, *work, after_unsew_middle_plane(n));
}

template <int D>
  requires(D == 3)
void bench_vertex_in_faces(benchmark::State& state, std::uint32_t n, const std::string& key) {
  auto work = on_fresh_copies<D>(
      state, n, [](Peer<D>& w) { return w.template one_dart_per_cell<2>(); },
      [](Lcc<D>& lcc, const auto& faces) {
        for (auto d : faces) lcc.template insert_barycenter_in_cell<2>(d);
      });
  check_once(state, key, *work, after_vertex_in_every_face(hex_counts(n)));
}

template <int D>
  requires(D == 3)
void bench_dangling_in_faces(benchmark::State& state, std::uint32_t n, const std::string& key) {
  auto work = on_fresh_copies<D>(
      state, n,
      [](Peer<D>& w) {
        auto faces = w.template one_dart_per_cell<2>();
        std::erase_if(faces, [&](auto d) { return !w.lcc.template is_free<3>(d); });
        return faces;
      },
      [](Lcc<D>& lcc, const auto& faces) {
        for (auto d : faces) lcc.insert_dangling_cell_1_in_cell_2(d, typename Lcc<D>::Point(lcc.point(d)));
      });
  check_once(state, key, *work, after_dangling_edge_in_every_boundary_face(n));
}

template <int D>
  requires(D == 3)
void bench_close_holes(benchmark::State& state, std::uint32_t n, const std::string& key) {
  // the holes reopened on the same maps each iteration, copies_for_holes(n) of them, as ours
  using Handle = typename Peer<D>::DartHandle;
  struct Work {
    Peer<D> grid;
    std::vector<Handle> top;
    std::vector<std::vector<Handle>> rings;
  };
  std::vector<std::unique_ptr<Work>> works;
  for (std::uint32_t c = 0; c < copies_for_holes(n); ++c) {
    works.push_back(std::make_unique<Work>(Work{proto<D>(n), {}, {}}));
    works.back()->top = works.back()->grid.faces_in_plane(static_cast<double>(n), true);
  }
  const std::size_t found = works.back()->top.size();
  for (auto _ : state) {
    {
      const Untimed untimed(state);
      for (auto& w : works) {
        w->rings.clear();
        for (Handle f : w->top) {
          std::vector<Handle> ring;
          Handle x = f;
          do {  // the β2 partners, in reverse order, as ours
            ring.insert(ring.begin(), w->grid.lcc.template beta<2>(x));
            x = w->grid.lcc.next(x);
          } while (x != f);
          w->grid.lcc.template remove_cell<2>(f);
          w->rings.push_back(std::move(ring));
        }
      }
    }
    for (auto& w : works)
      for (std::size_t i = 0; i < w->rings.size(); ++i)
        w->top[i] = w->grid.lcc.insert_cell_2_in_cell_3(w->rings[i].begin(), w->rings[i].end());
  }
  if (found != std::uint64_t{n} * n)
    state.SkipWithError(("found " + std::to_string(found) + " faces in the top plane").c_str());
  else
    check_once(state, key, works.back()->grid, hex_counts(n));
}

template <int D>
void register_grid(std::uint32_t n) {
  const std::string g = grid_name(D, n);
  auto add = [&](const char* operation, auto body) {
    const std::string c = g + "/" + operation;
    peer(suite, c, peer_name<D>(), [n, body, key = c + "/peer"](benchmark::State& s) { body(s, n, key); });
  };
  add(op::build, [](benchmark::State& s, std::uint32_t m, const std::string& k) { bench_build<D>(s, m, k); });
  [&]<int... I>(std::integer_sequence<int, I...>) {
    (add(op::iterate[I], [](benchmark::State& s, std::uint32_t m, const std::string&) { bench_iterate<D, I>(s, m); }),
     ...);
  }(std::make_integer_sequence<int, D + 1>{});
  add(op::count_all, [](benchmark::State& s, std::uint32_t m, const std::string&) { bench_count_all<D>(s, m); });
  add(op::split_edges,
      [](benchmark::State& s, std::uint32_t m, const std::string& k) { bench_split_edges<D>(s, m, k); });
  if constexpr (D == 2)
    add(op::split_faces, [](benchmark::State& s, std::uint32_t m, const std::string& k) { bench_split_faces<D>(s, m, k); });
  else {
    add(op::unsew_plane, [](benchmark::State& s, std::uint32_t m, const std::string& k) { bench_unsew_plane<D>(s, m, k); });
    add(op::vertex_in_faces,
        [](benchmark::State& s, std::uint32_t m, const std::string& k) { bench_vertex_in_faces<D>(s, m, k); });
    add(op::dangling_in_faces,
        [](benchmark::State& s, std::uint32_t m, const std::string& k) { bench_dangling_in_faces<D>(s, m, k); });
    add(op::close_holes, [](benchmark::State& s, std::uint32_t m, const std::string& k) { bench_close_holes<D>(s, m, k); });
  }
  add(op::validate, [](benchmark::State& s, std::uint32_t m, const std::string&) { bench_validate<D>(s, m); });
}

}  // namespace sewn::bench::cmap::cgal
