#pragma once
// Scoped helpers for a map: paused hooks and reserved marks released on destruction.

#include <vector>

#include "sewn/cmap/dart.hpp"
#include "sewn/cmap/marks.hpp"

namespace sewn {

/// Pauses a map's hooks for the lifetime of the guard (attributes stay consistent).
template <class Map>
class HooksPaused {
 public:
  explicit HooksPaused(Map& m) : map_(m), was_(m.hooks_enabled()) { map_.set_hooks_enabled(false); }
  ~HooksPaused() { map_.set_hooks_enabled(was_); }
  HooksPaused(const HooksPaused&) = delete;
  HooksPaused& operator=(const HooksPaused&) = delete;

 private:
  Map& map_;
  bool was_;
};

/// A reserved mark freed (and cleared) on destruction. Clearing is O(1) when no or all live
/// darts are marked, O(n/64) otherwise: for marking a few darts of a big map use ScopedMarker.
template <class Map>
class ScopedMark {
 public:
  explicit ScopedMark(const Map& m) : map_(m), mark_(m.reserve_mark()) {}
  ~ScopedMark() { map_.free_mark(mark_); }
  ScopedMark(const ScopedMark&) = delete;
  ScopedMark& operator=(const ScopedMark&) = delete;
  [[nodiscard]] Mark get() const { return mark_; }
  operator Mark() const { return mark_; }  // NOLINT(google-explicit-constructor)

 private:
  const Map& map_;
  Mark mark_;
};

/// A reserved mark that remembers what it marked and unmarks only that on destruction: O(k).
template <class Map>
class ScopedMarker {
 public:
  explicit ScopedMarker(const Map& m) : map_(m), mark_(m.reserve_mark()) {}
  ~ScopedMarker() {
    for (Dart d : marked_) map_.unmark(d, mark_);
    map_.free_mark(mark_);
  }
  ScopedMarker(const ScopedMarker&) = delete;
  ScopedMarker& operator=(const ScopedMarker&) = delete;
  /// Marks d; returns false if it was already marked.
  bool mark(Dart d) {
    if (!map_.mark(d, mark_)) return false;
    marked_.push_back(d);
    return true;
  }
  [[nodiscard]] bool is_marked(Dart d) const { return map_.is_marked(d, mark_); }
  [[nodiscard]] Mark get() const { return mark_; }

 private:
  const Map& map_;
  Mark mark_;
  std::vector<Dart> marked_;
};

}  // namespace sewn
