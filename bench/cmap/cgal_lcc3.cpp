// CGAL's side of the hexahedral cases (see cgal_lcc.hpp).
#include "cgal_lcc.hpp"

namespace sewn::bench::cmap::cgal {
namespace {

void register_all() {
  for (std::uint32_t n : hex_sizes(scale())) register_grid<3>(n);
}

const Registration registration(&register_all);

}  // namespace
}  // namespace sewn::bench::cmap::cgal
