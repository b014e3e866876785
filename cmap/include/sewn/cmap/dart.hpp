#pragma once
// Dart handles: 32-bit indices into a map's dart arrays, with a null value meaning "free".

#include <compare>
#include <cstdint>
#include <functional>
#include <limits>
#include <ostream>

namespace sewn {

/// A dart of a combinatorial map: an index, or null. Cheap to copy, totally ordered, hashable.
/// A Dart stays valid until the dart is erased or the map is compacted.
class Dart {
 public:
  static constexpr std::uint32_t null_index = std::numeric_limits<std::uint32_t>::max();

  constexpr Dart() = default;
  constexpr explicit Dart(std::uint32_t index) : index_(index) {}

  /// The index of the dart in the map's arrays (null_index for the null dart).
  [[nodiscard]] constexpr std::uint32_t index() const { return index_; }
  [[nodiscard]] constexpr bool is_null() const { return index_ == null_index; }
  [[nodiscard]] constexpr explicit operator bool() const { return index_ != null_index; }

  friend constexpr auto operator<=>(Dart, Dart) = default;
  friend std::ostream& operator<<(std::ostream& os, Dart d) {
    return d.is_null() ? (os << "null") : (os << d.index_);
  }

 private:
  std::uint32_t index_ = null_index;
};

inline constexpr Dart null_dart{};

}  // namespace sewn

template <>
struct std::hash<sewn::Dart> {
  std::size_t operator()(sewn::Dart d) const noexcept { return std::hash<std::uint32_t>{}(d.index()); }
};
