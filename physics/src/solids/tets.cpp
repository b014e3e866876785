#include "sewn/physics/solids/tets.hpp"

#include "sewn/physics/errors.hpp"

namespace sewn::physics::solids {

Index Tets::add(const std::array<Index, 4>& nodes, const TetPositions& X, double young, double poisson) {
  try {
    const Lame m = lame_from_young(young, poisson);
    const TetRest r = tet_rest(X);
    const Index e = push_element(nodes);
    rest_.push_back(r);
    lame_.push_back(m);
    return e;
  } catch (const InputError& err) {
    throw InputError("tets element " + std::to_string(size()) + ": " + err.what());
  }
}

}  // namespace sewn::physics::solids
