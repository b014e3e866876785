#pragma once
// DartBuffer: the list of dart indices that traversals and operations fill (a breadth-first
// queue, the darts of a cell, the darts an operation touched). Typical cells have a few dozen
// darts, so the first N live inside the object, on the caller's stack: an operation allocates
// nothing, and nested traversals (hooks may call back into the map) each have their own.

#include <algorithm>
#include <cstddef>
#include <cstdint>
#include <memory>

namespace sewn::detail {

// Its state is three pointers, not a pointer and counts: a store of a dart index (uint32_t)
// cannot alias a pointer, so loops keep the end in a register across push_back.
template <std::size_t N>
class DartBuffer {
 public:
  using value_type = std::uint32_t;

  DartBuffer() = default;
  DartBuffer(const DartBuffer&) = delete;
  DartBuffer& operator=(const DartBuffer&) = delete;
  DartBuffer(DartBuffer&& o) noexcept { take(o); }
  DartBuffer& operator=(DartBuffer&& o) noexcept {
    if (this != &o) take(o);
    return *this;
  }
  ~DartBuffer() = default;

  // Inlined into traversal loops; only growth leaves the loop.
  [[gnu::always_inline]] void push_back(std::uint32_t x) {
    if (end_ == cap_) [[unlikely]]
      grow();
    *end_++ = x;
  }
  void clear() { end_ = begin_; }
  [[nodiscard]] std::size_t size() const { return static_cast<std::size_t>(end_ - begin_); }
  [[nodiscard]] bool empty() const { return end_ == begin_; }
  std::uint32_t& operator[](std::size_t k) { return begin_[k]; }
  std::uint32_t operator[](std::size_t k) const { return begin_[k]; }
  [[nodiscard]] std::uint32_t front() const { return *begin_; }
  [[nodiscard]] std::uint32_t back() const { return end_[-1]; }
  std::uint32_t* begin() { return begin_; }
  std::uint32_t* end() { return end_; }
  [[nodiscard]] const std::uint32_t* begin() const { return begin_; }
  [[nodiscard]] const std::uint32_t* end() const { return end_; }

 private:
  [[gnu::noinline]] void grow() {
    const std::size_t n = size(), cap = 2 * static_cast<std::size_t>(cap_ - begin_);
    auto bigger = std::make_unique<std::uint32_t[]>(cap);
    std::copy(begin_, end_, bigger.get());
    heap_ = std::move(bigger);
    begin_ = heap_.get();
    end_ = begin_ + n;
    cap_ = begin_ + cap;
  }
  void take(DartBuffer& o) {
    const std::size_t n = o.size();
    if (o.heap_) {
      heap_ = std::move(o.heap_);
      begin_ = o.begin_;
      cap_ = o.cap_;
    } else {
      heap_.reset();
      std::copy(o.begin_, o.end_, inline_);
      begin_ = inline_;
      cap_ = inline_ + N;
    }
    end_ = begin_ + n;
    o.begin_ = o.end_ = o.inline_;
    o.cap_ = o.inline_ + N;
  }

  std::uint32_t inline_[N];
  std::unique_ptr<std::uint32_t[]> heap_;
  std::uint32_t* begin_ = inline_;
  std::uint32_t* end_ = inline_;
  std::uint32_t* cap_ = inline_ + N;
};

}  // namespace sewn::detail
