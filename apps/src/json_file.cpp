#include "json_file.hpp"

#include <algorithm>
#include <vector>

#include "sewn/apps/schema.hpp"

namespace sewn::app {

namespace {

using json = nlohmann::json;

// Builds the document like nlohmann's own DOM parser, but knows at every event where it is, so
// that a refusal can name the key path; it refuses nesting beyond max_json_depth before
// descending.
class PathBuilder {
 public:
  using number_integer_t = json::number_integer_t;
  using number_unsigned_t = json::number_unsigned_t;
  using number_float_t = json::number_float_t;
  using string_t = json::string_t;
  using binary_t = json::binary_t;

  json root;
  std::string error_path, error_reason;
  bool syntax_error = false;
  std::size_t error_byte = 0;

  bool null() { return put(json(nullptr)); }
  bool boolean(bool b) { return put(json(b)); }
  bool number_integer(number_integer_t v) { return put(json(v)); }
  bool number_unsigned(number_unsigned_t v) { return put(json(v)); }
  bool number_float(number_float_t v, const string_t&) { return put(json(v)); }
  bool string(string_t& s) { return put(json(std::move(s))); }
  bool binary(binary_t&) { return fail(path(), "binary values are not JSON"); }
  bool start_object(std::size_t) { return open(json::object()); }
  bool start_array(std::size_t) { return open(json::array()); }
  bool end_object() { return close(); }
  bool end_array() { return close(); }
  bool key(string_t& k) {
    Level& top = stack_.back();
    const bool repeated = top.value->contains(k);
    top.key = std::move(k);
    return repeated ? fail(path(), "the key appears twice in one object") : true;
  }
  bool parse_error(std::size_t byte, const std::string& token, const nlohmann::detail::exception& e) {
    if (e.id == 406) return fail(path(), "the number " + token + " is out of range (too large for a double)");
    syntax_error = true;
    error_byte = byte;
    error_reason = std::string("not valid JSON: ") + e.what();
    return false;
  }

 private:
  struct Level {
    json* value;
    std::string key;  // objects: the key of the value being read
  };
  std::vector<Level> stack_;

  bool fail(std::string where, std::string reason) {
    error_path = std::move(where);
    error_reason = std::move(reason);
    return false;
  }
  // The key path of the value about to be read.
  [[nodiscard]] std::string path() const {
    std::string p;
    for (std::size_t i = 0; i < stack_.size(); ++i) {
      const Level& l = stack_[i];
      if (l.value->is_object()) {
        if (!p.empty()) p.push_back('.');
        p.append(l.key);
      } else {
        p.push_back('[');
        // an enclosing list already holds the open entry; the innermost one is about to get it
        p.append(std::to_string(l.value->size() - (i + 1 < stack_.size() ? 1 : 0)));
        p.push_back(']');
      }
    }
    return p;
  }
  json* place(json&& v) {
    if (stack_.empty()) {
      root = std::move(v);
      return &root;
    }
    json& parent = *stack_.back().value;
    if (parent.is_object()) return &(parent[stack_.back().key] = std::move(v));
    parent.push_back(std::move(v));
    return &parent.back();
  }
  bool put(json&& v) {
    place(std::move(v));
    return true;
  }
  bool open(json&& container) {
    if (stack_.size() >= max_json_depth)
      return fail(path(), "nested more than " + std::to_string(max_json_depth) + " levels deep (a scene needs fewer than 10)");
    json* c = place(std::move(container));
    stack_.push_back({c, {}});
    return true;
  }
  bool close() {
    stack_.pop_back();
    return true;
  }
};

}  // namespace

json parse_json(const std::string& text, const std::string& file) {
  PathBuilder b;
  const bool ok = json::sax_parse(text, &b, json::input_format_t::json, /*strict=*/true, /*ignore_comments=*/true);
  if (ok) return std::move(b.root);
  if (b.syntax_error) {
    const std::size_t end = std::min(b.error_byte, text.size());
    const std::size_t line = 1 + static_cast<std::size_t>(std::count(text.begin(), text.begin() + static_cast<std::ptrdiff_t>(end), '\n'));
    throw SceneError(file, "line " + std::to_string(line), b.error_reason);
  }
  throw SceneError(file, b.error_path, b.error_reason);
}

}  // namespace sewn::app
