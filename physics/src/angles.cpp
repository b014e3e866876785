#include "sewn/physics/angles.hpp"

#include <cmath>

#include "sewn/physics/errors.hpp"
#include "format.hpp"

namespace sewn::physics {

Index AngleTable::add(const std::string& owner, std::span<const double> values, std::span<const double> inertias,
                      std::span<const unsigned char> fixed, std::span<const double> lengths) {
  if (inertias.size() != values.size() || fixed.size() != values.size() || (!lengths.empty() && lengths.size() != values.size()))
    throw InputError("angles of " + owner + ": " + std::to_string(values.size()) + " values but " +
                     std::to_string(inertias.size()) + " inertias, " + std::to_string(fixed.size()) + " fixed flags and " +
                     std::to_string(lengths.size()) + " lengths");
  for (std::size_t k = 0; k < values.size(); ++k) {
    if (!std::isfinite(values[k]))
      throw InputError("angles of " + owner + ": angle " + std::to_string(k) + " is not finite");
    if (!(std::isfinite(inertias[k]) && inertias[k] >= 0))
      throw InputError("angles of " + owner + ": inertia of angle " + std::to_string(k) + " must be finite and >= 0, got " +
                       detail::format_number(inertias[k]));
    if (!lengths.empty() && !(std::isfinite(lengths[k]) && lengths[k] > 0))
      throw InputError("angles of " + owner + ": length of angle " + std::to_string(k) + " must be finite and > 0, got " +
                       detail::format_number(lengths[k]));
  }
  const Index first = size();
  value_.insert(value_.end(), values.begin(), values.end());
  rate_.resize(value_.size(), 0.0);
  inertia_.insert(inertia_.end(), inertias.begin(), inertias.end());
  fixed_.insert(fixed_.end(), fixed.begin(), fixed.end());
  condensed_.resize(value_.size(), 0);
  if (lengths.empty())
    length_.resize(value_.size(), 1.0);
  else
    length_.insert(length_.end(), lengths.begin(), lengths.end());
  ++topology_version_;
  return first;
}

void AngleTable::set_fixed(Index a, bool on) {
  if (a >= size()) throw InputError("AngleTable::set_fixed: angle " + std::to_string(a) + " of " + std::to_string(size()));
  fixed_[a] = on ? 1 : 0;
}

void AngleTable::set_condensed(Index a, bool on) {
  if (a >= size()) throw InputError("AngleTable::set_condensed: angle " + std::to_string(a) + " of " + std::to_string(size()));
  condensed_[a] = on ? 1 : 0;
  if (on) inertia_[a] = 0.0;  // solved at every evaluation: quasi-static
}

void AngleTable::set_length(Index a, double metres) {
  if (a >= size()) throw InputError("AngleTable::set_length: angle " + std::to_string(a) + " of " + std::to_string(size()));
  if (!(std::isfinite(metres) && metres > 0.0))
    throw InputError("AngleTable::set_length: angle " + std::to_string(a) + ": the length must be finite and > 0, got " +
                     detail::format_number(metres) + " m");
  length_[a] = metres;
}

}  // namespace sewn::physics
