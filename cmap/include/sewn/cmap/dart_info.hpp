#pragma once
// DartInfo<T>: the optional first type parameter of CMap that gives every dart a value.

#include <type_traits>

namespace sewn {

/// CMap<D, DartInfo<T>, A0, A1, ...> gives every dart a value of type T (CGAL's Dart_info), read
/// and written with info(d). Without it a map stores nothing per dart beyond its links and
/// attribute indices. T must be default-constructible and copyable.
template <class T>
struct DartInfo {
  static_assert(!std::is_void_v<T> && std::is_default_constructible_v<T> && std::is_copy_assignable_v<T>,
                "DartInfo<T>: T must be a default-constructible, copyable type");
  using type = T;
};

}  // namespace sewn
