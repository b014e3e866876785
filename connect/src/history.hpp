#pragma once
// A connection's history as flat numbers (ConnectionHistory, point.hpp), shared by point and
// curve connections: the accepted twist, then each side's rod frame history or zeros.

#include <algorithm>
#include <cmath>
#include <numeric>
#include <span>
#include <string>
#include <variant>
#include <vector>

#include "sewn/connect/point.hpp"
#include "sewn/connect/stencil_dofs.hpp"

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

/// A term's history: its connections' in order, history_size values each.
template <class Items>
std::vector<double> items_history(const Items& items) {
  std::vector<double> out;
  out.reserve(items.size() * history_size);
  for (const auto& it : items) {
    const ConnectionHistory h = it.connection.history();
    out.insert(out.end(), h.begin(), h.end());
  }
  return out;
}

/// Takes up items_history() of a term built the same way; nothing changes if a value does not
/// fit (physics::InputError naming `term` or the connection).
template <class Items>
void restore_items(Items& items, std::span<const double> h, const std::string& term) {
  if (h.size() != items.size() * history_size)
    throw physics::InputError(term + ": a history of " + std::to_string(h.size()) + " values for " + std::to_string(items.size()) +
                              " connections (" + std::to_string(history_size) + " each)");
  std::vector<decltype(items.front().connection)> restored;
  restored.reserve(items.size());
  for (std::size_t c = 0; c < items.size(); ++c) {
    ConnectionHistory one{};
    std::copy(h.begin() + static_cast<std::ptrdiff_t>(c * history_size), h.begin() + static_cast<std::ptrdiff_t>((c + 1) * history_size),
              one.begin());
    restored.push_back(items[c].connection);
    restored.back().restore(one);
  }
  for (std::size_t c = 0; c < items.size(); ++c) items[c].connection = std::move(restored[c]);
}

/// The rule under cuts for a term's items (follow_nodes): per item, remove or rename its nodes.
template <class Items>
std::vector<bool> follow_items(Items& items, Index num_nodes, const NodeDecision& decide) {
  // every decision first, checked, then applied: an id out of range changes nothing
  std::vector<bool> kept(items.size(), false);
  std::vector<std::vector<std::pair<Index, Index>>> renames(items.size());
  for (std::size_t c = 0; c < items.size(); ++c) {
    kept[c] = decide(static_cast<Index>(c), renames[c]);
    for (const auto& r : renames[c])
      if (r.first >= num_nodes || r.second >= num_nodes)
        throw physics::InputError(items[c].owner() + ": renamed node " + std::to_string(r.first) + " -> " + std::to_string(r.second) +
                                  " is not below the node count " + std::to_string(num_nodes));
  }
  std::vector<Index> map(num_nodes);
  std::iota(map.begin(), map.end(), Index{0});
  Items out;
  for (std::size_t c = 0; c < items.size(); ++c) {
    if (!kept[c]) continue;
    for (const auto& r : renames[c]) map[r.first] = r.second;
    items[c].dofs.remap_nodes(map);
    items[c].connection.remap_nodes(map);
    for (const auto& r : renames[c]) map[r.first] = r.first;
    out.push_back(std::move(items[c]));
  }
  items = std::move(out);
  return kept;
}

}  // namespace sewn::connect::detail
