#include <doctest/doctest.h>

#include <cmath>
#include <cstdlib>
#include <cstring>
#include <limits>
#include <random>

#include "io_test_util.hpp"
#include "sewn/io/write.hpp"

namespace test_write {

using namespace sewn;
using namespace sewn::io;
using sewn::io::test::message_of;

TEST_CASE("format_double: shortest text that reads back to the same double") {
  std::mt19937_64 rng(7);
  for (int i = 0; i < 2000; ++i) {
    double x = 0;
    do {
      const std::uint64_t bits = rng();
      std::memcpy(&x, &bits, sizeof x);
    } while (!std::isfinite(x));
    CHECK(std::strtod(format_double(x).c_str(), nullptr) == x);
  }
  CHECK(format_double(0.1) == "0.1");
  CHECK(format_double(3) == "3");
  CHECK(format_double(std::numeric_limits<double>::quiet_NaN()) == "nan");
  CHECK(format_double(-std::numeric_limits<double>::infinity()) == "-inf");
}

TEST_CASE("csv: header once, quoted when needed, one flushed row per call") {
  test::TempDir dir("csv");
  const auto p = dir.path() / "energy.csv";
  CsvWriter csv(p, {"step", "kinetic energy", "a,b", "say \"hi\""});
  CHECK(test::read_text(p) == "step,kinetic energy,\"a,b\",\"say \"\"hi\"\"\"\n");
  csv.row({0, 0.1, 1e-300, -2.5});
  // flushed: readable while the writer is still open
  CHECK(test::read_text(p) == "step,kinetic energy,\"a,b\",\"say \"\"hi\"\"\"\n0,0.1,1e-300,-2.5\n");
  csv.row({1, std::numeric_limits<double>::quiet_NaN(), 2, 3});
  CHECK(test::read_text(p).ends_with("1,nan,2,3\n"));
  CHECK_THROWS_AS(csv.row({1, 2}), std::invalid_argument);
  message_of<FileError>([&] { CsvWriter(dir.path() / "no" / "such" / "dir.csv", {"a"}); });
}

TEST_CASE("pvd: complete after every frame, files relative to the index") {
  test::TempDir dir("pvd");
  std::filesystem::create_directories(dir.path() / "frames");
  PvdWriter pvd(dir.path() / "run.pvd");
  const std::string empty = test::read_text(dir.path() / "run.pvd");
  CHECK(empty.find("<Collection>") != std::string::npos);
  CHECK(empty.find("</VTKFile>") != std::string::npos);
  pvd.add(0.0, dir.path() / "frames" / "f0.vtu");
  pvd.add(0.25, dir.path() / "frames" / "f&1.vtu");
  const std::string two = test::read_text(dir.path() / "run.pvd");
  CHECK(two.find("<DataSet timestep=\"0\" group=\"\" part=\"0\" file=\"frames/f0.vtu\"/>") != std::string::npos);
  CHECK(two.find("timestep=\"0.25\" group=\"\" part=\"0\" file=\"frames/f&amp;1.vtu\"/>") != std::string::npos);
  CHECK(two.ends_with("</VTKFile>\n"));
  CHECK_FALSE(std::filesystem::exists(dir.path() / "run.pvd.part"));
  CHECK_THROWS_AS(pvd.add(std::numeric_limits<double>::quiet_NaN(), "x.vtu"), std::invalid_argument);
}

TEST_CASE("vtu: base64 blocks are a 64-bit byte count followed by the data") {
  test::TempDir dir("vtu");
  IndexedMesh m;
  m.points = {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}, {0, 0, 1}};
  m.add_cell(CellType::tetrahedron, {0, 1, 2, 3});
  write_vtu(dir.path() / "t.vtu", m);
  const std::string s = test::read_text(dir.path() / "t.vtu");
  // types = {10}: bytes 01 00 00 00 00 00 00 00 0a
  CHECK(s.find("Name=\"types\" format=\"binary\">\n          AQAAAAAAAAAK\n") != std::string::npos);
  CHECK(s.find("header_type=\"UInt64\"") != std::string::npos);
  write_vtu(dir.path() / "a.vtu", m, {}, {}, {VtuEncoding::ascii});
  const std::string a = test::read_text(dir.path() / "a.vtu");
  CHECK(a.find("Name=\"offsets\" format=\"ascii\">\n          4\n") != std::string::npos);
  CHECK(a.find("Name=\"Points\" NumberOfComponents=\"3\" format=\"ascii\">\n          0 0 0 1 0 0 0 1 0 0 0 1\n") !=
        std::string::npos);
}

TEST_CASE("vtu: a segment chain flagged a poly-line is one VTK cell of type 4; misuse is refused") {
  test::TempDir dir("vtu_poly");
  const std::vector<Point3> pts = {{0, 0, 0}, {1, 0, 0}, {2, 0, 0}, {2, 1, 0}, {0, 1, 0}};
  const std::vector<CellType> types = {CellType::segment, CellType::segment};
  const std::vector<std::uint32_t> offsets = {0, 4, 6}, conn = {0, 1, 2, 3, 3, 4};
  const std::vector<std::uint8_t> poly = {1, 0};
  write_vtu(dir.path() / "p.vtu", pts, CellsView{types, offsets, conn, poly}, {}, {}, {VtuEncoding::ascii});
  const std::string a = test::read_text(dir.path() / "p.vtu");
  CHECK(a.find("Name=\"types\" format=\"ascii\">\n          4 3\n") != std::string::npos);
  CHECK(a.find("Name=\"offsets\" format=\"ascii\">\n          4 6\n") != std::string::npos);
  const std::vector<std::uint8_t> short_flags = {1};
  CHECK_THROWS_WITH_AS(write_vtu(dir.path() / "x.vtu", pts, CellsView{types, offsets, conn, short_flags}),
                       doctest::Contains("1 poly-line flags for 2 cells"), std::invalid_argument);
  const std::vector<CellType> tri = {CellType::triangle};
  const std::vector<std::uint32_t> tri_offsets = {0, 3}, tri_conn = {0, 1, 4};
  const std::vector<std::uint8_t> one = {1};
  CHECK_THROWS_WITH_AS(write_vtu(dir.path() / "x.vtu", pts, CellsView{tri, tri_offsets, tri_conn, one}),
                       doctest::Contains("cell 0 is flagged a poly-line"), std::invalid_argument);
}

TEST_CASE("vtu: caller mistakes are std::invalid_argument naming the array; I/O failures FileError") {
  test::TempDir dir("vtu_bad");
  const IndexedMesh m = hex_grid(1, 1, 1);
  const std::vector<double> short_array(3);
  const DataArray pd[] = {DataArray::scalars("pressure", short_array)};
  try {
    write_vtu(dir.path() / "x.vtu", m, pd);
    FAIL("no exception");
  } catch (const std::invalid_argument& e) {
    CHECK(std::string(e.what()).find("'pressure' has 3 tuples but there are 8 points") != std::string::npos);
  }
  const std::vector<double> odd(7);
  const DataArray pd2[] = {{"pairs", std::span<const double>(odd), 2}};
  CHECK_THROWS_AS(write_vtu(dir.path() / "x.vtu", m, pd2), std::invalid_argument);
  const std::vector<Point3> few(3);
  CHECK_THROWS_AS(write_vtu(dir.path() / "x.vtu", few, CellsView::of(m)), std::invalid_argument);
  message_of<FileError>([&] { write_vtu(dir.path() / "missing" / "x.vtu", m); });
}

}  // namespace test_write
