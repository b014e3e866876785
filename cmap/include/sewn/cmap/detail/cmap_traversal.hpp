#pragma once
// CMap: orbits, cells, incidence, adjacency and counting. Included by cmap.hpp.

namespace sewn {

namespace detail {
// Lets walks append raw indices to DartList, DartBuffer and std::vector<uint32_t> alike.
inline std::uint32_t raw(std::uint32_t x) { return x; }
inline std::uint32_t raw(Dart d) { return d.index(); }
}  // namespace detail


template <int D, class... A>
template <unsigned Mask, class F>
void CMap<D, A...>::for_each_neighbor(std::uint32_t x, F&& f) const {
  constexpr std::uint32_t null = detail::null_index;
  if constexpr (Mask == vertex_orbit) {
    // Darts starting at the same vertex: β1∘βj, βj∘β0 and βk∘βj (j ≠ k, both ≥ 2).
    const std::uint32_t x0 = b(x, 0);
    for (int j = 2; j <= D; ++j) {
      const std::uint32_t y = b(x, j);
      if (y != null) {
        if (const std::uint32_t z = b(y, 1); z != null) f(z);
        for (int k = 2; k <= D; ++k)
          if (k != j)
            if (const std::uint32_t z = b(y, k); z != null) f(z);
      }
      if (x0 != null)
        if (const std::uint32_t z = b(x0, j); z != null) f(z);
    }
  } else {
    if constexpr ((Mask & 2u) != 0) {
      if (const std::uint32_t y = b(x, 0); y != null) f(y);
      if (const std::uint32_t y = b(x, 1); y != null) f(y);
    }
    for (int j = 2; j <= D; ++j)
      if (((Mask >> j) & 1u) != 0)
        if (const std::uint32_t y = b(x, j); y != null) f(y);
  }
}

template <int D, class... A>
template <unsigned Mask, class Out>
void CMap<D, A...>::expand(std::size_t head, MarkView mk, Out& out) const {
  // `out` doubles as the BFS queue: darts are appended once, when first marked.
  while (head < out.size()) {
    const std::uint32_t x = detail::raw(out[head++]);
    for_each_neighbor<Mask>(x, [&](std::uint32_t y) {
      if (mk.set(y)) out.push_back(typename Out::value_type(y));
    });
  }
}

template <int D, class... A>
template <unsigned Mask, class Out>
void CMap<D, A...>::walk(std::uint32_t root, MarkView mk, Out& out) const {
  const std::size_t head = out.size();
  if (!mk.set(root)) return;
  out.push_back(typename Out::value_type(root));
  expand<Mask>(head, mk, out);
}

template <int D, class... A>
template <class Out>
void CMap<D, A...>::walk_chain(std::uint32_t x, MarkView mk, Out& out) const {
  // x's β1 cycle, or both directions of its β1 path when the face is open
  if (!mk.set(x)) return;
  out.push_back(typename Out::value_type(x));
  std::uint32_t y = b(x, 1);
  for (; y != detail::null_index && mk.set(y); y = b(y, 1)) out.push_back(typename Out::value_type(y));
  if (y != detail::null_index) return;  // closed (back at a marked dart)
  for (y = b(x, 0); y != detail::null_index && mk.set(y); y = b(y, 0)) out.push_back(typename Out::value_type(y));
}

template <int D, class... A>
template <int I, class Out>
void CMap<D, A...>::walk_cell(std::uint32_t root, MarkView mk, Out& out) const {
  constexpr std::uint32_t null = detail::null_index;
  using V = typename Out::value_type;
  const std::size_t first = out.size();
  if constexpr (I == 1 && D <= 3) {
    // ⟨β2, β3⟩: an alternating path or cycle through the edge
    if (!mk.set(root)) return;
    out.push_back(V(root));
    if constexpr (D >= 2) {
      int j = 2;
      std::uint32_t x = root;
      bool closed = false;
      for (std::uint32_t y = b(x, j); y != null; y = b(x, j)) {
        if (!mk.set(y)) {
          closed = true;
          break;
        }
        out.push_back(V(y));
        x = y;
        if constexpr (D == 3) j = 5 - j;
      }
      if constexpr (D == 3)
        if (!closed)
          for (std::uint32_t y = b(root, 3), jj = 2; y != null && mk.set(y); y = b(y, static_cast<int>(jj)), jj = 5 - jj)
            out.push_back(V(y));
    }
  } else if constexpr (I == D && D <= 3) {
    // D-cell: β1 chains joined by β_j, j < D
    walk_chain(root, mk, out);
    for (std::size_t h = first; h < out.size(); ++h)
      for (int j = 2; j < D; ++j)
        if (const std::uint32_t y = b(detail::raw(out[h]), j); y != null && !mk.test(y)) walk_chain(y, mk, out);
  } else if constexpr (I == 2 && D == 3) {
    // a face: its β1 chain and the chain of its β3 partner
    walk_chain(root, mk, out);
    for (std::size_t h = first; h < out.size(); ++h)
      if (const std::uint32_t y = b(detail::raw(out[h]), 3); y != null && !mk.test(y)) walk_chain(y, mk, out);
  } else if constexpr (I == 0 && D == 2) {
    // ⟨β1∘β2⟩: around the vertex forward, then backward by β2∘β0 if the vertex is open
    if (!mk.set(root)) return;
    out.push_back(V(root));
    auto fwd = [&](std::uint32_t x) { const std::uint32_t t = b(x, 2); return t == null ? null : b(t, 1); };
    auto bwd = [&](std::uint32_t x) { const std::uint32_t t = b(x, 0); return t == null ? null : b(t, 2); };
    std::uint32_t y = fwd(root);
    for (; y != null && mk.set(y); y = fwd(y)) out.push_back(V(y));
    if (y == null)
      for (y = bwd(root); y != null && mk.set(y); y = bwd(y)) out.push_back(V(y));
  } else if constexpr (I == 0 && D == 3) {
    // Darts starting at the vertex, by the maps f_j = β1∘βj and g_j = βj∘β0 = f_j⁻¹ (j = 2, 3).
    // 1) Around an interior vertex f_2 and f_3 are defined on every dart; the darts they reach
    //    then form the whole orbit (an injective self-map of a finite set is onto, so the
    //    inverses stay inside too, and so do the compositions of step 2).
    // 2) Near a boundary, add g_2 and g_3: when every dart reached has a β0, and a β1 after its
    //    β2 and β3, each βk∘βj = g_k∘f_j is reached too, so these four maps give the orbit.
    // 3) Otherwise (open faces) the generic search, from the darts found so far.
    if (!mk.set(root)) return;
    out.push_back(V(root));
    auto step = [&](std::uint32_t y) {
      if (mk.set(y)) out.push_back(V(y));
    };
    std::size_t h = first;
    for (; h < out.size(); ++h) {
      const std::uint32_t x = detail::raw(out[h]);
      const std::uint32_t s2 = b(x, 2), s3 = b(x, 3);
      if (s2 == null || s3 == null) break;
      const std::uint32_t y = b(s2, 1), z = b(s3, 1);
      if (y == null || z == null) break;
      step(y);
      step(z);
    }
    if (h == out.size()) return;
    for (h = first; h < out.size(); ++h) {
      const std::uint32_t x = detail::raw(out[h]);
      const std::uint32_t x0 = b(x, 0);
      if (x0 == null) break;
      bool open = false;
      for (int j = 2; j <= 3; ++j)
        if (const std::uint32_t s = b(x, j); s != null) {
          const std::uint32_t y = b(s, 1);
          if (y == null) open = true;
          else step(y);
        }
      if (open) break;
      if (const std::uint32_t y = b(x0, 2); y != null) step(y);
      if (const std::uint32_t y = b(x0, 3); y != null) step(y);
    }
    if (h == out.size()) return;
    expand<vertex_orbit>(first, mk, out);
  } else {
    walk<cell_mask<I>>(root, mk, out);
  }
}

template <int D, class... A>
template <int I, class Out>
void CMap<D, A...>::collect_cell(std::uint32_t root, Mark m, Out& out) const {
  const std::size_t first = out.size();
  walk_cell<I>(root, marks_.view(m), out);
  marks_.add_count(m, static_cast<std::int64_t>(out.size() - first));
}

template <int D, class... A>
template <unsigned Mask, class Out>
void CMap<D, A...>::collect_unmarked(std::uint32_t root, Out& out) const {
  const std::size_t first = out.size();
  const Mark m = marks_.reserve();
  const MarkView mk = marks_.view(m);
  walk<Mask>(root, mk, out);
  for (std::size_t i = first; i < out.size(); ++i) mk.clear(detail::raw(out[i]));
  marks_.release(m);
}

template <int D, class... A>
template <int I, class Out>
void CMap<D, A...>::collect_cell_unmarked(std::uint32_t root, Out& out) const {
  if constexpr (D == 3 && I == 1) {
    // The darts of an edge lie in different volumes, far apart in memory, and each step of the
    // walk waits for the previous one's load. Walking the β2-first and the β3-first directions
    // together until they meet halves that wait around an interior edge; the darts come out in
    // walk_chain_cell's order (the β3-first ones reversed, unless the edge is open).
    constexpr std::uint32_t null = detail::null_index;
    using V = typename Out::value_type;
    out.push_back(V(root));
    detail::DartBuffer<16> back;
    std::uint32_t a = root, bk = root;
    int ja = 2, jb = 3;
    bool a_on = true, b_on = true, met = false;
    for (std::uint32_t budget = dart_capacity(); (a_on || b_on) && budget != 0; --budget) {
      if (a_on) {
        const std::uint32_t y = b(a, ja);
        if (y == null || y == root) {
          a_on = false;
        } else if (!back.empty() && y == back.back()) {
          met = true;
          break;
        } else {
          out.push_back(V(y));
          a = y;
          ja = 5 - ja;
        }
      }
      if (b_on) {
        const std::uint32_t y = b(bk, jb);
        if (y == null || y == root) {
          b_on = false;
        } else if (y == detail::raw(out.back()) && out.size() > 1) {
          met = true;
          break;
        } else {
          back.push_back(y);
          bk = y;
          jb = 5 - jb;
        }
      }
    }
    if (met)  // a cycle: the β3-first darts, last first, continue the β2-first ones
      for (std::size_t i = back.size(); i-- > 0;) out.push_back(V(back[i]));
    else
      for (std::uint32_t y : back) out.push_back(V(y));
  } else if constexpr (chain_cell<I>) {  // a chain needs no mark to be walked once
    out.push_back(typename Out::value_type(root));
    walk_chain_cell<I>(root, [&](std::uint32_t y) {
      out.push_back(typename Out::value_type(y));
      return true;
    });
  } else {
    const std::size_t first = out.size();
    const Mark m = marks_.reserve();
    const MarkView mk = marks_.view(m);
    walk_cell<I>(root, mk, out);
    for (std::size_t i = first; i < out.size(); ++i) mk.clear(detail::raw(out[i]));
    marks_.release(m);
  }
}

template <int D, class... A>
template <int I, class F>
bool CMap<D, A...>::walk_chain_cell(std::uint32_t x, F&& f) const {
  constexpr std::uint32_t null = detail::null_index;
  std::uint32_t budget = dart_capacity();
  // The darts after x by `next` until x comes back or the chain ends; if it ended, the darts
  // before x by `prev` (the inverse of next).
  auto chain = [&](auto next, auto prev) {
    std::uint32_t y = next(x);
    for (; y != null && y != x; y = next(y)) {
      if (!f(y)) return false;
      if (--budget == 0) return true;
    }
    if (y == x) return true;
    for (y = prev(x); y != null && y != x; y = prev(y)) {
      if (!f(y)) return false;
      if (--budget == 0) return true;
    }
    return true;
  };
  if constexpr (D == 1) {
    return true;  // no generator: every cell is one dart
  } else if constexpr (D == 2 && I == 1) {
    const std::uint32_t y = b(x, 2);
    return y == null || y == x || f(y);
  } else if constexpr (D == 2 && I == 2) {
    return chain([&](std::uint32_t y) { return b(y, 1); }, [&](std::uint32_t y) { return b(y, 0); });
  } else if constexpr (D == 2 && I == 0) {
    // β1∘β2 and its inverse β2∘β0
    return chain(
        [&](std::uint32_t y) {
          const std::uint32_t t = b(y, 2);
          return t == null ? null : b(t, 1);
        },
        [&](std::uint32_t y) {
          const std::uint32_t t = b(y, 0);
          return t == null ? null : b(t, 2);
        });
  } else {
    static_assert(D == 3 && I == 1);
    // β2 and β3 alternately from x, then, if that path ends, alternately from x's β3
    for (int first = 2; first <= 3; ++first) {
      std::uint32_t y = x;
      for (int j = first;; j = 5 - j) {
        y = b(y, j);
        if (y == null) break;
        if (y == x) return true;
        if (!f(y)) return false;
        if (--budget == 0) return true;
      }
    }
    return true;
  }
}

template <int D, class... A>
template <int I>
bool CMap<D, A...>::is_chain_root(std::uint32_t x) const {
  constexpr std::uint32_t null = detail::null_index;
  auto smaller = [x](std::uint32_t y) { return y != null && y < x; };
  // Both chain neighbours of x first, as independent loads: most darts are not the smallest
  // and stop there. (D = 2 vertices: β1∘β2 and β2∘β0; faces: β1, β0; edges: β2 (and β3).)
  if constexpr (D == 2 && I == 0) {
    const std::uint32_t s2 = b(x, 2), s0 = b(x, 0);
    if (smaller(s2 == null ? null : b(s2, 1)) || smaller(s0 == null ? null : b(s0, 2))) return false;
  } else if constexpr (D == 2 && I == 2) {
    if (smaller(b(x, 1)) || smaller(b(x, 0))) return false;
  } else if constexpr (D == 3 && I == 1) {
    if (smaller(b(x, 2)) || smaller(b(x, 3))) return false;
  }
  return walk_chain_cell<I>(x, [x](std::uint32_t y) { return y > x; });
}

template <int D, class... A>
bool CMap<D, A...>::face_root_by_mark(std::uint32_t x) const {
  DartList face;
  collect_cell_unmarked<2>(x, face);
  return std::all_of(face.begin(), face.end(), [x](Dart d) { return d.index() >= x; });
}

template <int D, class... A>
bool CMap<D, A...>::face_root_walk(std::uint32_t x) const {
  static_assert(D == 3);
  constexpr std::uint32_t null = detail::null_index;
  // A face is x's β1 cycle z and, if x is 3-sewn, its partner's cycle w = β3(z), run the other
  // way (β3∘β1 = β0∘β3). The walk follows z and checks each dart of z and w to be larger than x;
  // each w is read from its z, so the partner's rows are not needed for that. β1(z) and β3(z)
  // lie in the orbit whatever its shape, so a smaller one answers at once. When the links are
  // not known sound, the walk also checks that they have this shape (z closed under β0 and β1,
  // w under β0, β1 and β3), which proves the two cycles are the whole orbit; that loads the
  // partner's rows too (each from its z, so the loads overlap), a cache miss per face on a
  // large mesh. An open face, or links of another shape, is settled by collecting the orbit
  // with a mark.
  const auto* rows = beta_.data();
  const bool sewn = rows[x][3] != null;
  const bool checked = !links_sound_;
  std::uint32_t z = x;
  for (std::uint32_t budget = dart_capacity(); budget != 0; --budget) {
    const std::uint32_t z1 = rows[z][1], w = rows[z][3];
    if (z1 < x || w < x) return false;
    if (z1 == null) return face_root_by_mark(x);
    if (checked) {
      const std::uint32_t w1 = rows[z1][3];
      if (rows[z1][0] != z || (sewn ? w1 == null || rows[w][3] != z || rows[w][0] != w1 || rows[w1][1] != w : w1 != null))
        return face_root_by_mark(x);
    }
    z = z1;
    if (z == x) return true;
  }
  return face_root_by_mark(x);
}

template <int D, class... A>
template <int... B>
DartList CMap<D, A...>::orbit(Dart d) const {
  static_assert(((B >= 0 && B <= D) && ...), "beta index outside [0, D]");
  check_alive(d, "orbit");
  constexpr unsigned mask = (0u | ... | (1u << (B == 0 ? 1 : B)));
  DartList out;
  collect_unmarked<mask>(d.index(), out);
  return out;
}

template <int D, class... A>
template <int I>
DartList CMap<D, A...>::cell(Dart d) const {
  static_assert(I >= 0 && I <= D);
  check_alive(d, "cell");
  DartList out;
  collect_cell_unmarked<I>(d.index(), out);
  return out;
}

template <int D, class... A>
std::vector<Dart> CMap<D, A...>::component(Dart d) const {
  check_alive(d, "component");
  std::vector<Dart> out;
  collect_unmarked<component_mask>(d.index(), out);
  return out;
}

template <int D, class... A>
template <int I>
bool CMap<D, A...>::same_cell(Dart a, Dart b2) const {
  check_alive(b2, "same_cell");
  for (Dart x : cell<I>(a))
    if (x == b2) return true;
  return false;
}

template <int D, class... A>
template <int I>
std::uint32_t CMap<D, A...>::mark_cell(Dart d, Mark m) const {
  check_alive(d, "mark_cell");
  std::uint32_t n = 0;
  for (Dart x : cell<I>(d)) n += marks_.set(x.index(), m) ? 1u : 0u;
  return n;
}

template <int D, class... A>
template <int I>
auto CMap<D, A...>::cells() const {
  static_assert(I >= 0 && I <= D);
  struct Iter {
    std::uint32_t x;
    Dart operator*() const { return Dart(x); }
    bool operator==(const Iter& o) const { return x == o.x; }
  };
  if constexpr (rooted_without_marks<I>) {
    // Each live dart that is the smallest of its cell.
    class Range {
     public:
      explicit Range(const CMap* m) : map_(m) {}
      struct It : Iter {
        const CMap* map;
        It& operator++() {
          this->x = next(map, this->x + 1);
          return *this;
        }
      };
      It begin() const { return It{{next(map_, 0)}, map_}; }
      It end() const { return It{{map_->dart_capacity()}, map_}; }

     private:
      static std::uint32_t next(const CMap* map, std::uint32_t x) {
        const std::uint32_t n = map->dart_capacity();
        while (x < n && !(map->is_live_index(x) && map->template is_cell_root<I>(x))) ++x;
        return x;
      }
      const CMap* map_;
    };
    return Range(this);
  } else {
    // The range owns a mark: each yielded dart's cell is marked before the loop body runs, so
    // the next unmarked dart starts a new cell. The destructor unmarks (O(1) after a full pass).
    class Range {
     public:
      explicit Range(const CMap* m) : map_(m), mark_(m->marks_.reserve()) {}
      ~Range() {
        if (map_) map_->free_mark(mark_);
      }
      Range(const Range&) = delete;
      Range& operator=(const Range&) = delete;
      Range(Range&& o) noexcept : map_(o.map_), mark_(o.mark_), queue_(std::move(o.queue_)) { o.map_ = nullptr; }

      // Iterating is logically const (the range still yields every cell once); the mark and
      // the queue are its bookkeeping, so a range held by const& can be iterated too.
      struct It : Iter {
        const Range* r;
        It& operator++() {
          this->x = r->next(this->x + 1);
          return *this;
        }
      };
      It begin() const {
        map_->unmark_all(mark_);  // a new pass (O(1) after a full one)
        return It{{next(0)}, this};
      }
      It end() const { return It{{map_->dart_capacity()}, this}; }

     private:
      std::uint32_t next(std::uint32_t x) const {
        const std::uint32_t n = map_->dart_capacity();
        const MarkView mk = map_->marks_.view(mark_);
        x = mk.next_unmarked(x, n);
        while (x < n && !map_->is_live_index(x)) x = mk.next_unmarked(x + 1, n);
        if (x < n) {
          queue_.clear();
          map_->template walk_cell<I>(x, mk, queue_);
          map_->marks_.add_count(mark_, static_cast<std::int64_t>(queue_.size()));
        }
        return x;
      }
      const CMap* map_;
      Mark mark_;
      mutable detail::DartBuffer<64> queue_;
    };
    return Range(this);
  }
}

template <int D, class... A>
template <int I, int J>
DartList CMap<D, A...>::incident(Dart d) const {
  static_assert(I >= 0 && I <= D && J >= 0 && J <= D);
  check_alive(d, "incident");
  DartList out;
  const DartList darts_of_cell = cell<I>(d);
  const Mark seen = marks_.reserve();
  const MarkView mk = marks_.view(seen);
  detail::DartBuffer<64> marked;
  for (Dart x : darts_of_cell) {
    if (mk.test(x.index())) continue;
    out.push_back(x);
    walk_cell<J>(x.index(), mk, marked);
  }
  for (std::uint32_t x : marked) mk.clear(x);
  marks_.release(seen);
  return out;
}

template <int D, class... A>
template <int I>
DartList CMap<D, A...>::adjacent(Dart d) const {
  static_assert(I >= 0 && I <= D);
  check_alive(d, "adjacent");
  constexpr std::uint32_t null = detail::null_index;
  DartList out;
  const Mark seen = marks_.reserve();
  {
    // cell<I - 1>() below reserves a mark of its own; it creates no dart, so `mk` stays valid
    const MarkView mk = marks_.view(seen);
    detail::DartBuffer<64> marked;
    walk_cell<I>(d.index(), mk, marked);  // the cell itself is excluded
    const std::size_t own = marked.size();
    auto consider = [&](std::uint32_t y) {
      if (y == null || mk.test(y)) return;
      out.push_back(Dart(y));
      walk_cell<I>(y, mk, marked);
    };
    for (std::size_t k = 0; k < own; ++k) {
      const std::uint32_t x = marked[k];
      if constexpr (I == 0) {
        // The vertex at the other end of x's edge starts β1(x), or βj(x) for j ≥ 2.
        std::uint32_t y = b(x, 1);
        for (int j = 2; y == null && j <= D; ++j) y = b(x, j);
        consider(y);
      } else {
        for (Dart y : cell<I - 1>(Dart(x))) consider(y.index());
      }
    }
    for (std::uint32_t x : marked) mk.clear(x);
  }
  marks_.release(seen);
  return out;
}

template <int D, class... A>
template <int I, class F>
void CMap<D, A...>::for_each_cell_root(F&& f) const {
  detail::DartBuffer<64> darts;
  const std::uint32_t cap = dart_capacity();
  const Mark m = marks_.reserve();
  const MarkView mk = marks_.view(m);
  std::int64_t marked = 0;
  for (std::uint32_t x = mk.next_unmarked(0, cap); x < cap; x = mk.next_unmarked(x + 1, cap)) {
    if (!is_live_index(x)) continue;
    darts.clear();
    if constexpr (I < 0)
      walk<component_mask>(x, mk, darts);
    else
      walk_cell<I>(x, mk, darts);
    marked += static_cast<std::int64_t>(darts.size());
    f(x, std::as_const(darts));
  }
  marks_.add_count(m, marked);
  free_mark(m);
}

template <int D, class... A>
template <int I>
std::uint32_t CMap<D, A...>::count_cells() const {
  std::uint32_t n = 0;
  if constexpr (I >= 0 && rooted_without_marks<I>) {
    const std::uint32_t cap = dart_capacity();
    for (std::uint32_t x = 0; x < cap; ++x) n += is_live_index(x) && is_cell_root<I>(x) ? 1u : 0u;
  } else {
    for_each_cell_root<I>([&](std::uint32_t, const auto&) { ++n; });
  }
  return n;
}

template <int D, class... A>
template <int I>
std::uint32_t CMap<D, A...>::count() const {
  static_assert(I >= 0 && I <= D);
  return count_cells<I>();
}

template <int D, class... A>
std::array<std::uint32_t, D + 1> CMap<D, A...>::count_all() const {
  std::array<std::uint32_t, D + 1> n{};
  for_each_dim([&](auto k) { n[k()] = count_cells<k()>(); });
  return n;
}

template <int D, class... A>
std::int64_t CMap<D, A...>::euler_characteristic() const {
  const auto n = count_all();
  std::int64_t chi = 0;
  for (int i = 0; i <= D; ++i) chi += (i % 2 == 0 ? 1 : -1) * static_cast<std::int64_t>(n[static_cast<std::size_t>(i)]);
  return chi;
}

template <int D, class... A>
std::uint32_t CMap<D, A...>::count_components() const {
  return count_cells<-1>();
}

template <int D, class... A>
std::vector<Dart> CMap<D, A...>::boundary_facets() const {
  std::vector<Dart> out;
  const Mark m = marks_.reserve();
  {
    const MarkView mk = marks_.view(m);
    detail::DartBuffer<64> queue;
    const std::uint32_t cap = dart_capacity();
    for (std::uint32_t x = mk.next_unmarked(0, cap); x < cap; x = mk.next_unmarked(x + 1, cap)) {
      if (!is_live_index(x) || b(x, D) != detail::null_index) continue;
      out.push_back(Dart(x));
      queue.clear();
      collect_cell<D - 1>(x, m, queue);
    }
  }
  free_mark(m);
  return out;
}

}  // namespace sewn
