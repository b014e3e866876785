#pragma once
// The corners of a VTK-ordered hexahedron as the solids code measures them: for each corner,
// its three neighbours along edges, in an order that gives every corner of an undistorted box
// the same sign of (a-o)·((b-o)×(c-o)). The inversion monitor and the volume term both read
// a hexahedron's orientation and volume at these corners.

#include <array>
#include <cstdint>

namespace sewn::physics::solids::detail {

inline constexpr std::array<std::array<std::uint8_t, 3>, 8> hex_corners{{
    {1, 3, 4}, {2, 0, 5}, {3, 1, 6}, {0, 2, 7}, {7, 5, 0}, {4, 6, 1}, {5, 7, 2}, {6, 4, 3}}};

}  // namespace sewn::physics::solids::detail
