#pragma once
// The InputError of one mesh cell, kept apart from errors.hpp so that what throws or catches it
// alone depends on it.

#include <cstdint>
#include <string>

#include "sewn/physics/errors.hpp"

namespace sewn::physics {

/// Bad input in one cell of the mesh a model was built from. what() names the cell by its index
/// in that mesh; cell() is that index and detail() the problem alone, so that a caller who built
/// the mesh from files can name the cell as its file does.
class CellInputError : public InputError {
 public:
  CellInputError(const std::string& source, std::uint32_t cell, const std::string& detail)
      : InputError(source + ": cell " + std::to_string(cell) + " " + detail), cell_(cell), detail_(detail) {}
  [[nodiscard]] std::uint32_t cell() const noexcept { return cell_; }
  /// The message after "cell N ": what is wrong with it (starting with its type in parentheses).
  [[nodiscard]] const std::string& detail() const noexcept { return detail_; }

 private:
  std::uint32_t cell_;
  std::string detail_;
};

}  // namespace sewn::physics
