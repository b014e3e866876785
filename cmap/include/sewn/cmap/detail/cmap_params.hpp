#pragma once
// How CMap turns its type parameters into storage: which attribute type each dimension has,
// the per-dimension attribute stores, and the per-dart info store. Internal to cmap.hpp.

#include <cstdint>
#include <functional>
#include <tuple>
#include <type_traits>
#include <utility>
#include <vector>

#include "sewn/cmap/attributes.hpp"
#include "sewn/cmap/dart.hpp"
#include "sewn/cmap/dart_info.hpp"
#include "sewn/cmap/detail/pod_array.hpp"

namespace sewn {

namespace detail {

template <int I, class... A>
struct nth_or_void {
  using type = void;
};
template <class H, class... T>
struct nth_or_void<0, H, T...> {
  using type = H;
};
template <int I, class H, class... T>
  requires(I > 0)
struct nth_or_void<I, H, T...> {
  using type = typename nth_or_void<I - 1, T...>::type;
};

template <int I, class T>
struct AttrStore {
  PodArray<std::uint32_t> of_dart;  // attribute index of each dart's I-cell
  AttributeContainer<T> values;
  std::function<void(AttrId<I>, AttrId<I>)> on_split, on_merge;
  std::function<void(AttrId<I>)> on_erase;
};
template <int I>
struct AttrStore<I, void> {};

template <class Seq, class... A>
struct StoreTuple;
template <int... I, class... A>
struct StoreTuple<std::integer_sequence<int, I...>, A...> {
  using type = std::tuple<AttrStore<I, typename nth_or_void<I, A...>::type>...>;
};

// CMap's type parameters: an optional DartInfo<T> first, then the cell attribute types.
template <class T>
struct is_dart_info : std::false_type {};
template <class T>
struct is_dart_info<DartInfo<T>> : std::true_type {};
template <class... A>
struct MapParams {
  using info = void;
  template <int I>
  using attr = typename nth_or_void<I, A...>::type;
  template <class Seq>
  using stores = typename StoreTuple<Seq, A...>::type;
  static constexpr std::size_t num_attrs = sizeof...(A);
  static constexpr bool info_only_first = (!is_dart_info<A>::value && ...);
};
template <class T, class... A>
struct MapParams<DartInfo<T>, A...> : MapParams<A...> {
  using info = T;
};

// The per-dart values of a map with DartInfo<T>; nothing at all without.
template <class T>
struct InfoStore {
  std::conditional_t<std::is_trivially_copyable_v<T>, PodArray<T>, std::vector<T>> of_dart;
};
template <>
struct InfoStore<void> {};

inline constexpr std::uint32_t null_index = Dart::null_index;
inline constexpr std::uint32_t dead_marker = Dart::null_index - 1;  // β0 of a free-listed dart

// For builders in sibling headers that link with link_beta and complete every orbit they
// touch: they read whether the links were sound before and say so again when done.
struct LinkSoundness {
  template <class Map>
  static bool get(const Map& m) { return m.links_sound_; }
  template <class Map>
  static void restore(const Map& m, bool sound) { m.links_sound_ = sound; }
};

}  // namespace detail

}  // namespace sewn
