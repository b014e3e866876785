#include <doctest/doctest.h>

#include "sewn/cmap/cmap.hpp"

// A full pass over a mark (cells(), create_attributes, count...) marks every live dart, so
// freeing it flips the plane's polarity. Dart slots past the last live dart in the same 64-bit
// word keep their raw bit, which then reads as "marked": a dart created there starts marked, and
// operations that use marks to find the darts they must update skip it.

TEST_CASE("marks: a dart created after a full-pass traversal starts unmarked") {
  sewn::CMap<2> map;
  map.make_quad();  // darts 0..3, one mark word
  for (sewn::Dart d : map.cells<2>()) (void)d;
  const sewn::Dart x = map.create_dart();
  const sewn::Mark m = map.reserve_mark();
  CHECK_FALSE(map.is_marked(x, m));
  map.free_mark(m);
}

TEST_CASE("marks: insert_edge_in_face after create_attributes gives the new darts their vertices' attributes") {
  sewn::CMap<2, int> map;
  const sewn::Dart f = map.make_quad();
  map.create_attributes<0>([](sewn::Dart) { return 1; });
  map.insert_edge_in_face(f, map.beta(f, 1, 1));
  const sewn::ValidationReport report = map.validate();
  INFO(report.str());
  CHECK(report.ok());
}
