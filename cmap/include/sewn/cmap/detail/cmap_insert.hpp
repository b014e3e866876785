#pragma once
// CMap: insertion of a vertex in an edge, an edge in a face, a face in a volume.
// Included by cmap.hpp.

namespace sewn {

template <int D, class... A>
Dart CMap<D, A...>::split_edge(Dart d, detail::DartBuffer<32>& made) {
  check_alive(d, "insert_vertex_in_edge");
  constexpr std::uint32_t null = detail::null_index;
  // 1) the darts of the edge (every dart on it, in every face and volume)
  detail::DartBuffer<32> edge;
  collect_cell_unmarked<1>(d.index(), edge);
  // 2) a new dart after each of them, in its face: x -> x' -> old β1(x)
  new_darts(static_cast<std::uint32_t>(edge.size()), made);
  for (std::size_t i = 0; i < edge.size(); ++i) {
    const std::uint32_t x = edge[i], nx = made[i], next = b(x, 1);
    inherit_attributes(x, nx, ~1u);  // same edge (for now), face, volume...; a new vertex
    copy_info(x, nx);
    raw_link(nx, 1, next);
    raw_link(x, 1, nx);
  }
  // 3) βj partners cross over: if βj(x) = y then βj(x) = y' and βj(x') = y, where y' = β1(y)
  //    is y's new dart (step 2)
  for (std::uint32_t x : edge)
    for (int j = 2; j <= D; ++j) {
      const std::uint32_t y = b(x, j), nx = b(x, 1);
      if (y == null || b(nx, j) != null) continue;
      raw_link(x, j, b(y, 1));
      raw_link(nx, j, y);
    }
  // 4) only the edge splits; the rest was inherited
  if constexpr (has_attribute<1>) {
    detail::DartBuffer<64> touched;
    for (std::uint32_t x : edge) {
      touched.push_back(x);
      touched.push_back(b(x, 1));
      if (const std::uint32_t next = b(b(x, 1), 1); next != null) touched.push_back(next);
    }
    update_attributes(touched, 1u << 1);
  }
  return Dart(b(d.index(), 1));
}

template <int D, class... A>
bool CMap<D, A...>::is_insertable_edge_in_face(Dart a, Dart b2) const {
  if constexpr (D < 2) return false;
  if (!is_alive(a) || !is_alive(b2) || a == b2) return false;
  std::uint32_t x = a.index();
  const std::uint32_t cap = dart_capacity();
  for (std::uint32_t steps = 0; steps <= cap; ++steps) {
    x = b(x, 1);
    if (x == detail::null_index) return false;  // open face
    if (x == a.index()) return false;           // b not on a's cycle
    if (x == b2.index()) break;
  }
  // the cycle must close (a closed face) for every βj-copy to be well defined
  for (std::uint32_t steps = 0; steps <= cap; ++steps) {
    if (x == a.index()) return true;
    x = b(x, 1);
    if (x == detail::null_index) return false;
  }
  return false;
}

template <int D, class... A>
Dart CMap<D, A...>::insert_edge_in_face(Dart a, Dart b2) {
  static_assert(D >= 2, "inserting an edge in a face needs D >= 2");
  if (!is_insertable_edge_in_face(a, b2))
    throw TopologyError("cmap::insert_edge_in_face: darts " + std::to_string(a.index()) + " and " +
                        std::to_string(b2.index()) + " are not two distinct darts of one closed face");
  constexpr std::uint32_t null = detail::null_index;
  // 1) every copy of the face across βj (j ≥ 3), with the darts starting at a's and b's
  //    vertices in that copy; a copy reached by an odd number of βj is reversed.
  struct Copy {
    std::uint32_t a, b;      // images of a and b under the βj path (for the BFS)
    std::uint32_t c1, c2;    // darts of this copy starting at the vertices of a and b
    bool flipped;
    std::uint32_t n1 = null, n2 = null;
    std::array<std::uint32_t, D + 1> next{};  // copy index reached by βj (j ≥ 3), or null
  };
  boost::container::small_vector<Copy, 2> copies;
  auto add_copy = [&](std::uint32_t ca, std::uint32_t cb, bool flipped) {
    copies.push_back({ca, cb, flipped ? b(ca, 1) : ca, flipped ? b(cb, 1) : cb, flipped});
    copies.back().next.fill(null);
  };
  add_copy(a.index(), b2.index(), false);
  if constexpr (D >= 3) {
    const Mark seen = marks_.reserve();
    const MarkView mk = marks_.view(seen);
    mk.set(a.index());
    for (std::size_t k = 0; k < copies.size(); ++k)
      for (int j = 3; j <= D; ++j) {
        const std::uint32_t ja = b(copies[k].a, j), jb = b(copies[k].b, j);
        if (ja == null || jb == null) continue;
        if (mk.set(ja)) add_copy(ja, jb, !copies[k].flipped);
        copies[k].next[static_cast<std::size_t>(j)] = static_cast<std::uint32_t>(
            std::find_if(copies.begin(), copies.end(), [&](const Copy& c) { return c.a == ja; }) - copies.begin());
      }
    for (const Copy& c : copies) mk.clear(c.a);
    marks_.release(seen);
  }
  // 2) in each copy, n1 (c1 -> c2 vertices) closes the face holding c2, n2 the one holding c1
  for (auto& c : copies) {
    const std::uint32_t p1 = b(c.c1, 0), p2 = b(c.c2, 0);
    c.n1 = new_dart();
    c.n2 = new_dart();
    inherit_attributes(c.c1, c.n1, ~2u);  // n1 starts at c1's vertex; the new edge has no attribute
    inherit_attributes(c.c1, c.n2, ~3u);
    inherit_attributes(c.c2, c.n2, 1u);
    copy_info(c.a, c.n1);
    copy_info(c.a, c.n2);
    raw_link(p1, 1, c.n1);
    raw_link(c.n1, 1, c.c2);
    raw_link(p2, 1, c.n2);
    raw_link(c.n2, 1, c.c1);
    raw_link(c.n1, 2, c.n2);
  }
  // 3) βj between copies: n1 of one copy faces n2 of the next (opposite orientation)
  for (const Copy& c : copies)
    for (int j = 3; j <= D; ++j) {
      const std::uint32_t l = c.next[static_cast<std::size_t>(j)];
      if (l == null) continue;
      raw_link(c.n1, j, copies[l].n2);
      raw_link(c.n2, j, copies[l].n1);
    }
  // 4) only the face splits; the rest was inherited
  if constexpr (has_attribute<2>) {
    detail::DartBuffer<64> touched;
    for (const Copy& c : copies)
      for (std::uint32_t x : {c.c1, c.n1, c.n2, c.c2, b(c.n1, 0), b(c.n2, 0)}) touched.push_back(x);
    update_attributes(touched, 1u << 2);
  }
  return Dart(copies[0].n1);
}

template <int D, class... A>
bool CMap<D, A...>::is_insertable_face_in_volume(std::span<const Dart> path) const {
  if constexpr (D < 3) return false;
  if (path.empty()) return false;
  for (Dart d : path) {
    if (!is_alive(d)) return false;
    for (int j = 4; j <= D; ++j)
      if (b(d.index(), j) != detail::null_index) return false;
  }
  if (chained_in_one_volume(path)) {
    // one volume and a closed chain, proved without walking the volume; distinct edges left
    for (std::size_t k = 0; k < path.size(); ++k)
      for (std::size_t l = 0; l < k; ++l)
        if (same_cell<1>(path[l], path[k])) return false;
    return true;
  }
  // one volume
  const DartList vol = cell<3>(path[0]);
  auto in_volume = [&](Dart d) { return std::find(vol.begin(), vol.end(), d) != vol.end(); };
  for (Dart d : path)
    if (!in_volume(d)) return false;
  // closed chain: each dart ends where the next starts (within the volume), distinct edges
  for (std::size_t k = 0; k < path.size(); ++k) {
    const std::uint32_t end = b(path[k].index(), 1);
    if (end == detail::null_index) return false;
    const Dart next = path[(k + 1) % path.size()];
    if (!same_cell<0>(Dart(end), next)) return false;
    for (std::size_t l = 0; l < k; ++l)
      if (same_cell<1>(path[l], path[k])) return false;
  }
  return true;
}

// The usual case, decided from the path's ends alone: each next dart is met turning around the
// vertex where the previous one ends, inside its volume (β1 then β2∘β1 steps stay at that
// vertex and in that volume), so all share one volume and the chain closes. False when a turn
// meets a free β1 or β2 or closes without meeting the next dart (a vertex the volume touches in
// several cones, say): the caller then walks the volume.
template <int D, class... A>
bool CMap<D, A...>::chained_in_one_volume(std::span<const Dart> path) const {
  constexpr std::uint32_t null = detail::null_index;
  const std::uint32_t cap = dart_capacity();
  for (std::size_t k = 0; k < path.size(); ++k) {
    const std::uint32_t first = b(path[k].index(), 1), next = path[(k + 1) % path.size()].index();
    if (first == null) return false;
    std::uint32_t y = first;
    for (std::uint32_t steps = 0; y != next; ++steps) {
      const std::uint32_t y2 = b(y, 2);
      if (y2 == null || steps > cap) return false;
      y = b(y2, 1);
      if (y == null || y == first) return false;
    }
  }
  return true;
}

template <int D, class... A>
Dart CMap<D, A...>::insert_face_in_volume(std::span<const Dart> path) {
  static_assert(D >= 3, "inserting a face in a volume needs D >= 3");
  if (!is_insertable_face_in_volume(path))
    throw TopologyError("cmap::insert_face_in_volume: the " + std::to_string(path.size()) +
                        " darts are not a closed chain of distinct edges of one volume");
  constexpr std::uint32_t null = detail::null_index;
  const std::size_t k = path.size();
  // Path dart d_i goes v_i -> v_{i+1}. New face: p_i (v_{i+1} -> v_i) on d's side and
  // q_i (v_i -> v_{i+1}) on the side of e_i = old β2(d_i), with β3(p_i) = q_i.
  std::vector<std::uint32_t> p(k), q(k), e(k);
  detail::DartBuffer<64> touched;
  for (std::size_t i = 0; i < k; ++i) {
    p[i] = new_dart();
    q[i] = new_dart();
    e[i] = b(path[i].index(), 2);
    // p_i, q_i lie on d_i's edge and in its volume (q_i's side is split off later if needed);
    // the new face has no attribute; vertices come from the path's ends.
    inherit_attributes(path[i].index(), p[i], ~5u);
    inherit_attributes(path[i].index(), q[i], ~5u);
    inherit_attributes(path[i].index(), q[i], 1u);
    inherit_attributes(path[(i + 1) % k].index(), p[i], 1u);
    copy_info(path[i].index(), p[i]);
    copy_info(path[i].index(), q[i]);
  }
  for (std::size_t i = 0; i < k; ++i) {
    raw_link(p[i], 1, p[(i + k - 1) % k]);
    raw_link(q[i], 1, q[(i + 1) % k]);
    raw_link(p[i], 3, q[i]);
    raw_link(path[i].index(), 2, p[i]);
    if (e[i] != null) raw_link(e[i], 2, q[i]);
    for (std::uint32_t x : {path[i].index(), p[i], q[i]}) touched.push_back(x);
    if (e[i] != null) touched.push_back(e[i]);
  }
  update_attributes(touched, 1u << 3);  // only the volume may split; the rest was inherited
  return Dart(p[0]);
}


template <int D, class... A>
bool CMap<D, A...>::is_insertable_face_in_hole(std::span<const Dart> path) const {
  if constexpr (D < 3) return false;
  if (path.empty()) return false;
  for (std::size_t k = 0; k < path.size(); ++k) {
    const Dart d = path[k];
    if (!is_alive(d) || b(d.index(), 2) != detail::null_index) return false;
    for (int j = 4; j <= D; ++j)
      if (b(d.index(), j) != detail::null_index) return false;
    for (std::size_t l = 0; l < k; ++l)
      if (path[l] == d) return false;
  }
  // Usual case, without walking the volume: each next dart is the first 2-free dart met turning
  // around the vertex where the previous one ends, inside its volume (β1 then β2∘β1 steps stay
  // at that vertex and in that volume), so all share one volume and the chain closes.
  const std::uint32_t cap = dart_capacity();
  bool chained = true;
  for (std::size_t k = 0; chained && k < path.size(); ++k) {
    std::uint32_t y = b(path[k].index(), 1);
    for (std::uint32_t steps = 0; y != detail::null_index && b(y, 2) != detail::null_index && steps <= cap; ++steps)
      y = b(b(y, 2), 1);
    chained = y == path[(k + 1) % path.size()].index();
  }
  if (chained) return true;
  const DartList vol = cell<3>(path[0]);
  for (std::size_t k = 0; k < path.size(); ++k) {
    if (std::find(vol.begin(), vol.end(), path[k]) == vol.end()) return false;
    const std::uint32_t end = b(path[k].index(), 1);
    if (end == detail::null_index || !same_cell<0>(Dart(end), path[(k + 1) % path.size()])) return false;
  }
  return true;
}

template <int D, class... A>
Dart CMap<D, A...>::insert_face_in_hole(std::span<const Dart> path) {
  static_assert(D >= 3, "closing a hole of a volume with a face needs D >= 3");
  if (!is_insertable_face_in_hole(path))
    throw TopologyError("cmap::insert_face_in_hole: the " + std::to_string(path.size()) +
                        " darts are not a closed chain of distinct 2-free darts of one volume");
  const std::size_t k = path.size();
  // Path dart d_i goes v_i -> v_{i+1}; the new dart p_i goes v_{i+1} -> v_i, β2(d_i) = p_i. It
  // lies on d_i's edge and in its volume and starts at d_{i+1}'s vertex: every cell it joins
  // already exists, so attributes are inherited and nothing merges.
  detail::DartBuffer<32> p;
  new_darts(static_cast<std::uint32_t>(k), p);
  for (std::size_t i = 0; i < k; ++i) {
    inherit_new<~5u>(path[i].index(), p[i]);
    inherit_new<1u>(path[(i + 1) % k].index(), p[i]);
    copy_info(path[i].index(), p[i]);
  }
  for (std::size_t i = 0; i < k; ++i) {
    raw_link(p[i], 1, p[(i + k - 1) % k]);
    raw_link(path[i].index(), 2, p[i]);
  }
  return Dart(p[0]);
}

// The face of a dart and its copies across βj (j ≥ 3): copy q's darts are darts[q·k + i],
// aligned so that position i of every copy lies on the edge of the i-th dart of the face's cycle
// from d. A copy reached by an odd number of βj runs the other way (flipped): its β1 goes from
// position i to i-1. next[q][j] is the copy that βj takes copy q to, or null.
template <int D, class... A>
struct CMap<D, A...>::FaceCopies {
  std::uint32_t k = 0;
  boost::container::small_vector<std::uint32_t, 16> darts;
  boost::container::small_vector<bool, 2> flipped;
  boost::container::small_vector<std::array<std::uint32_t, D + 1>, 2> next;
  [[nodiscard]] std::size_t copies() const { return flipped.size(); }
};

template <int D, class... A>
bool CMap<D, A...>::face_copies(std::uint32_t d, FaceCopies& out) const {
  constexpr std::uint32_t null = detail::null_index;
  if (!is_alive(Dart(d))) return false;
  const std::uint32_t cap = dart_capacity();
  std::uint32_t x = d;
  do {
    out.darts.push_back(x);
    x = b(x, 1);
    if (x == null || out.darts.size() > cap) return false;  // an open face
  } while (x != d);
  const auto k = static_cast<std::uint32_t>(out.darts.size());
  if (k < 2) return false;
  out.k = k;
  std::array<std::uint32_t, D + 1> none;
  none.fill(null);
  out.flipped.push_back(false);
  out.next.push_back(none);
  if constexpr (D >= 3) {
    // breadth-first over the copies; βj maps whole closed cycles to whole cycles (valid links),
    // so a copy is new unless its position-0 image is already listed
    for (std::size_t q = 0; q < out.copies(); ++q)
      for (int j = 3; j <= D; ++j) {
        const std::uint32_t img = b(out.darts[q * k], j);
        if (img == null) continue;
        const auto at = static_cast<std::size_t>(std::find(out.darts.begin(), out.darts.end(), img) - out.darts.begin());
        if (at < out.darts.size() && at % k != 0) return false;  // the face is sewn to itself
        std::size_t r = at / k;
        if (at == out.darts.size()) {
          r = out.copies();
          for (std::uint32_t i = 0; i < k; ++i) {
            const std::uint32_t y = b(out.darts[q * k + i], j);
            if (y == null) return false;
            out.darts.push_back(y);
          }
          out.flipped.push_back(!out.flipped[q]);
          out.next.push_back(none);
        }
        out.next[q][static_cast<std::size_t>(j)] = static_cast<std::uint32_t>(r);
      }
  }
  return true;
}

template <int D, class... A>
bool CMap<D, A...>::is_insertable_vertex_in_face(Dart d) const {
  if constexpr (D < 2) return false;
  FaceCopies fc;
  return face_copies(d.index(), fc);
}

template <int D, class... A>
Dart CMap<D, A...>::star_face(Dart d, detail::DartBuffer<32>& centre) {
  FaceCopies fc;
  if (D < 2 || !face_copies(d.index(), fc))
    throw TopologyError("cmap::insert_vertex_in_face: the face of dart " + std::to_string(d.index()) +
                        " is not a closed cycle of at least two darts, or is sewn to itself");
  const std::uint32_t k = fc.k;
  const std::size_t copies = fc.copies();
  // Dart c_i of a copy runs V_i -> V_{i+1} (flipped: V_{i+1} -> V_i) and becomes triangle i with
  // the centre v: x_i on the edge {V_{i+1}, v}, y_i on {V_i, v}. Unflipped, c_i -> x_i -> y_i
  // (x_i leaves V_{i+1}, y_i leaves v); flipped, c_i -> y_i -> x_i (y_i leaves V_i, x_i leaves
  // v). Either way β2(x_i) = y_{i+1} inside a copy, and βj pairs x with x and y with y at the
  // same position across copies.
  detail::DartBuffer<64> made;
  new_darts(static_cast<std::uint32_t>(2 * k * copies), made);
  auto X = [&](std::size_t q, std::uint32_t i) { return made[2 * (q * k + i)]; };
  auto Y = [&](std::size_t q, std::uint32_t i) { return made[2 * (q * k + i) + 1]; };
  constexpr unsigned above_faces = ~7u;  // volumes and higher: each new dart's copy's own
  for (std::size_t q = 0; q < copies; ++q) {
    const bool flip = fc.flipped[q];
    const std::uint32_t* c = &fc.darts[q * k];
    for (std::uint32_t i = 0; i < k; ++i) {
      const std::uint32_t x = X(q, i), y = Y(q, i), ci = c[i];
      // the new dart after c_i starts where the old β1(c_i) starts; the other one at v
      const std::uint32_t after = flip ? y : x, at_centre = flip ? x : y;
      const std::uint32_t old_next = c[flip ? (i + k - 1) % k : (i + 1) % k];
      inherit_new<above_faces>(ci, x);
      inherit_new<above_faces>(ci, y);
      inherit_new<1u>(old_next, after);
      copy_info(c[0], x);
      copy_info(c[0], y);
      raw_link(ci, 1, after);
      raw_link(after, 1, at_centre);
      raw_link(at_centre, 1, ci);
      raw_link(x, 2, Y(q, (i + 1) % k));
      centre.push_back(at_centre);
      for (int j = 3; j <= D; ++j)
        if (const std::uint32_t r = fc.next[q][static_cast<std::size_t>(j)]; r != detail::null_index) {
          raw_link(x, j, X(r, i));
          raw_link(y, j, Y(r, i));
        }
    }
  }
  // The face splits into k triangles: triangle 0 (holding d) keeps the attribute, each other
  // one gets a copy of it on all its darts, in every copy of the face; the hooks run last.
  if constexpr (has_attribute<2>) {
    auto& st = store<2>();
    const std::uint32_t orig = st.of_dart[d.index()];
    if (orig != detail::null_index) {
      boost::container::small_vector<std::uint32_t, 8> split;
      for (std::uint32_t i = 0; i < k; ++i) {
        const std::uint32_t a = i == 0 ? orig : copy_attribute<2>(orig);
        for (std::size_t q = 0; q < copies; ++q) {
          st.of_dart[fc.darts[q * k + i]] = a;
          st.of_dart[X(q, i)] = a;
          st.of_dart[Y(q, i)] = a;
        }
        st.values.add_count(a, static_cast<std::int64_t>(i == 0 ? 2 * copies : 3 * copies));
        st.values.set_dart(a, fc.darts[i]);
        if (i != 0) split.push_back(a);
      }
      st.values.add_count(orig, -static_cast<std::int64_t>((k - 1) * copies));
      if (hooks_on_ && st.on_split)
        for (std::uint32_t a : split) st.on_split(AttrId<2>(orig), AttrId<2>(a));
    }
  }
  return Dart(Y(0, 1));
}

template <int D, class... A>
bool CMap<D, A...>::is_insertable_dangling_edge_in_face(Dart d) const {
  if constexpr (D < 2 || D > 3) return false;
  return is_alive(d) && b(d.index(), 0) != detail::null_index;
}

template <int D, class... A>
Dart CMap<D, A...>::insert_dangling_edge_in_face(Dart d) {
  static_assert(D == 2 || D == 3, "a dangling edge in a face is inserted in 2- and 3-maps");
  if (!is_insertable_dangling_edge_in_face(d))
    throw TopologyError("cmap::insert_dangling_edge_in_face: dart " + std::to_string(d.index()) +
                        (is_alive(d) ? " has no β0 (an open face)" : " is not a live dart"));
  // In d's face: β0(d) -> a (s -> v) -> b (v -> s) -> d, with s = d's start and v the new vertex.
  // On the other side d3 = β3(d) ends at s: d3 -> a3 (s -> v) -> b3 (v -> s) -> old β1(d3), with
  // β3(a) = b3 and β3(b) = a3, which keeps β1∘β3 = β3∘β0.
  const std::uint32_t x = d.index(), p = b(x, 0);
  const std::uint32_t a = new_dart(), bb = new_dart();
  inherit_attributes(x, a, ~3u);
  inherit_attributes(x, a, 1u);
  inherit_attributes(x, bb, ~3u);
  copy_info(x, a);
  copy_info(x, bb);
  raw_link(p, 1, a);
  raw_link(a, 1, bb);
  raw_link(bb, 1, x);
  raw_link(a, 2, bb);
  if constexpr (D == 3) {
    if (const std::uint32_t x3 = b(x, 3); x3 != detail::null_index) {
      const std::uint32_t n3 = b(x3, 1);
      const std::uint32_t a3 = new_dart(), b3 = new_dart();
      inherit_attributes(x3, a3, ~3u);
      inherit_attributes(x, a3, 1u);
      inherit_attributes(x3, b3, ~3u);
      copy_info(x3, a3);
      copy_info(x3, b3);
      raw_link(x3, 1, a3);
      raw_link(a3, 1, b3);
      raw_link(b3, 1, n3);
      raw_link(a3, 2, b3);
      raw_link(a, 3, b3);
      raw_link(bb, 3, a3);
    }
  }
  return Dart(a);
}

}  // namespace sewn
