// Uses the installed library as an outside project would: a map, the mass-spring model on it,
// a cut, an implicit step, and the io module (which brings cairo along).
#include <cstdio>

#include "sewn/cmap/build.hpp"
#include "sewn/connect/point.hpp"
#include "sewn/io/geometry.hpp"
#include "sewn/io/render.hpp"
#include "sewn/physics/integrators.hpp"
#include "sewn/refine/cut.hpp"

int main() {
  const auto mesh = sewn::hex_grid(3, 2, 2, {{0.1, 0.1, 0.1}, {}});
  sewn::io::check_mesh_geometry(mesh, "consumer beam");
  (void)sewn::io::boundary_faces(sewn::io::CellsView::of(mesh));
  sewn::physics::MssModel<3> beam(mesh, {{1e6, 0.3, 1000}}, {});
  const auto faces = sewn::refine::facets_across_plane(beam, {0.1, 0, 0}, {1, 0, 0});  // the faces at x = 0.1
  const auto cut = sewn::refine::cut(beam, faces);
  sewn::physics::LinearlyImplicitEuler euler;
  const auto step = euler.step(beam.system(), 1e-3);
  const auto report = beam.map().validate();
  const auto n = beam.map().count_all();
  std::printf("consumer: %u vertices, %u volumes, %u components after cutting %u faces; CG %d iterations; %s\n", n[0],
              n[3], beam.map().count_components(), cut.facets, step.cg_iterations, report.ok() ? "valid" : report.str().c_str());
  return report.ok() && n[3] == 12 && cut.facets == 4 && beam.map().count_components() == 2 && step.cg_converged ? 0 : 1;
}
