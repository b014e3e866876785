#pragma once
// A connection's history as flat numbers (ConnectionHistory, point.hpp), shared by point and
// curve connections: the accepted twist, then each side's rod frame history or zeros.

#include <algorithm>
#include <cmath>
#include <string>
#include <variant>
#include <vector>

#include "sewn/connect/point.hpp"

namespace sewn::connect::detail {

template <class SideVariant>
ConnectionHistory make_history(double accepted_twist, const SideVariant& m, const SideVariant& n) {
  ConnectionHistory h{};
  h[0] = accepted_twist;
  int at = 1;
  for (const SideVariant* s : {&m, &n}) {
    if (const auto* r = std::get_if<RodEdgeSide>(s))
      for (int k = 0; k < 3; ++k) {
        h[static_cast<std::size_t>(at + k)] = r->tangent[k];
        h[static_cast<std::size_t>(at + 3 + k)] = r->director[k];
      }
    at += 6;
  }
  return h;
}

/// Checks h against the sides (throws physics::InputError naming `owner`), then writes the rod
/// sides' frames and returns the accepted twist.
template <class SideVariant>
double take_history(const ConnectionHistory& h, SideVariant& m, SideVariant& n, const std::string& owner) {
  for (double v : h)
    if (!std::isfinite(v)) throw physics::InputError(owner + ": its history holds a non-finite value");
  int at = 1;
  for (const SideVariant* s : {&m, &n}) {
    const Vec3 t(h[static_cast<std::size_t>(at)], h[static_cast<std::size_t>(at + 1)], h[static_cast<std::size_t>(at + 2)]);
    const Vec3 d(h[static_cast<std::size_t>(at + 3)], h[static_cast<std::size_t>(at + 4)], h[static_cast<std::size_t>(at + 5)]);
    if (std::holds_alternative<RodEdgeSide>(*s)) {
      if (std::abs(t.norm() - 1) > 1e-9 || std::abs(d.norm() - 1) > 1e-9 || std::abs(t.dot(d)) > 1e-9)
        throw physics::InputError(owner + ": its history's rod frame is not orthonormal");
    } else if (t != Vec3::Zero() || d != Vec3::Zero()) {
      throw physics::InputError(owner + ": its history has a rod frame for a side that is not a rod");
    }
    at += 6;
  }
  at = 1;
  for (SideVariant* s : {&m, &n}) {
    if (auto* r = std::get_if<RodEdgeSide>(s)) {
      r->tangent = Vec3(h[static_cast<std::size_t>(at)], h[static_cast<std::size_t>(at + 1)], h[static_cast<std::size_t>(at + 2)]);
      r->director = Vec3(h[static_cast<std::size_t>(at + 3)], h[static_cast<std::size_t>(at + 4)], h[static_cast<std::size_t>(at + 5)]);
    }
    at += 6;
  }
  return h[0];
}

}  // namespace sewn::connect::detail
