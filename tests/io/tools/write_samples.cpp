// Writes VTU frames, a PVD series and a CSV with sewn::io into the folder given as argv[1], for
// vtk_check.py to read back with VTK's own readers. The arrays are simple functions of the
// written coordinates and indices, so the checker can recompute them from what VTK reads.
#include <cmath>
#include <cstdio>
#include <exception>
#include <filesystem>

#include "sewn/io/write.hpp"

using namespace sewn;

int main(int argc, char** argv) {
  if (argc != 2) {
    std::fprintf(stderr, "usage: %s OUTPUT_DIR\n", argv[0]);
    return 2;
  }
  try {
    const std::filesystem::path dir = argv[1];
    std::filesystem::create_directories(dir / "frames");
    const IndexedMesh beam = hex_grid(6, 2, 2, GridSpec{{0.5, 0.5, 0.5}, {0, 0, 0}});
    io::PvdWriter series(dir / "beam.pvd");
    for (int k = 0; k < 3; ++k) {
      std::vector<Point3> x = beam.points;
      for (auto& p : x) p[2] += 0.1 * k * p[0] * p[0];  // bend
      std::vector<double> f(x.size());
      std::vector<Point3> vel(x.size());
      std::vector<std::uint8_t> fixed(x.size());
      std::vector<std::int32_t> id(x.size());
      for (std::size_t i = 0; i < x.size(); ++i) {
        f[i] = x[i][0] + 2 * x[i][1] + 3 * x[i][2];
        vel[i] = {x[i][1], -x[i][0], static_cast<double>(k)};
        fixed[i] = x[i][0] == 0.0 ? 1 : 0;
        id[i] = static_cast<std::int32_t>(i);
      }
      std::vector<std::int32_t> material(beam.num_cells());
      std::vector<double> level(beam.num_cells());
      for (std::uint32_t c = 0; c < beam.num_cells(); ++c) {
        material[c] = static_cast<std::int32_t>(c % 3);
        level[c] = 0.25 * c;
      }
      const io::DataArray pd[] = {io::DataArray::scalars("f", f), io::DataArray::vectors("velocity", vel),
                                  io::DataArray::flags("fixed", fixed), io::DataArray::ints("id", id)};
      const io::DataArray cd[] = {io::DataArray::ints("material", material), io::DataArray::scalars("level", level)};
      const auto file = dir / "frames" / ("beam_" + std::to_string(k) + ".vtu");
      io::write_vtu(file, x, io::CellsView::of(beam), pd, cd,
                    {k == 1 ? io::VtuEncoding::ascii : io::VtuEncoding::base64});
      series.add(0.5 * k, file);
    }
    // one cell of every type, positively oriented in VTK's convention
    IndexedMesh mixed;
    mixed.points = {{0, 0, 0}, {1, 0, 0}, {1, 1, 0},   {0, 1, 0},     {0, 0, 1}, {1, 0, 1}, {1, 1, 1},
                    {0, 1, 1}, {0, 0, 2}, {1, 0, 2},   {0, 1, 2},     {0.5, 0.5, -1}, {2, 0, 0}, {2, 1, 0}};
    mixed.add_cell(CellType::hexahedron, {0, 1, 2, 3, 4, 5, 6, 7});
    mixed.add_cell(CellType::prism, {4, 7, 5, 8, 10, 9});
    mixed.add_cell(CellType::pyramid, {0, 3, 2, 1, 11});
    mixed.add_cell(CellType::tetrahedron, {1, 12, 2, 5});
    mixed.add_cell(CellType::quad, {1, 12, 13, 2});
    mixed.add_cell(CellType::triangle, {2, 13, 6});
    mixed.add_cell(CellType::segment, {12, 13});
    io::write_vtu(dir / "mixed.vtu", mixed);
    io::write_vtu(dir / "mixed_ascii.vtu", mixed, {}, {}, {io::VtuEncoding::ascii});
  } catch (const std::exception& e) {
    std::fprintf(stderr, "write_samples: %s\n", e.what());
    return 1;
  }
  return 0;
}
