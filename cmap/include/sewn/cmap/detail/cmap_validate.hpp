#pragma once
// CMap::validate(): every invariant of a combinatorial map with attributes. Included by cmap.hpp.

namespace sewn {

template <int D, class... A>
template <int I>
bool CMap<D, A...>::chain_attributes_sound() const {
  constexpr std::uint32_t null = detail::null_index;
  const auto& st = store<I>();
  const auto& vals = st.values;
  const auto cap = static_cast<std::uint32_t>(beta_.size());
  const std::uint32_t slots = vals.capacity();
  const std::uint32_t* of = st.of_dart.data();
  // 1) how many darts carry each attribute: the attribute indices alone, in order (a dead dart
  //    carries none; one that did would only send validate() the long way)
  std::vector<std::uint32_t> counted(slots, 0);
  for (std::uint32_t x = 0; x < cap; ++x) {
    const std::uint32_t a = of[x];
    if (a == null) continue;
    if (a >= slots) return false;
    ++counted[a];
  }
  // 2) each live attribute: its reference count, and the cell of its recorded dart, walked,
  //    is exactly the darts that carry it. Then no other cell carries it, no cell carries it in
  //    part, and every other cell carries none.
  for (std::uint32_t a = 0; a < slots; ++a) {
    if (!vals.is_alive(a)) {
      if (counted[a] != 0) return false;
      continue;
    }
    const std::uint32_t n = counted[a];
    if (n == 0 || n != vals.count(a)) return false;
    const std::uint32_t d = vals.dart(a);
    if (d >= cap || !is_live_index(d) || of[d] != a) return false;
    std::uint32_t size = 1;
    const bool whole = walk_chain_cell<I>(d, [&](std::uint32_t y) { return of[y] == a && ++size <= n; });
    if (!whole || size != n) return false;
  }
  return true;
}

template <int D, class... A>
ValidationReport CMap<D, A...>::validate() const {
  using K = ValidationIssue::Kind;
  constexpr std::uint32_t null = detail::null_index;
  ValidationReport r;
  const auto cap = static_cast<std::uint32_t>(beta_.size());
  auto s = [](std::uint32_t x) { return x == null ? std::string("null") : std::to_string(x); };
  auto live = [&](std::uint32_t x) { return x < cap && beta_[x][0] != detail::dead_marker; };

  // 1) free list: only dead darts, no cycle, and it accounts for every dead dart
  std::uint32_t dead = 0;
  for (std::uint32_t x = free_head_; x != null; x = beta_[x][1]) {
    if (x >= cap || beta_[x][0] != detail::dead_marker) {
      r.add(K::free_list, x, -1, "free list reaches dart " + s(x) + ", which is not a dead dart");
      break;
    }
    if (++dead > cap) {
      r.add(K::free_list, x, -1, "free list has a cycle");
      break;
    }
  }
  if (dead + alive_ != cap)
    r.add(K::free_list, null, -1,
          std::to_string(alive_) + " live + " + std::to_string(dead) + " free darts != capacity " + std::to_string(cap));

  // 2) links: live targets, β0 = β1⁻¹, involutions, commuting pairs. A lean test settles the
  //    darts whose links are sound (all of them in a valid map); a dart it rejects is checked
  //    again by `report_links`, which names each broken link. Kept apart, the lean test keeps
  //    its pointers in registers.
  const std::array<std::uint32_t, D + 1>* rows = beta_.data();
  auto sound = [rows, cap](std::uint32_t x) {
    const std::array<std::uint32_t, D + 1> row = rows[x];
    bool outside = false;  // null + 1 wraps to 0
    for (int i = 0; i <= D; ++i) outside |= row[static_cast<std::size_t>(i)] + 1u > cap;
    if (outside) return false;
    // A dead dart's β0 is the dead marker and its βi (i ≥ 2) are null, so a link to one fails
    // the inverse checks below; only β0's target is checked alive, as a dead dart's β1 threads
    // the free list.
    if (row[1] != null && rows[row[1]][0] != x) return false;
    if (row[0] != null && (rows[row[0]][1] != x || rows[row[0]][0] == detail::dead_marker)) return false;
    for (int i = 2; i <= D; ++i) {
      const std::uint32_t y = row[static_cast<std::size_t>(i)];
      if (y == x || (y != null && rows[y][static_cast<std::size_t>(i)] != x)) return false;
    }
    for (int j = 3; j <= D; ++j) {
      const std::uint32_t xj = row[static_cast<std::size_t>(j)];
      if (xj != null && (row[1] == null ? null : rows[row[1]][static_cast<std::size_t>(j)]) != rows[xj][0])
        return false;
    }
    for (int i = 2; i <= D; ++i)
      for (int j = i + 2; j <= D; ++j) {
        const std::uint32_t xi = row[static_cast<std::size_t>(i)], xj = row[static_cast<std::size_t>(j)];
        if ((xi == null ? null : rows[xi][static_cast<std::size_t>(j)]) !=
            (xj == null ? null : rows[xj][static_cast<std::size_t>(i)]))
          return false;
      }
    return true;
  };
  auto report_links = [&](std::uint32_t x) {
    const std::array<std::uint32_t, D + 1> row = beta_[x];
    bool links_ok = true;
    for (int i = 0; i <= D; ++i) {
      const std::uint32_t y = row[static_cast<std::size_t>(i)];
      if (y != null && !live(y)) [[unlikely]] {
        r.add(K::dangling_link, x, i, "beta" + std::to_string(i) + "(" + s(x) + ") = " + s(y) + " is not a live dart");
        links_ok = false;
      }
    }
    if (!links_ok) return;
    if (const std::uint32_t y = row[1]; y != null && b(y, 0) != x) [[unlikely]]
      r.add(K::beta0_beta1, x, 1, "beta0(beta1(" + s(x) + ")) = " + s(b(y, 0)) + ", expected " + s(x));
    if (const std::uint32_t y = row[0]; y != null && b(y, 1) != x) [[unlikely]]
      r.add(K::beta0_beta1, x, 0, "beta1(beta0(" + s(x) + ")) = " + s(b(y, 1)) + ", expected " + s(x));
    for (int i = 2; i <= D; ++i) {
      const std::uint32_t y = row[static_cast<std::size_t>(i)];
      if (y == x) [[unlikely]]
        r.add(K::not_involution, x, i, "beta" + std::to_string(i) + "(" + s(x) + ") = " + s(x) + " (a fixed point)");
      else if (y != null && b(y, i) != x) [[unlikely]]
        r.add(K::not_involution, x, i,
              "beta" + std::to_string(i) + " is not an involution at dart " + s(x) + ": beta" + std::to_string(i) +
                  "(" + s(y) + ") = " + s(b(y, i)));
    }
    // β1∘βj (j ≥ 3): βj(β1(x)) = β0(βj(x)), both null or both equal
    for (int j = 3; j <= D; ++j) {
      const std::uint32_t xj = row[static_cast<std::size_t>(j)];
      if (xj == null) continue;
      const std::uint32_t x1 = row[1];
      const std::uint32_t lhs = x1 == null ? null : b(x1, j);
      const std::uint32_t rhs = b(xj, 0);
      if (lhs != rhs) [[unlikely]]
        r.add(K::composition, x, j,
              "beta1 o beta" + std::to_string(j) + " is not an involution at dart " + s(x) + ": beta" +
                  std::to_string(j) + "(beta1(" + s(x) + ")) = " + s(lhs) + " but beta0(beta" + std::to_string(j) +
                  "(" + s(x) + ")) = " + s(rhs));
    }
    // βi∘βj for 2 ≤ i, i+2 ≤ j: they commute
    for (int i = 2; i <= D; ++i)
      for (int j = i + 2; j <= D; ++j) {
        const std::uint32_t xi = row[static_cast<std::size_t>(i)], xj = row[static_cast<std::size_t>(j)];
        const std::uint32_t ij = xi == null ? null : b(xi, j);
        const std::uint32_t ji = xj == null ? null : b(xj, i);
        if (ij != ji) [[unlikely]]
          r.add(K::composition, x, j,
                "beta" + std::to_string(i) + " o beta" + std::to_string(j) + " is not an involution at dart " + s(x) +
                    ": beta" + std::to_string(j) + "(beta" + std::to_string(i) + ") = " + s(ij) + ", beta" +
                    std::to_string(i) + "(beta" + std::to_string(j) + ") = " + s(ji));
      }
  };
  for (std::uint32_t x = 0; x < cap; ++x) {
    if (rows[x][0] != detail::dead_marker && !sound(x)) [[unlikely]]
      report_links(x);
  }
  links_sound_ = r.ok();
  if (!r.ok()) return r;  // attribute checks traverse orbits and need sound links

  // 3) attributes, walking each cell once: every dart carries the attribute of the cell's
  //    smallest dart, each attribute lies in one cell, reference counts match, no orphan, and
  //    the recorded dart carries its attribute.
  for_each_dim([&](auto k) {
    constexpr int I = k();
    if constexpr (has_attribute<I>) {
      if constexpr (chain_cell<I>)
        if (chain_attributes_sound<I>()) return;  // nothing to report
      const auto& st = store<I>();
      const auto& vals = st.values;
      const std::string dim = std::to_string(I) + "-attribute";
      std::vector<std::uint32_t> counted(vals.capacity(), 0);
      // The smallest dart of the first cell seen carrying each attribute; `reported` once a
      // second cell has been reported.
      constexpr std::uint32_t reported = detail::dead_marker;
      std::vector<std::uint32_t> cell_of(vals.capacity(), null);
      // Whether the dart each attribute records was met carrying it: checked during the walks
      // (every live dart is met once) rather than by looking each recorded dart up afterwards.
      std::vector<std::uint8_t> recorded_ok(vals.capacity(), 0);
      // Records that dart y of the cell of `root` carries a; reports a second cell carrying it.
      auto book_cell = [&](std::uint32_t a, std::uint32_t y, std::uint32_t root) {
        std::uint32_t& c = cell_of[a];
        if (c == null) {
          c = root;
        } else if (c != root && c != reported) [[unlikely]] {
          r.add(K::attribute_two_cells, y, I,
                dim + " " + s(a) + " is carried by darts of two " + std::to_string(I) + "-cells: those of darts " +
                    s(c) + " and " + s(root));
          c = reported;
        }
      };
      for_each_cell_root<I>([&](std::uint32_t root, const auto& darts) {
        const std::uint32_t a0 = st.of_dart[root];
        // The common case, a cell whose darts all carry one live attribute (or none), is booked
        // once per cell, touching the attribute's arrays once instead of once per dart; any
        // other cell is booked dart by dart below, which reports what is wrong.
        const bool a0_live = a0 != null && vals.is_alive(a0);
        const std::uint32_t rec = a0_live ? vals.dart(a0) : null;
        bool uniform = a0 == null || a0_live, has_rec = false;
        for (std::uint32_t y : darts) {
          uniform &= st.of_dart[y] == a0;
          has_rec |= y == rec;
        }
        if (uniform) [[likely]] {
          if (a0 == null) return;
          counted[a0] += static_cast<std::uint32_t>(darts.size());
          recorded_ok[a0] |= static_cast<std::uint8_t>(has_rec);
          book_cell(a0, root, root);
          return;
        }
        for (std::uint32_t y : darts) {
          const std::uint32_t a = st.of_dart[y];
          if (a != a0) [[unlikely]]
            r.add(K::attribute_mismatch, y, I,
                  "darts " + s(root) + " and " + s(y) + " are in one " + std::to_string(I) + "-cell but carry " + dim +
                      "s " + s(a0) + " and " + s(a));
          if (a == null) continue;
          if (!vals.is_alive(a)) [[unlikely]] {
            r.add(K::attribute_dead, y, I, "dart " + s(y) + " refers to " + dim + " " + s(a) + ", which is not live");
            continue;
          }
          ++counted[a];
          if (vals.dart(a) == y) recorded_ok[a] = 1;
          book_cell(a, y, root);
        }
      });
      for (std::uint32_t a = 0; a < vals.capacity(); ++a) {
        if (!vals.is_alive(a)) continue;
        if (vals.count(a) != counted[a]) [[unlikely]]
          r.add(K::attribute_count, null, I,
                dim + " " + s(a) + " has reference count " + std::to_string(vals.count(a)) + " but " +
                    std::to_string(counted[a]) + " darts refer to it");
        if (counted[a] == 0) [[unlikely]] {
          r.add(K::attribute_orphan, null, I, dim + " " + s(a) + " is live but no dart refers to it");
          continue;
        }
        if (!recorded_ok[a]) [[unlikely]]
          r.add(K::attribute_dart, vals.dart(a), I,
                dim + " " + s(a) + " records dart " + s(vals.dart(a)) + ", which is not in its cell");
      }
    }
  });

  // 4) marks: unreserved marks have no marked dart (reserved ones are the caller's business)
  for (int m = 0; m < detail::MarkPlanes::max_marks; ++m) {
    const Mark mk(m);
    if (marks_.is_reserved(mk)) continue;
    if (marks_.count(mk) != 0)
      r.add(K::marks, null, m, "mark " + std::to_string(m) + " is free but counts " +
                                   std::to_string(marks_.count(mk)) + " marked darts");
  }
  return r;
}

}  // namespace sewn
