#pragma once
// CMap: removal and contraction of i-cells. Included by cmap.hpp.
//
// Removing an i-cell C (i < D) glues the (i+1)-cells around it: for each dart x of C whose
// βi-predecessor w lies outside C, w is relinked by βi to the first dart reached from x by
// alternating β_{i+1} and βi that leaves C. Contraction is the dual: the same walk with β_{i-1}.
// Vertex removal (i = 0) and edge contraction (i = 1) relink by β1 directly.

namespace sewn {

template <int D, class... A>
void CMap<D, A...>::apply_relinks_and_erase(const DartList& cell_darts, const std::vector<Relink>& links,
                                            int merge_dim, bool into_w) {
  constexpr std::uint32_t null = detail::null_index;
  // 0) a fusing cell made only of erased darts merges into its surviving neighbour's cell
  for_each_dim([&](auto kk) {
    constexpr int K = kk();
    if constexpr (has_attribute<K>) {
      if (K != merge_dim) return;
      auto& st = store<K>();
      for (const Relink& l : links) {
        const std::uint32_t gone = st.of_dart[l.from];
        const std::uint32_t survivor_dart = into_w ? l.w : l.target;
        if (gone == null || survivor_dart == null) continue;
        const std::uint32_t kept = st.of_dart[survivor_dart];
        if (kept == null || kept == gone) continue;
        std::uint32_t in_c = 0;
        for (Dart x : cell_darts) in_c += st.of_dart[x.index()] == gone ? 1u : 0u;
        if (in_c != st.values.count(gone)) continue;  // the cell survives elsewhere
        if (hooks_on_ && st.on_merge) st.on_merge(AttrId<K>(kept), AttrId<K>(gone));
        for (Dart x : cell_darts)
          if (st.of_dart[x.index()] == gone) st.of_dart[x.index()] = kept;
        st.values.add_count(kept, in_c);
        st.values.erase(gone);
      }
    }
  });
  const Mark in_cell = marks_.reserve();
  for (Dart x : cell_darts) marks_.set(x.index(), in_cell);
  std::vector<std::uint32_t> touched;
  // 1) detach every outside dart from the cell
  for (Dart xd : cell_darts) {
    const std::uint32_t x = xd.index();
    for (int i = 0; i <= D; ++i) {
      const std::uint32_t y = b(x, i);
      if (y == null || marks_.test(y, in_cell)) continue;
      const int inv = i == 0 ? 1 : (i == 1 ? 0 : i);
      set_b(y, inv, null);
      touched.push_back(y);
    }
  }
  // 2) the new links (computed on the old map by the caller)
  for (const Relink& l : links) {
    raw_link(l.w, l.i, l.target);
    touched.push_back(l.w);
    if (l.target != null) touched.push_back(l.target);
  }
  // 3) erase the cell
  for (Dart x : cell_darts) {
    marks_.clear(x.index(), in_cell);
    beta_[x.index()].fill(null);
    erase_dart_raw(x.index());
  }
  marks_.release(in_cell);
  update_attributes(touched, ~0u);
}

template <int D, class... A>
template <int I>
bool CMap<D, A...>::plan_removal(const DartList& c, std::vector<Relink>& links) const {
  constexpr std::uint32_t null = detail::null_index;
  links.clear();
  if constexpr (I < D - 1) {
    // β_{I+1}∘β_{I+2} must be an involution on the cell (at most two (I+1)-cells around it).
    auto y_of = [&](std::uint32_t x) {
      const std::uint32_t t = b(x, I + 2);
      return t == null ? null : b(t, I + 1);
    };
    for (Dart x : c) {
      const std::uint32_t y = y_of(x.index());
      if (y != null && y_of(y) != x.index()) return false;
    }
  }
  const Mark in_cell = marks_.reserve();
  for (Dart x : c) marks_.set(x.index(), in_cell);
  auto inside = [&](std::uint32_t y) { return y != null && marks_.test(y, in_cell); };
  const std::size_t guard = c.size() + 1;
  for (Dart xd : c) {
    const std::uint32_t x = xd.index();
    if constexpr (I == 0) {
      const std::uint32_t w = b(x, 0);
      if (w == null || inside(w)) continue;
      std::uint32_t t = b(x, 1);
      for (std::size_t s = 0; inside(t) && s < guard; ++s) t = b(t, 1);
      links.push_back({1, w, inside(t) ? null : t, x});
      for (int j = 2; j <= D; ++j) {
        const std::uint32_t y = b(x, j);
        links.push_back({j, w, inside(y) ? null : y, x});
      }
    } else if constexpr (I < D) {
      const std::uint32_t w = b(x, I == 1 ? 0 : I);
      if (w == null || inside(w)) continue;
      std::uint32_t t = b(x, I + 1);
      for (std::size_t s = 0; t != null && inside(b(t, I)) && s < guard; ++s) t = b(b(t, I), I + 1);
      const std::uint32_t target = t == null ? null : b(t, I);
      links.push_back({I, w, inside(target) ? null : target, x});
    }
  }
  for (Dart x : c) marks_.clear(x.index(), in_cell);
  marks_.release(in_cell);
  for (const Relink& l : links)
    if (l.i >= 2 && l.target == l.w) return false;
  return true;
}

template <int D, class... A>
template <int I>
bool CMap<D, A...>::is_removable(Dart d) const {
  static_assert(I >= 0 && I <= D);
  if (!is_alive(d)) return false;
  std::vector<Relink> links;
  return plan_removal<I>(cell<I>(d), links);
}

template <int D, class... A>
template <int I>
void CMap<D, A...>::remove_cell(Dart d) {
  static_assert(I >= 0 && I <= D);
  check_alive(d, "remove_cell");
  const DartList c = cell<I>(d);
  std::vector<Relink> links;
  if (!plan_removal<I>(c, links))
    throw TopologyError("cmap::remove_cell<" + std::to_string(I) + ">: the cell of dart " + std::to_string(d.index()) +
                        " lies in more than two " + std::to_string(I + 1) +
                        "-cells, or removing it would fold a cell onto itself (see is_removable)");
  apply_relinks_and_erase(c, links, I + 1, I == 0);
}

template <int D, class... A>
template <int I>
bool CMap<D, A...>::plan_contraction(const DartList& c, std::vector<Relink>& links) const {
  constexpr std::uint32_t null = detail::null_index;
  links.clear();
  if constexpr (I >= 2) {
    // I = 2: β1 an involution (a face of at most two edges); I = 3: β2∘β0; I ≥ 4: β_{I-1}∘β_{I-2}.
    auto y_of = [&](std::uint32_t x) -> std::uint32_t {
      if constexpr (I == 2) {
        return b(x, 1);
      } else {
        const std::uint32_t t = b(x, I == 3 ? 0 : I - 2);
        return t == null ? null : b(t, I - 1);
      }
    };
    for (Dart x : c) {
      const std::uint32_t y = y_of(x.index());
      if (y != null && y_of(y) != x.index()) return false;
    }
  }
  const Mark in_cell = marks_.reserve();
  for (Dart x : c) marks_.set(x.index(), in_cell);
  auto inside = [&](std::uint32_t y) { return y != null && marks_.test(y, in_cell); };
  const std::size_t guard = c.size() + 1;
  for (Dart xd : c) {
    const std::uint32_t x = xd.index();
    if constexpr (I == 1) {
      const std::uint32_t w = b(x, 0);
      if (w == null || inside(w)) continue;
      std::uint32_t t = b(x, 1);
      for (std::size_t s = 0; inside(t) && s < guard; ++s) t = b(t, 1);
      links.push_back({1, w, inside(t) ? null : t, x});
    } else {
      const std::uint32_t w = b(x, I);
      if (w == null || inside(w)) continue;
      std::uint32_t t = b(x, I - 1);
      for (std::size_t s = 0; t != null && inside(b(t, I)) && s < guard; ++s) t = b(b(t, I), I - 1);
      const std::uint32_t target = t == null ? null : b(t, I);
      links.push_back({I, w, inside(target) ? null : target, x});
    }
  }
  for (Dart x : c) marks_.clear(x.index(), in_cell);
  marks_.release(in_cell);
  for (const Relink& l : links)
    if (l.i >= 2 && l.target == l.w) return false;
  return true;
}

template <int D, class... A>
template <int I>
bool CMap<D, A...>::is_contractible(Dart d) const {
  static_assert(I >= 0 && I <= D);
  if (!is_alive(d)) return false;
  if constexpr (I == 0) {
    return false;
  } else {
    std::vector<Relink> links;
    return plan_contraction<I>(cell<I>(d), links);
  }
}

template <int D, class... A>
template <int I>
void CMap<D, A...>::contract_cell(Dart d) {
  static_assert(I >= 1 && I <= D, "only i-cells with i >= 1 can be contracted");
  check_alive(d, "contract_cell");
  const DartList c = cell<I>(d);
  std::vector<Relink> links;
  if (!plan_contraction<I>(c, links))
    throw TopologyError("cmap::contract_cell<" + std::to_string(I) + ">: the cell of dart " + std::to_string(d.index()) +
                        " has more than two " + std::to_string(I - 1) +
                        "-cells, or contracting it would fold a cell onto itself (see is_contractible)");
  apply_relinks_and_erase(c, links, I - 1, false);
}

}  // namespace sewn
