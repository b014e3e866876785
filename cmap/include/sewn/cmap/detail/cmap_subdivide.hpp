#pragma once
// CMap::subdivide_hexahedra: the 1:8 subdivision of every hexahedron of a 3-map in one pass.
// Included by cmap.hpp.
//
// Each volume's 24 darts are labelled against one reference hexahedron (unit cube, corners
// s = a + 2b + 4c): a dart is named by its source corner s and the axis i it leaves along,
// label 3s + i; the face it lies in (the axis k held fixed on it) follows from the orientation.
// A child v (the octant at corner v) is the same cube halved, so it has the same 24 labels, its
// corner u at fine lattice point v + u (coordinates 0..2). Everything about the children (β1,
// β2 inside a child, β3 between siblings, which fine point each dart starts at) is therefore a
// fixed table; only β3 across the parent's faces reads the map: the parent dart with label p
// in face k, β3-sewn to a dart of the neighbour's label q, says where the neighbour's children
// are. The parent's darts are kept: parent dart 3s + i becomes child s's dart 3s + i (same
// source, along the same edge, in the same face), as the insertion operations would keep it.

#include <algorithm>
#include <array>
#include <cstdint>
#include <span>
#include <type_traits>
#include <string>
#include <vector>

namespace sewn::detail {

// The reference hexahedron's tables (see the header comment). Built at compile time.
struct HexLabels {
  static constexpr std::uint8_t none = 0xff;
  std::array<std::uint8_t, 24> face_axis{};  // k of label 3s + i
  std::array<std::uint8_t, 24> next1{}, prev1{}, next2{};
  // child v, label l: the index of the fine lattice point it starts at (x + 3y + 9z), its
  // slot among child v's 21 new darts (none if it is the parent's dart), and across a face of
  // the parent (the fine dart on the parent's boundary): the parent label p of the dart leaving
  // corner v in that face and the position n of l after it in its face ring (β1^n).
  std::array<std::array<std::uint8_t, 24>, 8> fine_point{}, slot{}, outer_label{}, outer_step{};
  std::array<std::uint8_t, 27> darts_at{};  // darts of the 8 children starting at each fine point
  std::array<std::array<std::uint8_t, 2>, 27> one_dart_at{};  // (child, label) of one of them
  // The fine edges that do not halve a parent edge, each with its darts in the 8 children
  // (24 v + l): the 6 inside the parent (cell centre to a face centre, 4 children around, 8
  // darts) and the 24 inside its faces (face centre to an edge midpoint, 2 children on this
  // side, 4 darts: first the 2 in the parent's face, whose β3 cross it, then the 2 in the
  // children's shared face).
  std::array<std::array<std::uint8_t, 8>, 6> inner_edge{};
  std::array<std::array<std::uint8_t, 4>, 24> face_edge{};

  static constexpr int source(int l) { return l / 3; }
  static constexpr int axis(int l) { return l % 3; }
  static constexpr int target(int l) { return (l / 3) ^ (1 << (l % 3)); }
  // β3 inside the parent: the sibling across the middle plane of axis face_axis[l] holds the
  // reversed dart, its corners flipped along that axis
  constexpr int sibling_label(int l) const {
    const int k = 1 << face_axis[static_cast<std::size_t>(l)];
    return 3 * (target(l) ^ k) + axis(l);
  }

  constexpr HexLabels() {
    for (auto& k : face_axis) k = none;
    // dart (s, axis i, face k): β1 leaves its target along the third axis j; β2 is the reversed
    // dart in the face holding j fixed. Propagated from label 0 in face k = 2.
    std::array<int, 24> stack{};
    int top = 0;
    face_axis[0] = 2;
    stack[top++] = 0;
    while (top > 0) {
      const int l = stack[--top];
      const int i = axis(l), k = face_axis[static_cast<std::size_t>(l)], j = 3 - i - k, t = target(l);
      const int n1 = 3 * t + j, n2 = 3 * t + i;
      next1[static_cast<std::size_t>(l)] = static_cast<std::uint8_t>(n1);
      prev1[static_cast<std::size_t>(n1)] = static_cast<std::uint8_t>(l);
      next2[static_cast<std::size_t>(l)] = static_cast<std::uint8_t>(n2);
      for (const auto& nk : {std::array<int, 2>{n1, k}, std::array<int, 2>{n2, j}})
        if (face_axis[static_cast<std::size_t>(nk[0])] == none) {
          face_axis[static_cast<std::size_t>(nk[0])] = static_cast<std::uint8_t>(nk[1]);
          stack[top++] = nk[0];
        }
    }
    for (int v = 0; v < 8; ++v) {
      int made = 0;
      for (int l = 0; l < 24; ++l) {
        const auto vv = static_cast<std::size_t>(v), ll = static_cast<std::size_t>(l);
        const int u = source(l);
        int p = 0;
        for (int a = 0, w = 1; a < 3; ++a, w *= 3) p += w * (((v >> a) & 1) + ((u >> a) & 1));
        fine_point[vv][ll] = static_cast<std::uint8_t>(p);
        ++darts_at[static_cast<std::size_t>(p)];
        one_dart_at[static_cast<std::size_t>(p)] = {static_cast<std::uint8_t>(v), static_cast<std::uint8_t>(l)};
        slot[vv][ll] = u == v ? none : static_cast<std::uint8_t>(made++);
        outer_label[vv][ll] = outer_step[vv][ll] = none;
        const int k = face_axis[ll];
        if (((v >> k) & 1) != ((u >> k) & 1)) continue;  // a face inside the parent
        for (int i = 0; i < 3; ++i) {
          if (face_axis[static_cast<std::size_t>(3 * v + i)] != k) continue;
          int x = 3 * v + i;
          for (int n = 0; n < 4; ++n, x = next1[static_cast<std::size_t>(x)])
            if (x == l) {
              outer_label[vv][ll] = static_cast<std::uint8_t>(3 * v + i);
              outer_step[vv][ll] = static_cast<std::uint8_t>(n);
            }
        }
      }
    }
    classify_fine_edges();
  }

  // Each fine dart's edge is named by its doubled midpoint (the sum of its ends' fine lattice
  // coordinates, 0..4 each): on a parent edge where two coordinates are 0 or 4, in a parent
  // face where one is, inside the parent where none is.
  constexpr void classify_fine_edges() {
    std::array<std::uint8_t, 125> slot_of{}, count{}, in_count{};
    for (auto& x : slot_of) x = none;
    int inner = 0, face = 0;
    for (int v = 0; v < 8; ++v)
      for (int l = 0; l < 24; ++l) {
        const int u = source(l), t = target(l);
        int key = 0, on_boundary = 0;
        for (int a = 0, w = 1; a < 3; ++a, w *= 5) {
          const int c = 2 * ((v >> a) & 1) + ((u >> a) & 1) + ((t >> a) & 1);
          key += w * c;
          on_boundary += c == 0 || c == 4 ? 1 : 0;
        }
        if (on_boundary == 2) continue;  // half of a parent edge: found through the parent's fan
        const auto k = static_cast<std::size_t>(key);
        if (slot_of[k] == none) slot_of[k] = static_cast<std::uint8_t>(on_boundary == 0 ? inner++ : face++);
        const auto code = static_cast<std::uint8_t>(24 * v + l);
        if (on_boundary == 0) {
          inner_edge[slot_of[k]][count[k]++] = code;
        } else {
          // the darts in the parent's face first (positions 0, 1), those inside it next (2, 3)
          const bool in_parent_face = outer_label[static_cast<std::size_t>(v)][static_cast<std::size_t>(l)] != none;
          auto& n = in_parent_face ? count[k] : in_count[k];
          face_edge[slot_of[k]][(in_parent_face ? 0u : 2u) + n++] = code;
        }
      }
    if (inner != 6 || face != 24) throw "HexLabels: a cube has 6 inner and 24 face edges once halved";  // fails the build
  }
};

inline constexpr HexLabels hex_labels{};

}  // namespace sewn::detail

namespace sewn {

template <int D, class... A>
template <class Mid>
void CMap<D, A...>::subdivide_hexahedra(Mid&& middle) {
  static_assert(!has_attribute<1> && !has_attribute<2> && !has_attribute<3>,
                "subdivide_hexahedra: a map with edge, face or volume attributes needs the `fine` argument");
  subdivide_hexahedra(std::forward<Mid>(middle), [](auto, const FineCell&) {});
}

template <int D, class... A>
template <class Mid, class Fine>
void CMap<D, A...>::subdivide_hexahedra(Mid&& middle, Fine&& fine) {
  static_assert(D == 3, "subdivide_hexahedra: a 3-map only");
  static_assert(!has_dart_info, "subdivide_hexahedra: maps without dart info only (it gives new darts none)");
  constexpr auto& T = detail::hex_labels;
  constexpr std::uint32_t null = detail::null_index;
  constexpr std::uint8_t none = detail::HexLabels::none;
  const auto cap = static_cast<std::uint32_t>(beta_.size());

  // 1) every volume labelled; anything but a closed hexahedron of quads is refused here, with
  // the map untouched
  std::vector<std::uint8_t> label(cap, none);
  std::vector<std::uint32_t> hex_of(cap, null);
  std::vector<std::uint32_t> hex_darts;  // 24 per volume, by label
  for (std::uint32_t x0 = 0; x0 < cap; ++x0) {
    if (!is_live_index(x0) || label[x0] != none) continue;
    const auto h = static_cast<std::uint32_t>(hex_darts.size() / 24);
    hex_darts.resize(hex_darts.size() + 24, null);
    std::uint32_t* pd = hex_darts.data() + 24 * std::size_t{h};
    std::array<std::uint32_t, 24> stack{};
    int top = 0, reached = 0;
    auto claim = [&](std::uint32_t x, int l) {
      if (x == null || (label[x] != none && (label[x] != l || hex_of[x] != h)) || (label[x] == none && pd[l] != null))
        throw TopologyError("cmap::subdivide_hexahedra: the volume of dart " + std::to_string(x0) +
                            " is not a closed hexahedron of 6 quads (at dart " +
                            (x == null ? std::string("null") : std::to_string(x)) + ")");
      if (label[x] != none) return;
      label[x] = static_cast<std::uint8_t>(l);
      hex_of[x] = h;
      pd[l] = x;
      stack[static_cast<std::size_t>(top++)] = x;
      ++reached;
    };
    claim(x0, 0);
    while (top > 0) {
      const std::uint32_t x = stack[static_cast<std::size_t>(--top)];
      const int l = label[x];
      claim(b(x, 1), T.next1[static_cast<std::size_t>(l)]);
      claim(b(x, 2), T.next2[static_cast<std::size_t>(l)]);
    }
    (void)reached;  // 24 distinct labels, each dart's β1 and β2 as on the cube: the cube
  }
  const auto hexes = static_cast<std::uint32_t>(hex_darts.size() / 24);
  if (hexes == 0) return;
  if (std::uint64_t{cap} + std::uint64_t{168} * hexes > detail::dead_marker - 1)
    throw CapacityError("cmap: the map cannot hold more than 2^32 - 3 darts");

  // which dimensions above 0 carry attributes before the pass (their fine cells get them too)
  std::array<bool, 4> had{};
  for_each_dim([&](auto kk) {
    if constexpr (kk() > 0 && has_attribute<kk()>) had[kk()] = store<kk()>().values.size() > 0;
  });

  // 2) the parent edges, numbered, each with its darts (walked once through the edge's β2/β3
  // fan, on the parent map), in pairs (y, β2 y), every y starting where the edge's first
  // dart does: its midpoint (edge id), and where an edge attribute goes, its halves' darts
  std::vector<std::uint32_t> edge_of, fan_start, fan;
  if (has_attribute<0> || had[1]) {
    edge_of.assign(cap, null);
    fan.reserve(cap);
    for (std::uint32_t h = 0; h < hexes; ++h) {
      const std::uint32_t* pd = hex_darts.data() + 24 * std::size_t{h};
      for (int l = 0; l < 24; ++l) {
        const std::uint32_t x = pd[l];
        if (((T.source(l) >> T.axis(l)) & 1) != 0 || edge_of[x] != null) continue;
        const auto id = static_cast<std::uint32_t>(fan_start.size());
        fan_start.push_back(static_cast<std::uint32_t>(fan.size()));
        auto take = [&](std::uint32_t y, std::uint32_t y2) {
          edge_of[y] = edge_of[y2] = id;
          fan.push_back(y);
          fan.push_back(y2);
        };
        std::uint32_t y = x;
        bool closed = false;
        for (;;) {
          take(y, b(y, 2));
          y = b(b(y, 2), 3);
          if (y == null || y == x) {
            closed = y == x;
            break;
          }
        }
        // the other way round an open fan: β3 reverses, so β2 y starts where x does
        for (y = closed ? null : b(x, 3); y != null; y = b(b(y, 2), 3)) take(b(y, 2), y);
      }
    }
    fan_start.push_back(static_cast<std::uint32_t>(fan.size()));
  }

  // 3) the new vertices' values, before anything changes: an edge midpoint once per edge, a
  // face centre once per face (its darts and those across β3), a cell centre per volume. A face
  // centre is the middle of two opposite edge midpoints, the cell centre the middle of two
  // opposite face centres, as the insertion path makes them. Midpoints come first, numbered as
  // their edges.
  std::vector<std::uint32_t> centre_of, value_of_cell;
  std::vector<attribute_type<0>> values;
  if constexpr (has_attribute<0>) {
    centre_of.assign(cap, null);
    value_of_cell.resize(hexes);
    auto point = [&](std::uint32_t x) -> const attribute_type<0>& { return store<0>().values.value(store<0>().of_dart[x]); };
    const auto edges = static_cast<std::uint32_t>(fan_start.size() - 1);
    values.reserve(edges + 3 * std::size_t{hexes} + hexes);
    for (std::uint32_t e = 0; e < edges; ++e) {
      const std::uint32_t x = fan[fan_start[e]];
      values.push_back(middle(point(x), point(b(x, 1))));
    }
    for (std::uint32_t h = 0; h < hexes; ++h) {
      const std::uint32_t* pd = hex_darts.data() + 24 * std::size_t{h};
      for (int l = 0; l < 24; ++l) {
        const std::uint32_t x = pd[l];
        if (centre_of[x] != null) continue;
        const auto id = static_cast<std::uint32_t>(values.size());
        values.push_back(middle(values[edge_of[x]], values[edge_of[b(b(x, 1), 1)]]));
        for (std::uint32_t y : {x, b(x, 3)})
          for (int n = 0; n < 4 && y != null; ++n, y = b(y, 1)) centre_of[y] = id;
      }
      // the faces holding axis 2 fixed at 0 and at 1: label 0 (corner 0, face k = 2) and its
      // opposite, the dart leaving corner 4 along axis 0 reversed (label 3 * 5 + 0)
      static_assert(T.face_axis[0] == 2 && T.face_axis[15] == 2);
      value_of_cell[h] = static_cast<std::uint32_t>(values.size());
      values.push_back(middle(values[centre_of[pd[0]]], values[centre_of[pd[15]]]));
    }
  }

  // 4) commit: attributes, then 168 new darts per volume (21 per child), every row written once
  std::vector<std::uint32_t> attr;
  if constexpr (has_attribute<0>) {
    attr.reserve(values.size());
    store<0>().values.reserve(store<0>().values.capacity() + values.size());  // one growth, not several
    for (auto& v : values) attr.push_back(store<0>().values.create(std::move(v)));
  }
  const std::uint32_t fresh_count = 168 * hexes;
  std::vector<std::uint32_t> fresh_list;  // only when erased slots are reused
  std::uint32_t x0 = 0;
  if (free_head_ == null) {
    x0 = cap;
    beta_.resize_uninitialised(std::size_t{cap} + fresh_count);
    if constexpr (has_attribute<0>) store<0>().of_dart.resize_uninitialised(std::size_t{cap} + fresh_count);
    for_each_dim([&](auto kk) {
      if constexpr (kk() > 0 && has_attribute<kk()>) store<kk()>().of_dart.resize(std::size_t{cap} + fresh_count, null);
    });
    if ((x0 + 63) / 64 != (x0 + fresh_count + 63) / 64) marks_.resize(x0 + fresh_count);
    alive_ += fresh_count;
  } else {
    fresh_list.reserve(fresh_count);
    new_darts(fresh_count, fresh_list);
  }
  const bool contiguous = fresh_list.empty();
  auto fresh = [&](std::uint32_t n) { return contiguous ? x0 + n : fresh_list[n]; };
  // child v's dart of label l in volume h (pd: its parent's darts)
  auto child_dart = [&](std::uint32_t h, const std::uint32_t* pd, int v, int l) {
    const std::uint8_t s = T.slot[static_cast<std::size_t>(v)][static_cast<std::size_t>(l)];
    return s == none ? pd[l] : fresh(168 * h + 21 * static_cast<std::uint32_t>(v) + s);
  };

  for (std::uint32_t h = 0; h < hexes; ++h) {
    const std::uint32_t* pd = hex_darts.data() + 24 * std::size_t{h};
    std::array<std::array<std::uint32_t, 24>, 8> dart{};
    for (int v = 0; v < 8; ++v)
      for (int l = 0; l < 24; ++l) dart[static_cast<std::size_t>(v)][static_cast<std::size_t>(l)] = child_dart(h, pd, v, l);
    std::array<std::uint32_t, 24> across{};  // the parent's β3, read before its rows are rewritten
    for (std::size_t l = 0; l < 24; ++l) across[l] = b(pd[l], 3);
    std::array<std::uint32_t, 27> vertex{};
    if constexpr (has_attribute<0>) {
      auto& st = store<0>();
      for (int l = 0; l < 24; ++l) {
        const std::uint32_t x = pd[l];
        const int s = T.source(l), i = T.axis(l), k = T.face_axis[static_cast<std::size_t>(l)];
        auto at = [](int a, int b2, int c) { return static_cast<std::size_t>(a + 3 * b2 + 9 * c); };
        std::array<int, 3> c2{2 * (s & 1), 2 * ((s >> 1) & 1), 2 * ((s >> 2) & 1)};
        vertex[at(c2[0], c2[1], c2[2])] = st.of_dart[x];
        c2[static_cast<std::size_t>(i)] = 1;
        vertex[at(c2[0], c2[1], c2[2])] = attr[edge_of[x]];
        for (int a = 0; a < 3; ++a)
          if (a != k) c2[static_cast<std::size_t>(a)] = 1;
        vertex[at(c2[0], c2[1], c2[2])] = attr[centre_of[x]];
      }
      vertex[13] = attr[value_of_cell[h]];
      for (std::size_t p = 0; p < 27; ++p) {
        const bool is_corner = p % 3 != 1 && (p / 3) % 3 != 1 && p / 9 != 1;
        if (is_corner) continue;  // a corner keeps its darts: the parent's, with the same sources
        st.values.add_count(vertex[p], T.darts_at[p]);
        st.values.set_dart(vertex[p], dart[T.one_dart_at[p][0]][T.one_dart_at[p][1]]);
      }
    }
    for (int v = 0; v < 8; ++v) {
      const auto vv = static_cast<std::size_t>(v);
      for (int l = 0; l < 24; ++l) {
        const auto ll = static_cast<std::size_t>(l);
        std::uint32_t b3;
        if (const std::uint8_t p = T.outer_label[vv][ll]; p == none) {
          b3 = dart[vv ^ (std::size_t{1} << T.face_axis[ll])][static_cast<std::size_t>(T.sibling_label(l))];
        } else if (const std::uint32_t q = across[p]; q == null) {
          b3 = null;
        } else {
          // q runs from the end of parent dart p back to corner v; in its volume's children,
          // the fine dart from q's midpoint to that corner is in child w = q's target, and the
          // fine dart across from l is n steps back (β3 reverses the face rings) from it
          const int ql = label[q], w = T.target(ql);
          int g = 3 * (w ^ (1 << T.axis(ql))) + T.axis(ql);
          for (int n = 0; n < T.outer_step[vv][ll]; ++n) g = T.prev1[static_cast<std::size_t>(g)];
          b3 = child_dart(hex_of[q], hex_darts.data() + 24 * std::size_t{hex_of[q]}, w, g);
        }
        const std::uint32_t x = dart[vv][ll];
        beta_[x] = {dart[vv][T.prev1[ll]], dart[vv][T.next1[ll]], dart[vv][T.next2[ll]], b3};
        if constexpr (has_attribute<0>) store<0>().of_dart[x] = vertex[T.fine_point[vv][ll]];
      }
    }
  }

  // 5) the fine edges', faces' and volumes' attributes, from the caller, and the parents'
  // released; edges and faces first, so that the caller making a volume's attribute can read
  // the attributes of its fine edges and faces.
  // The fine edges without a walk: those inside a parent and inside its faces from the table
  // (a face's across its β3, given by the hexahedron whose darts there come first), the halves
  // of each parent edge from its fan (a parent dart and its fine β2, in every volume around).
  auto fine_edges = [&](auto give) {
    std::vector<std::uint32_t> cell;
    for (std::uint32_t h = 0; h < hexes; ++h) {
      const std::uint32_t* pd = hex_darts.data() + 24 * std::size_t{h};
      auto at = [&](std::uint8_t code) { return child_dart(h, pd, code / 24, code % 24); };
      for (const auto& e : T.inner_edge) {
        cell.clear();
        for (std::uint8_t code : e) cell.push_back(at(code));
        give(cell);
      }
      for (const auto& e : T.face_edge) {
        cell.clear();
        std::uint32_t here = null, there = null;
        for (std::uint8_t code : e) {
          cell.push_back(at(code));
          here = std::min(here, cell.back());
        }
        for (std::size_t i = 0; i < 2; ++i)  // across the parent's face: a dart there and its β2
          if (const std::uint32_t z = b(cell[i], 3); z != null)
            for (std::uint32_t w : {z, b(z, 2)}) {
              cell.push_back(w);
              there = std::min(there, w);
            }
        if (here < there) give(cell);  // made once, by the side whose darts come first
      }
    }
    for (std::size_t e = 0; e + 1 < fan_start.size(); ++e)
      for (std::uint32_t end = 0; end < 2; ++end) {
        cell.clear();
        for (std::uint32_t i = fan_start[e] + end; i < fan_start[e + 1]; i += 2) {
          cell.push_back(fan[i]);
          cell.push_back(b(fan[i], 2));
        }
        give(cell);
      }
  };
  auto cells_of = [&](auto kk) {
    constexpr int I = decltype(kk)::value;
    if constexpr (I < 3 && has_attribute<I>) {
      if (!had[I]) return;
      auto& st = store<I>();
      std::vector<std::uint32_t> parents;
      auto give = [&](std::span<const std::uint32_t> cell) {
        std::uint32_t parent = null;
        for (std::uint32_t y : cell)
          if (st.of_dart[y] != null) {
            parent = st.of_dart[y];
            break;
          }
        int piece = 0;
        if (parent != null) {
          parents.push_back(parent);
          piece = std::find(cell.begin(), cell.end(), st.values.dart(parent)) != cell.end() ? 0 : 1;
        }
        give_fine_attribute<I>(fine(std::integral_constant<int, I>{}, FineCell{parent, piece, cell, {}}), cell);
      };
      if constexpr (I == 1) {
        fine_edges(give);
      } else {
        const Mark m = marks_.reserve();
        std::vector<std::uint32_t> cell;
        for (std::uint32_t x = 0; x < static_cast<std::uint32_t>(beta_.size()); ++x) {
          if (!is_live_index(x) || marks_.test(x, m)) continue;
          cell.clear();
          collect_cell<I>(x, m, cell);
          give(cell);
        }
        free_mark(m);
      }
      std::sort(parents.begin(), parents.end());
      parents.erase(std::unique(parents.begin(), parents.end()), parents.end());
      for (std::uint32_t a : parents) st.values.erase(a);  // no hook: the caller made its successors
    }
  };
  cells_of(std::integral_constant<int, 1>{});
  cells_of(std::integral_constant<int, 2>{});
  if constexpr (has_attribute<3>)
    if (had[3]) {
      auto& st = store<3>();
      std::array<std::uint32_t, 24> child{};
      for (std::uint32_t h = 0; h < hexes; ++h) {
        const std::uint32_t* pd = hex_darts.data() + 24 * std::size_t{h};
        const std::uint32_t parent = st.of_dart[pd[0]];
        for (int v = 0; v < 8; ++v) {
          for (int l = 0; l < 24; ++l) child[static_cast<std::size_t>(l)] = child_dart(h, pd, v, l);
          const FineCell cell{parent, v, child, std::span<const std::uint32_t>(pd, 24)};
          give_fine_attribute<3>(fine(std::integral_constant<int, 3>{}, cell), child);
        }
        if (parent != null) st.values.erase(parent);  // no hook: the caller made its successors
      }
    }
}

template <int D, class... A>
template <int I, class V>
void CMap<D, A...>::give_fine_attribute(V&& value, std::span<const std::uint32_t> cell) {
  auto& st = store<I>();
  std::uint32_t a = detail::null_index;
  if (value) {
    a = st.values.create(std::move(*value));
    st.values.add_count(a, static_cast<std::int64_t>(cell.size()));
    st.values.set_dart(a, cell.front());
  }
  for (std::uint32_t y : cell) st.of_dart[y] = a;
}

}  // namespace sewn
