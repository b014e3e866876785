#pragma once
// Reading a JSON document from a file or a string so that every refusal names a place in it:
// a syntax error its line, a number that overflows a double (1e999) its key path, nesting
// deeper than a scene can need the key path where the limit was crossed.

#include <cstddef>
#include <string>

#include <nlohmann/json.hpp>

namespace sewn::app {

/// Deepest nesting of lists and objects accepted (scene files need fewer than 10 levels).
inline constexpr std::size_t max_json_depth = 64;

/// Parses `text` (comments allowed) read from `file`. Throws SceneError(file, path, reason) for
/// a syntax error (path "line N"), a non-finite number (path = its key path), a key repeated in
/// one object, or nesting deeper than max_json_depth. Cost: one pass, memory of the document;
/// no recursion, so no input can exhaust the stack.
nlohmann::json parse_json(const std::string& text, const std::string& file);

}  // namespace sewn::app
