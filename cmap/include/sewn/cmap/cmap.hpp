#pragma once
// CMap<D, A0, A1, ...>: a D-dimensional combinatorial map with optional cell attributes.
//
// Vocabulary (Damiand & Lienhardt, "Combinatorial Maps", 2014): a dart is an oriented piece of
// an edge inside one face of one volume (...); β1 links a dart to the next dart of its face,
// β0 = β1⁻¹ to the previous one; for 2 ≤ i ≤ D, βi is an involution linking a dart to the dart
// of the i-adjacent cell with the opposite orientation. A null β means "i-free". An i-cell is
// the orbit of its darts under every β except βi (for i = 0: the compositions βj∘βk, j≠k).
//
// Storage: darts are 32-bit indices; β0..βD are stored packed per dart; removed darts go on a
// free list. With DartInfo<T> as first type parameter, every dart also holds a T (see info()). For each dimension I whose attribute type A_I is not void, every dart also stores
// the index of its I-cell's attribute (null if the cell has none), and the values live in one
// AttributeContainer<A_I> (contiguous, iterable without darts). A void attribute costs nothing.
//
// Attribute hooks, set per dimension with on_split / on_merge / on_erase, fire after an
// operation has finished changing β links, in this order: dimension 0 first, then 1, ..., D;
// within a dimension, cells are visited starting from the operation's first dart argument.
//   on_merge(kept, gone): two cells became one; fires before `gone`'s darts are relabelled to
//                         `kept` and `gone` is freed. `kept` is the attribute of the cell of the
//                         operation's first dart (for sew<i>(a, b): a's side).
//   on_split(orig, copy): one cell became two; fires after `copy` (a copy of orig's value) has
//                         been given to the darts of the part that does not contain the first dart.
//   on_erase(gone):       the last dart of a cell was erased; fires before the slot is freed.
// remove_cell / contract_cell first fire on_merge for the fusing cells that lose all their darts
// (e.g. the edge of a removed degree-2 vertex in a lone polygon), then the order above applies.
// New darts made by an insertion inherit the attributes of the dart they were split from, except
// for the new cell (the inserted vertex / edge / face), which has none until given one.
// Hooks can be paused (set_hooks_enabled(false) or HooksPaused) for bulk edits; attributes are
// still kept consistent while hooks are paused.
//
// Not thread-safe, not even for const traversals: they use the map's marks.

#include <algorithm>
#include <array>
#include <cstdint>
#include <functional>
#include <initializer_list>
#include <span>
#include <string>
#include <tuple>
#include <type_traits>
#include <utility>
#include <vector>

#include <boost/container/small_vector.hpp>

#include "sewn/cmap/attributes.hpp"
#include "sewn/cmap/detail/dart_buffer.hpp"
#include "sewn/cmap/detail/pod_array.hpp"
#include "sewn/cmap/dart.hpp"
#include "sewn/cmap/dart_info.hpp"
#include "sewn/cmap/detail/cmap_params.hpp"
#include "sewn/cmap/errors.hpp"
#include "sewn/cmap/marks.hpp"
#include "sewn/cmap/validation.hpp"

namespace sewn {

/// Darts of an orbit or cell, in breadth-first order from the dart asked for (which comes first).
using DartList = boost::container::small_vector<Dart, 32>;

/// A fine cell made by CMap::subdivide_hexahedra(middle, fine), as its `fine` sees it.
struct FineCell {
  std::uint32_t parent = Dart::null_index;  ///< the parent cell's attribute index (null if none or new)
  /// Edges and faces: 0 for the piece holding the parent attribute's recorded dart, else 1.
  /// Volumes: the child v, the octant at corner v of the reference cube (see parent_darts).
  int piece = 0;
  std::span<const std::uint32_t> darts;  ///< its darts (volumes: the child's 24, by label 3s + i)
  /// Volumes only: the parent's 24 darts by label 3s + i (dart 3s + i leaves corner s of the
  /// reference cube, s = a + 2b + 4c, along axis i); parent dart 3v + i is child v's dart 3v + i.
  std::span<const std::uint32_t> parent_darts;
};

/// A face table checked once and ready to instantiate: each half-edge (a dart-to-be, in table
/// order) with its local start and end vertex and the index of its opposite half-edge.
struct CellTemplate {
  std::vector<std::uint32_t> face_size;
  std::vector<std::uint32_t> from, to, mate;  // mate: null_index for a single polygon
  std::uint32_t first = 0;                    // the half-edge 0 -> 1 if any, else 0
  /// Checks and converts a table (see CMap::make_cell). Throws TopologyError if malformed.
  static CellTemplate from_faces(std::span<const std::span<const std::uint32_t>> faces);
};

template <int D, class... Attrs>
class CMap {
  using Params = detail::MapParams<Attrs...>;
  static_assert(D >= 1 && D <= 8, "CMap dimension must be in 1..8");
  static_assert(Params::num_attrs <= D + 1, "at most D+1 attribute types (one per dimension 0..D)");
  static_assert(Params::info_only_first, "DartInfo<T> may only be CMap's first type after D");

 public:
  static constexpr int dimension = D;
  /// The attribute type of I-cells (void when disabled).
  template <int I>
  using attribute_type = typename Params::template attr<I>;
  /// The per-dart value type (void without DartInfo<T>).
  using dart_info_type = typename Params::info;
  static constexpr bool has_dart_info = !std::is_void_v<dart_info_type>;
  template <int I>
  static constexpr bool has_attribute = (I >= 0 && I <= D) && !std::is_void_v<attribute_type<I>>;

  CMap() = default;
  /// Deep copy of darts, attributes and marks; the hooks are copied too (so they still refer to
  /// whatever they captured). O(n).
  CMap(const CMap&) = default;
  CMap(CMap&&) noexcept = default;
  CMap& operator=(const CMap&) = default;
  CMap& operator=(CMap&&) noexcept = default;

  // ---------------------------------------------------------------- darts
  /// Creates an isolated dart (every β null, no attributes). O(1) amortised; may reallocate
  /// internal arrays but never invalidates Dart handles.
  Dart create_dart();
  /// Erases an isolated dart (every β null). Throws TopologyError if d is dead or linked.
  /// Frees attributes whose last dart it was (on_erase fires). O(1).
  void erase_dart(Dart d);
  /// Number of live darts. O(1).
  [[nodiscard]] std::uint32_t num_darts() const { return alive_; }
  /// One past the largest dart index ever used (live or free-listed). O(1).
  [[nodiscard]] std::uint32_t dart_capacity() const { return static_cast<std::uint32_t>(beta_.size()); }
  /// True if d indexes a live dart of this map. O(1).
  [[nodiscard]] bool is_alive(Dart d) const {
    return d.index() < beta_.size() && beta_[d.index()][0] != detail::dead_marker;
  }
  /// Range over live darts in index order. Do not create or erase darts while iterating.
  [[nodiscard]] auto darts() const;
  /// Reserves storage for n darts. Invalidates nothing.
  void reserve(std::uint32_t n);
  /// Renumbers live darts to 0..num_darts()-1, keeping their order, and releases free slots.
  /// Returns old index -> new dart (null for dead slots). Invalidates every Dart held by the
  /// caller; attribute ids are unchanged. Throws TopologyError if a mark is reserved. O(n).
  std::vector<Dart> compact();
  /// Removes every dart and attribute (hooks do not fire). Marks must be free.
  void clear();
  /// Bytes of heap memory held by the map: β arrays, attribute indices and containers, marks.
  [[nodiscard]] std::size_t memory_bytes() const;

  // ---------------------------------------------------------------- β
  /// βi(d), null if d is i-free. Throws TopologyError if d is not a live dart or i ∉ [0, D].
  [[nodiscard]] Dart beta(Dart d, int i) const {
    check_alive(d, "beta");
    if (i < 0 || i > D) throw TopologyError("cmap::beta: index " + std::to_string(i) + " outside [0, D]");
    return Dart(b(d.index(), i));
  }
  /// Composition applied left to right: beta(d, 1, 2) = β2(β1(d)); null propagates.
  template <class... I>
  [[nodiscard]] Dart beta(Dart d, int i, int j, I... rest) const {
    Dart e = beta(d, i);
    return e ? beta(e, j, rest...) : null_dart;
  }
  /// βI(d) with I checked at compile time; d as in beta(d, i). O(1).
  template <int I>
  [[nodiscard]] Dart beta(Dart d) const {
    static_assert(I >= 0 && I <= D);
    check_alive(d, "beta");
    return Dart(b(d.index(), I));
  }
  /// True if βi(d) is null. Same checks as beta().
  [[nodiscard]] bool is_free(Dart d, int i) const { return beta(d, i).is_null(); }

  // ---------------------------------------------------------------- marks
  /// Reserves one of 32 marks; every live dart is unmarked for it. Throws CapacityError when
  /// all are reserved. O(1) (O(n/64) the first time a mark number is used).
  [[nodiscard]] Mark reserve_mark() const { return marks_.reserve(); }
  /// Unmarks every dart for m and releases it. O(1) when no or all live darts are marked.
  void free_mark(Mark m) const;
  /// True if d is marked for m (m reserved, d live). O(1).
  [[nodiscard]] bool is_marked(Dart d, Mark m) const { return marks_.test(d.index(), m); }
  /// Marks d; returns false if it was already marked. O(1).
  bool mark(Dart d, Mark m) const { return marks_.set(d.index(), m); }
  /// Unmarks d; returns false if it was not marked. O(1).
  bool unmark(Dart d, Mark m) const { return marks_.clear(d.index(), m); }
  /// Unmarks every dart. O(1) if all or none of the live darts are marked, else O(n/64).
  void unmark_all(Mark m) const { marks_.clear_all(m, alive_, dead_darts(), dart_capacity()); }
  /// Number of live darts marked for m. O(1).
  [[nodiscard]] std::uint32_t num_marked(Mark m) const { return marks_.count(m); }
  /// Number of marks currently reserved (0 when no traversal or guard is alive). O(1).
  [[nodiscard]] int num_reserved_marks() const { return marks_.reserved_count(); }
  /// Marks every dart of the I-cell of d; returns how many were newly marked. O(cell).
  template <int I>
  std::uint32_t mark_cell(Dart d, Mark m) const;

  // ---------------------------------------------------------------- attributes
  /// The I-attribute of the I-cell of d (null if none). O(1).
  template <int I>
  [[nodiscard]] AttrId<I> attribute(Dart d) const {
    static_assert(has_attribute<I>, "attributes are not enabled for this dimension");
    check_alive(d, "attribute");
    return AttrId<I>(store<I>().of_dart[d.index()]);
  }
  /// The value of attribute a. Throws TopologyError if a is null or dead.
  template <int I>
  attribute_type<I>& value(AttrId<I> a) {
    check_attr(a);
    return store<I>().values.value(a.index());
  }
  /// Read-only value of attribute a; same checks. O(1).
  template <int I>
  const attribute_type<I>& value(AttrId<I> a) const {
    check_attr(a);
    return store<I>().values.value(a.index());
  }
  /// Creates an attribute holding v and gives it to every dart of the I-cell of d; the cell's
  /// previous attribute, if any, is freed (on_erase fires). O(cell).
  template <int I>
  AttrId<I> set_attribute(Dart d, attribute_type<I> v);
  /// Gives an attribute f(dart) to every I-cell that has none. Returns how many were created. O(n).
  template <int I, class F>
  std::uint32_t create_attributes(F&& f);
  /// A dart of the cell carrying a. Throws TopologyError if a is null or dead. O(1).
  template <int I>
  [[nodiscard]] Dart dart_of(AttrId<I> a) const {
    check_attr(a);
    return Dart(store<I>().values.dart(a.index()));
  }
  /// Number of live I-attributes. O(1).
  template <int I>
  [[nodiscard]] std::uint32_t num_attributes() const {
    return store<I>().values.size();
  }
  /// Range over live I-attribute ids, in slot order, without touching darts.
  template <int I>
  [[nodiscard]] auto attributes() const;
  /// The container of I-attribute values, for bulk access by slot index.
  template <int I>
  [[nodiscard]] const AttributeContainer<attribute_type<I>>& attribute_container() const {
    return store<I>().values;
  }

  /// Sets the hook run when an I-cell splits in two (see the firing order at the top). O(1).
  template <int I>
  void on_split(std::function<void(AttrId<I> orig, AttrId<I> copy)> f) {
    store<I>().on_split = std::move(f);
  }
  /// Sets the hook run when two I-cells become one, before `gone` is freed. O(1).
  template <int I>
  void on_merge(std::function<void(AttrId<I> kept, AttrId<I> gone)> f) {
    store<I>().on_merge = std::move(f);
  }
  /// Sets the hook run when the last dart of an I-cell is erased, before its slot is freed. O(1).
  template <int I>
  void on_erase(std::function<void(AttrId<I> gone)> f) {
    store<I>().on_erase = std::move(f);
  }
  /// Pauses (false) or resumes every hook; attributes stay consistent either way. O(1).
  void set_hooks_enabled(bool on) { hooks_on_ = on; }
  [[nodiscard]] bool hooks_enabled() const { return hooks_on_; }

  // ---------------------------------------------------------------- per-dart data
  /// The info of dart d (maps declared with DartInfo<T> only). Throws TopologyError if d is not
  /// a live dart. O(1).
  ///
  /// Every operation keeps it, so no table indexed by dart needs clearing by hand:
  ///   - sew, unsew, link, unlink and the attribute hooks leave each dart's info alone;
  ///   - erasing a dart (erase_dart, remove_cell, contract_cell) drops its info: a dart made
  ///     later in the same slot starts from T{}, never from the erased dart's value;
  ///   - create_dart, make_polygon/polyline/cell and the other builders give new darts T{};
  ///   - compact() moves each info with its dart; copying the map copies them;
  ///   - an insertion gives each dart it makes a copy of the info of one argument dart:
  ///       insert_vertex_in_edge(d): each new dart copies the dart it was split from (the one
  ///         before it in its face);
  ///       insert_edge_in_face(a, b): both new darts copy a (in a βj-sewn copy of the face,
  ///         a's βj image);
  ///       insert_vertex_in_face(d), insert_dangling_edge_in_face(d): every new dart copies d
  ///         (on the other side of a 3-sewn face, β3(d));
  ///       insert_face_in_volume(path), insert_face_in_hole(path): the new darts along the edge
  ///         of path[i] copy path[i].
  /// CGAL's insertions give their new darts a default-constructed info instead; the copy is what
  /// a tag such as "which input face or material this dart came from" needs.
  template <class T = dart_info_type>
    requires(!std::is_void_v<T>)
  T& info(Dart d) {
    check_alive(d, "info");
    return info_.of_dart[d.index()];
  }
  /// Read-only info of dart d; same checks. O(1).
  template <class T = dart_info_type>
    requires(!std::is_void_v<T>)
  const T& info(Dart d) const {
    check_alive(d, "info");
    return info_.of_dart[d.index()];
  }

  // ---------------------------------------------------------------- traversal
  /// Darts reachable from d through the listed β indices (1 also follows β0). O(orbit).
  template <int... B>
  [[nodiscard]] DartList orbit(Dart d) const;
  /// Darts of the I-cell of d, d first. O(cell).
  template <int I>
  [[nodiscard]] DartList cell(Dart d) const;
  /// Darts of the connected component of d. O(component).
  [[nodiscard]] std::vector<Dart> component(Dart d) const;
  /// Range yielding the smallest dart of each I-cell, in increasing order. Holds a mark while
  /// alive (released on destruction, early break included), except for the cells it recognises
  /// without one (every cell of a 1- or 2-map, edges and faces of a 3-map). Iterable through a
  /// const& and more than once (each begin() starts a new pass). Do not modify the map while
  /// iterating.
  template <int I>
  [[nodiscard]] auto cells() const;
  /// One dart per J-cell incident to the I-cell of d (J < I: its faces; J > I: the cells it
  /// lies in), each returned dart belonging to the I-cell of d. O(I-cell · J-cell).
  template <int I, int J>
  [[nodiscard]] DartList incident(Dart d) const;
  /// One dart per I-cell adjacent to the I-cell of d, the cell itself excluded: for I ≥ 1 the
  /// I-cells sharing an (I-1)-cell with it, for I = 0 the other ends of its edges.
  template <int I>
  [[nodiscard]] DartList adjacent(Dart d) const;
  /// True if a and b belong to the same I-cell. O(cell).
  template <int I>
  [[nodiscard]] bool same_cell(Dart a, Dart b) const;

  // ---------------------------------------------------------------- counting
  /// Number of I-cells. O(n).
  template <int I>
  [[nodiscard]] std::uint32_t count() const;
  /// Number of i-cells for every i in one pass. O(n·(D+1)).
  [[nodiscard]] std::array<std::uint32_t, D + 1> count_all() const;
  /// Σ (-1)^i · count<i>(), i = 0..D. O(n·(D+1)).
  [[nodiscard]] std::int64_t euler_characteristic() const;
  /// Number of connected components. O(n).
  [[nodiscard]] std::uint32_t count_components() const;
  /// One dart per boundary facet: a (D-1)-cell with a D-free dart. O(n).
  [[nodiscard]] std::vector<Dart> boundary_facets() const;

  // ---------------------------------------------------------------- sewing
  /// True if sew<I>(a, b) would succeed: both live, a I-free (I = 1: a 1-free, b 0-free),
  /// and the orbits to be sewn have the same shape. O(orbit).
  template <int I>
  [[nodiscard]] bool is_sewable(Dart a, Dart b) const;
  /// I-sews a and b (βI(a) = b) and every matching pair of their orbits, then merges the
  /// attributes of cells that became one (on_merge: a's side is kept). Throws TopologyError
  /// if not sewable. O(orbit + merged cells).
  template <int I>
  void sew(Dart a, Dart b);
  /// I-unsews the orbit of d, then splits attributes of cells that became two (on_split: the
  /// part holding d keeps the original). Throws TopologyError if d is I-free. O(orbit + cells).
  template <int I>
  void unsew(Dart d);
  /// unsew<I> of every dart of `darts` still I-sewn when its turn comes (dead and I-free darts
  /// are skipped: a facet listed twice, or from both sides), then one attribute update for all:
  /// a cell that several of the orbits touch is walked once instead of once per orbit. Leaves
  /// the same cells and attribute values as the unsews one by one; which piece of a split cell
  /// keeps the original attribute may differ. Returns how many orbits were unsewn.
  /// O(Σ orbits + cells touched).
  template <int I>
  std::uint32_t unsew_all(std::span<const Dart> darts);
  /// As sew<I> but leaves attributes untouched (the caller fixes them; validate() will tell).
  template <int I>
  void link(Dart a, Dart b);
  /// As unsew<I> but leaves attributes untouched.
  template <int I>
  void unlink(Dart d);
  /// Low level: sets βI(a) = b and its inverse, nothing else. For builders that complete whole
  /// orbits themselves; the map is invalid until they do. Throws TopologyError on dead darts.
  /// Until a validate() finds the links sound again, face traversals of a 3-map check the
  /// links' shape as they go (a little slower) instead of relying on it.
  template <int I>
  void link_beta(Dart a, Dart b);
  /// Low level: makes d I-free (and its partner's inverse link), nothing else. As link_beta,
  /// face traversals check the links' shape until a validate() finds them sound.
  template <int I>
  void unlink_beta(Dart d);

  // ---------------------------------------------------------------- construction
  /// A closed polygon of n ≥ 1 edges (n darts in a β1 cycle). Returns its first dart. O(n).
  Dart make_polygon(std::uint32_t n);
  Dart make_triangle() { return make_polygon(3); }
  Dart make_quad() { return make_polygon(4); }
  /// An open chain of n ≥ 1 edges. D = 1: n darts chained by β1. D ≥ 2: 2n darts, each edge a
  /// β2-linked pair, forward darts chained by β1 and backward darts in reverse. Returns the
  /// first forward dart. O(n).
  Dart make_polyline(std::uint32_t n);
  /// Closed polyhedra (D ≥ 3) with outward-oriented faces. Local vertex numbers follow VTK:
  /// the returned dart starts at local vertex 0 and goes to local vertex 1 (see mesh.hpp for
  /// the face tables). O(1).
  Dart make_tetrahedron();
  Dart make_hexahedron();
  Dart make_prism();
  Dart make_pyramid();
  /// Creates a closed cell from a face table (faces as local vertex lists, outward, each edge in
  /// exactly two faces with opposite directions). D ≥ 3 for polyhedra, D ≥ 2 for one polygon.
  /// `darts`, if given, receives the new darts in table order (face 0's darts starting at its
  /// vertices in order, then face 1's, ...). Throws TopologyError on a malformed table, before
  /// changing the map. O(size of table²).
  Dart make_cell(std::span<const std::span<const std::uint32_t>> faces, std::vector<Dart>* darts = nullptr);
  /// As above from a table validated once (see CellTemplate), for building many cells. O(darts).
  Dart make_cell(const CellTemplate& t, std::vector<Dart>* darts = nullptr);

  // ---------------------------------------------------------------- insertion
  /// Splits the edge of d at a new vertex. Returns the new dart following d in its face (it
  /// starts at the new vertex). The edge's attribute is copied to the second half (on_split);
  /// the new vertex gets no 0-attribute. O(edge).
  Dart insert_vertex_in_edge(Dart d) {
    detail::DartBuffer<32> made;
    return split_edge(d, made);
  }
  /// As insert_vertex_in_edge(d) followed by set_attribute<0> on the new vertex with v (on_split
  /// fires for the edge before the vertex has its attribute), without walking the vertex: its
  /// darts are the ones the split made. O(edge).
  template <int I = 0>
    requires(I == 0 && has_attribute<0>)
  Dart insert_vertex_in_edge(Dart d, attribute_type<I> v) {
    return with_new_vertex<I>(&CMap::split_edge, d, std::move(v));
  }
  /// True if insert_edge_in_face(a, b) may be called: a ≠ b, both live, b on a's closed β1 cycle.
  /// Subdivides every hexahedron of a 3-map 1:8 in one pass: each edge split at a new vertex,
  /// each face cut in 4 through a new centre, each volume cut by its three middle planes through
  /// a new centre, as the insertions (insert_vertex_in_edge, insert_edge_in_face,
  /// insert_face_in_volume) would make it, without their per-dart work: the new darts are
  /// allocated at once and linked from a per-hexahedron table. The map's darts are kept (each
  /// becomes the first half of its edge, in the child at its source). With vertex attributes,
  /// `middle(a, b)` gives the value of the vertex between two vertex values: an edge's midpoint
  /// from its ends, a face's centre from two opposite midpoints, a volume's from two opposite
  /// face centres. Every volume must be a closed hexahedron of 6 quads (TopologyError, the map
  /// unchanged, otherwise); volumes may be 3-free. Maps with vertex attributes only, no hooks
  /// called. O(darts).
  template <class Mid>
  void subdivide_hexahedra(Mid&& middle);
  /// As subdivide_hexahedra(middle), on a map whose edges, faces or volumes may carry
  /// attributes. For each I ≥ 1 with attributes, if any I-cell carried one before the pass, every
  /// fine I-cell gets the value `fine(std::integral_constant<int, I>{}, const FineCell&)` returns
  /// (a std::optional: nullopt leaves the cell without), and the parents' I-attributes are
  /// released afterwards. No hooks are called: the caller makes the new cells' values from
  /// their parents' (FineCell names the parent's attribute, still readable during the calls).
  /// Fine cells are visited with the vertex attributes already in place, edges first, then
  /// faces, then volumes (a volume's `fine` can read its edges' new attributes). O(darts).
  template <class Mid, class Fine>
  void subdivide_hexahedra(Mid&& middle, Fine&& fine);

  [[nodiscard]] bool is_insertable_edge_in_face(Dart a, Dart b) const;
  /// Splits the face of a and b by a new edge from a's start vertex to b's start vertex (D ≥ 2;
  /// also across every βj-sewn copy of the face, j ≥ 3). Returns the new dart that starts at a's
  /// vertex; it lies in the face of b. The face holding a keeps the attribute; the other gets a
  /// copy (on_split). The new edge has no 1-attribute. O(face).
  Dart insert_edge_in_face(Dart a, Dart b);
  /// True if path is a closed chain of darts of one volume (end of each = start of the next),
  /// with distinct edges, along which a face may be inserted (D ≥ 3; 4..D-free darts).
  /// Stricter than CGAL's is_insertable_cell_2_in_cell_3, which takes any closed path of one
  /// volume and, when its darts are 2-free, closes the hole with a one-sided face instead of
  /// inserting a two-sided one. Here one operation makes one shape: the two-sided face always
  /// (distinct edges, so each edge gets one new pair), and insert_face_in_hole for the hole.
  [[nodiscard]] bool is_insertable_face_in_volume(std::span<const Dart> path) const;
  /// Inserts a face along the closed dart path inside a volume (two β3-linked polygons). Returns
  /// the new dart β2(path[0]). If the volume falls in two, the part holding path[0] keeps its
  /// attribute and the other gets a copy (on_split). The new face has no 2-attribute. O(path + volume).
  Dart insert_face_in_volume(std::span<const Dart> path);

  /// True if insert_face_in_hole(path) may be called: D ≥ 3, path a closed chain of 2-free darts
  /// of one volume (end of each = start of the next), 4..D-free, no dart twice. O(path · volume).
  [[nodiscard]] bool is_insertable_face_in_hole(std::span<const Dart> path) const;
  /// Closes the hole bounded by the 2-free path with one face (CGAL's insert_cell_2_in_cell_3 on
  /// a 2-free path): a polygon of path.size() darts, each 2-sewn to its path dart and running
  /// the other way, 3-free. The new darts take the edge and volume attributes of their path
  /// dart and the vertex attribute of the vertex they start at; the face has none. No cell
  /// splits or merges, so no hook fires. Returns the new dart β2(path[0]). Throws TopologyError
  /// if not insertable. O(path).
  Dart insert_face_in_hole(std::span<const Dart> path);
  /// True if insert_vertex_in_face(d) may be called: D ≥ 2, d's face a closed β1 cycle of at
  /// least two darts, not βj-sewn (j ≥ 3) to itself (a face folded onto itself). O(face · copies).
  [[nodiscard]] bool is_insertable_vertex_in_face(Dart d) const;
  /// Inserts a vertex inside the face of d joined to each of its k vertices (CGAL's
  /// insert_cell_0_in_cell_2): the face becomes k triangles, across every βj-sewn copy (j ≥ 3),
  /// in one pass that makes the 2k new darts of each copy and their links. The triangle holding
  /// d keeps the face's attribute, the k-1 others get copies (on_split fires for each, once the
  /// map is whole); the new vertex and edges have no attribute, the new darts keep their copy's
  /// volume (and higher) attributes. Returns the new dart that starts at the new vertex and ends
  /// at β1(d)'s start. Throws TopologyError if not insertable. O(k · copies).
  Dart insert_vertex_in_face(Dart d) {
    detail::DartBuffer<32> centre;
    return star_face(d, centre);
  }
  /// As insert_vertex_in_face(d) followed by set_attribute<0> on the new vertex with v, without
  /// walking the vertex: its darts are the ones the insertion made (CGAL's
  /// insert_cell_0_in_cell_2 with a vertex attribute). O(k · copies).
  template <int I = 0>
    requires(I == 0 && has_attribute<0>)
  Dart insert_vertex_in_face(Dart d, attribute_type<I> v) {
    return with_new_vertex<I>(&CMap::star_face, d, std::move(v));
  }

  /// True if insert_dangling_edge_in_face(d) may be called: D is 2 or 3, d live with a β0. O(1).
  [[nodiscard]] bool is_insertable_dangling_edge_in_face(Dart d) const;
  /// Inserts an edge inside the face of d from d's start vertex to a new vertex (CGAL's
  /// insert_dangling_cell_1_in_cell_2), on both sides of a 3-sewn face: two darts per side,
  /// placed before d. The face stays one face; no cell splits or merges, so no hook fires; the
  /// new darts keep the face's and volume's attributes and the start vertex's; the new edge and
  /// vertex have none. Returns the new dart from d's start to the new vertex. Throws
  /// TopologyError if not insertable. O(1).
  Dart insert_dangling_edge_in_face(Dart d);

  // ---------------------------------------------------------------- removal, contraction
  /// True if the I-cell of d can be removed: I ≥ D-1, or it is incident to at most two
  /// (I+1)-cells (β_{I+1}∘β_{I+2} is an involution on its darts); and removing it does not fold
  /// a cell onto itself (a dart would become its own βi partner). O(cell).
  /// Stricter than CGAL: CGAL's is_removable checks only the degree and then removes, e.g., the
  /// only edge between a face and itself, leaving a βi with a fixed point that its own
  /// is_valid() rejects. Refusing such a cell here keeps every operation's result valid().
  template <int I>
  [[nodiscard]] bool is_removable(Dart d) const;
  /// Removes the I-cell of d, merging the (I+1)-cells around it (on_merge keeps the attribute
  /// of the first cell reached). Erases its darts. Throws TopologyError if not removable. O(cells).
  template <int I>
  void remove_cell(Dart d);
  /// True if the I-cell of d can be contracted: I = 1, or (I ≥ 2) it has at most two (I-1)-cells;
  /// and contracting it does not fold a cell onto itself. O(cell).
  /// Stricter than CGAL for the reason given at is_removable: CGAL's is_contractible checks only
  /// the number of (I-1)-cells and can leave a βi fixed point; the fold check refuses that case.
  template <int I>
  [[nodiscard]] bool is_contractible(Dart d) const;
  /// Contracts the I-cell of d into an (I-1)-cell (I = 1: the edge's two vertices merge).
  /// Erases its darts. Throws TopologyError if not contractible. O(cells).
  template <int I>
  void contract_cell(Dart d);

  // ---------------------------------------------------------------- checks
  /// Checks every invariant and names each violation with its dart: β0∘β1 = id, βi involutions
  /// without fixed points (i ≥ 2), βi∘βj involutions for i+2 ≤ j, links to live darts only,
  /// attribute consistency (one attribute per cell, reference counts, no orphan, one cell per
  /// attribute), the free list, and marks. O(n·D²). A report with sound links (and free list)
  /// lets face traversals rely on the links again after link_beta / unlink_beta.
  [[nodiscard]] ValidationReport validate() const;

  // ---------------------------------------------------------------- internals for sibling headers
  /// Raw β without checks (builders and operations). i ∈ [0, D], x a live dart index.
  [[nodiscard]] std::uint32_t b(std::uint32_t x, int i) const { return beta_[x][static_cast<std::size_t>(i)]; }
  /// Raw index of the I-attribute of dart x (null_index if none), without checks: for hot loops
  /// of modules built on the map; x must be a live dart index. Values: attribute_container<I>().
  template <int I>
  [[nodiscard]] std::uint32_t attribute_index(std::uint32_t x) const {
    return store<I>().of_dart[x];
  }

 private:
  using Stores = typename Params::template stores<std::make_integer_sequence<int, D + 1>>;

  template <int I>
  auto& store() {
    static_assert(has_attribute<I>, "attributes are not enabled for this dimension");
    return std::get<I>(stores_);
  }
  template <int I>
  const auto& store() const {
    static_assert(has_attribute<I>, "attributes are not enabled for this dimension");
    return std::get<I>(stores_);
  }
  template <class F>
  static void for_each_dim(F&& f) {
    [&]<int... I>(std::integer_sequence<int, I...>) {
      (f(std::integral_constant<int, I>{}), ...);
    }(std::make_integer_sequence<int, D + 1>{});
  }

  // Orbits, as a compile-time mask: a bit per β index (bit 1 stands for β1 and β0), or
  // vertex_orbit (bit 0, which no β mask uses) for the darts starting at one vertex.
  static constexpr unsigned vertex_orbit = 1u;
  static constexpr unsigned all_betas = ((1u << (D + 1)) - 1u) & ~1u;
  template <int I>
  static constexpr unsigned cell_mask = I == 0 ? vertex_orbit : all_betas & ~(1u << I);
  static constexpr unsigned component_mask = all_betas;
  using MarkView = detail::MarkPlanes::View;

  void set_b(std::uint32_t x, int i, std::uint32_t y) { beta_[x][static_cast<std::size_t>(i)] = y; }
  // Links x -> y for βi, with the inverse (β0/β1 pair or involution). Null y makes x i-free.
  void raw_link(std::uint32_t x, int i, std::uint32_t y);
  void check_alive(Dart d, const char* where) const {
    if (!is_alive(d)) [[unlikely]]
      throw_dead(d, where);
  }
  [[noreturn]] void throw_dead(Dart d, const char* where) const;
  template <int I>
  void check_attr(AttrId<I> a) const;
  [[nodiscard]] std::vector<std::uint32_t> dead_darts() const;

  // Calls f(y) for each neighbour y of x in the orbit (the generators, not the closure).
  template <unsigned Mask, class F>
  void for_each_neighbor(std::uint32_t x, F&& f) const;
  // Walks mark the darts they visit through a view and append exactly those darts to `out`,
  // which is how callers know how many to add to the mark's count (see MarkPlanes::View).
  // Breadth-first walk of an orbit from root.
  template <unsigned Mask, class Out>
  void walk(std::uint32_t root, MarkView mk, Out& out) const;
  // Continues a breadth-first walk: expands out[head..] (already marked) until closed.
  template <unsigned Mask, class Out>
  void expand(std::size_t head, MarkView mk, Out& out) const;
  // The I-cell of root, with walks specialised per dimension (β1 chains for faces and volumes,
  // alternating involutions for edges, generator maps around vertices) that fall back to the
  // generic search where the map is open.
  template <int I, class Out>
  void walk_cell(std::uint32_t root, MarkView mk, Out& out) const;
  template <class Out>
  void walk_chain(std::uint32_t x, MarkView mk, Out& out) const;
  // walk_cell with the mark's count kept.
  template <int I, class Out>
  void collect_cell(std::uint32_t root, Mark m, Out& out) const;
  // As collect_cell / walk with a mark of their own, left clear on return.
  template <int I, class Out>
  void collect_cell_unmarked(std::uint32_t root, Out& out) const;
  template <unsigned Mask, class Out>
  void collect_unmarked(std::uint32_t root, Out& out) const;
  [[nodiscard]] bool is_live_index(std::uint32_t x) const { return beta_[x][0] != detail::dead_marker; }
  // I-cells whose orbit is a single path or cycle of darts: every cell of a 1- or 2-map, and
  // the edges of a 3-map. Whether a dart is the smallest of such a cell is found by walking
  // the chain until a smaller dart comes up, without marks: no stores, so the walks from
  // successive darts overlap in the processor instead of queueing behind each mark update.
  template <int I>
  static constexpr bool chain_cell = D <= 2 || (D == 3 && I == 1);
  // Calls f(y) for each dart of x's chain cell after x, in walk order (one way along the chain
  // and, if it is open, the other way), until f returns false; returns false if f stopped it.
  // Gives up after dart_capacity() steps, which only a map with inconsistent links (β0 ≠ β1⁻¹,
  // a βi not an involution) can take.
  template <int I, class F>
  bool walk_chain_cell(std::uint32_t x, F&& f) const;
  // True if x is the smallest dart of its I-cell (a chain cell).
  template <int I>
  [[nodiscard]] bool is_chain_root(std::uint32_t x) const;
  // True if the I-attributes (I a chain cell) pass every check of validate(), found without
  // walking every cell; false if validate() must look closer. Links must be sound.
  template <int I>
  [[nodiscard]] bool chain_attributes_sound() const;
  // Cells whose smallest dart is recognised without marks: chain cells, and the faces of a
  // 3-map (a β1 cycle and its β3 partner's, checked to have that shape).
  template <int I>
  static constexpr bool rooted_without_marks = chain_cell<I> || (D == 3 && I == 2);
  // True if x is the smallest dart of its face (D = 3). Inlined: most darts have a smaller
  // neighbour in their own row and stop there; the others walk the face (face_root_walk).
  [[nodiscard]] bool is_face_root(std::uint32_t x) const {
    const auto& r = beta_[x];
    // null is the largest index, so a free link never counts as smaller.
    return !(r[0] < x || r[1] < x || r[3] < x) && face_root_walk(x);
  }
  [[nodiscard]] bool face_root_walk(std::uint32_t x) const;
  [[nodiscard, gnu::noinline]] bool face_root_by_mark(std::uint32_t x) const;
  template <int I>
  [[nodiscard]] bool is_cell_root(std::uint32_t x) const {
    static_assert(rooted_without_marks<I>);
    if constexpr (chain_cell<I>)
      return is_chain_root<I>(x);
    else
      return is_face_root(x);
  }
  // Calls f(x, darts) for the smallest dart x of each I-cell (I < 0: each connected component)
  // in increasing order, with the darts of the cell (x first), found by marking: each dart is
  // walked once (chain walks revisit darts, which only pays when the darts are not wanted).
  // f must not change the map.
  template <int I, class F>
  void for_each_cell_root(F&& f) const;
  // Number of I-cells (I < 0: connected components).
  template <int I>
  [[nodiscard]] std::uint32_t count_cells() const;

  // Dart pairs an operation links or unlinks; a sew or unsew of a face has a handful.
  using DartPairs = boost::container::small_vector<std::pair<std::uint32_t, std::uint32_t>, 16>;
  template <int I>
  bool sew_pairs(std::uint32_t a, std::uint32_t b, std::vector<std::pair<std::uint32_t, std::uint32_t>>* out) const;
  template <int I>
  void unsew_pairs(std::uint32_t d, DartPairs& out) const;
  // The β links of sew/link and unsew/unlink (`who` names the caller in errors); the pairs
  // they changed are returned for the attribute update of sew and unsew.
  template <int I>
  std::vector<std::pair<std::uint32_t, std::uint32_t>> link_orbits(Dart a, Dart b, const char* who);
  template <int I>
  void unlink_orbits(Dart d, const char* who, DartPairs& pairs);
  // Merges or splits the attributes of every dimension but I around the darts of `pairs`.
  template <int I, class Pairs>
  void update_attributes_around(const Pairs& pairs);

  std::uint32_t new_dart();
  // k new darts appended to out, as k calls of new_dart would (free slots first, same indices)
  // but growing the arrays once: operations that make several darts at a time.
  template <class Out>
  void new_darts(std::uint32_t k, Out& out);
  void erase_dart_raw(std::uint32_t x);
  // insert_vertex_in_edge; `made` receives the new darts, which are the new vertex's.
  Dart split_edge(Dart d, detail::DartBuffer<32>& made);
  // A new 0-attribute holding v for the darts of a new vertex (all of them, none carrying one),
  // `first` among them.
  template <int I>
  void give_new_vertex(const detail::DartBuffer<32>& darts, Dart first, attribute_type<I> v) {
    auto& st = store<I>();
    const std::uint32_t a = st.values.create(std::move(v));
    for (std::uint32_t x : darts) st.of_dart[x] = a;
    st.values.add_count(a, static_cast<std::int64_t>(darts.size()));
    st.values.set_dart(a, first.index());
  }
  // An insertion that makes a vertex (split_edge, star_face: they return a dart of the new
  // vertex and fill `made` with all of them), followed by the vertex's attribute holding v.
  template <int I>
  Dart with_new_vertex(Dart (CMap::*insert)(Dart, detail::DartBuffer<32>&), Dart d, attribute_type<I> v) {
    detail::DartBuffer<32> made;
    const Dart nd = (this->*insert)(d, made);
    give_new_vertex<I>(made, nd, std::move(v));
    return nd;
  }
  // The face of a dart and its copies across βj (j ≥ 3), see cmap_insert.hpp.
  struct FaceCopies;
  [[nodiscard]] bool face_copies(std::uint32_t d, FaceCopies& out) const;
  // True if each dart of the path is met turning inside its volume around the vertex where the
  // previous one ends (is_insertable_face_in_volume's usual case, without walking the volume).
  [[nodiscard]] bool chained_in_one_volume(std::span<const Dart> path) const;
  // insert_vertex_in_face; `centre` receives the new darts that start at the new vertex.
  Dart star_face(Dart d, detail::DartBuffer<32>& centre);
  // A bit per dimension whose attributes are enabled: work that only serves attributes is
  // skipped at compile time when an operation's dimensions have none.
  static constexpr unsigned attribute_dims = []<int... I>(std::integer_sequence<int, I...>) {
    return (0u | ... | (has_attribute<I> ? 1u << I : 0u));
  }(std::make_integer_sequence<int, D + 1>{});
  // Re-derives attributes after a topological change: `touched` holds the darts whose β links
  // changed (first the operation's first dart); `dims` a bit per dimension to update.
  void update_attributes(std::span<const std::uint32_t> touched, unsigned dims);
  template <int I>
  void update_attributes_of(std::span<const std::uint32_t> touched);
  // The survivors of the cells an attribute update has processed so far, each known by the
  // dart it now names (its cell's first dart). An update of one sew or unsew has a handful,
  // searched in a list; past the list's size a mark takes over (unsew_all of a whole plane has
  // thousands, and a search per cell would be quadratic), so small updates reserve no mark and
  // never allocate its plane.
  struct Claims {
    static constexpr std::size_t list_max = 64;
    detail::DartBuffer<list_max> darts;
    Mark mark;  // reserved once darts outgrows list_max
  };
  [[nodiscard]] bool in_claims(const Claims& c, std::uint32_t x) const;
  void add_claim(Claims& c, std::uint32_t x);
  void release_claims(Claims& c);
  template <int I>
  void process_new_cell(std::span<const std::uint32_t> cell, Claims& claims);
  template <int I>
  std::uint32_t copy_attribute(std::uint32_t a);
  template <int I>
  void relabel(std::span<const std::uint32_t> cell, std::uint32_t from, std::uint32_t to);
  void flush_erased();
  // subdivide_hexahedra: gives the darts of a fine I-cell the attribute `value` (a std::optional).
  template <int I, class V>
  void give_fine_attribute(V&& value, std::span<const std::uint32_t> cell);

  // Gives `to` the attributes of `from` for every dimension whose bit is set in dims.
  void inherit_attributes(std::uint32_t from, std::uint32_t to, unsigned dims);
  // The same for a dart just made (it carries no attribute yet), the dimensions known at
  // compile time: the per-dart work of the one-pass insertions, which make many darts.
  template <unsigned Dims>
  void inherit_new(std::uint32_t from, std::uint32_t to) {
    for_each_dim([&](auto k) {
      constexpr int K = k();
      if constexpr (has_attribute<K> && ((Dims >> K) & 1u) != 0) {
        auto& st = store<K>();
        const std::uint32_t a = st.of_dart[from];
        st.of_dart[to] = a;
        if (a != detail::null_index) st.values.add_count(a, 1);
      }
    });
  }
  // Gives the new dart `to` a copy of the info of `from` (the insertion rule above).
  void copy_info(std::uint32_t from, std::uint32_t to) {
    if constexpr (has_dart_info) info_.of_dart[to] = info_.of_dart[from];
  }

  // Cell removal and contraction share one relinking engine (see ops header): βi(w) becomes
  // `target`, replacing the links of the erased dart `from`.
  struct Relink {
    int i;
    std::uint32_t w, target, from;
  };
  // `merge_dim`: the dimension of the cells that fuse; a cell of that dimension whose darts are
  // all erased merges into the cell of the relink's w (into_w) or target, with on_merge.
  void apply_relinks_and_erase(const DartList& cell, const std::vector<Relink>& links, int merge_dim, bool into_w);
  // The links that removing (contracting) the I-cell `c` creates, computed on the current map.
  // False if the cell lies in more than two neighbours, or if a link would make a dart its own
  // βi partner (a cell folded onto itself, which has no valid result).
  template <int I>
  bool plan_removal(const DartList& c, std::vector<Relink>& links) const;
  template <int I>
  bool plan_contraction(const DartList& c, std::vector<Relink>& links) const;

  detail::PodArray<std::array<std::uint32_t, D + 1>> beta_;
  std::uint32_t free_head_ = detail::null_index;  // free list threaded through β1 of dead darts
  std::uint32_t alive_ = 0;
  Stores stores_;
  [[no_unique_address]] detail::InfoStore<dart_info_type> info_;
  mutable detail::MarkPlanes marks_;
  bool hooks_on_ = true;
  friend struct detail::LinkSoundness;
  // The β links are known to pass validate()'s link checks: true from construction (every
  // operation but link_beta / unlink_beta keeps sound links sound), false after those two,
  // true again after a validate() that finds no broken link.
  mutable bool links_sound_ = true;
  std::vector<std::pair<int, std::uint32_t>> pending_erase_;  // (dimension, attribute) to free
};

}  // namespace sewn

#include "sewn/cmap/guards.hpp"
#include "sewn/cmap/detail/cmap_core.hpp"
#include "sewn/cmap/detail/cmap_traversal.hpp"
#include "sewn/cmap/detail/cmap_attributes.hpp"
#include "sewn/cmap/detail/cmap_sew.hpp"
#include "sewn/cmap/detail/cmap_make.hpp"
#include "sewn/cmap/detail/cmap_insert.hpp"
#include "sewn/cmap/detail/cmap_remove.hpp"
#include "sewn/cmap/detail/cmap_validate.hpp"
#include "sewn/cmap/detail/cmap_subdivide.hpp"
