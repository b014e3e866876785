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
//
// Each range remembers its origin, the mapping it lies in (the address mmap or a moving mremap
// returned), and is joined or extended only within it: mremap moves one mapping, and fails on a
// range across two (that made every fourth growth of quad512's arrays a copy).
class MappedBlocks {
 public:
  static constexpr std::size_t budget = std::size_t{64} << 20;  // bytes kept at most
  static MappedBlocks& instance() {
    static MappedBlocks blocks;
    return blocks;
  }
  // The first `bytes` of the smallest kept block that holds them, no longer kept, and its
  // origin; {nullptr, nullptr} if none.
  std::pair<void*, void*> take(std::size_t bytes) {
    const std::lock_guard<std::mutex> lock(mutex_);
    std::size_t best = count_;
    for (std::size_t i = 0; i < count_; ++i)
      if (blocks_[i].bytes >= bytes && (best == count_ || blocks_[i].bytes < blocks_[best].bytes)) best = i;
    if (best == count_) return {nullptr, nullptr};
    void* origin = blocks_[best].origin;
    return {cut_front(best, bytes), origin};
  }
  // If a kept block of `origin` starts at `at` and holds `bytes`, its first `bytes` are no
  // longer kept and true is returned: the array ending at `at` may extend over them.
  bool take_at(void* at, std::size_t bytes, void* origin) {
    const std::lock_guard<std::mutex> lock(mutex_);
    for (std::size_t i = 0; i < count_; ++i)
      if (blocks_[i].p == at) {
        if (blocks_[i].bytes < bytes || blocks_[i].origin != origin) return false;
        cut_front(i, bytes);
        return true;
      }
    return false;
  }
  // Keeps a range of `origin` that is no longer used, joined with the kept ranges of the same
  // origin it touches, unmapping the oldest ones it does not fit beside.
  void give(void* p, std::size_t bytes, void* origin) {
    const std::lock_guard<std::mutex> lock(mutex_);
    for (std::size_t i = 0; i < count_;) {
      char* q = static_cast<char*>(blocks_[i].p);
      if (blocks_[i].origin == origin && q + blocks_[i].bytes == p) {
        p = q;
        bytes += blocks_[i].bytes;
        remove(i);
      } else if (blocks_[i].origin == origin && static_cast<char*>(p) + bytes == q) {
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
    blocks_[count_++] = {p, bytes, origin};
    kept_ += bytes;
  }

 private:
  struct Block {
    void* p;
    std::size_t bytes;
    void* origin;
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
      : data_(std::exchange(o.data_, nullptr)),
        size_(std::exchange(o.size_, 0)),
        cap_(std::exchange(o.cap_, 0)),
        origin_(std::exchange(o.origin_, nullptr)) {}
  PodArray& operator=(PodArray&& o) noexcept {
    if (this != &o) {
      release();
      data_ = std::exchange(o.data_, nullptr);
      size_ = std::exchange(o.size_, 0);
      cap_ = std::exchange(o.cap_, 0);
      origin_ = std::exchange(o.origin_, nullptr);
    }
    return *this;
  }
  ~PodArray() { release(); }

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
  /// Resizes without writing the new elements: for a caller that writes every one of them next
  /// (the map's batch subdivision; a fill first would pass over the memory twice).
  void resize_uninitialised(std::size_t n) {
    if (n > cap_) grow_for(n);
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
    if (cap == 0) {
      release();
      data_ = nullptr;
      origin_ = nullptr;
    } else if (!was_mapped && !now_mapped) {
      T* p = static_cast<T*>(std::realloc(data_, cap * sizeof(T)));
      if (!p) throw std::bad_alloc();
      data_ = p;
    } else if (was_mapped && now_mapped) {
      remap(cap);
    } else {  // crossing the threshold: a fresh block of the other kind
      move_to_fresh(cap);
    }
    cap_ = cap;
  }
  // Copies the elements into a new block of capacity cap and releases the old one.
  void move_to_fresh(std::size_t cap) {
    void* origin = nullptr;
    T* p = allocate(cap, origin);
    if (size_ != 0) std::memcpy(p, data_, size_ * sizeof(T));
    release();
    data_ = p;
    origin_ = origin;
  }

#if defined(__linux__)
  static constexpr std::size_t map_from = std::size_t{256} << 10;  // bytes
  static bool mapped(std::size_t cap) { return cap * sizeof(T) >= map_from; }
  static std::size_t mapped_bytes(std::size_t cap) {
    constexpr std::size_t page = 4096;
    return (cap * sizeof(T) + page - 1) / page * page;
  }
  static void ask_huge_pages(void* p, std::size_t bytes) { (void)madvise(p, bytes, MADV_HUGEPAGE); }  // a hint: failure is harmless
  // A block of capacity cap; `origin` receives the mapping it lies in (nullptr on the heap).
  static T* allocate(std::size_t cap, void*& origin) {
    origin = nullptr;
    if (!mapped(cap)) {
      T* p = static_cast<T*>(std::malloc(cap * sizeof(T)));
      if (!p) throw std::bad_alloc();
      return p;
    }
    if (auto [q, from] = MappedBlocks::instance().take(mapped_bytes(cap)); q) {
      origin = from;
      return static_cast<T*>(q);
    }
    void* p = mmap(nullptr, mapped_bytes(cap), PROT_READ | PROT_WRITE, MAP_PRIVATE | MAP_ANONYMOUS, -1, 0);
    if (p == MAP_FAILED) throw std::bad_alloc();
    ask_huge_pages(p, mapped_bytes(cap));
    origin = p;
    return static_cast<T*>(p);
  }
  // Grows in place over a kept range of the same mapping right after the block if there is
  // one, else moves the pages (mremap; the moved block is a mapping of its own); shrinking keeps
  // the freed tail.
  void remap(std::size_t cap) {
    const std::size_t old_bytes = mapped_bytes(cap_), bytes = mapped_bytes(cap);
    char* end = reinterpret_cast<char*>(data_) + old_bytes;
    if (bytes <= old_bytes) {
      if (bytes < old_bytes) MappedBlocks::instance().give(end - (old_bytes - bytes), old_bytes - bytes, origin_);
      return;
    }
    if (MappedBlocks::instance().take_at(end, bytes - old_bytes, origin_)) return;
    void* q = mremap(data_, old_bytes, bytes, MREMAP_MAYMOVE);
    if (q == MAP_FAILED) {  // not expected with origins tracked; a copy still works
      move_to_fresh(cap);
      return;
    }
    ask_huge_pages(q, bytes);
    if (q != data_) origin_ = q;
    data_ = static_cast<T*>(q);
  }
  void release() {
    if (!data_) return;
    if (mapped(cap_))
      MappedBlocks::instance().give(data_, mapped_bytes(cap_), origin_);
    else
      std::free(data_);
  }
#else
  static bool mapped(std::size_t) { return false; }
  static std::size_t mapped_bytes(std::size_t cap) { return cap * sizeof(T); }
  static T* allocate(std::size_t cap, void*& origin) {
    origin = nullptr;
    T* p = static_cast<T*>(std::malloc(cap * sizeof(T)));
    if (!p) throw std::bad_alloc();
    return p;
  }
  void remap(std::size_t) {}  // never called: nothing is mapped
  void release() { std::free(data_); }
#endif
  static constexpr std::size_t max_elements = std::size_t(-1) / 2 / sizeof(T);

  void assign_copy(const PodArray& o) {
    if (o.size_ > cap_) set_capacity(o.size_);
    if (o.size_ != 0) std::memcpy(data_, o.data_, o.size_ * sizeof(T));
    size_ = o.size_;
  }

  T* data_ = nullptr;
  std::size_t size_ = 0, cap_ = 0;
  void* origin_ = nullptr;  // the mapping a mapped block lies in (see MappedBlocks)
};

}  // namespace sewn::detail
