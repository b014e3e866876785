#pragma once
// Error messages about cells and points of an indexed mesh, kept so that a caller who knows how
// the user's files number them can restate them. The library numbers cells and points as the
// mesh it was given does; that mesh may be several files put together, with their unused points
// dropped, so its numbers are not the ones the user can look up. An IndexedMessage keeps the
// numbers apart from the words: str() says "cell 3" and "point 7", render() lets the caller say
// "cell 1 (Gmsh element 9) of b.msh" and "node 40".
//
//   throw MeshCellError(source, IndexedMessage() << CellRef{c} << " (tetrahedron) and " << CellRef{d} << " ...");

#include <cstdint>
#include <functional>
#include <string>
#include <utility>
#include <vector>

#include "sewn/cmap/errors.hpp"

namespace sewn {

struct CellRef {
  std::uint32_t index;
};
struct PointRef {
  std::uint32_t index;
};
/// A material of the cells, by its index in the list the caller gave with the mesh.
struct MaterialRef {
  std::uint32_t index;
};

class IndexedMessage {
 public:
  /// One number of the message: a cell or a point of the mesh, by its index there, or a material.
  struct Ref {
    enum class Kind : std::uint8_t { cell, point, material } kind;
    std::uint32_t index;
  };

  IndexedMessage& operator<<(const std::string& text);
  IndexedMessage& operator<<(CellRef c);
  IndexedMessage& operator<<(PointRef p);
  IndexedMessage& operator<<(MaterialRef m);
  IndexedMessage& operator<<(const IndexedMessage& more);

  /// The message with each reference in the words `name` gives it. O(length).
  [[nodiscard]] std::string render(const std::function<std::string(const Ref&)>& name) const;
  /// The message in the mesh's own numbers: "cell 3", "point 7", "material 1".
  [[nodiscard]] std::string str() const;
  [[nodiscard]] const std::vector<Ref>& refs() const noexcept { return refs_; }
  /// The same words with each reference replaced by what `to` maps it to: a builder that numbers
  /// a subset of the cells (a model's own elements) restates its message in the mesh's. O(length).
  [[nodiscard]] IndexedMessage renumbered(const std::function<Ref(const Ref&)>& to) const;

 private:
  std::vector<std::string> texts_{std::string()};  // one more than refs_: text, ref, text, ...
  std::vector<Ref> refs_;
};

/// A MeshError about cells and points of the mesh a builder was given: what() is
/// "<source>: <message.str()>", message() the message a caller can restate in its files' numbers.
class MeshCellError : public MeshError {
 public:
  MeshCellError(const std::string& source, IndexedMessage message)
      : MeshError(source + ": " + message.str()), message_(std::move(message)) {}
  [[nodiscard]] const IndexedMessage& message() const noexcept { return message_; }

 private:
  IndexedMessage message_;
};

}  // namespace sewn
