#pragma once
// Reservable boolean marks on darts, stored as one bit plane per mark (1 bit per dart).
// Planes are allocated the first time a mark number is reserved, so a map that never uses
// more than k marks at once pays k bits per dart. Unmarking every dart is O(1) when all live
// darts are marked (the plane's polarity flips), O(n/64) otherwise.

#include <array>
#include <bit>
#include <cstdint>
#include <string>
#include <vector>

#include "sewn/cmap/detail/pod_array.hpp"
#include "sewn/cmap/errors.hpp"

namespace sewn {

/// A reserved mark number. Obtained from CMap::reserve_mark(), given back with free_mark().
class Mark {
 public:
  constexpr Mark() = default;
  constexpr explicit Mark(int id) : id_(id) {}
  [[nodiscard]] constexpr int id() const { return id_; }
  [[nodiscard]] constexpr bool valid() const { return id_ >= 0; }
  friend constexpr bool operator==(Mark, Mark) = default;

 private:
  int id_ = -1;
};

namespace detail {

class MarkPlanes {
 public:
  static constexpr int max_marks = 32;

  /// One reserved mark seen through its plane's raw words, for traversal loops: passed by
  /// value, the word pointer and polarity stay in registers and test / set compile to a few
  /// instructions. A view does not keep the marked count: code that marks or unmarks through
  /// one adds the difference with add_count() before the count is read or the mark cleared.
  /// Valid while the mark stays reserved and no dart is created (that may grow the plane).
  struct View {
    std::uint64_t* words;
    std::uint64_t polarity;

    [[nodiscard]] bool test(std::uint32_t d) const { return (((words[d >> 6] ^ polarity) >> (d & 63)) & 1u) != 0; }
    /// Sets the bit; returns true if it was not set before.
    bool set(std::uint32_t d) const {
      const std::uint64_t bit = std::uint64_t{1} << (d & 63);
      std::uint64_t& w = words[d >> 6];
      if (((w ^ polarity) & bit) != 0) return false;
      w ^= bit;
      return true;
    }
    /// Clears the bit; returns true if it was set before.
    bool clear(std::uint32_t d) const {
      const std::uint64_t bit = std::uint64_t{1} << (d & 63);
      std::uint64_t& w = words[d >> 6];
      if (((w ^ polarity) & bit) == 0) return false;
      w ^= bit;
      return true;
    }
    /// The first unmarked index in [d, end), or end: a word at a time over marked runs.
    [[nodiscard]] std::uint32_t next_unmarked(std::uint32_t d, std::uint32_t end) const {
      if (d >= end) return end;
      std::size_t w = d >> 6;
      std::uint64_t free = ~(words[w] ^ polarity) & (~std::uint64_t{0} << (d & 63));
      const std::size_t last = (static_cast<std::size_t>(end) + 63) >> 6;
      while (free == 0) {
        if (++w >= last) return end;
        free = ~(words[w] ^ polarity);
      }
      const auto found = static_cast<std::uint32_t>((w << 6) + static_cast<std::size_t>(std::countr_zero(free)));
      return found < end ? found : end;
    }
  };
  [[nodiscard]] View view(Mark m) {
    const auto i = static_cast<std::size_t>(m.id());
    return View{planes_[i].data(), polarity_[i]};
  }
  /// Adds delta to the marked count of m (after marking or unmarking through a View).
  void add_count(Mark m, std::int64_t delta) {
    auto& c = count_[static_cast<std::size_t>(m.id())];
    c = static_cast<std::uint32_t>(static_cast<std::int64_t>(c) + delta);
  }

  Mark reserve() {
    if (reserved_ == ~std::uint32_t{0})
      throw CapacityError("cmap: all " + std::to_string(max_marks) +
                          " marks are reserved (a mark was not freed, or traversals nest too deeply)");
    const int m = std::countr_one(reserved_);
    reserved_ |= std::uint32_t{1} << m;
    auto& p = planes_[static_cast<std::size_t>(m)];
    if (p.size() < words_) p.resize(words_, polarity_[static_cast<std::size_t>(m)]);
    return Mark(m);
  }
  void release(Mark m) { reserved_ &= ~(std::uint32_t{1} << m.id()); }
  [[nodiscard]] bool is_reserved(Mark m) const {
    return m.valid() && m.id() < max_marks && ((reserved_ >> m.id()) & 1u);
  }
  [[nodiscard]] int reserved_count() const { return std::popcount(reserved_); }
  [[nodiscard]] std::uint32_t reserved_bits() const { return reserved_; }

  [[nodiscard]] bool test(std::uint32_t d, Mark m) const {
    const auto i = static_cast<std::size_t>(m.id());
    return (((planes_[i][d >> 6] ^ polarity_[i]) >> (d & 63)) & 1u) != 0;
  }
  /// Sets the bit; returns true if it was not set before.
  bool set(std::uint32_t d, Mark m) {
    const auto i = static_cast<std::size_t>(m.id());
    const std::uint64_t bit = std::uint64_t{1} << (d & 63);
    std::uint64_t& w = planes_[i][d >> 6];
    if (((w ^ polarity_[i]) & bit) != 0) return false;
    w ^= bit;
    ++count_[i];
    return true;
  }
  /// Clears the bit; returns true if it was set before.
  bool clear(std::uint32_t d, Mark m) {
    const auto i = static_cast<std::size_t>(m.id());
    const std::uint64_t bit = std::uint64_t{1} << (d & 63);
    std::uint64_t& w = planes_[i][d >> 6];
    if (((w ^ polarity_[i]) & bit) == 0) return false;
    w ^= bit;
    --count_[i];
    return true;
  }
  [[nodiscard]] std::uint32_t count(Mark m) const { return count_[static_cast<std::size_t>(m.id())]; }

  /// Marks every dart unmarked. `live` is the number of live darts, `dead` lists the dead ones
  /// and `capacity` bounds dart indices. When every live dart is marked, flipping the polarity
  /// is O(#dead); otherwise O(n/64). Either way dead and not-yet-created darts stay unmarked.
  template <class DeadRange>
  void clear_all(Mark m, std::uint32_t live, const DeadRange& dead, std::uint32_t capacity) {
    const auto i = static_cast<std::size_t>(m.id());
    if (count_[i] == 0) return;
    if (count_[i] == live) {
      polarity_[i] = ~polarity_[i];
      for (std::uint32_t d : dead) planes_[i][d >> 6] ^= std::uint64_t{1} << (d & 63);
      // indices past the last dart share its word: flip them back too
      if ((capacity & 63u) != 0) planes_[i][capacity >> 6] ^= ~std::uint64_t{0} << (capacity & 63u);
      for (std::size_t w = (static_cast<std::size_t>(capacity) + 63) / 64; w < planes_[i].size(); ++w)
        planes_[i][w] = polarity_[i];
    } else {
      for (auto& w : planes_[i]) w = polarity_[i];
    }
    count_[i] = 0;
  }

  /// Grows every allocated plane to hold `darts` darts; new darts are unmarked.
  void resize(std::uint32_t darts) {
    words_ = (static_cast<std::size_t>(darts) + 63) / 64;
    for (std::size_t i = 0; i < max_marks; ++i)
      if (!planes_[i].empty() || ((reserved_ >> i) & 1u)) planes_[i].resize(words_, polarity_[i]);
  }
  void clear_storage() {
    for (auto& p : planes_) p.clear();
    polarity_.fill(0);
    count_.fill(0);
    words_ = 0;
  }
  [[nodiscard]] std::size_t bytes() const {
    std::size_t b = 0;
    for (const auto& p : planes_) b += p.capacity() * sizeof(std::uint64_t);
    return b;
  }

 private:
  std::array<PodArray<std::uint64_t>, max_marks> planes_{};
  std::array<std::uint64_t, max_marks> polarity_{};
  std::array<std::uint32_t, max_marks> count_{};
  std::uint32_t reserved_ = 0;
  std::size_t words_ = 0;
};

}  // namespace detail
}  // namespace sewn
