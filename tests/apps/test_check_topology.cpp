// The topology part of `sewn check`: the numbers of a mesh's complex, as text and as JSON.
#include <doctest/doctest.h>

#include "sewn/apps/check_topology.hpp"

namespace test_check_topology {

using namespace sewn;

TEST_CASE("sewn check reports the topology of a mesh") {
  SUBCASE("a block of hexahedra: one ball, one sphere as boundary") {
    const app::MeshTopology t = app::mesh_topology(hex_grid(2, 2, 3), "block");
    REQUIRE(t.dim == 3);
    const auto j = app::topology_json(t);
    CHECK(j["betti"] == nlohmann::json::array({1, 0, 0, 0}));
    CHECK(j["euler"] == 1);
    CHECK(j["orientable"] == true);
    REQUIRE(j["boundary"].size() == 1);
    CHECK(j["boundary"][0]["genus"] == 0);
    CHECK(j["nonmanifold"].empty());
    const std::string text = app::topology_text(t);
    CHECK(text.find("1 component, χ = 1, Betti numbers over Z/2 (1, 0, 0, 0), orientable") != std::string::npos);
    CHECK(text.find("genus 0") != std::string::npos);
  }
  SUBCASE("two tetrahedra sharing a point: the point is named") {
    IndexedMesh m;
    m.points.resize(7);
    m.add_cell(CellType::tetrahedron, {0, 1, 2, 3});
    m.add_cell(CellType::tetrahedron, {3, 4, 5, 6});
    const app::MeshTopology t = app::mesh_topology(m, "pinch");
    const auto j = app::topology_json(t);
    REQUIRE(j["nonmanifold"].size() == 1);
    CHECK(j["nonmanifold"][0]["point"] == 3);
    CHECK(app::topology_text(t).find("vertex at point 3: its link has 2 pieces") != std::string::npos);
  }
  SUBCASE("a Möbius strip of quads is not orientable") {
    IndexedMesh m;
    m.points.resize(10);
    for (std::uint32_t i = 0; i < 5; ++i) {
      const std::uint32_t a = i, b = i + 5, c = i == 4 ? 0 : i + 6, d = i == 4 ? 5 : i + 1;  // the last quad twisted
      m.add_cell(CellType::quad, {a, d, c, b});
    }
    const app::MeshTopology t = app::mesh_topology(m, "strip");
    REQUIRE(t.dim == 2);
    const auto j = app::topology_json(t);
    CHECK(j["orientable"] == false);
    CHECK(j["betti"] == nlohmann::json::array({1, 1, 0}));
    CHECK(j["boundary"].size() == 1);
  }
  SUBCASE("mixed dimensions are skipped with the reason") {
    IndexedMesh m = hex_grid(1, 1, 1);
    append(m, quad_grid(1, 1));
    const app::MeshTopology t = app::mesh_topology(m, "mixed");
    CHECK(t.dim == 0);
    CHECK(app::topology_json(t)["skipped"].get<std::string>().find("1 volumes, 1 surface cells") != std::string::npos);
  }
}

}  // namespace test_check_topology
