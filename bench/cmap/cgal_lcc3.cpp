// CGAL's side of the hexahedral cases (see cgal_lcc.hpp).
#include "cgal_lcc.hpp"

namespace sewn::bench::cmap::cgal {
namespace {

void register_lcc3() {
  for (std::uint32_t n : hex_sizes(scale())) register_grid<3>(n);
}

const Registration lcc3_registration(&register_lcc3);

}  // namespace
}  // namespace sewn::bench::cmap::cgal
