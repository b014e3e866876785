#pragma once
// CMap: orbits, cells, incidence, adjacency and counting. Included by cmap.hpp.

namespace sewn {

namespace detail {
// Lets collect() push raw indices into DartList and std::vector<uint32_t> alike.
inline std::uint32_t raw(std::uint32_t x) { return x; }
inline std::uint32_t raw(Dart d) { return d.index(); }
}  // namespace detail


template <int D, class... A>
template <class F>
void CMap<D, A...>::for_each_neighbor(std::uint32_t x, Orbit o, F&& f) const {
  constexpr std::uint32_t null = detail::null_index;
  if (o.vertex) {
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
    return;
  }
  if (o.mask & 2u) {
    if (const std::uint32_t y = b(x, 0); y != null) f(y);
    if (const std::uint32_t y = b(x, 1); y != null) f(y);
  }
  for (int j = 2; j <= D; ++j)
    if ((o.mask >> j) & 1u)
      if (const std::uint32_t y = b(x, j); y != null) f(y);
}

template <int D, class... A>
template <class Out>
void CMap<D, A...>::expand(std::size_t head, Orbit o, Mark m, Out& out) const {
  // `out` doubles as the BFS queue: darts are appended once, when first marked.
  while (head < out.size()) {
    const std::uint32_t x = detail::raw(out[head++]);
    for_each_neighbor(x, o, [&](std::uint32_t y) {
      if (marks_.set(y, m)) out.push_back(typename Out::value_type(y));
    });
  }
}

template <int D, class... A>
template <class Out>
void CMap<D, A...>::collect(std::uint32_t root, Orbit o, Mark m, Out& out) const {
  const std::size_t head = out.size();
  if (!marks_.set(root, m)) return;
  out.push_back(typename Out::value_type(root));
  expand(head, o, m, out);
}

template <int D, class... A>
template <class Out>
void CMap<D, A...>::collect_chain(std::uint32_t x, Mark m, Out& out) const {
  // x's β1 cycle, or both directions of its β1 path when the face is open
  if (!marks_.set(x, m)) return;
  out.push_back(typename Out::value_type(x));
  std::uint32_t y = b(x, 1);
  for (; y != detail::null_index && marks_.set(y, m); y = b(y, 1)) out.push_back(typename Out::value_type(y));
  if (y != detail::null_index) return;  // closed (back at a marked dart)
  for (y = b(x, 0); y != detail::null_index && marks_.set(y, m); y = b(y, 0)) out.push_back(typename Out::value_type(y));
}

template <int D, class... A>
template <int I, class Out>
void CMap<D, A...>::collect_cell(std::uint32_t root, Mark m, Out& out) const {
  constexpr std::uint32_t null = detail::null_index;
  const std::size_t first = out.size();
  if constexpr (I == 1 && D <= 3) {
    // ⟨β2, β3⟩: an alternating path or cycle through the edge
    if (!marks_.set(root, m)) return;
    out.push_back(typename Out::value_type(root));
    if constexpr (D >= 2) {
      int j = 2;
      std::uint32_t x = root;
      bool closed = false;
      for (std::uint32_t y = b(x, j); y != null; y = b(x, j)) {
        if (!marks_.set(y, m)) {
          closed = true;
          break;
        }
        out.push_back(typename Out::value_type(y));
        x = y;
        if constexpr (D == 3) j = 5 - j;
      }
      if constexpr (D == 3)
        if (!closed)
          for (std::uint32_t y = b(root, 3), jj = 2; y != null && marks_.set(y, m); y = b(y, static_cast<int>(jj)), jj = 5 - jj)
            out.push_back(typename Out::value_type(y));
    }
  } else if constexpr (I == D && D <= 3) {
    // D-cell: β1 chains joined by β_j, j < D
    collect_chain(root, m, out);
    for (std::size_t h = first; h < out.size(); ++h)
      for (int j = 2; j < D; ++j)
        if (const std::uint32_t y = b(detail::raw(out[h]), j); y != null && !marks_.test(y, m)) collect_chain(y, m, out);
  } else if constexpr (I == 2 && D == 3) {
    // a face: its β1 chain and the chain of its β3 partner
    collect_chain(root, m, out);
    for (std::size_t h = first; h < out.size(); ++h)
      if (const std::uint32_t y = b(detail::raw(out[h]), 3); y != null && !marks_.test(y, m)) collect_chain(y, m, out);
  } else if constexpr (I == 0 && D == 2) {
    // ⟨β1∘β2⟩: around the vertex forward, then backward by β2∘β0 if the vertex is open
    if (!marks_.set(root, m)) return;
    out.push_back(typename Out::value_type(root));
    auto fwd = [&](std::uint32_t x) { const std::uint32_t t = b(x, 2); return t == null ? null : b(t, 1); };
    auto bwd = [&](std::uint32_t x) { const std::uint32_t t = b(x, 0); return t == null ? null : b(t, 2); };
    std::uint32_t y = fwd(root);
    for (; y != null && marks_.set(y, m); y = fwd(y)) out.push_back(typename Out::value_type(y));
    if (y == null)
      for (y = bwd(root); y != null && marks_.set(y, m); y = bwd(y)) out.push_back(typename Out::value_type(y));
  } else if constexpr (I == 0 && D == 3) {
    // Around an interior vertex every dart has β1∘β2 and β1∘β3 defined; the darts reached by
    // these two forward maps then form the whole orbit (an injective self-map of a finite set
    // is onto, so the inverses stay inside too). Anything undefined: the generic search.
    if (!marks_.set(root, m)) return;
    out.push_back(typename Out::value_type(root));
    for (std::size_t h = first; h < out.size(); ++h) {
      const std::uint32_t x = detail::raw(out[h]);
      const std::uint32_t a = b(x, 2), c = b(x, 3);
      const std::uint32_t y = a == null ? null : b(a, 1), z = c == null ? null : b(c, 1);
      if (y == null || z == null) {
        expand(first, cell_orbit(0), m, out);
        return;
      }
      if (marks_.set(y, m)) out.push_back(typename Out::value_type(y));
      if (marks_.set(z, m)) out.push_back(typename Out::value_type(z));
    }
  } else {
    collect(root, cell_orbit(I), m, out);
  }
}

template <int D, class... A>
template <class Out>
void CMap<D, A...>::collect_unmarked(std::uint32_t root, Orbit o, Out& out) const {
  const std::size_t first = out.size();
  const Mark m = marks_.reserve();
  std::size_t head = first;
  marks_.set(root, m);
  out.push_back(typename Out::value_type(root));
  while (head < out.size()) {
    const std::uint32_t x = detail::raw(out[head++]);
    for_each_neighbor(x, o, [&](std::uint32_t y) {
      if (marks_.set(y, m)) out.push_back(typename Out::value_type(y));
    });
  }
  for (std::size_t i = first; i < out.size(); ++i) marks_.clear(detail::raw(out[i]), m);
  marks_.release(m);
}

template <int D, class... A>
template <int I, class Out>
void CMap<D, A...>::collect_cell_unmarked(std::uint32_t root, Out& out) const {
  const std::size_t first = out.size();
  const Mark m = marks_.reserve();
  collect_cell<I>(root, m, out);
  for (std::size_t i = first; i < out.size(); ++i) marks_.clear(detail::raw(out[i]), m);
  marks_.release(m);
}

template <int D, class... A>
template <int... B>
DartList CMap<D, A...>::orbit(Dart d) const {
  static_assert(((B >= 0 && B <= D) && ...), "beta index outside [0, D]");
  check_alive(d, "orbit");
  unsigned mask = 0;
  ((mask |= 1u << (B == 0 ? 1 : B)), ...);
  DartList out;
  collect_unmarked(d.index(), Orbit{mask, false}, out);
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
  collect_unmarked(d.index(), component_orbit(), out);
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

    struct Iter {
      Range* r;
      std::uint32_t x;
      Dart operator*() const { return Dart(x); }
      Iter& operator++() {
        x = r->next(x + 1);
        return *this;
      }
      bool operator==(const Iter& o) const { return x == o.x; }
    };
    Iter begin() { return Iter{this, next(0)}; }
    Iter end() { return Iter{this, static_cast<std::uint32_t>(map_->beta_.size())}; }

   private:
    std::uint32_t next(std::uint32_t x) {
      const auto n = static_cast<std::uint32_t>(map_->beta_.size());
      while (x < n && (map_->beta_[x][0] == detail::dead_marker || map_->marks_.test(x, mark_))) ++x;
      if (x < n) {
        queue_.clear();
        map_->template collect_cell<I>(x, mark_, queue_);
      }
      return x;
    }
    const CMap* map_;
    Mark mark_;
    std::vector<std::uint32_t> queue_;
  };
  return Range(this);
}

template <int D, class... A>
template <int I, int J>
DartList CMap<D, A...>::incident(Dart d) const {
  static_assert(I >= 0 && I <= D && J >= 0 && J <= D);
  check_alive(d, "incident");
  DartList out;
  const DartList darts_of_cell = cell<I>(d);
  const Mark seen = marks_.reserve();
  std::vector<std::uint32_t> marked;
  for (Dart x : darts_of_cell) {
    if (marks_.test(x.index(), seen)) continue;
    out.push_back(x);
    collect_cell<J>(x.index(), seen, marked);
  }
  for (std::uint32_t x : marked) marks_.clear(x, seen);
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
  std::vector<std::uint32_t> marked;
  const Mark seen = marks_.reserve();
  collect_cell<I>(d.index(), seen, marked);  // the cell itself is excluded
  const std::size_t own = marked.size();
  auto consider = [&](std::uint32_t y) {
    if (y == null || marks_.test(y, seen)) return;
    out.push_back(Dart(y));
    collect_cell<I>(y, seen, marked);
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
  for (std::uint32_t x : marked) marks_.clear(x, seen);
  marks_.release(seen);
  return out;
}

template <int D, class... A>
std::uint32_t CMap<D, A...>::count_orbits(Orbit o) const {
  const Mark m = marks_.reserve();
  std::vector<std::uint32_t> queue;
  std::uint32_t n = 0;
  const auto cap = static_cast<std::uint32_t>(beta_.size());
  for (std::uint32_t x = 0; x < cap; ++x) {
    if (beta_[x][0] == detail::dead_marker || marks_.test(x, m)) continue;
    ++n;
    queue.clear();
    collect(x, o, m, queue);
  }
  free_mark(m);
  return n;
}

template <int D, class... A>
template <int I>
std::uint32_t CMap<D, A...>::count_cells() const {
  const Mark m = marks_.reserve();
  std::vector<std::uint32_t> queue;
  std::uint32_t n = 0;
  const auto cap = static_cast<std::uint32_t>(beta_.size());
  for (std::uint32_t x = 0; x < cap; ++x) {
    if (beta_[x][0] == detail::dead_marker || marks_.test(x, m)) continue;
    ++n;
    queue.clear();
    collect_cell<I>(x, m, queue);
  }
  free_mark(m);
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
  return count_orbits(component_orbit());
}

template <int D, class... A>
std::vector<Dart> CMap<D, A...>::boundary_facets() const {
  std::vector<Dart> out;
  const Mark m = marks_.reserve();
  std::vector<std::uint32_t> queue;
  const auto cap = static_cast<std::uint32_t>(beta_.size());
  for (std::uint32_t x = 0; x < cap; ++x) {
    if (beta_[x][0] == detail::dead_marker || marks_.test(x, m) || b(x, D) != detail::null_index) continue;
    out.push_back(Dart(x));
    queue.clear();
    collect_cell<D - 1>(x, m, queue);
  }
  free_mark(m);
  return out;
}

}  // namespace sewn
