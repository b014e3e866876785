#pragma once
// CMap: i-sew / i-unsew and their attribute-free variants. Included by cmap.hpp.
//
// Sewing a and b by βI also sews every pair of darts reached from (a, b) by the involutions
// that must keep commuting with βI: βj for |j - I| ≥ 2 (with β1 standing for β1 and β0).
// For I ≥ 2 a pair (x, y) spreads to (βj x, βj y) and, through β1, to (β1 x, β0 y) and
// (β0 x, β1 y). For I = 1 (β1 x = y) it spreads to (βj y, βj x): βj reverses orientation.

#include <unordered_map>

namespace sewn {

template <int D, class... A>
template <int I>
bool CMap<D, A...>::sew_pairs(std::uint32_t a, std::uint32_t b0, std::vector<std::pair<std::uint32_t, std::uint32_t>>* out) const {
  static_assert(I >= 1 && I <= D);
  constexpr std::uint32_t null = detail::null_index;
  std::vector<std::pair<std::uint32_t, std::uint32_t>> pairs;
  // partner of each first-side dart, and the set of second-side darts, to check the pairing
  // is a bijection (and, for I ≥ 2, that no dart is on both sides).
  std::unordered_map<std::uint32_t, std::uint32_t> first, second;
  auto free_ok = [&](std::uint32_t x, std::uint32_t y) {
    if constexpr (I == 1)
      return b(x, 1) == null && b(y, 0) == null;
    else
      return x != y && b(x, I) == null && b(y, I) == null;
  };
  auto visit = [&](std::uint32_t x, std::uint32_t y) -> bool {
    if (auto it = first.find(x); it != first.end()) return it->second == y;
    if (second.count(y)) return false;
    if constexpr (I >= 2)
      if (first.count(y) || second.count(x)) return false;
    if (!free_ok(x, y)) return false;
    first.emplace(x, y);
    second.emplace(y, x);
    pairs.emplace_back(x, y);
    return true;
  };
  if (!visit(a, b0)) return false;
  for (std::size_t head = 0; head < pairs.size(); ++head) {
    const auto [x, y] = pairs[head];
    if constexpr (I >= 3) {  // β1 commutes (up to inversion) with βI
      const std::uint32_t x1 = b(x, 1), y0 = b(y, 0), x0 = b(x, 0), y1 = b(y, 1);
      if ((x1 == null) != (y0 == null) || (x0 == null) != (y1 == null)) return false;
      if (x1 != null && !visit(x1, y0)) return false;
      if (x0 != null && !visit(x0, y1)) return false;
    }
    for (int j = std::max(2, I + 2); j <= D; ++j) {
      const std::uint32_t xj = b(x, j), yj = b(y, j);
      if ((xj == null) != (yj == null)) return false;
      if (xj == null) continue;
      if (!(I == 1 ? visit(yj, xj) : visit(xj, yj))) return false;
    }
    for (int j = 2; j <= I - 2; ++j) {
      const std::uint32_t xj = b(x, j), yj = b(y, j);
      if ((xj == null) != (yj == null)) return false;
      if (xj != null && !visit(xj, yj)) return false;
    }
  }
  if (out) *out = std::move(pairs);
  return true;
}

template <int D, class... A>
template <int I>
void CMap<D, A...>::unsew_pairs(std::uint32_t d, DartPairs& pairs) const {
  constexpr std::uint32_t null = detail::null_index;
  pairs.clear();
  const Mark m = marks_.reserve();
  const MarkView mk = marks_.view(m);
  // A partial map may hold an I-sewn dart whose β1-neighbour is I-free (its partner's face is
  // open there); only sewn darts belong to the orbit being unsewn.
  auto visit = [&](std::uint32_t x) {
    if (x == null || b(x, I) == null || !mk.set(x)) return;
    const std::uint32_t y = b(x, I);
    if constexpr (I >= 2) mk.set(y);
    pairs.emplace_back(x, y);
  };
  visit(d);
  for (std::size_t head = 0; head < pairs.size(); ++head) {
    const auto [x, y] = pairs[head];
    if constexpr (I >= 3) {
      visit(b(x, 1));
      visit(b(x, 0));
    }
    for (int j = std::max(2, I + 2); j <= D; ++j) {
      if constexpr (I == 1) {
        if (const std::uint32_t yj = b(y, j); yj != null) visit(yj);
      } else {
        visit(b(x, j));
      }
    }
    for (int j = 2; j <= I - 2; ++j) visit(b(x, j));
  }
  for (auto [x, y] : pairs) {  // the marked darts: the pairs' first darts, and for I ≥ 2 their partners
    mk.clear(x);
    if constexpr (I >= 2) mk.clear(y);
  }
  marks_.release(m);
}

template <int D, class... A>
template <int I>
bool CMap<D, A...>::is_sewable(Dart a, Dart b2) const {
  static_assert(I >= 1 && I <= D, "sew index must be in [1, D]");
  if (!is_alive(a) || !is_alive(b2)) return false;
  return sew_pairs<I>(a.index(), b2.index(), nullptr);
}

template <int D, class... A>
template <int I>
std::vector<std::pair<std::uint32_t, std::uint32_t>> CMap<D, A...>::link_orbits(Dart a, Dart b2, const char* who) {
  static_assert(I >= 1 && I <= D, "sew index must be in [1, D]");
  check_alive(a, who);
  check_alive(b2, who);
  std::vector<std::pair<std::uint32_t, std::uint32_t>> pairs;
  if (!sew_pairs<I>(a.index(), b2.index(), &pairs))
    throw TopologyError("cmap::" + std::string(who) + "<" + std::to_string(I) + ">: darts " + std::to_string(a.index()) +
                        " and " + std::to_string(b2.index()) +
                        " are not sewable (not free, or their orbits differ in shape; see is_sewable)");
  for (auto [x, y] : pairs) raw_link(x, I, y);
  return pairs;
}

template <int D, class... A>
template <int I>
void CMap<D, A...>::unlink_orbits(Dart d, const char* who, DartPairs& pairs) {
  static_assert(I >= 1 && I <= D, "unsew index must be in [1, D]");
  check_alive(d, who);
  if (b(d.index(), I) == detail::null_index)
    throw TopologyError("cmap::" + std::string(who) + "<" + std::to_string(I) + ">: dart " + std::to_string(d.index()) +
                        " is " + std::to_string(I) + "-free");
  unsew_pairs<I>(d.index(), pairs);
  constexpr int inv = I == 1 ? 0 : I;
  for (auto [x, y] : pairs) {
    set_b(x, I, detail::null_index);
    set_b(y, inv, detail::null_index);
  }
}

template <int D, class... A>
template <int I, class Pairs>
void CMap<D, A...>::update_attributes_around(const Pairs& pairs) {
  // I-cells keep their darts (βI is not among their generators); the others may merge or split.
  constexpr unsigned dims = ~(1u << I);
  if constexpr ((attribute_dims & dims) != 0) {
    detail::DartBuffer<64> touched;
    for (auto [x, y] : pairs) {
      touched.push_back(x);
      touched.push_back(y);
    }
    update_attributes(touched, dims);
  }
}

template <int D, class... A>
template <int I>
void CMap<D, A...>::link(Dart a, Dart b2) {
  (void)link_orbits<I>(a, b2, "link");
}

template <int D, class... A>
template <int I>
void CMap<D, A...>::sew(Dart a, Dart b2) {
  update_attributes_around<I>(link_orbits<I>(a, b2, "sew"));
}

template <int D, class... A>
template <int I>
void CMap<D, A...>::unlink(Dart d) {
  DartPairs pairs;
  unlink_orbits<I>(d, "unlink", pairs);
}

template <int D, class... A>
template <int I>
void CMap<D, A...>::unsew(Dart d) {
  DartPairs pairs;
  unlink_orbits<I>(d, "unsew", pairs);
  update_attributes_around<I>(pairs);
}

template <int D, class... A>
template <int I>
std::uint32_t CMap<D, A...>::unsew_all(std::span<const Dart> darts) {
  std::vector<std::pair<std::uint32_t, std::uint32_t>> all;
  DartPairs pairs;
  std::uint32_t done = 0;
  for (Dart d : darts) {
    if (!is_alive(d) || b(d.index(), I) == detail::null_index) continue;
    unlink_orbits<I>(d, "unsew_all", pairs);
    all.insert(all.end(), pairs.begin(), pairs.end());
    ++done;
  }
  if (done != 0) update_attributes_around<I>(all);
  return done;
}

}  // namespace sewn
