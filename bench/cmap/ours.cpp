// The cmap suite, our side: sewn::CMap<D, std::uint32_t> whose 0-attribute is a node index into
// a separate positions array, the layout physics uses (DESIGN §2). The CGAL side, in
// cgal_lcc.hpp, registers the same cases; see there for how each operation is matched.

#include <map>
#include <memory>
#include <utility>

#include "grids.hpp"
#include "sewn/cmap/build.hpp"
#include "sewn/cmap/cmap.hpp"

namespace sewn::bench::cmap {
namespace {

template <int D>
struct Ours {
  CMap<D, std::uint32_t> map;
  std::vector<Point3> positions;

  explicit Ours(const IndexedMesh& mesh) {
    const BuildResult built = build(map, mesh);
    map.template create_attributes<0>([&](Dart d) { return built.vertex_of_dart[d.index()]; });
    positions = mesh.points;
  }

  // Every heap byte that holds the map and its geometry: β arrays, per-dart attribute indices,
  // the attribute container (values, darts, reference counts, free list), mark planes, and the
  // positions array, all at capacity (slack included). CGAL stores the points inside its
  // vertex attributes, so leaving positions out would flatter us.
  [[nodiscard]] double bytes_per_dart() const {
    const std::size_t bytes = map.memory_bytes() + positions.capacity() * sizeof(Point3);
    return static_cast<double>(bytes) / map.num_darts();
  }

  [[nodiscard]] Counts counts() const {
    Counts c;
    c.darts = map.num_darts();
    const auto n = map.count_all();
    for (int i = 0; i <= D; ++i) c.cells[static_cast<std::size_t>(i)] = n[static_cast<std::size_t>(i)];
    return c;
  }

  // Empty if the map is valid, has the expected counts and one position per vertex.
  [[nodiscard]] std::string check(const Counts& want) const {
    if (const ValidationReport r = map.validate(); !r.ok()) return "invalid map:\n" + r.str(5);
    if (std::string e = mismatch("cell counts", want, counts()); !e.empty()) return e;
    if (positions.size() != want.cells[0])
      return "expected " + std::to_string(want.cells[0]) + " positions, got " + std::to_string(positions.size());
    return {};
  }
};

// The built grid every non-building benchmark starts from, made once per process, and the darts
// the operations apply to, collected outside the timed loops (copying the map keeps indices).
template <int D>
struct Proto {
  Ours<D> ours;
  std::vector<Dart> edges;        // one dart per edge
  std::vector<Dart> faces;        // one dart per face
  std::vector<Dart> plane_faces;  // D = 3: one dart per face of the middle plane
  std::vector<Dart> top_faces;    // D = 3: one dart per boundary face of the top plane
  std::vector<Dart> boundary_faces;  // D = 3: one dart per 3-free face

  explicit Proto(std::uint32_t n) : ours(grid_mesh(D, n)) {
    for (Dart d : ours.map.template cells<1>()) edges.push_back(d);
    for (Dart d : ours.map.template cells<2>()) faces.push_back(d);
    if constexpr (D == 3) {
      auto z_of = [&](Dart d) { return ours.positions[ours.map.value(ours.map.template attribute<0>(d))][2]; };
      auto in_plane = [&](Dart d, double z) {
        bool all = true;
        Dart x = d;
        do {
          all = all && z_of(x) == z;
          x = ours.map.template beta<1>(x);
        } while (x != d);
        return all;
      };
      for (Dart d : faces) {
        if (ours.map.template beta<3>(d).is_null()) boundary_faces.push_back(d);
        if (!ours.map.template beta<3>(d).is_null() && in_plane(d, middle_plane_z(n))) plane_faces.push_back(d);
        if (ours.map.template beta<3>(d).is_null() && in_plane(d, static_cast<double>(n))) top_faces.push_back(d);
      }
    }
  }
};

template <int D>
const Proto<D>& proto(std::uint32_t n) {
  static std::map<std::uint32_t, std::unique_ptr<Proto<D>>> made;
  auto& p = made[n];
  if (!p) p = std::make_unique<Proto<D>>(n);
  return *p;
}

// Checks `work` once per case (key); a failed check marks the run as an error, which fails the
// report.
template <int D>
void check_once(benchmark::State& state, const std::string& key, const Ours<D>& work, const Counts& want) {
  if (!first_time(key)) return;
  if (std::string e = work.check(want); !e.empty()) state.SkipWithError(e.c_str());
}

// Times op(work) on a fresh copy of the prototype each repetition; making the copy and
// prepare(work) are untimed. Returns the last copy, for the check.
template <int D, class Prepare, class Op>
std::unique_ptr<Ours<D>> on_fresh_copies(benchmark::State& state, const Proto<D>& p, Prepare prepare, Op op) {
  std::unique_ptr<Ours<D>> work;
  for (auto _ : state) {
    {
      const Untimed untimed(state);
      work.reset();
      work = std::make_unique<Ours<D>>(p.ours);
      prepare(*work);
    }
    op(*work);
  }
  return work;
}
inline constexpr auto no_preparation = [](auto&) {};

template <int D>
void bench_build(benchmark::State& state, std::uint32_t n, const std::string& key) {
  const IndexedMesh& mesh = grid_mesh(D, n);
  std::unique_ptr<Ours<D>> work;
  for (auto _ : state) {
    {
      const Untimed untimed(state);
      work.reset();  // destroying the previous map is not part of building one
    }
    work = std::make_unique<Ours<D>>(mesh);
  }
  state.counters["bytes/dart"] = work->bytes_per_dart();
  check_once(state, key, *work, built_counts(D, n));
}

template <int D, int I>
void bench_iterate(benchmark::State& state, std::uint32_t n) {
  const auto& map = proto<D>(n).ours.map;
  std::uint64_t cells = 0, sum = 0;
  for (auto _ : state) {
    cells = 0;
    for (Dart d : map.template cells<I>()) {
      sum += d.index();
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
  const auto& map = proto<D>(n).ours.map;
  std::array<std::uint32_t, D + 1> got{};
  for (auto _ : state) {
    got = map.count_all();
    benchmark::DoNotOptimize(got);
  }
  Counts c = built_counts(D, n);
  for (int i = 0; i <= D; ++i) c.cells[static_cast<std::size_t>(i)] = got[static_cast<std::size_t>(i)];
  if (std::string e = mismatch("count_all", built_counts(D, n), c); !e.empty()) state.SkipWithError(e.c_str());
}

template <int D>
void bench_validate(benchmark::State& state, std::uint32_t n) {
  const auto& map = proto<D>(n).ours.map;
  bool ok = false;
  for (auto _ : state) {
    ok = map.validate().ok();
    benchmark::DoNotOptimize(ok);
  }
  if (!ok) state.SkipWithError("validate() reports a valid map as invalid");
}

// The new vertex gets a node and a 0-attribute naming it, as CGAL's insert_barycenter_in_cell
// gives it a point: without them our map would be doing less work than CGAL's. Both give the
// attribute as part of the insertion (CGAL's insert_cell_0_in_cell_1 takes the new vertex's
// attribute and sets it on each dart it makes; ours takes the value).
template <int D>
void bench_split_edges(benchmark::State& state, std::uint32_t n, const std::string& key) {
  const Proto<D>& p = proto<D>(n);
  auto work = on_fresh_copies<D>(state, p, no_preparation, [&](Ours<D>& w) {
    auto& map = w.map;
    auto& pos = w.positions;
    for (Dart d : p.edges) {
      const Point3& a = pos[map.value(map.template attribute<0>(d))];
      const Point3& b = pos[map.value(map.template attribute<0>(map.template beta<1>(d)))];
      const Point3 mid{(a[0] + b[0]) / 2, (a[1] + b[1]) / 2, (a[2] + b[2]) / 2};
      map.insert_vertex_in_edge(d, static_cast<std::uint32_t>(pos.size()));
      pos.push_back(mid);
    }
  });
  check_once(state, key, *work, after_vertex_in_every_edge(built_counts(D, n)));
}

void bench_split_faces(benchmark::State& state, std::uint32_t n, const std::string& key) {
  const Proto<2>& p = proto<2>(n);
  auto work = on_fresh_copies<2>(state, p, no_preparation, [&](Ours<2>& w) {
    for (Dart d : p.faces) w.map.insert_edge_in_face(d, w.map.beta(d, 1, 1));
  });
  check_once(state, key, *work, after_edge_in_every_face(quad_counts(n)));
}

// A vertex that the cut splits gets a node of its own (the split hook copies its position), as
// CGAL's unsew copies the point into the new vertex attribute: this is what a cut must do.
void bench_unsew_plane(benchmark::State& state, std::uint32_t n, const std::string& key) {
  const Proto<3>& p = proto<3>(n);
  auto copy_position = [](Ours<3>& w) {
    w.map.on_split<0>([pw = &w](AttrId<0> orig, AttrId<0> copy) {
      pw->map.value(copy) = static_cast<std::uint32_t>(pw->positions.size());
      pw->positions.push_back(pw->positions[pw->map.value(orig)]);
    });
  };
  auto work = on_fresh_copies<3>(state, p, copy_position, [&](Ours<3>& w) {
    for (Dart d : p.plane_faces) w.map.unsew<3>(d);
  });
  if (p.plane_faces.size() != std::uint64_t{n} * n)
    state.SkipWithError(("found " + std::to_string(p.plane_faces.size()) + " faces in the middle plane").c_str());
  else
    check_once(state, key, *work, after_unsew_middle_plane(n));
}

// The new vertex gets a node at the face's barycentre, as CGAL's insert_barycenter_in_cell<2>
// gives it a point: both pass the new vertex's attribute to the insertion (CGAL's
// insert_cell_0_in_cell_2(d, attribute), ours insert_vertex_in_face(d, value)).
void bench_vertex_in_faces(benchmark::State& state, std::uint32_t n, const std::string& key) {
  const Proto<3>& p = proto<3>(n);
  auto work = on_fresh_copies<3>(state, p, no_preparation, [&](Ours<3>& w) {
    auto& map = w.map;
    auto& pos = w.positions;
    for (Dart d : p.faces) {
      Point3 c{0, 0, 0};
      double k = 0;
      Dart x = d;
      do {
        const Point3& q = pos[map.value(map.attribute<0>(x))];
        for (int i = 0; i < 3; ++i) c[static_cast<std::size_t>(i)] += q[static_cast<std::size_t>(i)];
        k += 1;
        x = map.beta<1>(x);
      } while (x != d);
      map.insert_vertex_in_face(d, static_cast<std::uint32_t>(pos.size()));
      pos.push_back({c[0] / k, c[1] / k, c[2] / k});
    }
  });
  check_once(state, key, *work, after_vertex_in_every_face(hex_counts(n)));
}

// The new vertex gets a node at the position of the vertex the edge hangs from, as CGAL's
// insert_dangling_cell_1_in_cell_2 is given that point. Boundary faces only: on a 3-sewn face
// CGAL 5.5.1 gives the new vertex's attribute to a dart of the old vertex on the far side, and
// its is_valid() then fails (ours handles both sides; see the CGAL twin check).
void bench_dangling_in_faces(benchmark::State& state, std::uint32_t n, const std::string& key) {
  const Proto<3>& p = proto<3>(n);
  auto work = on_fresh_copies<3>(state, p, no_preparation, [&](Ours<3>& w) {
    auto& map = w.map;
    auto& pos = w.positions;
    for (Dart d : p.boundary_faces) {
      const Point3 at = pos[map.value(map.attribute<0>(d))];
      const Dart a = map.insert_dangling_edge_in_face(d);
      map.set_attribute<0>(map.beta<1>(a), static_cast<std::uint32_t>(pos.size()));
      pos.push_back(at);
    }
  });
  check_once(state, key, *work, after_dangling_edge_in_every_boundary_face(n));
}

// Every top boundary face removed (untimed), then each hole closed by insert_face_in_hole on
// the ring of 2-free darts it left: the grid is whole again, and the next iteration reopens the
// holes on the same map (closing them takes microseconds; a fresh copy of the grid per
// iteration would make the run copy it thousands of times). The grid has only n² top faces, so
// holes_per_timing() copies of it are closed per timing, so that the clock's pause and resume
// (about a microsecond) weigh little on either side.
void bench_close_holes(benchmark::State& state, std::uint32_t n, const std::string& key) {
  const Proto<3>& p = proto<3>(n);
  struct Work {
    Ours<3> grid;
    std::vector<Dart> top;
    std::vector<std::vector<Dart>> rings;
  };
  std::vector<std::unique_ptr<Work>> works;
  for (std::uint32_t c = 0; c < copies_for_holes(n); ++c)
    works.push_back(std::make_unique<Work>(Work{p.ours, p.top_faces, {}}));
  for (auto _ : state) {
    {
      const Untimed untimed(state);
      for (auto& w : works) {
        w->rings.clear();
        for (Dart f : w->top) {
          std::vector<Dart> ring;
          Dart x = f;
          do {  // the β2 partners, in reverse order: a path running the other way
            ring.insert(ring.begin(), w->grid.map.beta<2>(x));
            x = w->grid.map.beta<1>(x);
          } while (x != f);
          w->grid.map.remove_cell<2>(f);
          w->rings.push_back(std::move(ring));
        }
      }
    }
    for (auto& w : works)
      for (std::size_t i = 0; i < w->rings.size(); ++i) w->top[i] = w->grid.map.insert_face_in_hole(w->rings[i]);
  }
  if (p.top_faces.size() != std::uint64_t{n} * n)
    state.SkipWithError(("found " + std::to_string(p.top_faces.size()) + " faces in the top plane").c_str());
  else
    check_once(state, key, works.back()->grid, hex_counts(n));
}

template <int D>
void register_grid(std::uint32_t n) {
  const std::string g = grid_name(D, n);
  auto add = [&](const char* operation, auto body) {
    const std::string c = g + "/" + operation;
    ours(suite, c, [n, body, key = c + "/ours"](benchmark::State& s) { body(s, n, key); });
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
    add(op::split_faces, [](benchmark::State& s, std::uint32_t m, const std::string& k) { bench_split_faces(s, m, k); });
  else {
    add(op::unsew_plane, [](benchmark::State& s, std::uint32_t m, const std::string& k) { bench_unsew_plane(s, m, k); });
    add(op::vertex_in_faces,
        [](benchmark::State& s, std::uint32_t m, const std::string& k) { bench_vertex_in_faces(s, m, k); });
    add(op::dangling_in_faces,
        [](benchmark::State& s, std::uint32_t m, const std::string& k) { bench_dangling_in_faces(s, m, k); });
    add(op::close_holes, [](benchmark::State& s, std::uint32_t m, const std::string& k) { bench_close_holes(s, m, k); });
  }
  add(op::validate, [](benchmark::State& s, std::uint32_t m, const std::string&) { bench_validate<D>(s, m); });
}

void register_all() {
  for (std::uint32_t n : hex_sizes(scale())) register_grid<3>(n);
  for (std::uint32_t n : quad_sizes(scale())) register_grid<2>(n);
}

const Registration registration(&register_all);

}  // namespace
}  // namespace sewn::bench::cmap
