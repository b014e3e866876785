#pragma once
// PodArray<T>: the growable arrays behind the map's per-dart data (β links, attribute indices,
// mark planes, attribute bookkeeping). Like std::vector, except in how it grows. A large block
// (from 256 KiB) is mapped by the array itself on Linux: it grows by moving its pages (mremap),
// never by copying them into fresh ones, and asks for transparent huge pages, so that a map of
// millions of darts takes one page fault per 2 MiB instead of one per 4 KiB (a fault costs 1-2 µs
// on a virtual machine). glibc's realloc would remap too, but only until the first large free:
// its mmap threshold then rises and large blocks come from the heap, copied on every growth.
// Small blocks use malloc/realloc. A freed mapped block is kept, its pages still populated, for
// the next arrays that need it (see MappedBlocks): a map copied or rebuilt again and again then
// faults no pages in, as the heap spares the small blocks. T must be trivially copyable;
// elements past size() are not kept initialised.

#include <algorithm>
#include <cstddef>
#include <cstdlib>
#include <cstring>
#include <mutex>
#include <new>
#include <type_traits>
#include <utility>

#if defined(__linux__)
#include <sys/mman.h>
#endif

namespace sewn::detail {

#if defined(__linux__)
// Mapped blocks released by PodArrays, kept for reuse up to a budget, the oldest given back to
// the system first (the heap keeps freed memory the same way, up to its trim threshold). Blocks
// are byte ranges, split and joined as the heap splits and joins its chunks: a request gets the
// front of the smallest block that holds it and the rest stays kept, so an array reserved to its
// exact size holds no slack of whatever array was freed before it (hex32's β array took the 2x
// block of a map whose edges had all been split: 16 bytes per dart that nothing used); and an
// array that grows takes the kept range right after its end, in place (a map copied and then
// grown again and again faults no pages in).
class MappedBlocks {
 public:
  static constexpr std::size_t budget = std::size_t{64} << 20;  // bytes kept at most
  static MappedBlocks& instance() {
    static MappedBlocks blocks;
    return blocks;
  }
  // The first `bytes` of the smallest kept block that holds them, no longer kept; nullptr if none.
  void* take(std::size_t bytes) {
    const std::lock_guard<std::mutex> lock(mutex_);
    std::size_t best = count_;
    for (std::size_t i = 0; i < count_; ++i)
      if (blocks_[i].bytes >= bytes && (best == count_ || blocks_[i].bytes < blocks_[best].bytes)) best = i;
    if (best == count_) return nullptr;
    return cut_front(best, bytes);
  }
  // If a kept block starts at `at` and holds `bytes`, its first `bytes` are no longer kept and
  // true is returned: the array ending at `at` may extend over them.
  bool take_at(void* at, std::size_t bytes) {
    const std::lock_guard<std::mutex> lock(mutex_);
    for (std::size_t i = 0; i < count_; ++i)
      if (blocks_[i].p == at) {
        if (blocks_[i].bytes < bytes) return false;
        cut_front(i, bytes);
        return true;
      }
    return false;
  }
  // Keeps a range that is no longer used, joined with the kept ranges it touches, unmapping the
  // oldest ones it does not fit beside.
  void give(void* p, std::size_t bytes) {
    const std::lock_guard<std::mutex> lock(mutex_);
    for (std::size_t i = 0; i < count_;) {
      char* q = static_cast<char*>(blocks_[i].p);
      if (q + blocks_[i].bytes == p) {
        p = q;
        bytes += blocks_[i].bytes;
        remove(i);
      } else if (static_cast<char*>(p) + bytes == q) {
        bytes += blocks_[i].bytes;
        remove(i);
      } else {
        ++i;
      }
    }
    if (bytes > budget) {
      munmap(p, bytes);
      return;
    }
    while (count_ == max_blocks || kept_ + bytes > budget) {
      munmap(blocks_[0].p, blocks_[0].bytes);
      remove(0);
    }
    blocks_[count_++] = {p, bytes};
    kept_ += bytes;
  }

 private:
  struct Block {
    void* p;
    std::size_t bytes;
  };
  void* cut_front(std::size_t i, std::size_t bytes) {
    Block& b = blocks_[i];
    void* p = b.p;
    if (b.bytes == bytes) {
      remove(i);
    } else {
      b.p = static_cast<char*>(b.p) + bytes;
      b.bytes -= bytes;
      kept_ -= bytes;
    }
    return p;
  }
  void remove(std::size_t i) {
    kept_ -= blocks_[i].bytes;
    std::copy(blocks_ + i + 1, blocks_ + count_, blocks_ + i);
    --count_;
  }
  static constexpr std::size_t max_blocks = 32;
  std::mutex mutex_;
  Block blocks_[max_blocks]{};
  std::size_t count_ = 0, kept_ = 0;
};
#endif

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
      release(data_, cap_);
      data_ = std::exchange(o.data_, nullptr);
      size_ = std::exchange(o.size_, 0);
      cap_ = std::exchange(o.cap_, 0);
    }
    return *this;
  }
  ~PodArray() { release(data_, cap_); }

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
  // A heap block doubles, as growth copies it; a mapped block grows by a quarter, as mremap
  // copies nothing: at most a quarter of it is slack (a doubled block of 263 169 quad512
  // vertices held 2^19 slots).
  void grow_for(std::size_t n) {
    const std::size_t step = mapped(cap_) ? cap_ + cap_ / 4 : (cap_ < 8 ? std::size_t{8} : 2 * cap_);
    set_capacity(std::max(n, step));
  }
  // Moves the first size_ elements into a block of capacity cap (cap >= size_). A mapped block
  // is whole pages, all of them usable and counted in capacity().
  void set_capacity(std::size_t cap) {
    if (cap > max_elements) throw std::bad_alloc();
    const bool was_mapped = mapped(cap_), now_mapped = mapped(cap);
    if (now_mapped) cap = mapped_bytes(cap) / sizeof(T);
    T* p = nullptr;
    if (cap == 0) {
      release(data_, cap_);
    } else if (!was_mapped && !now_mapped) {
      p = static_cast<T*>(std::realloc(data_, cap * sizeof(T)));
      if (!p) throw std::bad_alloc();
    } else if (was_mapped && now_mapped) {
      p = remap(data_, cap_, cap, size_);
    } else {  // crossing the threshold: a fresh block of the other kind
      p = allocate(cap);
      if (size_ != 0) std::memcpy(p, data_, size_ * sizeof(T));
      release(data_, cap_);
    }
    data_ = p;
    cap_ = cap;
  }

#if defined(__linux__)
  static constexpr std::size_t map_from = std::size_t{256} << 10;  // bytes
  static bool mapped(std::size_t cap) { return cap * sizeof(T) >= map_from; }
  static std::size_t mapped_bytes(std::size_t cap) {
    constexpr std::size_t page = 4096;
    return (cap * sizeof(T) + page - 1) / page * page;
  }
  static void ask_huge_pages(void* p, std::size_t bytes) { (void)madvise(p, bytes, MADV_HUGEPAGE); }  // a hint: failure is harmless
  static T* allocate(std::size_t cap) {
    if (!mapped(cap)) {
      T* p = static_cast<T*>(std::malloc(cap * sizeof(T)));
      if (!p) throw std::bad_alloc();
      return p;
    }
    if (void* q = MappedBlocks::instance().take(mapped_bytes(cap)); q) return static_cast<T*>(q);
    void* p = mmap(nullptr, mapped_bytes(cap), PROT_READ | PROT_WRITE, MAP_PRIVATE | MAP_ANONYMOUS, -1, 0);
    if (p == MAP_FAILED) throw std::bad_alloc();
    ask_huge_pages(p, mapped_bytes(cap));
    return static_cast<T*>(p);
  }
  // Grows in place over a kept range right after the block if there is one, else moves the
  // pages (mremap); shrinking keeps the freed tail. A block joined from two mappings cannot be
  // moved by mremap: it is then copied into a fresh one.
  static T* remap(T* p, std::size_t old_cap, std::size_t cap, std::size_t size) {
    const std::size_t old_bytes = mapped_bytes(old_cap), bytes = mapped_bytes(cap);
    char* end = reinterpret_cast<char*>(p) + old_bytes;
    if (bytes <= old_bytes) {
      if (bytes < old_bytes) MappedBlocks::instance().give(end - (old_bytes - bytes), old_bytes - bytes);
      return p;
    }
    if (MappedBlocks::instance().take_at(end, bytes - old_bytes)) return p;
    void* q = mremap(p, old_bytes, bytes, MREMAP_MAYMOVE);
    if (q == MAP_FAILED) {
      T* fresh = allocate(cap);
      if (size != 0) std::memcpy(fresh, p, size * sizeof(T));
      release(p, old_cap);
      return fresh;
    }
    ask_huge_pages(q, bytes);
    return static_cast<T*>(q);
  }
  static void release(T* p, std::size_t cap) {
    if (!p) return;
    if (mapped(cap))
      MappedBlocks::instance().give(p, mapped_bytes(cap));
    else
      std::free(p);
  }
#else
  static bool mapped(std::size_t) { return false; }
  static std::size_t mapped_bytes(std::size_t cap) { return cap * sizeof(T); }
  static T* allocate(std::size_t cap) {
    T* p = static_cast<T*>(std::malloc(cap * sizeof(T)));
    if (!p) throw std::bad_alloc();
    return p;
  }
  static T* remap(T*, std::size_t, std::size_t, std::size_t) { return nullptr; }  // never called: nothing is mapped
  static void release(T* p, std::size_t) { std::free(p); }
#endif
  static constexpr std::size_t max_elements = std::size_t(-1) / 2 / sizeof(T);

  void assign_copy(const PodArray& o) {
    if (o.size_ > cap_) set_capacity(o.size_);
    if (o.size_ != 0) std::memcpy(data_, o.data_, o.size_ * sizeof(T));
    size_ = o.size_;
  }

  T* data_ = nullptr;
  std::size_t size_ = 0, cap_ = 0;
};

}  // namespace sewn::detail
