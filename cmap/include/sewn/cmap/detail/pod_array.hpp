#pragma once
// PodArray<T>: the growable arrays behind the map's per-dart data (β links, attribute indices,
// mark planes, attribute bookkeeping). Like std::vector, except that it grows with realloc: a
// large block (mapped pages, for glibc) then grows by remapping its pages instead of copying
// them into fresh ones, which saves the copy and the page faults of the old half (a fault costs
// 1-2 µs on a virtual machine). T must be trivially copyable; elements past size() are not kept
// initialised.

#include <algorithm>
#include <cstddef>
#include <cstdlib>
#include <cstring>
#include <new>
#include <type_traits>
#include <utility>

namespace sewn::detail {

template <class T>
class PodArray {
  static_assert(std::is_trivially_copyable_v<T>, "PodArray holds trivially copyable values");

 public:
  using value_type = T;

  PodArray() = default;
  PodArray(const PodArray& o) { assign_copy(o); }
  PodArray& operator=(const PodArray& o) {
    if (this != &o) {
      size_ = 0;
      assign_copy(o);
    }
    return *this;
  }
  PodArray(PodArray&& o) noexcept
      : data_(std::exchange(o.data_, nullptr)), size_(std::exchange(o.size_, 0)), cap_(std::exchange(o.cap_, 0)) {}
  PodArray& operator=(PodArray&& o) noexcept {
    if (this != &o) {
      std::free(data_);
      data_ = std::exchange(o.data_, nullptr);
      size_ = std::exchange(o.size_, 0);
      cap_ = std::exchange(o.cap_, 0);
    }
    return *this;
  }
  ~PodArray() { std::free(data_); }

  [[nodiscard]] std::size_t size() const { return size_; }
  [[nodiscard]] std::size_t capacity() const { return cap_; }
  [[nodiscard]] bool empty() const { return size_ == 0; }
  T* data() { return data_; }
  const T* data() const { return data_; }
  T& operator[](std::size_t i) { return data_[i]; }
  const T& operator[](std::size_t i) const { return data_[i]; }
  T* begin() { return data_; }
  T* end() { return data_ + size_; }
  const T* begin() const { return data_; }
  const T* end() const { return data_ + size_; }
  T& back() { return data_[size_ - 1]; }
  const T& back() const { return data_[size_ - 1]; }

  void push_back(const T& v) {
    if (size_ == cap_) [[unlikely]]
      grow_for(size_ + 1);
    data_[size_++] = v;
  }
  void pop_back() { --size_; }
  void clear() { size_ = 0; }
  void reserve(std::size_t n) {
    if (n > cap_) set_capacity(n);
  }
  void resize(std::size_t n, const T& v = T()) {
    if (n > cap_) grow_for(n);
    std::fill(data_ + std::min(n, size_), data_ + n, v);
    size_ = n;
  }
  void assign(std::size_t n, const T& v) {
    size_ = 0;
    resize(n, v);
  }
  void shrink_to_fit() {
    if (cap_ != size_) set_capacity(size_);
  }

 private:
  void grow_for(std::size_t n) { set_capacity(std::max(n, cap_ < 8 ? std::size_t{8} : 2 * cap_)); }
  // Moves the first size_ elements into a block of capacity cap (cap >= size_).
  void set_capacity(std::size_t cap) {
    if (cap == 0) {
      std::free(data_);
      data_ = nullptr;
    } else {
      T* p = static_cast<T*>(std::realloc(data_, cap * sizeof(T)));
      if (!p) throw std::bad_alloc();
      data_ = p;
    }
    cap_ = cap;
  }

  void assign_copy(const PodArray& o) {
    if (o.size_ > cap_) set_capacity(o.size_);
    if (o.size_ != 0) std::memcpy(data_, o.data_, o.size_ * sizeof(T));
    size_ = o.size_;
  }

  T* data_ = nullptr;
  std::size_t size_ = 0, cap_ = 0;
};

}  // namespace sewn::detail
