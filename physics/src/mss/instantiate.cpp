// The class-level instantiations that mss_model.hpp's `extern template` promises: they emit the
// members defined in the header (nodes(), system(), ...), which a consumer built without
// inlining (-O0) links against. The members defined in build.cpp, queries.cpp and
// topology_changes.cpp are instantiated member by member there; this file sees none of their
// definitions, so nothing is instantiated twice. It is kept out of unity groups because a
// class-level and a member-level instantiation of the same member in one translation unit is an
// error for clang.
#include "sewn/physics/mss_model.hpp"

namespace sewn::physics {

template class MssModel<2>;
template class MssModel<3>;

}  // namespace sewn::physics
