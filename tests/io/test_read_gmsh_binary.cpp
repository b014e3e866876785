// Binary MSH 4.1 and 2.2: the two sample files of test_read_gmsh.cpp written out byte by byte as
// Gmsh lays them out (reference manual, "MSH file format"), in this machine's byte order and
// in the opposite one, read back equal to the ASCII files; and the binary-only failures. The
// round trip through the real gmsh (-bin) is in test_gmsh_roundtrip.cpp.
#include <doctest/doctest.h>

#include <algorithm>
#include <cstdint>
#include <cstring>
#include <string>
#include <string_view>

#include "io_test_util.hpp"
#include "sewn/io/read.hpp"

namespace test_read_gmsh_binary {

using namespace sewn;
using namespace sewn::io;
using sewn::io::test::message_of;

namespace {

// Bytes of a binary MSH file: text, and C ints, size_ts and doubles in native or reversed order.
struct Bytes {
  std::string s;
  bool swap = false;

  template <class T>
  Bytes& put(T v) {
    char b[sizeof(T)];
    std::memcpy(b, &v, sizeof(T));
    if (swap) std::reverse(b, b + sizeof(T));
    s.append(b, sizeof(T));
    return *this;
  }
  Bytes& text(std::string_view t) {
    s += t;
    return *this;
  }
  Bytes& i(std::int32_t v) { return put(v); }
  Bytes& z(std::uint64_t v) { return put(v); }
  Bytes& d(double v) { return put(v); }
};

// tests/io/data/mixed41.msh in binary: entities, two node blocks with sparse tags, hexahedron,
// prism and pyramid blocks.
std::string mixed41_binary(bool swap) {
  Bytes b;
  b.swap = swap;
  b.text("$MeshFormat\n4.1 1 8\n").i(1).text("\n$EndMeshFormat\n");
  b.text("$PhysicalNames\n3\n3 10 \"hexes\"\n3 20 \"wedges\"\n3 30 \"pyramids\"\n$EndPhysicalNames\n");
  b.text("$Entities\n").z(0).z(0).z(0).z(3);
  const double boxes[3][6] = {{0, 0, 0, 1, 1, 1}, {0, 0, 1, 1, 1, 2}, {0, 0, -1, 1, 1, 0}};
  for (int v = 0; v < 3; ++v) {
    b.i(v + 1);
    for (double c : boxes[v]) b.d(c);
    b.z(1).i(10 * (v + 1)).z(0);
  }
  b.text("\n$EndEntities\n");
  b.text("$Nodes\n").z(2).z(15).z(10).z(150);
  b.i(3).i(1).i(0).z(12);
  for (std::uint64_t t = 10; t <= 120; t += 10) b.z(t);
  const double corners[12][3] = {{0, 0, 0}, {1, 0, 0}, {1, 1, 0}, {0, 1, 0}, {0, 0, 1}, {1, 0, 1},
                                 {1, 1, 1}, {0, 1, 1}, {0, 0, 2}, {1, 0, 2}, {1, 1, 2}, {0, 1, 2}};
  for (const auto& p : corners) b.d(p[0]).d(p[1]).d(p[2]);
  b.i(3).i(3).i(0).z(3).z(130).z(140).z(150);
  b.d(0.5).d(0.5).d(-1).d(0.5).d(0.25).d(2.8).d(0.75).d(0.75).d(2.8);
  b.text("\n$EndNodes\n");
  b.text("$Elements\n").z(3).z(4).z(1).z(4);
  b.i(3).i(1).i(5).z(1).z(1);
  for (std::uint64_t t : {10, 20, 30, 40, 50, 60, 70, 80}) b.z(t);
  b.i(3).i(2).i(6).z(2);
  b.z(2);
  for (std::uint64_t t : {50, 60, 80, 90, 100, 120}) b.z(t);
  b.z(3);
  for (std::uint64_t t : {60, 70, 80, 100, 110, 120}) b.z(t);
  b.i(3).i(3).i(7).z(1).z(4);
  for (std::uint64_t t : {10, 40, 30, 20, 130}) b.z(t);
  b.text("\n$EndElements\n");
  return b.s;
}

// tests/io/data/two_tets.msh in binary MSH 2.2: element groups of one type and tag count.
std::string two_tets_binary(bool swap) {
  Bytes b;
  b.swap = swap;
  b.text("$MeshFormat\n2.2 1 8\n").i(1).text("\n$EndMeshFormat\n");
  b.text("$PhysicalNames\n2\n2 5 \"skin\"\n3 7 \"body\"\n$EndPhysicalNames\n");
  b.text("$Nodes\n5\n");
  const double p[5][3] = {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}, {0, 0, 1}, {1, 1, 1}};
  for (int n = 0; n < 5; ++n) b.i(n + 1).d(p[n][0]).d(p[n][1]).d(p[n][2]);
  b.text("\n$EndNodes\n$Elements\n4\n");
  b.i(15).i(1).i(2).i(1).i(0).i(1).i(1);                    // a point
  b.i(2).i(1).i(2).i(2).i(5).i(3).i(1).i(2).i(3);           // a triangle
  b.i(4).i(2).i(2).i(3).i(7).i(1).i(1).i(2).i(3).i(4);      // two tetrahedra in one group
  b.i(4).i(7).i(1).i(2).i(3).i(4).i(5);
  b.text("\n$EndElements\n");
  return b.s;
}

void check_same(const MeshFile& got, const MeshFile& want) {
  CHECK(got.version == want.version);
  CHECK(got.mesh.points == want.mesh.points);
  CHECK(got.mesh.types == want.mesh.types);
  CHECK(got.mesh.offsets == want.mesh.offsets);
  CHECK(got.mesh.conn == want.mesh.conn);
  CHECK(got.mesh.tags == want.mesh.tags);
  CHECK(got.file_elements == want.file_elements);
  CHECK(got.skipped_points == want.skipped_points);
  REQUIRE(got.tag_names.size() == want.tag_names.size());
  for (std::size_t k = 0; k < got.tag_names.size(); ++k) CHECK(got.tag_names[k].name == want.tag_names[k].name);
}

MeshFile parse(const std::string& bytes) { return parse_gmsh(bytes, "bad.msh"); }

}  // namespace

TEST_CASE("binary gmsh 4.1 and 2.2, in either byte order, read as their ASCII files") {
  for (const bool swap : {false, true}) {
    CAPTURE(swap);
    check_same(parse_gmsh(mixed41_binary(swap), "mixed41b.msh"), read_gmsh(test::data("mixed41.msh")));
    check_same(parse_gmsh(two_tets_binary(swap), "two_tets_b.msh"), read_gmsh(test::data("two_tets.msh")));
  }
}

TEST_CASE("binary gmsh bad input: each problem named with the file") {
  SUBCASE("the byte-order integer missing or wrong") {
    CHECK(message_of<ParseError>([] { parse("$MeshFormat\n4.1 1 8\n"); }).find("byte order") != std::string::npos);
    Bytes b;
    b.text("$MeshFormat\n4.1 1 8\n").i(7).text("\n$EndMeshFormat\n");
    CHECK(message_of<SemanticError>([&] { parse(b.s); }).find("byte-order check reads 7") != std::string::npos);
  }
  SUBCASE("a data size other than 4 or 8") {
    CHECK(message_of<UnsupportedError>([] { parse("$MeshFormat\n4.1 1 2\n"); }).find("data size 2") != std::string::npos);
  }
  SUBCASE("truncated node data: the byte offset where it ends") {
    const std::string whole = mixed41_binary(false);
    const std::string cut = whole.substr(0, whole.find("$EndNodes") - 40);
    const auto m = message_of<ParseError>([&] { parse(cut); });
    CHECK(m.find("bad.msh:") == 0);
    CHECK(m.find("bytes of binary data at byte offset") != std::string::npos);
  }
  SUBCASE("an element refers to a node that does not exist") {
    std::string bytes = two_tets_binary(false);
    // the last tetrahedron's last node, 5, made 9
    const std::size_t end = bytes.find("\n$EndElements");
    const std::int32_t nine = 9;
    std::memcpy(bytes.data() + end - 4, &nine, 4);
    CHECK(message_of<SemanticError>([&] { parse(bytes); }).find("element 4 refers to node 9") != std::string::npos);
  }
  SUBCASE("an MSH 2.2 element group larger than the declared count") {
    Bytes b;
    b.text("$MeshFormat\n2.2 1 8\n").i(1).text("\n$EndMeshFormat\n$Nodes\n1\n").i(1).d(0).d(0).d(0);
    b.text("\n$EndNodes\n$Elements\n1\n").i(15).i(2).i(0).i(1).i(1).i(2).i(1);
    CHECK(message_of<SemanticError>([&] { parse(b.s); }).find("a binary element group of 2 elements") != std::string::npos);
  }
}

}  // namespace test_read_gmsh_binary
