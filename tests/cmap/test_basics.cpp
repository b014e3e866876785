#include <doctest/doctest.h>

#include "sewn/cmap/build.hpp"
#include "sewn/cmap/cmap.hpp"

TEST_CASE("smoke: a hexahedral grid builds, validates and counts") {
  sewn::CMap<3, std::uint32_t> map;
  auto mesh = sewn::hex_grid(2, 2, 1);
  auto built = sewn::build(map, mesh);
  map.create_attributes<0>([&](sewn::Dart d) { return built.vertex_of_dart[d.index()]; });
  auto report = map.validate();
  INFO(report.str());
  CHECK(report.ok());
  auto n = map.count_all();
  CHECK(n[0] == 18);
  CHECK(n[1] == 33);
  CHECK(n[2] == 20);
  CHECK(n[3] == 4);
  CHECK(map.euler_characteristic() == 1);
  CHECK(map.num_reserved_marks() == 0);
}
