// CGAL's side of the quad-grid cases (see cgal_lcc.hpp).
#include "cgal_lcc.hpp"

namespace sewn::bench::cmap::cgal {
namespace {

void register_lcc2() {
  for (std::uint32_t n : quad_sizes(scale())) register_grid<2>(n);
}

const Registration lcc2_registration(&register_lcc2);

}  // namespace
}  // namespace sewn::bench::cmap::cgal
