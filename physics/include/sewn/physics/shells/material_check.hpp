#pragma once
// The one check of a shell material's constants, shared by the membrane, hinge and patch models.

#include <string_view>

namespace sewn::physics::shells {

/// Throws InputError, naming `model` and the values, unless E > 0, -1 < ν < ½ and thickness
/// > 0 (all finite). O(1).
void check_shell_material(std::string_view model, double young, double poisson, double thickness);

}  // namespace sewn::physics::shells
