// Outputs that are never half-written (issue 19): past a file size limit, as on a full disk,
// every writer fails with FileError naming the file, leaves no temporary behind, and the file
// keeps its last complete content. And duplicate cells, which `sewn check` and `sewn run` both
// refuse through find_geometry_issues.
#include <doctest/doctest.h>

#include <sys/resource.h>

#include <csignal>
#include <sstream>

#include "io_test_util.hpp"
#include "sewn/io/geometry.hpp"
#include "sewn/io/render.hpp"
#include "sewn/io/write.hpp"

namespace test_write_robustness {

using namespace sewn;
using namespace sewn::io;
using sewn::io::test::message_of;

namespace {

// Lowers this process's file size limit (as `ulimit -f` does) for the object's lifetime, with
// SIGXFSZ ignored so that a write past it fails with EFBIG instead of killing the process.
class FileSizeLimit {
 public:
  explicit FileSizeLimit(rlim_t bytes) {
    ::getrlimit(RLIMIT_FSIZE, &old_);
    old_handler_ = std::signal(SIGXFSZ, SIG_IGN);
    rlimit lower = old_;
    lower.rlim_cur = bytes;
    REQUIRE(::setrlimit(RLIMIT_FSIZE, &lower) == 0);
  }
  ~FileSizeLimit() {
    ::setrlimit(RLIMIT_FSIZE, &old_);
    std::signal(SIGXFSZ, old_handler_);
  }
  FileSizeLimit(const FileSizeLimit&) = delete;
  FileSizeLimit& operator=(const FileSizeLimit&) = delete;

 private:
  rlimit old_{};
  void (*old_handler_)(int) = SIG_DFL;
};

bool has_part_file(const std::filesystem::path& dir) {
  for (const auto& e : std::filesystem::directory_iterator(dir))
    if (e.path().extension() == ".part") return true;
  return false;
}

}  // namespace

TEST_CASE("csv: past the size limit the write fails naming the file, which keeps only complete rows") {
  test::TempDir dir("csv_limit");
  const auto p = dir.path() / "frames.csv";
  std::size_t rows = 0;
  std::string message;
  {
    FileSizeLimit limit(4096);
    CsvWriter csv(p, {"a", "b", "c"});
    try {
      for (; rows < 10000; ++rows) csv.row({static_cast<double>(rows), 0.125, -1e-300});
    } catch (const FileError& e) {
      message = e.what();
    }
  }
  CHECK(rows < 10000);  // the limit was reached
  CHECK(message.find(p.string()) != std::string::npos);
  CHECK(message.find("File too large") != std::string::npos);
  CHECK_FALSE(has_part_file(dir.path()));
  const std::string text = test::read_text(p);
  REQUIRE(text.size() <= 4096);
  CHECK(text.ends_with("\n"));
  std::istringstream lines(text);
  std::string line;
  std::getline(lines, line);
  CHECK(line == "a,b,c");
  std::size_t k = 0;
  while (std::getline(lines, line)) CHECK(line == std::to_string(k++) + ",0.125,-1e-300");
  CHECK(k > 0);
  CHECK(k <= rows);
}

TEST_CASE("csv: rows reach the file at once while it is small, at doubling sizes after, all of them at flush") {
  test::TempDir dir("csv_doubling");
  const auto p = dir.path() / "big.csv";
  // rows of 64 values of 8 bytes each ("10000ii,"): 512 bytes a row
  CsvWriter csv(p, std::vector<std::string>(64, "v"));
  std::size_t behind = 0;  // most rows ever missing from the file
  std::size_t expected = 128;  // the header: 64 times "v,"
  for (int i = 1; i <= 2000; ++i) {
    csv.row(std::vector<double>(64, 1e6 + i));
    expected += 512;
    const std::size_t on_disk = std::filesystem::file_size(p);
    if (expected <= 64 * 1024) CHECK(on_disk == expected);
    CHECK(2 * on_disk >= expected);  // never more than half behind
    behind = std::max(behind, (expected - on_disk) / 512);
  }
  CHECK(behind > 0);  // past 64 KiB the file does lag (the rewrite cost stays linear)
  csv.flush();
  CHECK(std::filesystem::file_size(p) == expected);
}

TEST_CASE("vtu, pvd and png: a failed write keeps the previous file whole and leaves no temporary") {
  test::TempDir dir("vtu_limit");
  const IndexedMesh small = hex_grid(1, 1, 1), big = hex_grid(20, 20, 20);
  const auto vtu = dir.path() / "frame.vtu";
  write_vtu(vtu, small);
  const std::string before = test::read_text(vtu);
  PvdWriter pvd(dir.path() / "run.pvd");
  pvd.add(0, vtu);
  const std::string pvd_before = test::read_text(dir.path() / "run.pvd");
  const auto png = dir.path() / "last.png";
  render_png(png, small.points, CellsView::of(small));
  const std::string png_before = test::read_text(png);
  {
    FileSizeLimit limit(before.size() + 100);
    const std::string m = message_of<FileError>([&] { write_vtu(vtu, big); });
    CHECK(m.find(vtu.string()) != std::string::npos);
    // the series grows past the limit: the index stays the last complete one
    CHECK_THROWS_AS(
        [&] {
          for (int i = 1; i < 1000; ++i) pvd.add(i, dir.path() / ("frame_with_a_long_name_" + std::to_string(i) + ".vtu"));
        }(),
        FileError);
    const std::string mp = message_of<FileError>([&] { render_png(png, big.points, CellsView::of(big)); });
    CHECK(mp.find(png.string()) != std::string::npos);
  }
  CHECK(test::read_text(vtu) == before);
  CHECK(test::read_text(png) == png_before);
  const std::string series = test::read_text(dir.path() / "run.pvd");
  CHECK(series.size() > pvd_before.size());  // frames added before the limit are listed
  CHECK(series.ends_with("</VTKFile>\n"));
  CHECK_FALSE(has_part_file(dir.path()));
}

TEST_CASE("duplicate cells, in any vertex order, are a geometry problem") {
  IndexedMesh m;
  m.points = {{0, 0, 0}, {1, 0, 0}, {1, 1, 0}, {0, 1, 0}};
  m.add_cell(CellType::quad, {0, 1, 2, 3});
  m.add_cell(CellType::triangle, {0, 1, 2});
  CHECK(find_geometry_issues(m).empty());  // a triangle on three of the quad's points is no repeat
  m.add_cell(CellType::quad, {2, 3, 0, 1});
  m.add_cell(CellType::segment, {3, 0});
  m.add_cell(CellType::segment, {0, 3});
  const auto issues = find_geometry_issues(m, "m.msh");
  REQUIRE(issues.size() == 2);
  CHECK(issues[0].kind == GeometryProblem::duplicate);
  CHECK(issues[0].cell == 2);
  CHECK(issues[0].message.find("m.msh: cell 2 (quad) repeats cell 0") == 0);
  CHECK(issues[1].cell == 4);
  message_of<DuplicateCellError>([&] { check_mesh_geometry(m, "m.msh"); });
  // a third copy names the first one, not the second
  m.add_cell(CellType::quad, {1, 2, 3, 0});
  const auto three = find_geometry_issues(m, "m.msh");
  REQUIRE(three.size() == 3);
  CHECK(three[2].message.find("m.msh: cell 5 (quad) repeats cell 0 ") == 0);
}

}  // namespace test_write_robustness
