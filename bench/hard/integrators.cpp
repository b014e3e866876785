// The cantilever's speed against error (bench/mss/cantilever.cpp, the mss suite's family) extended
// with the implicit midpoint integrator and the volume term, for issue 17's report. The cases and
// their names are in bench/mss/cantilever.hpp; bench/hard/derive makes the table.

#include "cantilever.hpp"
#include "sewn_bench.hpp"

namespace sewn::bench::mss {

namespace {

void register_integrators() { register_cantilever_integrators(scale()); }

const Registration integrators_registration(&register_integrators);

}  // namespace

}  // namespace sewn::bench::mss
