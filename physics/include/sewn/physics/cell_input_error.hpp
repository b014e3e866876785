#pragma once
// The InputError of cells and points of one mesh, kept apart from errors.hpp so that what throws
// or catches it alone depends on it.

#include <cstdint>
#include <string>
#include <utility>

#include "sewn/cmap/indexed_message.hpp"
#include "sewn/physics/errors.hpp"

namespace sewn::physics {

/// Bad input in cells or points of the mesh a model was built from. what() is
/// "<source>: <message>", naming them by their index in that mesh; message() keeps the numbers
/// apart (IndexedMessage) so that a caller who built the mesh from files can name them as its
/// files do.
class CellInputError : public InputError {
 public:
  CellInputError(const std::string& source, IndexedMessage message)
      : InputError(source + ": " + message.str()), message_(std::move(message)) {}
  /// "cell <cell> <detail>", detail starting with the cell's type in parentheses.
  CellInputError(const std::string& source, std::uint32_t cell, const std::string& detail)
      : CellInputError(source, IndexedMessage() << CellRef{cell} << " " + detail) {}
  [[nodiscard]] const IndexedMessage& message() const noexcept { return message_; }

 private:
  IndexedMessage message_;
};

}  // namespace sewn::physics
