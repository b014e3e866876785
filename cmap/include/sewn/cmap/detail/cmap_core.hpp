#pragma once
// CMap: dart storage, free list, compaction, raw links, marks glue. Included by cmap.hpp.

namespace sewn {

template <int D, class... A>
void CMap<D, A...>::throw_dead(Dart d, const char* where) const {
  if (d.is_null()) throw TopologyError(std::string("cmap::") + where + ": null dart");
  throw TopologyError(std::string("cmap::") + where + ": dart " + std::to_string(d.index()) +
                      (d.index() < beta_.size() ? " has been erased" : " is out of range (capacity " +
                                                                          std::to_string(beta_.size()) + ")"));
}

template <int D, class... A>
template <int I>
void CMap<D, A...>::check_attr(AttrId<I> a) const {
  if (!store<I>().values.is_alive(a.index())) [[unlikely]]
    throw TopologyError("cmap: " + std::to_string(I) + "-attribute " +
                        (a.is_null() ? std::string("null") : std::to_string(a.index())) + " is not a live attribute");
}

template <int D, class... A>
std::uint32_t CMap<D, A...>::new_dart() {
  std::array<std::uint32_t, D + 1> unlinked;
  unlinked.fill(detail::null_index);
  std::uint32_t x;
  if (free_head_ != detail::null_index) {
    x = free_head_;
    free_head_ = beta_[x][1];
    beta_[x] = unlinked;
    for_each_dim([&](auto k) {
      if constexpr (has_attribute<k()>) store<k()>().of_dart[x] = detail::null_index;
    });
  } else {
    if (beta_.size() >= detail::dead_marker - 1)
      throw CapacityError("cmap: the map cannot hold more than 2^32 - 3 darts");
    x = static_cast<std::uint32_t>(beta_.size());
    beta_.push_back(unlinked);
    for_each_dim([&](auto k) {
      if constexpr (has_attribute<k()>) store<k()>().of_dart.push_back(detail::null_index);
    });
    if constexpr (has_dart_info) info_.of_dart.push_back(dart_info_type{});
    if ((x & 63u) == 0) marks_.resize(x + 64);
  }
  ++alive_;
  return x;
}

template <int D, class... A>
template <class Out>
void CMap<D, A...>::new_darts(std::uint32_t k, Out& out) {
  for (; k != 0 && free_head_ != detail::null_index; --k) out.push_back(new_dart());
  if (k == 0) return;
  const auto x0 = static_cast<std::uint32_t>(beta_.size());
  if (x0 + std::uint64_t{k} > detail::dead_marker - 1)
    throw CapacityError("cmap: the map cannot hold more than 2^32 - 3 darts");
  std::array<std::uint32_t, D + 1> unlinked;
  unlinked.fill(detail::null_index);
  beta_.resize(x0 + k, unlinked);
  for_each_dim([&](auto kk) {
    if constexpr (has_attribute<kk()>) store<kk()>().of_dart.resize(x0 + k, detail::null_index);
  });
  if constexpr (has_dart_info) info_.of_dart.resize(x0 + k, dart_info_type{});
  if ((x0 + 63) / 64 != (x0 + k + 63) / 64) marks_.resize(x0 + k);
  alive_ += k;
  for (std::uint32_t i = 0; i < k; ++i) out.push_back(x0 + i);
}

template <int D, class... A>
Dart CMap<D, A...>::create_dart() {
  return Dart(new_dart());
}

template <int D, class... A>
void CMap<D, A...>::erase_dart_raw(std::uint32_t x) {
  for_each_dim([&](auto k) {
    constexpr int K = k();
    if constexpr (has_attribute<K>) {
      auto& st = store<K>();
      const std::uint32_t a = st.of_dart[x];
      if (a != detail::null_index) {
        st.values.add_count(a, -1);
        if (st.values.count(a) == 0)
          pending_erase_.emplace_back(K, a);
        else if (st.values.dart(a) == x)
          st.values.set_dart(a, detail::null_index);  // refreshed by update_attributes
        st.of_dart[x] = detail::null_index;
      }
    }
  });
  std::uint32_t bits = marks_.reserved_bits();
  while (bits) {
    const int m = std::countr_zero(bits);
    bits &= bits - 1;
    marks_.clear(x, Mark(m));
  }
  // Dropped now, so a dart made later in this slot starts from a default value (and a value
  // holding memory frees it).
  if constexpr (has_dart_info) info_.of_dart[x] = dart_info_type{};
  beta_[x].fill(detail::null_index);
  beta_[x][0] = detail::dead_marker;
  beta_[x][1] = free_head_;
  free_head_ = x;
  --alive_;
}

template <int D, class... A>
void CMap<D, A...>::erase_dart(Dart d) {
  check_alive(d, "erase_dart");
  for (int i = 0; i <= D; ++i)
    if (b(d.index(), i) != detail::null_index)
      throw TopologyError("cmap::erase_dart: dart " + std::to_string(d.index()) + " is still linked by beta" +
                          std::to_string(i) + "; unlink it first or use remove_cell");
  erase_dart_raw(d.index());
  flush_erased();
}

template <int D, class... A>
void CMap<D, A...>::flush_erased() {
  if (pending_erase_.empty()) return;
  auto pending = std::move(pending_erase_);
  pending_erase_.clear();
  // Plain variables, not a structured binding: clang 14 cannot capture bindings in the lambda.
  for (const auto& entry : pending) {
    const int k = entry.first;
    const std::uint32_t a = entry.second;
    for_each_dim([&](auto kk) {
      constexpr int K = kk();
      if constexpr (has_attribute<K>) {
        if (K == k) {
          auto& st = store<K>();
          if (hooks_on_ && st.on_erase) st.on_erase(AttrId<K>(a));
          st.values.erase(a);
        }
      }
    });
  }
}

template <int D, class... A>
std::vector<std::uint32_t> CMap<D, A...>::dead_darts() const {
  std::vector<std::uint32_t> out;
  out.reserve(beta_.size() - alive_);
  for (std::uint32_t x = free_head_; x != detail::null_index; x = beta_[x][1]) out.push_back(x);
  return out;
}

template <int D, class... A>
void CMap<D, A...>::free_mark(Mark m) const {
  if (!marks_.is_reserved(m)) throw TopologyError("cmap::free_mark: mark " + std::to_string(m.id()) + " is not reserved");
  unmark_all(m);
  marks_.release(m);
}

template <int D, class... A>
void CMap<D, A...>::raw_link(std::uint32_t x, int i, std::uint32_t y) {
  if (i == 0) {
    set_b(x, 0, y);
    if (y != detail::null_index) set_b(y, 1, x);
  } else if (i == 1) {
    set_b(x, 1, y);
    if (y != detail::null_index) set_b(y, 0, x);
  } else {
    set_b(x, i, y);
    if (y != detail::null_index) set_b(y, i, x);
  }
}

template <int D, class... A>
template <int I>
void CMap<D, A...>::link_beta(Dart a, Dart b2) {
  static_assert(I >= 0 && I <= D);
  check_alive(a, "link_beta");
  check_alive(b2, "link_beta");
  links_sound_ = false;
  raw_link(a.index(), I, b2.index());
}

template <int D, class... A>
template <int I>
void CMap<D, A...>::unlink_beta(Dart d) {
  static_assert(I >= 0 && I <= D);
  check_alive(d, "unlink_beta");
  const std::uint32_t x = d.index();
  const std::uint32_t y = b(x, I);
  if (y == detail::null_index) return;
  links_sound_ = false;
  constexpr int inv = I == 0 ? 1 : (I == 1 ? 0 : I);
  set_b(x, I, detail::null_index);
  set_b(y, inv, detail::null_index);
}

template <int D, class... A>
void CMap<D, A...>::reserve(std::uint32_t n) {
  beta_.reserve(n);
  for_each_dim([&](auto k) {
    if constexpr (has_attribute<k()>) store<k()>().of_dart.reserve(n);
  });
  if constexpr (has_dart_info) info_.of_dart.reserve(n);
}

template <int D, class... A>
void CMap<D, A...>::clear() {
  if (marks_.reserved_count() != 0) throw TopologyError("cmap::clear: marks are still reserved");
  beta_.clear();
  free_head_ = detail::null_index;
  alive_ = 0;
  for_each_dim([&](auto k) {
    if constexpr (has_attribute<k()>) {
      store<k()>().of_dart.clear();
      store<k()>().values.clear();
    }
  });
  if constexpr (has_dart_info) info_.of_dart.clear();
  marks_.clear_storage();
  pending_erase_.clear();
  links_sound_ = true;  // no links left
}

template <int D, class... A>
std::vector<Dart> CMap<D, A...>::compact() {
  if (marks_.reserved_count() != 0)
    throw TopologyError("cmap::compact: " + std::to_string(marks_.reserved_count()) + " mark(s) still reserved");
  const auto n = static_cast<std::uint32_t>(beta_.size());
  std::vector<Dart> old_to_new(n);
  std::uint32_t next = 0;
  for (std::uint32_t x = 0; x < n; ++x)
    if (beta_[x][0] != detail::dead_marker) old_to_new[x] = Dart(next++);
  auto remap = [&](std::uint32_t y) { return y == detail::null_index ? y : old_to_new[y].index(); };
  for (std::uint32_t x = 0; x < n; ++x) {
    if (old_to_new[x].is_null()) continue;
    const std::uint32_t nx = old_to_new[x].index();
    std::array<std::uint32_t, D + 1> row;
    for (int i = 0; i <= D; ++i) row[static_cast<std::size_t>(i)] = remap(beta_[x][static_cast<std::size_t>(i)]);
    beta_[nx] = row;
    for_each_dim([&](auto k) {
      if constexpr (has_attribute<k()>) store<k()>().of_dart[nx] = store<k()>().of_dart[x];
    });
    if constexpr (has_dart_info)
      if (nx != x) info_.of_dart[nx] = std::move(info_.of_dart[x]);
  }
  beta_.resize(next);
  beta_.shrink_to_fit();
  if constexpr (has_dart_info) {
    info_.of_dart.resize(next);
    info_.of_dart.shrink_to_fit();
  }
  for_each_dim([&](auto k) {
    constexpr int K = k();
    if constexpr (has_attribute<K>) {
      auto& st = store<K>();
      st.of_dart.resize(next);
      st.of_dart.shrink_to_fit();
      for (std::uint32_t a = 0; a < st.values.capacity(); ++a)
        if (st.values.is_alive(a) && st.values.dart(a) != detail::null_index)
          st.values.set_dart(a, remap(st.values.dart(a)));
    }
  });
  free_head_ = detail::null_index;
  marks_.clear_storage();
  marks_.resize(next);
  return old_to_new;
}

template <int D, class... A>
std::size_t CMap<D, A...>::memory_bytes() const {
  std::size_t bytes = beta_.capacity() * sizeof(beta_[0]) + marks_.bytes();
  for_each_dim([&](auto k) {
    if constexpr (has_attribute<k()>)
      bytes += store<k()>().of_dart.capacity() * sizeof(std::uint32_t) + store<k()>().values.bytes();
  });
  if constexpr (has_dart_info) bytes += info_.of_dart.capacity() * sizeof(dart_info_type);
  return bytes;
}

template <int D, class... A>
auto CMap<D, A...>::darts() const {
  struct Iter {
    const CMap* map;
    std::uint32_t x;
    Dart operator*() const { return Dart(x); }
    Iter& operator++() {
      const auto n = static_cast<std::uint32_t>(map->beta_.size());
      do ++x;
      while (x < n && map->beta_[x][0] == detail::dead_marker);
      return *this;
    }
    bool operator==(const Iter& o) const { return x == o.x; }
  };
  struct Range {
    const CMap* map;
    Iter begin() const {
      Iter it{map, 0};
      if (!map->beta_.empty() && map->beta_[0][0] == detail::dead_marker) ++it;
      return it;
    }
    Iter end() const { return Iter{map, static_cast<std::uint32_t>(map->beta_.size())}; }
  };
  return Range{this};
}

}  // namespace sewn
