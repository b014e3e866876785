#include <algorithm>
#include <cctype>
#include <cmath>
#include <cstring>
#include <map>
#include <string>

#include "cursor.hpp"
#include "sewn/io/surface.hpp"

namespace sewn::io {

namespace {

using detail::Cursor;

std::string lower(std::string s) {
  std::transform(s.begin(), s.end(), s.begin(), [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
  return s;
}

Point3 finite_point(Cursor& c, std::uint64_t index) {
  Point3 p{};
  for (double& x : p) {
    x = c.real("a vertex coordinate");
    if (!std::isfinite(x)) c.fail_semantic("vertex " + std::to_string(index) + " has a non-finite coordinate", c.line());
  }
  return p;
}

// A triangle that uses one vertex twice (an STL facet with two equal corners, a polygon that
// repeats a vertex) bounds nothing: it is left out, or its edge would count as used 4 times
// and the surface as not closed.
void add_triangle(Surface& s, const std::array<std::uint32_t, 3>& t) {
  if (t[0] != t[1] && t[1] != t[2] && t[2] != t[0]) s.triangles.push_back(t);
}

// A polygon fanned into triangles from its first vertex.
void add_polygon(Surface& s, const std::vector<std::uint32_t>& v) {
  for (std::size_t i = 1; i + 1 < v.size(); ++i) add_triangle(s, {v[0], v[i], v[i + 1]});
}

// The OFF header keyword: [ST][C][N][4][n]OFF (Princeton/Geomview). ST, C and N add texture
// coordinates, a colour and a normal after each vertex's x y z, which are read past; 4 and n
// change what a vertex is, and BINARY the encoding: those are refused rather than misread.
struct OffHeader {
  bool vertex_extras = false;  // values after x y z on a vertex line
};

OffHeader off_header(Cursor& c) {
  const std::string_view head = c.token("the OFF header");
  if (head.size() < 3 || head.substr(head.size() - 3) != "OFF") c.fail_expected("the header OFF (or COFF, NOFF, STOFF, ...)", head);
  std::string_view prefix = head.substr(0, head.size() - 3);
  OffHeader h;
  for (std::string_view p : {"ST", "C", "N"})
    if (prefix.substr(0, p.size()) == p) prefix.remove_prefix(p.size()), h.vertex_extras = true;
  if (prefix == "4" || prefix == "n" || prefix == "4n") {
    std::string reason(head);  // appended to, not prepended: g++ 12 warns (-Wrestrict) on "'" + string
    reason += " files (homogeneous or n-dimensional vertices) are not supported; write 3D OFF";
    c.fail_unsupported(reason);
  }
  if (!prefix.empty()) c.fail_expected("the header OFF (or COFF, NOFF, STOFF, ...)", head);
  if (const auto t = c.peek_on_line(); t && *t == "BINARY") c.fail_unsupported("binary OFF files are not supported; write ASCII OFF");
  return h;
}

Surface parse_off(std::string_view text, const std::string& source) {
  Cursor c(text, source, '#');
  const OffHeader h = off_header(c);
  const std::uint64_t nv = c.count("the vertex count"), nf = c.count("the face count");
  (void)c.count("the edge count");
  Surface s;
  s.points.reserve(std::min<std::uint64_t>(nv, text.size() / 6));
  for (std::uint64_t i = 0; i < nv; ++i) {
    s.points.push_back(finite_point(c, i));
    // a vertex is a line: extra values are the header's extras, or a wrong count to report
    if (h.vertex_extras)
      (void)c.rest_of_line();
    else
      c.end_line("vertex " + std::to_string(i) + "'s x y z (a vertex line of an OFF file holds 3 numbers; COFF, NOFF, STOFF hold more)");
  }
  std::vector<std::uint32_t> poly;
  for (std::uint64_t f = 0; f < nf; ++f) {
    const std::uint64_t n = c.count("a face's vertex count", 1u << 16);
    if (n < 3) c.fail_semantic("face " + std::to_string(f) + " has " + std::to_string(n) + " vertices (at least 3 needed)", c.line());
    poly.clear();
    for (std::uint64_t k = 0; k < n; ++k) {
      const std::uint64_t v = c.count("a vertex index");
      if (v >= nv) c.fail_semantic("face " + std::to_string(f) + " uses vertex " + std::to_string(v) + " of " + std::to_string(nv), c.line());
      poly.push_back(static_cast<std::uint32_t>(v));
    }
    add_polygon(s, poly);
    (void)c.rest_of_line();  // colours may follow
  }
  // Data past the declared faces means the counts are wrong: reading on would drop faces silently.
  if (!c.at_end())
    c.fail_expected("the end of the file after the " + std::to_string(nf) + " faces the header declares", c.token("the end"));
  return s;
}

Surface parse_obj(std::string_view text, const std::string& source) {
  Cursor c(text, source, '#');
  Surface s;
  std::vector<std::uint32_t> poly;
  while (!c.at_end()) {
    const std::string_view key = c.token("a record");
    if (key == "v") {
      s.points.push_back(finite_point(c, s.points.size()));
      (void)c.rest_of_line();  // an optional w or colour
    } else if (key == "f") {
      poly.clear();
      while (auto t = c.peek_on_line()) {
        const std::string_view item = c.token("a face vertex");
        const std::string_view index = item.substr(0, item.find('/'));  // v, v/vt, v//vn, v/vt/vn
        long long v = 0;
        try {
          std::size_t used = 0;
          v = std::stoll(std::string(index), &used);
          if (used != index.size()) throw std::invalid_argument("trailing");
        } catch (const std::exception&) {
          c.fail_expected("a vertex index", item);
        }
        const long long n = static_cast<long long>(s.points.size());
        const long long at = v < 0 ? n + v : v - 1;  // negative: relative to the end
        if (v == 0 || at < 0 || at >= n)
          c.fail_semantic("a face uses vertex " + std::to_string(v) + " with " + std::to_string(n) + " vertices defined so far", c.line());
        poly.push_back(static_cast<std::uint32_t>(at));
      }
      if (poly.size() < 3) c.fail_semantic("a face has " + std::to_string(poly.size()) + " vertices (at least 3 needed)", c.line());
      add_polygon(s, poly);
    } else {
      (void)c.rest_of_line();  // vt, vn, g, o, s, usemtl, mtllib, ...
    }
  }
  return s;
}

// STL vertices merged when bitwise equal (STL repeats them per facet).
struct StlBuilder {
  Surface s;
  std::map<Point3, std::uint32_t> index;
  std::uint32_t vertex(const Point3& p) {
    auto [it, fresh] = index.try_emplace(p, static_cast<std::uint32_t>(s.points.size()));
    if (fresh) s.points.push_back(p);
    return it->second;
  }
};

// One solid ... endsolid block; a file may hold several, one after the other.
void parse_stl_solid(Cursor& c, StlBuilder& b) {
  c.expect("solid");
  (void)c.rest_of_line();
  while (true) {
    const std::string_view key = c.token("facet or endsolid");
    if (key == "endsolid") break;
    if (key != "facet") c.fail_expected("facet or endsolid", key);
    c.expect("normal");
    for (int k = 0; k < 3; ++k) (void)c.real("a normal component");
    c.expect("outer");
    c.expect("loop");
    std::array<std::uint32_t, 3> t{};
    for (auto& v : t) {
      c.expect("vertex");
      v = b.vertex(finite_point(c, b.s.points.size()));
    }
    c.expect("endloop");
    c.expect("endfacet");
    add_triangle(b.s, t);
  }
  (void)c.rest_of_line();  // the solid's name
}

Surface parse_stl_ascii(std::string_view text, const std::string& source) {
  Cursor c(text, source);
  StlBuilder b;
  do parse_stl_solid(c, b);
  while (!c.at_end());
  return b.s;
}

Surface parse_stl_binary(std::string_view bytes, const std::string& source) {
  if (bytes.size() < 84) throw ParseError(source, 0, "an 84-byte binary STL header", std::to_string(bytes.size()) + " bytes");
  std::uint32_t n = 0;
  std::memcpy(&n, bytes.data() + 80, 4);
  if ((bytes.size() - 84) / 50 < n)
    throw SemanticError(source, 0, "declares " + std::to_string(n) + " triangles but holds " + std::to_string((bytes.size() - 84) / 50));
  StlBuilder b;
  for (std::uint32_t f = 0; f < n; ++f) {
    const char* rec = bytes.data() + 84 + 50 * static_cast<std::size_t>(f);
    std::array<std::uint32_t, 3> t{};
    for (int v = 0; v < 3; ++v) {
      Point3 p{};
      for (int k = 0; k < 3; ++k) {
        float x = 0;
        std::memcpy(&x, rec + 12 + 12 * v + 4 * k, 4);
        if (!std::isfinite(x)) throw SemanticError(source, 0, "triangle " + std::to_string(f) + " has a non-finite coordinate");
        p[static_cast<std::size_t>(k)] = x;
      }
      t[static_cast<std::size_t>(v)] = b.vertex(p);
    }
    add_triangle(b.s, t);
  }
  return b.s;
}

bool starts_with_word(std::string_view text, std::string_view word) {
  std::size_t i = 0;
  while (i < text.size() && std::isspace(static_cast<unsigned char>(text[i]))) ++i;
  return text.substr(i, word.size()) == word;
}

// An OFF header of any variant (OFF, COFF, NOFF, STOFF, ...) as the first word.
bool starts_with_off_header(std::string_view text) {
  const std::size_t b = std::min(text.size(), text.find_first_not_of(" \t\r\n"));
  const std::size_t e = std::min(text.size(), text.find_first_of(" \t\r\n", b));
  const std::string_view w = text.substr(b, e - b);
  return w.size() >= 3 && w.size() <= 8 && w.substr(w.size() - 3) == "OFF";
}

// A binary STL is its 84-byte header and 50 bytes per declared triangle, exactly. Many
// exporters start the 80-byte comment with "solid" too: the size tells them from ASCII.
bool is_binary_stl(std::string_view bytes) {
  if (bytes.size() < 84) return false;
  std::uint32_t n = 0;
  std::memcpy(&n, bytes.data() + 80, 4);
  return bytes.size() - 84 == 50 * static_cast<std::uint64_t>(n);
}

}  // namespace

Surface read_surface(const std::filesystem::path& path) { return parse_surface(detail::slurp(path), path.string()); }

Surface parse_surface(std::string_view data, const std::string& name) {
  const std::string ext = lower(std::filesystem::path(name).extension().string());
  Surface s;
  if (starts_with_off_header(data)) {
    s = parse_off(data, name);
  } else if (starts_with_word(data, "solid") && !is_binary_stl(data) && data.find("facet") != std::string::npos) {
    s = parse_stl_ascii(data, name);
  } else if (ext == ".stl") {
    s = parse_stl_binary(data, name);
  } else if (ext == ".obj") {
    s = parse_obj(data, name);
  } else if (ext == ".off") {
    s = parse_off(data, name);  // reports the missing header
  } else {
    throw UnsupportedError(name, 0, "not a surface file Sewn reads (OFF, OBJ or STL, by content or by extension)");
  }
  if (s.triangles.empty()) throw SemanticError(name, 0, "has no triangle");
  return s;
}

}  // namespace sewn::io
