#pragma once
// CMap: attribute assignment and the re-derivation of attributes after topological changes
// (where on_split / on_merge fire). Included by cmap.hpp.

namespace sewn {

template <int D, class... A>
template <int I>
AttrId<I> CMap<D, A...>::set_attribute(Dart d, attribute_type<I> v) {
  static_assert(has_attribute<I>, "attributes are not enabled for this dimension");
  check_alive(d, "set_attribute");
  auto& st = store<I>();
  const std::uint32_t a = st.values.create(std::move(v));
  detail::DartBuffer<64> darts;
  collect_cell_unmarked<I>(d.index(), darts);
  for (std::uint32_t x : darts) {
    const std::uint32_t old = st.of_dart[x];
    if (old != detail::null_index) {
      st.values.add_count(old, -1);
      if (st.values.count(old) == 0) pending_erase_.emplace_back(I, old);
    }
    st.of_dart[x] = a;
  }
  st.values.add_count(a, static_cast<std::int64_t>(darts.size()));
  st.values.set_dart(a, d.index());
  flush_erased();
  return AttrId<I>(a);
}

template <int D, class... A>
template <int I, class F>
std::uint32_t CMap<D, A...>::create_attributes(F&& f) {
  static_assert(has_attribute<I>, "attributes are not enabled for this dimension");
  auto& st = store<I>();
  const Mark m = marks_.reserve();
  std::vector<std::uint32_t> darts;
  std::uint32_t created = 0;
  const auto cap = static_cast<std::uint32_t>(beta_.size());
  for (std::uint32_t x = 0; x < cap; ++x) {
    if (beta_[x][0] == detail::dead_marker || marks_.test(x, m)) continue;
    darts.clear();
    collect_cell<I>(x, m, darts);
    if (st.of_dart[x] != detail::null_index) continue;  // the whole cell shares x's attribute
    const std::uint32_t a = st.values.create(f(Dart(x)));
    for (std::uint32_t y : darts) st.of_dart[y] = a;
    st.values.add_count(a, static_cast<std::int64_t>(darts.size()));
    st.values.set_dart(a, x);
    ++created;
  }
  free_mark(m);
  return created;
}

template <int D, class... A>
template <int I>
auto CMap<D, A...>::attributes() const {
  const auto& c = store<I>().values;
  struct Iter {
    const AttributeContainer<attribute_type<I>>* c;
    std::uint32_t a;
    AttrId<I> operator*() const { return AttrId<I>(a); }
    Iter& operator++() {
      do ++a;
      while (a < c->capacity() && !c->is_alive(a));
      return *this;
    }
    bool operator==(const Iter& o) const { return a == o.a; }
  };
  struct Range {
    const AttributeContainer<attribute_type<I>>* c;
    Iter begin() const {
      Iter it{c, 0};
      if (c->capacity() > 0 && !c->is_alive(0)) ++it;
      return it;
    }
    Iter end() const { return Iter{c, c->capacity()}; }
  };
  return Range{&c};
}

template <int D, class... A>
void CMap<D, A...>::inherit_attributes(std::uint32_t from, std::uint32_t to, unsigned dims) {
  for_each_dim([&](auto k) {
    constexpr int K = k();
    if constexpr (has_attribute<K>) {
      if (!((dims >> K) & 1u)) return;
      auto& st = store<K>();
      const std::uint32_t a = st.of_dart[from];
      if (st.of_dart[to] != detail::null_index) st.values.add_count(st.of_dart[to], -1);
      st.of_dart[to] = a;
      if (a != detail::null_index) st.values.add_count(a, 1);
    }
  });
}

template <int D, class... A>
void CMap<D, A...>::update_attributes(std::span<const std::uint32_t> touched, unsigned dims) {
  for_each_dim([&](auto k) {
    constexpr int K = k();
    if constexpr (has_attribute<K>)
      if ((dims >> K) & 1u) update_attributes_of<K>(touched);
  });
  flush_erased();
}

template <int D, class... A>
template <int I>
void CMap<D, A...>::update_attributes_of(std::span<const std::uint32_t> touched) {
  // Every new I-cell that differs from an old one contains a dart whose links changed (for
  // I = 0: such a dart or a β-neighbour of one, since vertex generators are two links long).
  detail::DartBuffer<128> candidates;
  for (std::uint32_t t : touched) {
    if (!is_alive(Dart(t))) continue;
    candidates.push_back(t);
    if constexpr (I == 0)
      for (int j = 0; j <= D; ++j)
        if (const std::uint32_t y = b(t, j); y != detail::null_index) candidates.push_back(y);
  }
  // The cells are walked into `visited`, one after the other; each is processed (hooks run
  // there, and may create or erase darts: the mark's view is taken again for each walk, and its
  // count kept exact) and all are unmarked at the end.
  const Mark seen = marks_.reserve();
  detail::DartBuffer<256> visited;
  Claims claims;
  for (std::uint32_t c : candidates) {
    if (marks_.test(c, seen)) continue;
    const std::size_t first = visited.size();
    collect_cell<I>(c, seen, visited);
    process_new_cell<I>(std::span<const std::uint32_t>(visited.begin() + first, visited.end()), claims);
  }
  const MarkView mk = marks_.view(seen);
  std::int64_t cleared = 0;
  for (std::uint32_t x : visited) cleared += mk.clear(x) ? 1 : 0;
  marks_.add_count(seen, -cleared);
  marks_.release(seen);
  release_claims(claims);
}

template <int D, class... A>
bool CMap<D, A...>::in_claims(const Claims& c, std::uint32_t x) const {
  if (c.mark.valid()) return marks_.test(x, c.mark);
  return std::find(c.darts.begin(), c.darts.end(), x) != c.darts.end();
}

template <int D, class... A>
void CMap<D, A...>::add_claim(Claims& c, std::uint32_t x) {
  c.darts.push_back(x);
  if (!c.mark.valid() && c.darts.size() > Claims::list_max) {
    c.mark = marks_.reserve();
    for (std::uint32_t y : c.darts) marks_.set(y, c.mark);
  } else if (c.mark.valid()) {
    marks_.set(x, c.mark);
  }
}

template <int D, class... A>
void CMap<D, A...>::release_claims(Claims& c) {
  if (!c.mark.valid()) return;
  for (std::uint32_t x : c.darts) marks_.clear(x, c.mark);
  marks_.release(c.mark);
}

template <int D, class... A>
template <int I>
std::uint32_t CMap<D, A...>::copy_attribute(std::uint32_t a) {
  auto& st = store<I>();
  attribute_type<I> v = st.values.value(a);  // copy first: create() may reallocate
  return st.values.create(std::move(v));
}

template <int D, class... A>
template <int I>
void CMap<D, A...>::relabel(std::span<const std::uint32_t> cell_darts, std::uint32_t from, std::uint32_t to) {
  auto& st = store<I>();
  std::int64_t moved = 0;
  for (std::uint32_t x : cell_darts)
    if (st.of_dart[x] == from) {
      st.of_dart[x] = to;
      ++moved;
    }
  if (from != detail::null_index) st.values.add_count(from, -moved);
  if (to != detail::null_index) st.values.add_count(to, moved);
}

template <int D, class... A>
template <int I>
void CMap<D, A...>::process_new_cell(std::span<const std::uint32_t> cell_darts, Claims& claims) {
  auto& st = store<I>();
  // Distinct attributes of the cell in BFS order, with how many of its darts carry each.
  boost::container::small_vector<std::pair<std::uint32_t, std::uint32_t>, 4> attrs;
  for (std::uint32_t x : cell_darts) {
    const std::uint32_t a = st.of_dart[x];
    if (a == detail::null_index) continue;
    auto it = std::find_if(attrs.begin(), attrs.end(), [&](const auto& p) { return p.first == a; });
    if (it == attrs.end())
      attrs.emplace_back(a, 1u);
    else
      ++it->second;
  }
  if (attrs.empty()) return;
  const bool hooks = hooks_on_;
  // An attribute is claimed once it is the survivor of a cell processed earlier in this update:
  // it then names that cell's first dart, which is among the claims. (An attribute split off or
  // merged never names a claimed dart: split_off re-points or clears it.)
  auto is_claimed = [&](std::uint32_t a) {
    const std::uint32_t x = st.values.dart(a);
    return x != detail::null_index && st.of_dart[x] == a && in_claims(claims, x);
  };
  // A piece of a cell whose identity went elsewhere (claimed by an earlier new cell, or, for
  // all but the survivor, still holding darts outside this cell) is split off into a copy.
  auto split_off = [&](std::uint32_t a) {
    const std::uint32_t c = copy_attribute<I>(a);
    relabel<I>(cell_darts, a, c);
    for (std::uint32_t x : cell_darts)
      if (st.of_dart[x] == c) {
        st.values.set_dart(c, x);
        break;
      }
    if (st.values.dart(a) != detail::null_index && st.of_dart[st.values.dart(a)] != a)
      st.values.set_dart(a, detail::null_index);  // refreshed where the rest of `a` is processed
    if (hooks && st.on_split) st.on_split(AttrId<I>(a), AttrId<I>(c));
    return c;
  };
  for (auto& [a, n] : attrs)
    if (is_claimed(a)) a = split_off(a);
  const std::uint32_t survivor = attrs.front().first;
  for (std::size_t k = 1; k < attrs.size(); ++k) {
    std::uint32_t o = attrs[k].first;
    if (st.values.count(o) > attrs[k].second) o = split_off(o);
    if (hooks && st.on_merge) st.on_merge(AttrId<I>(survivor), AttrId<I>(o));
    relabel<I>(cell_darts, o, survivor);
    st.values.erase(o);
  }
  relabel<I>(cell_darts, detail::null_index, survivor);
  st.values.set_dart(survivor, cell_darts.front());
  add_claim(claims, cell_darts.front());
}

}  // namespace sewn
