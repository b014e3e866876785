#include "sewn/apps/schema.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <sstream>

namespace sewn::app {

namespace {

std::string join_path(const std::string& path, const std::string& key) { return path.empty() ? key : path + "." + key; }

const char* kind_name(Kind k) {
  switch (k) {
    case Kind::number: return "number";
    case Kind::integer: return "integer";
    case Kind::boolean: return "boolean";
    case Kind::string: return "string";
    case Kind::vec3: return "[x, y, z]";
    case Kind::number_list: return "list of numbers";
    case Kind::object: return "object";
    case Kind::array: return "list";
    case Kind::map: return "object of named entries";
  }
  return "?";
}

// A short description of a bad value. Lists and objects are summarised, never dumped: dumping
// recurses once per nesting level, and a value nested 10^4 deep would overflow the stack.
std::string describe(const nlohmann::json& v) {
  if (v.is_array()) return "a list of " + std::to_string(v.size()) + (v.size() == 1 ? " entry" : " entries");
  if (v.is_object()) return "an object with " + std::to_string(v.size()) + (v.size() == 1 ? " key" : " keys");
  std::string s = v.dump();
  if (s.size() > 40) s = s.substr(0, 37) + "...";
  return s;
}

// Whole numbers in full (an index bound of 4294967294 must not read as 4.29497e+09), others in
// the stream's short form.
std::string format_number(double x) {
  if (std::isfinite(x) && std::trunc(x) == x && std::fabs(x) < 1e16) {
    char buf[32];
    std::snprintf(buf, sizeof buf, "%.0f", x);
    return buf;
  }
  std::ostringstream os;
  os << x;
  return os.str();
}

std::string range_text(const Field& f) {
  std::string lo, hi;
  if (std::isfinite(f.min_)) lo = (f.min_open_ ? "> " : ">= ") + format_number(f.min_);
  if (std::isfinite(f.max_)) hi = (f.max_open_ ? "< " : "<= ") + format_number(f.max_);
  if (!lo.empty() && !hi.empty()) return lo + " and " + hi;
  return lo + hi;
}

void check_range(double x, const Field& f, const std::string& file, const std::string& path) {
  const bool low = f.min_open_ ? !(x > f.min_) : !(x >= f.min_);
  const bool high = f.max_open_ ? !(x < f.max_) : !(x <= f.max_);
  if (low || high) throw SceneError(file, path, "must be " + range_text(f) + " (got " + format_number(x) + ")");
}

void check_number(const nlohmann::json& v, const Field& f, const std::string& file, const std::string& path) {
  if (!v.is_number() || v.is_boolean())
    throw SceneError(file, path, std::string("expected a number") + (f.unit_.empty() ? "" : " in " + f.unit_) +
                                     ", got " + describe(v));
  const double x = v.get<double>();
  if (!std::isfinite(x)) throw SceneError(file, path, "must be finite");
  if (f.whole_ && std::trunc(x) != x) throw SceneError(file, path, "must be a whole number (got " + describe(v) + ")");
  check_range(x, f, file, path);
}

std::vector<std::string> keys_of(const Field& schema, const std::string& variant) {
  std::vector<std::string> out;
  for (const auto& m : schema.fields_) out.push_back(m.key);
  if (auto it = schema.variants_.find(variant); it != schema.variants_.end())
    for (const auto& m : it->second) out.push_back(m.key);
  return out;
}

}  // namespace

SceneError::SceneError(std::string file, std::string path, std::string reason)
    : std::runtime_error(file + ": " + (path.empty() ? std::string("(top level)") : path) + ": " + reason),
      file_(std::move(file)),
      path_(std::move(path)),
      reason_(std::move(reason)) {}

Field field(std::string key, Kind kind) {
  Field f;
  f.key = std::move(key);
  f.kind = kind;
  if (kind == Kind::vec3) f.items(3, 3);
  return f;
}

const Field* Field::member(const std::string& key, const std::string& variant) const {
  for (const auto& m : fields_)
    if (m.key == key) return &m;
  if (auto it = variants_.find(variant); it != variants_.end())
    for (const auto& m : it->second)
      if (m.key == key) return &m;
  return nullptr;
}

std::string closest_key(const std::string& key, const std::vector<std::string>& known) {
  auto distance = [](const std::string& a, const std::string& b) {
    std::vector<std::size_t> row(b.size() + 1);
    for (std::size_t j = 0; j <= b.size(); ++j) row[j] = j;
    for (std::size_t i = 1; i <= a.size(); ++i) {
      std::size_t diag = row[0];
      row[0] = i;
      for (std::size_t j = 1; j <= b.size(); ++j) {
        const std::size_t up = row[j];
        const bool same = std::tolower(static_cast<unsigned char>(a[i - 1])) == std::tolower(static_cast<unsigned char>(b[j - 1]));
        row[j] = std::min({row[j] + 1, row[j - 1] + 1, diag + (same ? 0 : 1)});
        diag = up;
      }
    }
    return row[b.size()];
  };
  std::string best;
  std::size_t best_d = std::max<std::size_t>(2, key.size() / 2) + 1;
  for (const auto& k : known) {
    const std::size_t d = distance(key, k);
    if (d < best_d) {
      best_d = d;
      best = k;
    }
  }
  return best;
}

void validate(const nlohmann::json& v, const Field& f, const std::string& file, const std::string& path) {
  switch (f.kind) {
    case Kind::number: check_number(v, f, file, path); return;
    case Kind::integer:
      if (!v.is_number_integer()) throw SceneError(file, path, "expected a whole number, got " + describe(v));
      check_range(v.get<double>(), f, file, path);
      return;
    case Kind::boolean:
      if (!v.is_boolean()) throw SceneError(file, path, "expected true or false, got " + describe(v));
      return;
    case Kind::string: {
      if (!v.is_string()) throw SceneError(file, path, "expected a string, got " + describe(v));
      if (!f.choices_.empty()) {
        const auto s = v.get<std::string>();
        if (std::find(f.choices_.begin(), f.choices_.end(), s) == f.choices_.end()) {
          std::string list;
          for (const auto& c : f.choices_) list += (list.empty() ? "" : ", ") + ("\"" + c + "\"");
          const std::string near = closest_key(s, f.choices_);
          throw SceneError(file, path, "\"" + s + "\" is not one of " + list + (near.empty() ? "" : " (did you mean \"" + near + "\"?)"));
        }
      }
      return;
    }
    case Kind::vec3:
    case Kind::number_list: {
      if (!v.is_array()) throw SceneError(file, path, std::string("expected ") + kind_name(f.kind) + ", got " + describe(v));
      if (v.size() < f.min_items_ || v.size() > f.max_items_)
        throw SceneError(file, path, f.min_items_ == f.max_items_
                                         ? "expected exactly " + std::to_string(f.min_items_) + " numbers, got " + std::to_string(v.size())
                                         : "expected between " + std::to_string(f.min_items_) + " and " +
                                               std::to_string(f.max_items_) + " numbers, got " + std::to_string(v.size()));
      for (std::size_t i = 0; i < v.size(); ++i) check_number(v[i], f, file, path + "[" + std::to_string(i) + "]");
      return;
    }
    case Kind::array: {
      if (!v.is_array()) throw SceneError(file, path, "expected a list, got " + describe(v));
      if (v.size() < f.min_items_ || v.size() > f.max_items_)
        throw SceneError(file, path, "expected between " + std::to_string(f.min_items_) + " and " +
                                         std::to_string(f.max_items_) + " entries, got " + std::to_string(v.size()));
      for (std::size_t i = 0; i < v.size(); ++i) validate(v[i], *f.element_, file, path + "[" + std::to_string(i) + "]");
      return;
    }
    case Kind::map: {
      if (!v.is_object()) throw SceneError(file, path, "expected an object of named entries, got " + describe(v));
      if (v.size() < f.min_items_) throw SceneError(file, path, "needs at least " + std::to_string(f.min_items_) + " entry");
      for (auto it = v.begin(); it != v.end(); ++it) validate(it.value(), *f.element_, file, join_path(path, it.key()));
      return;
    }
    case Kind::object: {
      if (!v.is_object()) throw SceneError(file, path, "expected an object, got " + describe(v));
      std::string variant;
      if (!f.discriminator_.empty()) {
        const std::string dpath = join_path(path, f.discriminator_);
        if (!v.contains(f.discriminator_)) {
          std::string list;
          for (const auto& [name, _] : f.variants_) list += (list.empty() ? "" : ", ") + ("\"" + name + "\"");
          throw SceneError(file, dpath, "missing; it must be one of " + list);
        }
        const auto& d = v[f.discriminator_];
        if (!d.is_string()) throw SceneError(file, dpath, "expected a string, got " + describe(d));
        variant = d.get<std::string>();
        if (!f.variants_.count(variant)) {
          std::vector<std::string> names;
          std::string list;
          for (const auto& [name, _] : f.variants_) {
            names.push_back(name);
            list += (list.empty() ? "" : ", ") + ("\"" + name + "\"");
          }
          const std::string near = closest_key(variant, names);
          throw SceneError(file, dpath, "\"" + variant + "\" is not one of " + list + (near.empty() ? "" : " (did you mean \"" + near + "\"?)"));
        }
      }
      const auto known = keys_of(f, variant);
      for (auto it = v.begin(); it != v.end(); ++it) {
        if (std::find(known.begin(), known.end(), it.key()) != known.end()) continue;
        const std::string near = closest_key(it.key(), known);
        throw SceneError(file, join_path(path, it.key()),
                         "unknown key" + (near.empty() ? std::string(" (known keys: ") + [&] {
                           std::string l;
                           for (const auto& k : known) l += (l.empty() ? "" : ", ") + k;
                           return l;
                         }() + ")"
                                                      : "; did you mean \"" + near + "\"?"));
      }
      auto check_members = [&](const std::vector<Field>& members) {
        for (const auto& m : members) {
          if (m.key == f.discriminator_) continue;
          const std::string mpath = join_path(path, m.key);
          if (v.contains(m.key))
            validate(v[m.key], m, file, mpath);
          else if (m.required_)
            throw SceneError(file, mpath, "missing (" + (m.doc_.empty() ? std::string(kind_name(m.kind)) : m.doc_) + ")");
        }
      };
      check_members(f.fields_);
      if (!variant.empty()) check_members(f.variants_.at(variant));
      return;
    }
  }
}

namespace {

std::string type_text(const Field& f) {
  std::string t = kind_name(f.kind);
  if (f.kind == Kind::string && !f.choices_.empty()) {
    t.clear();
    for (const auto& c : f.choices_) t += (t.empty() ? "" : " \\| ") + ("`" + c + "`");
  }
  if (f.kind == Kind::array && f.element_) t = "list of " + std::string(kind_name(f.element_->kind));
  return t;
}

std::string default_text(const Field& f) {
  if (f.required_) return "required";
  if (f.default_.is_null()) return "—";
  return "`" + f.default_.dump() + "`";
}

void table(std::ostringstream& os, const std::vector<Field>& members, const std::string& skip) {
  os << "| key | type | unit | default | meaning |\n|---|---|---|---|---|\n";
  for (const auto& m : members) {
    if (m.key == skip) continue;
    std::string meaning = m.doc_;
    const std::string range = (m.kind == Kind::number || m.kind == Kind::integer || m.kind == Kind::vec3 ||
                               m.kind == Kind::number_list)
                                  ? range_text(m)
                                  : "";
    if (!range.empty()) meaning += " Must be " + range + ".";
    os << "| `" << m.key << "` | " << type_text(m) << " | " << (m.unit_.empty() ? "—" : m.unit_) << " | "
       << default_text(m) << " | " << meaning << " |\n";
  }
  os << "\n";
}

void describe_object(std::ostringstream& os, const Field& f, const std::string& heading, int level) {
  const std::string hashes(static_cast<std::size_t>(level), '#');
  os << hashes << " " << heading << "\n\n";
  if (!f.doc_.empty()) os << f.doc_ << "\n\n";
  if (!f.discriminator_.empty()) {
    os << "The key `" << f.discriminator_ << "` selects the kind; keys common to every kind:\n\n";
  }
  table(os, f.fields_, f.discriminator_);
  for (const auto& [name, members] : f.variants_) {
    os << hashes << "# `" << f.discriminator_ << ": \"" << name << "\"`\n\n";
    if (auto it = f.variant_docs_.find(name); it != f.variant_docs_.end() && !it->second.empty()) os << it->second << "\n\n";
    if (!members.empty()) table(os, members, "");
  }
  auto nested = [&](const Field& m) -> const Field* {
    if (m.kind == Kind::object) return &m;
    if ((m.kind == Kind::array || m.kind == Kind::map) && m.element_ && m.element_->kind == Kind::object) return m.element_.get();
    return nullptr;
  };
  auto recurse = [&](const std::vector<Field>& members) {
    for (const auto& m : members)
      if (const Field* o = nested(m)) describe_object(os, *o, "`" + m.key + "`" + (m.kind == Kind::array ? " entries" : m.kind == Kind::map ? " entries" : ""), level + 1);
  };
  recurse(f.fields_);
  for (const auto& [name, members] : f.variants_) recurse(members);
}

}  // namespace

std::string to_markdown(const Field& schema, const std::string& title) {
  std::ostringstream os;
  describe_object(os, schema, title, 1);
  return os.str();
}

Reader::Reader(const nlohmann::json& j, const Field& schema, std::string variant)
    : j_(j), schema_(schema), variant_(std::move(variant)) {}

const Field& Reader::schema_of(const std::string& key) const {
  const Field* m = schema_.member(key, variant_);
  if (!m) throw std::logic_error("scene reader: key \"" + key + "\" is not in the schema");
  return *m;
}

bool Reader::has(const std::string& key) const {
  (void)schema_of(key);
  return j_.contains(key);
}

const nlohmann::json& Reader::operator[](const std::string& key) const {
  const Field& m = schema_of(key);
  if (j_.contains(key)) return j_[key];
  if (m.default_.is_null() && !m.required_) {
    static const nlohmann::json null_value;
    return null_value;
  }
  return m.default_;
}

std::array<double, 3> Reader::vec3(const std::string& key) const {
  const auto& v = (*this)[key];
  return {v[0].get<double>(), v[1].get<double>(), v[2].get<double>()};
}

}  // namespace sewn::app
