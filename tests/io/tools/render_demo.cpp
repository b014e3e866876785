// Renders the pictures used to judge the renderer by eye: a hexahedral beam, the same beam bent
// and coloured by displacement, a tetrahedral block in perspective, a triangulated sheet, and a
// wireframe. Usage: io_render_demo OUTPUT_DIR
#include <cmath>
#include <cstdio>
#include <exception>
#include <filesystem>

#include "sewn/io/render.hpp"

using namespace sewn;

int main(int argc, char** argv) {
  if (argc != 2) {
    std::fprintf(stderr, "usage: %s OUTPUT_DIR\n", argv[0]);
    return 2;
  }
  try {
    const std::filesystem::path dir = argv[1];
    std::filesystem::create_directories(dir);
    const IndexedMesh beam = hex_grid(20, 3, 3, GridSpec{{0.5, 0.5, 0.5}, {0, 0, 0}});
    std::vector<double> x_coord(beam.num_points());
    for (std::size_t i = 0; i < x_coord.size(); ++i) x_coord[i] = beam.points[i][0];
    io::RenderOptions o;
    o.title = "hexahedral beam 20 x 3 x 3, coloured by x";
    o.scalar_name = "x [m]";
    io::render_png(dir / "beam.png", beam.points, io::CellsView::of(beam), x_coord, o);

    // cantilever-like bend: rotate each cross-section about the y axis
    std::vector<Point3> bent = beam.points;
    std::vector<double> disp(bent.size());
    const double L = 10.0, R = 8.0;
    for (std::size_t i = 0; i < bent.size(); ++i) {
      const auto& p = beam.points[i];
      const double phi = p[0] / R, r = R - (p[2] - 0.75);
      bent[i] = {r * std::sin(phi), p[1], R + 0.75 - r * std::cos(phi)};
      disp[i] = std::hypot(bent[i][0] - p[0], bent[i][2] - p[2]);
    }
    o.title = "bent beam, t = 1.00 s (L = " + std::to_string(static_cast<int>(L)) + " m)";
    o.scalar_name = "|u| [m]";
    io::render_png(dir / "beam_bent.png", bent, io::CellsView::of(beam), disp, o);

    o.mode = io::RenderMode::wireframe;
    o.title = "bent beam, wireframe";
    io::render_png(dir / "beam_bent_wire.png", bent, io::CellsView::of(beam), disp, o);

    const IndexedMesh block = tet_grid(6, 4, 3, TetSplit::five);
    std::vector<double> height(block.num_points());
    for (std::size_t i = 0; i < height.size(); ++i) height[i] = block.points[i][2];
    io::RenderOptions p;
    p.title = "tetrahedral block, perspective, no edges";
    p.scalar_name = "z";
    p.edges = false;
    p.camera.projection = io::Camera::Projection::perspective;
    p.camera.azimuth_deg = -40;
    io::render_png(dir / "tets_perspective.png", block.points, io::CellsView::of(block), height, p);

    const IndexedMesh sheet = tri_grid(16, 10, GridSpec{{0.25, 0.25, 1}, {0, 0, 0}});
    std::vector<Point3> wavy = sheet.points;
    std::vector<double> w(wavy.size());
    for (std::size_t i = 0; i < wavy.size(); ++i) {
      wavy[i][2] = 0.4 * std::sin(wavy[i][0]) * std::cos(wavy[i][1]);
      w[i] = wavy[i][2];
    }
    io::RenderOptions s;
    s.title = "triangulated sheet";
    s.scalar_name = "w";
    io::render_png(dir / "sheet.png", wavy, io::CellsView::of(sheet), w, s);
    io::RenderOptions g;
    g.title = "flat quad grid, no scalar";
    const IndexedMesh quads = quad_grid(8, 5);
    io::render_png(dir / "quads_plain.png", quads.points, io::CellsView::of(quads), {}, g);
  } catch (const std::exception& e) {
    std::fprintf(stderr, "render_demo: %s\n", e.what());
    return 1;
  }
  return 0;
}
