#pragma once
// Exceptions thrown by Sewn. Every message names what is wrong and where (dart, cell, file, key).

#include <stdexcept>
#include <string>

namespace sewn {

/// A map operation was called on arguments that violate its documented precondition
/// (dead dart, cells that cannot be sewn, a cell that is not removable, ...). The map is unchanged.
class TopologyError : public std::invalid_argument {
 public:
  using std::invalid_argument::invalid_argument;
};

/// A resource limit of the map was reached (all marks reserved, 2^32 darts).
class CapacityError : public std::length_error {
 public:
  using std::length_error::length_error;
};

/// An indexed mesh handed to a builder is malformed (index out of range, degenerate or
/// inconsistently oriented cell, non-manifold facet where a manifold is required).
class MeshError : public std::invalid_argument {
 public:
  using std::invalid_argument::invalid_argument;
};

}  // namespace sewn
