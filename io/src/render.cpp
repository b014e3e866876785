#include "sewn/io/render.hpp"

#include "sewn/io/atomic_file.hpp"

#include <cairo.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>
#include <memory>
#include <numbers>
#include <stdexcept>

namespace sewn::io {

namespace {

using V3 = std::array<double, 3>;

V3 sub(const V3& a, const V3& b) { return {a[0] - b[0], a[1] - b[1], a[2] - b[2]}; }
V3 add(const V3& a, const V3& b) { return {a[0] + b[0], a[1] + b[1], a[2] + b[2]}; }
V3 scale(const V3& a, double s) { return {a[0] * s, a[1] * s, a[2] * s}; }
V3 cross(const V3& a, const V3& b) {
  return {a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]};
}
double dot(const V3& a, const V3& b) { return a[0] * b[0] + a[1] * b[1] + a[2] * b[2]; }
V3 normalized(const V3& a) {
  const double n = std::sqrt(dot(a, a));
  return n > 0 ? scale(a, 1.0 / n) : V3{0, 0, 0};
}
bool finite(const V3& p) { return std::isfinite(p[0]) && std::isfinite(p[1]) && std::isfinite(p[2]); }

// viridis sampled at t = 0, 1/9, ..., 1 (the ten-colour table of matplotlib's map); linear
// interpolation between samples keeps its monotone lightness.
constexpr std::array<std::array<int, 3>, 10> viridis_table{{{68, 1, 84},
                                                            {72, 40, 120},
                                                            {62, 74, 137},
                                                            {49, 104, 142},
                                                            {38, 130, 142},
                                                            {31, 158, 137},
                                                            {53, 183, 121},
                                                            {109, 205, 89},
                                                            {180, 222, 44},
                                                            {253, 231, 37}}};

constexpr std::array<double, 3> no_value_colour{0.62, 0.62, 0.62};
constexpr std::array<double, 3> plain_colour{0.55, 0.66, 0.80};  // when there is no scalar

struct View {
  V3 centre, right, up, forward;  // forward points from the eye into the scene
  V3 eye;
  bool perspective = false;
  double focal = 1.0;
  // maps camera-plane coordinates to pixels
  double s = 1, ox = 0, oy = 0;

  [[nodiscard]] std::array<double, 3> camera(const V3& p) const {
    const V3 d = sub(p, centre);
    double x = dot(d, right), y = dot(d, up);
    const double depth = dot(sub(p, eye), forward);
    if (perspective) {
      x *= focal / depth;
      y *= focal / depth;
    }
    return {x, y, depth};
  }
  [[nodiscard]] std::array<double, 2> pixel(const std::array<double, 3>& c) const { return {ox + s * c[0], oy - s * c[1]}; }
  // direction from a point towards the eye
  [[nodiscard]] V3 to_eye(const V3& p) const { return perspective ? normalized(sub(eye, p)) : scale(forward, -1); }
};

struct Primitive {
  double depth;
  std::uint8_t n;  // 2 = segment, 3 or 4 = face
  std::array<std::uint32_t, 4> v;
  double shade;  // Lambert factor (faces)
  bool highlighted = false;
};

std::string format_tick(double x) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%.4g", x);
  return buf;
}

// Fills a triangle (grown by half a pixel, so that neighbours overlap instead of letting the
// background show through their antialiased edges) with the colormap of the affine function
// taking values t at its corners, times `shade`; or with `flat` times `shade` if !valued.
void fill_triangle(cairo_t* cr, const std::array<std::array<double, 2>, 3>& px, const std::array<double, 3>& t,
                   bool valued, const std::array<double, 3>& flat, double shade) {
  // every edge moves out by half a pixel (moving the corners away from the centre would barely
  // widen the long edges of a thin triangle); the miter is capped at sharp corners
  const double area2 = (px[1][0] - px[0][0]) * (px[2][1] - px[0][1]) - (px[1][1] - px[0][1]) * (px[2][0] - px[0][0]);
  const double side = area2 >= 0 ? 1.0 : -1.0;
  auto outward = [&](std::size_t a, std::size_t b) {
    const double ex = px[b][0] - px[a][0], ey = px[b][1] - px[a][1], l = std::hypot(ex, ey);
    return l > 0 ? std::array<double, 2>{side * ey / l, -side * ex / l} : std::array<double, 2>{0, 0};
  };
  for (std::size_t k = 0; k < 3; ++k) {
    const auto n1 = outward((k + 2) % 3, k), n2 = outward(k, (k + 1) % 3);
    double mx = n1[0] + n2[0], my = n1[1] + n2[1];
    const double c = 1 + n1[0] * n2[0] + n1[1] * n2[1];
    if (c > 1e-6) mx /= c, my /= c;
    const double m = std::hypot(mx, my);
    if (m > 3) mx *= 3 / m, my *= 3 / m;
    const double x = px[k][0] + 0.5 * mx, y = px[k][1] + 0.5 * my;
    k == 0 ? cairo_move_to(cr, x, y) : cairo_line_to(cr, x, y);
  }
  cairo_close_path(cr);
  // gradient g of t over the picture: [p1 - p0; p2 - p0] g = [t1 - t0; t2 - t0]
  const double e1x = px[1][0] - px[0][0], e1y = px[1][1] - px[0][1];
  const double e2x = px[2][0] - px[0][0], e2y = px[2][1] - px[0][1];
  const double det = e1x * e2y - e1y * e2x;
  double gx = 0, gy = 0;
  if (valued && std::abs(det) > 1e-12) {
    const double d1 = t[1] - t[0], d2 = t[2] - t[0];
    gx = (d1 * e2y - d2 * e1y) / det;
    gy = (e1x * d2 - e2x * d1) / det;
  }
  const double g2 = gx * gx + gy * gy;
  if (!valued || g2 < 1e-14) {
    const auto c = valued ? viridis((t[0] + t[1] + t[2]) / 3) : flat;
    cairo_set_source_rgb(cr, c[0] * shade, c[1] * shade, c[2] * shade);
    cairo_fill(cr);
    return;
  }
  // the line along g from where t = 0 to where t = 1
  const double x0 = px[0][0] - t[0] * gx / g2, y0 = px[0][1] - t[0] * gy / g2;
  cairo_pattern_t* grad = cairo_pattern_create_linear(x0, y0, x0 + gx / g2, y0 + gy / g2);
  for (std::size_t i = 0; i < viridis_table.size(); ++i) {
    const double f = static_cast<double>(i) / (viridis_table.size() - 1);
    const auto c = viridis(f);
    cairo_pattern_add_color_stop_rgb(grad, f, c[0] * shade, c[1] * shade, c[2] * shade);
  }
  cairo_pattern_set_extend(grad, CAIRO_EXTEND_PAD);
  cairo_set_source(cr, grad);
  cairo_fill(cr);
  cairo_pattern_destroy(grad);
}

// About five round values (1, 2, 2.5 or 5 times a power of ten apart) within [lo, hi].
std::vector<double> nice_ticks(double lo, double hi) {
  const double raw = (hi - lo) / 5;
  const double mag = std::pow(10.0, std::floor(std::log10(raw)));
  double step = 10 * mag;
  for (double m : {1.0, 2.0, 2.5, 5.0})
    if (m * mag >= raw) {
      step = m * mag;
      break;
    }
  std::vector<double> t;
  for (double v = std::ceil(lo / step) * step; v <= hi + 1e-9 * step && t.size() < 12; v += step)
    t.push_back(std::abs(v) < 1e-12 * step ? 0.0 : v);
  return t;
}

struct Cairo {
  cairo_surface_t* surface;
  cairo_t* cr;
  Cairo(int w, int h) : surface(cairo_image_surface_create(CAIRO_FORMAT_RGB24, w, h)), cr(cairo_create(surface)) {}
  ~Cairo() {
    cairo_destroy(cr);
    cairo_surface_destroy(surface);
  }
  Cairo(const Cairo&) = delete;
  Cairo& operator=(const Cairo&) = delete;
};

}  // namespace

std::array<double, 3> viridis(double t) {
  if (!(t >= 0)) t = 0;  // also catches NaN
  if (t > 1) t = 1;
  const double x = t * (viridis_table.size() - 1);
  const std::size_t i = std::min<std::size_t>(static_cast<std::size_t>(x), viridis_table.size() - 2);
  const double f = x - static_cast<double>(i);
  std::array<double, 3> c{};
  for (std::size_t k = 0; k < 3; ++k)
    c[k] = ((1 - f) * viridis_table[i][k] + f * viridis_table[i + 1][k]) / 255.0;
  return c;
}

std::vector<BoundaryFace> boundary_faces(CellsView cells) {
  struct Entry {
    std::array<std::uint32_t, 4> key;  // sorted vertices, padded
    BoundaryFace face;
  };
  std::vector<Entry> faces;
  for (std::uint32_t c = 0; c < cells.size(); ++c) {
    const CellType t = cells.types[c];
    if (cell_dimension(t) != 3) continue;
    const std::uint32_t* v = cells.conn.data() + cells.offsets[c];
    for (auto f : cell_faces(t)) {
      Entry e{{0, 0, 0, 0}, {c, static_cast<std::uint8_t>(f.size()), {0, 0, 0, 0}}};
      for (std::size_t k = 0; k < f.size(); ++k) e.face.v[k] = e.key[k] = v[f[k]];
      for (std::size_t k = f.size(); k < 4; ++k) e.key[k] = std::numeric_limits<std::uint32_t>::max();
      std::sort(e.key.begin(), e.key.end());
      faces.push_back(e);
    }
  }
  std::sort(faces.begin(), faces.end(), [](const Entry& a, const Entry& b) {
    return a.key != b.key ? a.key < b.key : a.face.cell < b.face.cell;
  });
  std::vector<BoundaryFace> out;
  for (std::size_t i = 0; i < faces.size();) {
    std::size_t j = i + 1;
    while (j < faces.size() && faces[j].key == faces[i].key) ++j;
    if (j - i == 1) out.push_back(faces[i].face);
    i = j;
  }
  std::sort(out.begin(), out.end(), [](const BoundaryFace& a, const BoundaryFace& b) { return a.cell < b.cell; });
  for (std::uint32_t c = 0; c < cells.size(); ++c) {
    if (cell_dimension(cells.types[c]) != 2) continue;
    BoundaryFace f{c, static_cast<std::uint8_t>(cell_vertex_count(cells.types[c])), {0, 0, 0, 0}};
    for (std::size_t k = 0; k < f.size; ++k) f.v[k] = cells.conn[cells.offsets[c] + k];
    out.push_back(f);
  }
  return out;
}

void render_png(const std::filesystem::path& path, std::span<const Point3> points, CellsView cells,
                std::span<const double> scalar, const RenderOptions& opt) {
  if (!scalar.empty() && scalar.size() != points.size())
    throw std::invalid_argument("render_png: the scalar has " + std::to_string(scalar.size()) + " values for " +
                                std::to_string(points.size()) + " points");
  if (opt.width < min_render_width || opt.height < min_render_height || opt.width > max_render_size ||
      opt.height > max_render_size)
    throw std::invalid_argument("render_png: image size must be between " + std::to_string(min_render_width) + " x " +
                                std::to_string(min_render_height) + " and " + std::to_string(max_render_size) + " x " +
                                std::to_string(max_render_size));
  if (cells.offsets.size() != cells.size() + 1 || cells.offsets.back() != cells.conn.size())
    throw std::invalid_argument("render_png: cell offsets do not match the cell types and connectivity");
  for (std::uint32_t v : cells.conn)
    if (v >= points.size()) throw std::invalid_argument("render_png: a cell refers to a point that does not exist");

  const bool coloured = !scalar.empty();
  double lo = 0, hi = 1;
  if (opt.range) {
    std::tie(lo, hi) = *opt.range;
  } else if (coloured) {
    lo = std::numeric_limits<double>::infinity();
    hi = -lo;
    for (double s : scalar)
      if (std::isfinite(s)) {
        lo = std::min(lo, s);
        hi = std::max(hi, s);
      }
    if (!(lo <= hi)) lo = 0, hi = 1;  // no finite value at all
  }
  const double span = hi - lo;
  auto colour_of = [&](std::uint32_t p) {
    if (!coloured) return plain_colour;
    const double s = scalar[p];
    if (!std::isfinite(s)) return no_value_colour;
    return viridis(span > 0 ? (s - lo) / span : 0.5);
  };

  // Bounding box of the finite points decides the view.
  V3 bmin{std::numeric_limits<double>::infinity(), 0, 0}, bmax{-std::numeric_limits<double>::infinity(), 0, 0};
  bool any = false;
  for (const auto& p : points) {
    if (!finite(p)) continue;
    if (!any) bmin = bmax = p;
    any = true;
    for (std::size_t k = 0; k < 3; ++k) {
      bmin[k] = std::min(bmin[k], p[k]);
      bmax[k] = std::max(bmax[k], p[k]);
    }
  }
  const V3 centre = scale(add(bmin, bmax), 0.5);
  const V3 ext = sub(bmax, bmin);
  double radius = 0.5 * std::sqrt(dot(ext, ext));
  if (!(radius > 0)) radius = 1;
  const bool flat = ext[2] <= 1e-9 * std::max({ext[0], ext[1], 1e-300});
  const double el = (opt.camera.elevation_deg ? *opt.camera.elevation_deg : (flat ? 60.0 : 25.0)) * std::numbers::pi / 180;
  const double az = opt.camera.azimuth_deg * std::numbers::pi / 180;

  View view;
  view.centre = centre;
  const V3 to_eye{std::sin(az) * std::cos(el), -std::cos(az) * std::cos(el), std::sin(el)};
  view.forward = scale(to_eye, -1);
  // looking straight down (or up) has no horizon: take +y as the picture's up then
  const V3 world_up = std::abs(std::sin(el)) > 0.999 ? V3{0, 1, 0} : V3{0, 0, 1};
  view.right = normalized(cross(view.forward, world_up));
  view.up = cross(view.right, view.forward);
  view.perspective = opt.camera.projection == Camera::Projection::perspective;
  const double half_fov = std::clamp(opt.camera.fov_deg, 5.0, 120.0) * std::numbers::pi / 360;
  const double distance = view.perspective ? 1.15 * radius / std::sin(half_fov) : 4 * radius;
  view.eye = add(centre, scale(to_eye, distance));
  view.focal = distance;

  std::vector<std::array<double, 3>> cam(points.size());
  std::vector<std::uint8_t> ok(points.size());
  for (std::size_t i = 0; i < points.size(); ++i) {
    ok[i] = finite(points[i]) ? 1 : 0;
    if (ok[i]) cam[i] = view.camera(points[i]);
    if (ok[i] && view.perspective && cam[i][2] <= 1e-9 * distance) ok[i] = 0;  // behind the eye
  }

  // Primitives: boundary faces facing the camera (all faces in wireframe), 2D cells (two-sided),
  // segments; each with its mean depth for back-to-front drawing.
  const V3 light = normalized(add(add(to_eye, scale(view.up, 0.6)), scale(view.right, -0.35)));
  std::vector<Primitive> prims;
  for (const BoundaryFace& f : boundary_faces(cells)) {
    bool good = true;
    V3 c{0, 0, 0};
    for (std::size_t k = 0; k < f.size; ++k) {
      good = good && ok[f.v[k]];
      if (good) c = add(c, points[f.v[k]]);
    }
    if (!good) continue;
    c = scale(c, 1.0 / f.size);
    V3 n{0, 0, 0};  // Newell normal: robust for non-planar quads
    for (std::size_t k = 0; k < f.size; ++k) n = add(n, cross(points[f.v[k]], points[f.v[(k + 1) % f.size]]));
    n = normalized(n);
    double facing = dot(n, view.to_eye(c));
    const bool two_sided = cell_dimension(cells.types[f.cell]) == 2;
    if (opt.mode == RenderMode::shaded && !two_sided && facing <= 0) continue;
    if (facing < 0) {
      n = scale(n, -1);
      facing = -facing;
    }
    // a key light from the upper left plus a weaker headlight, so no visible face goes black
    const double lambert = std::max(0.0, dot(n, light));
    double depth = 0;
    for (std::size_t k = 0; k < f.size; ++k) depth += cam[f.v[k]][2];
    const bool highlighted = opt.highlight && opt.highlight(std::span<const std::uint32_t>(f.v.data(), f.size));
    prims.push_back({depth / f.size, f.size, f.v, 0.30 + 0.50 * lambert + 0.25 * facing, highlighted});
  }
  for (std::uint32_t c = 0; c < cells.size(); ++c) {
    if (cells.types[c] != CellType::segment) continue;
    const std::uint32_t a = cells.conn[cells.offsets[c]], b = cells.conn[cells.offsets[c] + 1];
    if (!ok[a] || !ok[b]) continue;
    prims.push_back({0.5 * (cam[a][2] + cam[b][2]), 2, {a, b, 0, 0}, 1.0});
  }
  std::stable_sort(prims.begin(), prims.end(), [](const Primitive& a, const Primitive& b) { return a.depth > b.depth; });

  // Layout: title band on top, colour bar on the right, the mesh fitted into the rest.
  const double W = opt.width, H = opt.height;
  const double unit = std::min(W, H) / 800.0;  // sizes scale with the picture
  const double top = opt.title.empty() ? 16 * unit : 56 * unit;
  const double bar_band = coloured ? 150 * unit : 0;
  const double margin = 24 * unit;
  const double area_w = W - bar_band - 2 * margin, area_h = H - top - 2 * margin;
  double xmin = std::numeric_limits<double>::infinity(), xmax = -xmin, ymin = xmin, ymax = -xmin;
  for (const auto& p : prims)
    for (std::size_t k = 0; k < p.n; ++k) {
      const auto& c = cam[p.v[k]];
      xmin = std::min(xmin, c[0]);
      xmax = std::max(xmax, c[0]);
      ymin = std::min(ymin, c[1]);
      ymax = std::max(ymax, c[1]);
    }
  if (prims.empty()) xmin = ymin = -1, xmax = ymax = 1;
  const double w = std::max(xmax - xmin, 1e-12 * radius), h = std::max(ymax - ymin, 1e-12 * radius);
  view.s = std::min(area_w / w, area_h / h);
  view.ox = margin + 0.5 * area_w - view.s * 0.5 * (xmin + xmax);
  view.oy = top + margin + 0.5 * area_h + view.s * 0.5 * (ymin + ymax);

  Cairo cx(opt.width, opt.height);
  cairo_t* cr = cx.cr;
  cairo_set_source_rgb(cr, 1, 1, 1);
  cairo_paint(cr);
  cairo_set_line_join(cr, CAIRO_LINE_JOIN_ROUND);
  cairo_set_line_cap(cr, CAIRO_LINE_CAP_ROUND);
  const double edge_width = std::clamp(0.9 * unit, 0.6, 3.0);
  const double depth_lo = prims.empty() ? 0 : prims.back().depth, depth_hi = prims.empty() ? 1 : prims.front().depth;

  auto trace = [&](const Primitive& p) {
    for (std::size_t k = 0; k < p.n; ++k) {
      const auto px = view.pixel(cam[p.v[k]]);
      k == 0 ? cairo_move_to(cr, px[0], px[1]) : cairo_line_to(cr, px[0], px[1]);
    }
    if (p.n > 2) cairo_close_path(cr);
  };
  auto mean_colour = [&](const Primitive& p) {
    std::array<double, 3> m{0, 0, 0};
    for (std::size_t k = 0; k < p.n; ++k) {
      const auto c = colour_of(p.v[k]);
      for (std::size_t i = 0; i < 3; ++i) m[i] += c[i] / p.n;
    }
    return m;
  };

  for (const Primitive& p : prims) {
    if (opt.mode == RenderMode::wireframe) {
      // farther edges fade a little so the front of the object reads first
      const double t = depth_hi > depth_lo ? (p.depth - depth_lo) / (depth_hi - depth_lo) : 0;
      const auto c = p.highlighted ? opt.highlight_colour : coloured ? mean_colour(p) : std::array<double, 3>{0.1, 0.15, 0.25};
      cairo_set_source_rgba(cr, c[0], c[1], c[2], 1.0 - 0.55 * t);
      cairo_set_line_width(cr, p.n == 2 || p.highlighted ? 2.5 * edge_width : edge_width);
      trace(p);
      cairo_stroke(cr);
      continue;
    }
    if (p.n == 2) {
      const auto c = mean_colour(p);
      cairo_set_line_width(cr, 3.5 * edge_width);
      cairo_set_source_rgb(cr, 0.15, 0.15, 0.15);
      trace(p);
      cairo_stroke_preserve(cr);
      cairo_new_path(cr);
      cairo_set_line_width(cr, 2.2 * edge_width);
      cairo_set_source_rgb(cr, c[0], c[1], c[2]);
      trace(p);
      cairo_stroke(cr);
      continue;
    }
    // Per-corner colours blended across the face (a cairo mesh gradient), times the face's light.
    // Quads are drawn as two triangles: over a triangle the interpolated scalar is affine in
    // the picture, so a cairo linear gradient carrying the colormap's stops colours every pixel
    // exactly (the scalar is interpolated, then mapped, as in ParaView).
    const std::array<std::array<std::size_t, 3>, 2> halves{{{0, 1, 2}, {0, 2, 3}}};
    for (std::size_t h = 0; h + 2 < p.n; ++h) {
      std::array<std::array<double, 2>, 3> px{};
      std::array<double, 3> t{};
      bool valued = coloured;
      for (std::size_t k = 0; k < 3; ++k) {
        const std::uint32_t v = p.v[halves[h][k]];
        px[k] = view.pixel(cam[v]);
        if (coloured) {
          valued = valued && std::isfinite(scalar[v]);
          t[k] = span > 0 ? (scalar[v] - lo) / span : 0.5;
        }
      }
      if (p.highlighted)
        fill_triangle(cr, px, t, false, opt.highlight_colour, p.shade);
      else
        fill_triangle(cr, px, t, valued, coloured ? no_value_colour : plain_colour, p.shade);
    }
    if (opt.edges) {
      cairo_set_source_rgba(cr, 0.08, 0.08, 0.1, 0.55);
      cairo_set_line_width(cr, edge_width);
      trace(p);
      cairo_stroke(cr);
    }
  }

  cairo_select_font_face(cr, "DejaVu Sans", CAIRO_FONT_SLANT_NORMAL, CAIRO_FONT_WEIGHT_NORMAL);
  if (!opt.title.empty()) {
    cairo_set_source_rgb(cr, 0.1, 0.1, 0.1);
    cairo_set_font_size(cr, 24 * unit);
    cairo_move_to(cr, margin, 38 * unit);
    cairo_show_text(cr, opt.title.c_str());
  }

  // Axis triad (where x, y, z point in this view): bottom of the right band, or bottom left
  // when there is no colour bar.
  {
    const double L = 30 * unit;
    const double x0 = coloured ? W - bar_band + 50 * unit : margin + 40 * unit, y0 = H - margin - 40 * unit;
    static constexpr const char* names[3] = {"x", "y", "z"};
    static constexpr std::array<double, 3> axis_colour[3] = {{0.80, 0.15, 0.15}, {0.15, 0.60, 0.15}, {0.15, 0.30, 0.85}};
    cairo_set_font_size(cr, 14 * unit);
    cairo_set_line_width(cr, 2 * unit);
    for (std::size_t a = 0; a < 3; ++a) {
      V3 d{0, 0, 0};
      d[a] = 1;
      const double dx = dot(d, view.right), dy = dot(d, view.up);
      cairo_set_source_rgb(cr, axis_colour[a][0], axis_colour[a][1], axis_colour[a][2]);
      cairo_move_to(cr, x0, y0);
      cairo_line_to(cr, x0 + L * dx, y0 - L * dy);
      cairo_stroke(cr);
      cairo_move_to(cr, x0 + (L + 8 * unit) * dx - 4 * unit, y0 - (L + 8 * unit) * dy + 5 * unit);
      cairo_show_text(cr, names[a]);
    }
  }

  if (coloured) {
    const double bx = W - bar_band + 22 * unit, bw = 24 * unit;
    const double by = top + margin + 30 * unit, bh = std::max(60.0, H - by - margin - 130 * unit);
    cairo_pattern_t* grad = cairo_pattern_create_linear(0, by + bh, 0, by);
    for (int i = 0; i <= 32; ++i) {
      const auto c = viridis(i / 32.0);
      cairo_pattern_add_color_stop_rgb(grad, i / 32.0, c[0], c[1], c[2]);
    }
    cairo_rectangle(cr, bx, by, bw, bh);
    cairo_set_source(cr, grad);
    cairo_fill_preserve(cr);
    cairo_pattern_destroy(grad);
    cairo_set_source_rgb(cr, 0.2, 0.2, 0.2);
    cairo_set_line_width(cr, 1 * unit);
    cairo_stroke(cr);
    cairo_set_font_size(cr, 15 * unit);
    if (span > 0) {
      for (const double v : nice_ticks(lo, hi)) {
        const double y = by + bh * (1 - (v - lo) / span);
        cairo_move_to(cr, bx + bw, y);
        cairo_line_to(cr, bx + bw + 6 * unit, y);
        cairo_stroke(cr);
        cairo_move_to(cr, bx + bw + 10 * unit, y + 5 * unit);
        cairo_show_text(cr, format_tick(v).c_str());
      }
    } else {
      cairo_move_to(cr, bx + bw + 10 * unit, by + 0.5 * bh + 5 * unit);
      cairo_show_text(cr, format_tick(lo).c_str());
    }
    if (!opt.scalar_name.empty()) {
      cairo_set_font_size(cr, 16 * unit);
      cairo_text_extents_t te;
      cairo_text_extents(cr, opt.scalar_name.c_str(), &te);
      cairo_move_to(cr, std::min(bx, W - te.x_advance - 6 * unit), by - 14 * unit);
      cairo_show_text(cr, opt.scalar_name.c_str());
    }
    // the exact range, which the rounded ticks do not show
    cairo_set_font_size(cr, 12 * unit);
    cairo_set_source_rgb(cr, 0.3, 0.3, 0.3);
    const std::string range_text[2] = {"max " + format_tick(hi), "min " + format_tick(lo)};
    for (int i = 0; i < 2; ++i) {
      cairo_move_to(cr, bx - 8 * unit, by + bh + (22 + 16 * i) * unit);
      cairo_show_text(cr, range_text[i].c_str());
    }
  }

  cairo_surface_flush(cx.surface);
  if (cairo_status(cr) != CAIRO_STATUS_SUCCESS)
    throw std::runtime_error(std::string("render_png: cairo failed: ") + cairo_status_to_string(cairo_status(cr)));
  // written aside and renamed, like the VTU frames, so a viewer never catches half a picture
  const std::string part = path.string() + ".part";
  const cairo_status_t st = cairo_surface_write_to_png(cx.surface, part.c_str());
  if (st != CAIRO_STATUS_SUCCESS) {
    std::error_code ec;
    std::filesystem::remove(part, ec);  // half a picture: never left behind
    throw FileError(path.string(), 0, std::string("cannot write the PNG: ") + cairo_status_to_string(st));
  }
  publish_part(part, path);
}

}  // namespace sewn::io
