#include <doctest/doctest.h>

#include <cairo.h>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <limits>

#include "io_test_util.hpp"
#include "sewn/io/render.hpp"

namespace test_render {

using namespace sewn;
using namespace sewn::io;
using sewn::io::test::message_of;

namespace {

double luminance(const std::array<double, 3>& c) { return 0.2126 * c[0] + 0.7152 * c[1] + 0.0722 * c[2]; }

// A PNG read back as RGB rows.
struct Picture {
  int width = 0, height = 0;
  std::vector<std::array<double, 3>> px;
  explicit Picture(const std::filesystem::path& p) {
    cairo_surface_t* s = cairo_image_surface_create_from_png(p.string().c_str());
    REQUIRE(cairo_surface_status(s) == CAIRO_STATUS_SUCCESS);
    width = cairo_image_surface_get_width(s);
    height = cairo_image_surface_get_height(s);
    const int stride = cairo_image_surface_get_stride(s);
    const unsigned char* d = cairo_image_surface_get_data(s);
    for (int y = 0; y < height; ++y)
      for (int x = 0; x < width; ++x) {
        std::uint32_t v = 0;
        std::memcpy(&v, d + y * stride + 4 * x, 4);
        px.push_back({((v >> 16) & 255) / 255.0, ((v >> 8) & 255) / 255.0, (v & 255) / 255.0});
      }
    cairo_surface_destroy(s);
  }
  [[nodiscard]] const std::array<double, 3>& at(int x, int y) const { return px[static_cast<std::size_t>(y * width + x)]; }
  [[nodiscard]] std::size_t non_white() const {
    return static_cast<std::size_t>(std::count_if(px.begin(), px.end(), [](const auto& c) { return c[0] + c[1] + c[2] < 2.9; }));
  }
};

double dist(const std::array<double, 3>& a, const std::array<double, 3>& b) {
  return std::max({std::abs(a[0] - b[0]), std::abs(a[1] - b[1]), std::abs(a[2] - b[2])});
}

}  // namespace

TEST_CASE("viridis: the published end colours, lightness rising monotonically") {
  CHECK(dist(viridis(0), {68 / 255.0, 1 / 255.0, 84 / 255.0}) < 1e-12);
  CHECK(dist(viridis(1), {253 / 255.0, 231 / 255.0, 37 / 255.0}) < 1e-12);
  CHECK(dist(viridis(-3), viridis(0)) == 0);
  CHECK(dist(viridis(std::numeric_limits<double>::quiet_NaN()), viridis(0)) == 0);
  for (int i = 1; i <= 100; ++i) CHECK(luminance(viridis(i / 100.0)) > luminance(viridis((i - 1) / 100.0)));
}

TEST_CASE("boundary faces: shared faces are left out, the rest point outwards") {
  const IndexedMesh hexes = hex_grid(3, 2, 1);
  const auto faces = boundary_faces(CellsView::of(hexes));
  CHECK(faces.size() == 2 * (3 * 2 + 3 * 1 + 2 * 1));
  const Point3 centre{1.5, 1.0, 0.5};
  for (const auto& f : faces) {
    REQUIRE(f.size == 4);
    const auto& a = hexes.points[f.v[0]];
    const auto& b = hexes.points[f.v[1]];
    const auto& c = hexes.points[f.v[2]];
    const Point3 n{(b[1] - a[1]) * (c[2] - a[2]) - (b[2] - a[2]) * (c[1] - a[1]),
                   (b[2] - a[2]) * (c[0] - a[0]) - (b[0] - a[0]) * (c[2] - a[2]),
                   (b[0] - a[0]) * (c[1] - a[1]) - (b[1] - a[1]) * (c[0] - a[0])};
    CHECK(n[0] * (a[0] - centre[0]) + n[1] * (a[1] - centre[1]) + n[2] * (a[2] - centre[2]) > 0);
  }
  CHECK(boundary_faces(CellsView::of(tet_grid(1, 1, 1, TetSplit::kuhn6))).size() == 12);
  // 2D cells are all drawn
  CHECK(boundary_faces(CellsView::of(tri_grid(2, 2))).size() == 8);
}

TEST_CASE("render_png: a picture of the given size with the object, its colour bar and a white background") {
  test::TempDir dir("render");
  const IndexedMesh beam = hex_grid(8, 2, 2);
  std::vector<double> s(beam.num_points());
  for (std::size_t i = 0; i < s.size(); ++i) s[i] = beam.points[i][0];
  RenderOptions o;
  o.width = 640;
  o.height = 400;
  o.title = std::string("test");
  o.scalar_name = std::string("x");
  render_png(dir.path() / "shaded.png", beam.points, CellsView::of(beam), s, o);
  const Picture shaded(dir.path() / "shaded.png");
  CHECK(shaded.width == 640);
  CHECK(shaded.height == 400);
  CHECK(dist(shaded.at(639, 399), {1, 1, 1}) < 1e-9);
  CHECK(dist(shaded.at(320, 220), {1, 1, 1}) > 0.1);  // the beam is in the middle
  // the colour bar shows both ends of the map, the high end above the low end
  auto find = [&](const std::array<double, 3>& c) {
    std::pair<int, int> best{-1, -1};
    double bd = 1;
    for (int y = 0; y < shaded.height; ++y)
      for (int x = 520; x < shaded.width; ++x)
        if (dist(shaded.at(x, y), c) < bd) bd = dist(shaded.at(x, y), c), best = {x, y};
    CHECK(bd < 0.02);
    return best;
  };
  CHECK(find(viridis(1)).second < find(viridis(0)).second);
  // wireframe draws lines only: far fewer coloured pixels
  o.mode = RenderMode::wireframe;
  render_png(dir.path() / "wire.png", beam.points, CellsView::of(beam), s, o);
  const Picture wire(dir.path() / "wire.png");
  CHECK(wire.non_white() < shaded.non_white() / 2);
  CHECK_FALSE(std::filesystem::exists(dir.path() / "wire.png.part"));
}

TEST_CASE("render_png: bad arguments and unwritable paths; non-finite points are left out, not fatal") {
  test::TempDir dir("render_bad");
  IndexedMesh m = hex_grid(2, 1, 1);
  const std::vector<double> wrong(3);
  CHECK_THROWS_AS(render_png(dir.path() / "a.png", m.points, CellsView::of(m), wrong), std::invalid_argument);
  RenderOptions tiny;
  tiny.width = 10;
  CHECK_THROWS_AS(render_png(dir.path() / "a.png", m.points, CellsView::of(m), {}, tiny), std::invalid_argument);
  message_of<FileError>([&] { render_png(dir.path() / "no" / "a.png", m.points, CellsView::of(m)); });
  m.points[0][0] = std::numeric_limits<double>::quiet_NaN();
  std::vector<double> s(m.num_points(), 1.0);
  s[3] = std::numeric_limits<double>::infinity();
  RenderOptions p;
  p.camera.projection = Camera::Projection::perspective;
  CHECK_NOTHROW(render_png(dir.path() / "nan.png", m.points, CellsView::of(m), s, p));
  CHECK(Picture(dir.path() / "nan.png").non_white() > 1000);
  // nothing drawable at all still gives a (blank) picture
  IndexedMesh none;
  CHECK_NOTHROW(render_png(dir.path() / "empty.png", none.points, CellsView::of(none)));
}

}  // namespace test_render
