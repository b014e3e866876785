#pragma once
// Attribute handles and the compact container that stores the attributes of one cell dimension.

#include <cstdint>
#include <ostream>
#include <type_traits>
#include <utility>
#include <vector>

#include "sewn/cmap/dart.hpp"
#include "sewn/cmap/detail/pod_array.hpp"

namespace sewn {

/// Handle of an I-attribute (the attribute of an I-cell). A plain index into the map's
/// I-attribute container; null when a cell carries no attribute.
template <int I>
class AttrId {
 public:
  static constexpr std::uint32_t null_index = Dart::null_index;
  constexpr AttrId() = default;
  constexpr explicit AttrId(std::uint32_t index) : index_(index) {}
  [[nodiscard]] constexpr std::uint32_t index() const { return index_; }
  [[nodiscard]] constexpr bool is_null() const { return index_ == null_index; }
  [[nodiscard]] constexpr explicit operator bool() const { return index_ != null_index; }
  friend constexpr auto operator<=>(AttrId, AttrId) = default;
  friend std::ostream& operator<<(std::ostream& os, AttrId a) {
    return a.is_null() ? (os << "null") : (os << a.index_);
  }

 private:
  std::uint32_t index_ = null_index;
};

/// Values of one attribute kind in a contiguous array with a free list. Each live slot also
/// records one dart of its cell and how many darts refer to it, so the map can find the cell
/// of an attribute and detect orphans. Iterating live slots never touches darts.
template <class T>
class AttributeContainer {
 public:
  static constexpr std::uint32_t dead = Dart::null_index - 1;

  /// Creates a slot holding `value`, with no dart yet. O(1) amortised.
  std::uint32_t create(T value) {
    std::uint32_t a;
    if (!free_.empty()) {
      a = free_.back();
      free_.pop_back();
      values_[a] = std::move(value);
      dart_[a] = Dart::null_index;
      count_[a] = 0;
    } else {
      a = static_cast<std::uint32_t>(values_.size());
      values_.push_back(std::move(value));
      dart_.push_back(Dart::null_index);
      count_.push_back(0);
    }
    ++alive_;
    return a;
  }
  /// Frees slot `a`; its index may be reused by the next create(). O(1).
  void erase(std::uint32_t a) {
    dart_[a] = dead;
    count_[a] = 0;
    free_.push_back(a);
    --alive_;
  }

  [[nodiscard]] bool is_alive(std::uint32_t a) const { return a < dart_.size() && dart_[a] != dead; }
  [[nodiscard]] std::uint32_t size() const { return alive_; }          ///< live attributes
  [[nodiscard]] std::uint32_t capacity() const { return static_cast<std::uint32_t>(values_.size()); }

  T& value(std::uint32_t a) { return values_[a]; }
  const T& value(std::uint32_t a) const { return values_[a]; }
  [[nodiscard]] std::uint32_t dart(std::uint32_t a) const { return dart_[a]; }
  void set_dart(std::uint32_t a, std::uint32_t d) { dart_[a] = d; }
  [[nodiscard]] std::uint32_t count(std::uint32_t a) const { return count_[a]; }
  void add_count(std::uint32_t a, std::int64_t delta) {
    count_[a] = static_cast<std::uint32_t>(static_cast<std::int64_t>(count_[a]) + delta);
  }
  const std::vector<std::uint32_t>& free_slots() const { return free_; }

  void reserve(std::size_t n) {
    values_.reserve(n);
    dart_.reserve(n);
    count_.reserve(n);
  }
  void clear() {
    values_.clear();
    dart_.clear();
    count_.clear();
    free_.clear();
    alive_ = 0;
  }
  [[nodiscard]] std::size_t bytes() const {
    return values_.capacity() * sizeof(T) + (dart_.capacity() + count_.capacity() + free_.capacity()) * 4;
  }

 private:
  // Plain values grow as the per-dart arrays do (a mapped block grows by a quarter, see
  // PodArray); std::vector would double them.
  std::conditional_t<std::is_trivially_copyable_v<T>, detail::PodArray<T>, std::vector<T>> values_;
  detail::PodArray<std::uint32_t> dart_;   // one dart of the cell, `dead` for a free slot
  detail::PodArray<std::uint32_t> count_;  // darts referring to the slot
  std::vector<std::uint32_t> free_;
  std::uint32_t alive_ = 0;
};

}  // namespace sewn
