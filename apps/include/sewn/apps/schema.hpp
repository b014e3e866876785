#pragma once
// A declarative schema for JSON input: one description drives validation (types, units,
// ranges, choices, unknown keys with the closest known one), defaults, and the generated
// reference documentation, so the three cannot drift apart.

#include <limits>
#include <map>
#include <memory>
#include <stdexcept>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

namespace sewn::app {

/// Bad input in a JSON file: names the file, the key path (e.g. "meshes[0].cells") and the reason.
class SceneError : public std::runtime_error {
 public:
  SceneError(std::string file, std::string path, std::string reason);
  [[nodiscard]] const std::string& file() const { return file_; }
  [[nodiscard]] const std::string& path() const { return path_; }
  [[nodiscard]] const std::string& reason() const { return reason_; }

 private:
  std::string file_, path_, reason_;
};

enum class Kind { number, integer, boolean, string, vec3, number_list, object, array, map };

/// One key of an object (or the element of an array / value of a map). Built fluently:
///   field("young", Kind::number).unit("Pa").doc("Young's modulus").required().above(0)
struct Field {
  std::string key;
  Kind kind = Kind::number;
  std::string unit_;
  std::string doc_;
  nlohmann::json default_;  // null: no default (required, or optional without value)
  bool required_ = false;
  double min_ = -std::numeric_limits<double>::infinity(), max_ = std::numeric_limits<double>::infinity();
  bool min_open_ = false, max_open_ = false;
  bool whole_ = false;  // numbers (and list items) must be whole: indices, counts, lattice cells
  std::size_t min_items_ = 0, max_items_ = std::numeric_limits<std::size_t>::max();
  std::vector<std::string> choices_;
  std::vector<Field> fields_;                          // object members (common to every variant)
  std::string discriminator_;                          // object: key whose value selects a variant
  std::map<std::string, std::vector<Field>> variants_;  // variant name -> extra members
  std::map<std::string, std::string> variant_docs_;
  std::shared_ptr<Field> element_;                     // array element / map value

  Field& unit(std::string u) { unit_ = std::move(u); return *this; }
  Field& doc(std::string d) { doc_ = std::move(d); return *this; }
  Field& fallback(nlohmann::json v) { default_ = std::move(v); return *this; }
  Field& required() { required_ = true; return *this; }
  Field& at_least(double v) { min_ = v; min_open_ = false; return *this; }
  Field& above(double v) { min_ = v; min_open_ = true; return *this; }
  Field& at_most(double v) { max_ = v; max_open_ = false; return *this; }
  Field& below(double v) { max_ = v; max_open_ = true; return *this; }
  Field& whole() { whole_ = true; return *this; }
  Field& items(std::size_t lo, std::size_t hi) { min_items_ = lo; max_items_ = hi; return *this; }
  Field& one_of(std::vector<std::string> c) { choices_ = std::move(c); return *this; }
  Field& members(std::vector<Field> f) { fields_ = std::move(f); return *this; }
  Field& variant(std::string name, std::string d, std::vector<Field> f) {
    variant_docs_[name] = std::move(d);
    variants_[std::move(name)] = std::move(f);
    return *this;
  }
  Field& select_by(std::string key) { discriminator_ = std::move(key); return *this; }
  Field& of(Field element) { element_ = std::make_shared<Field>(std::move(element)); return *this; }

  /// The member named key for the given variant (or a common one); nullptr if unknown.
  [[nodiscard]] const Field* member(const std::string& key, const std::string& variant = {}) const;
};

Field field(std::string key, Kind kind);

/// Throws SceneError for the first problem in `value` against `schema`. `path` is the key path
/// of `value` itself ("" for the root).
void validate(const nlohmann::json& value, const Field& schema, const std::string& file, const std::string& path = {});

/// The known key closest to `key` by edit distance, or "" if none is close.
std::string closest_key(const std::string& key, const std::vector<std::string>& known);

/// Markdown reference for a schema: one table per object, with key, type, unit, default, meaning.
std::string to_markdown(const Field& schema, const std::string& title);

/// Reads validated JSON with the schema's defaults: get(j, schema, "young") returns j["young"] or
/// the documented default. A key missing from the schema is a programming error (logic_error).
class Reader {
 public:
  Reader(const nlohmann::json& j, const Field& schema, std::string variant = {});
  [[nodiscard]] const nlohmann::json& operator[](const std::string& key) const;
  [[nodiscard]] bool has(const std::string& key) const;
  [[nodiscard]] double number(const std::string& key) const { return (*this)[key].get<double>(); }
  [[nodiscard]] long long integer(const std::string& key) const { return (*this)[key].get<long long>(); }
  [[nodiscard]] bool boolean(const std::string& key) const { return (*this)[key].get<bool>(); }
  [[nodiscard]] std::string string(const std::string& key) const { return (*this)[key].get<std::string>(); }
  [[nodiscard]] std::array<double, 3> vec3(const std::string& key) const;
  [[nodiscard]] const Field& schema_of(const std::string& key) const;

 private:
  const nlohmann::json& j_;
  const Field& schema_;
  std::string variant_;
};

}  // namespace sewn::app
