// Preview pictures: several orthographic views of bodies and garments side by side.
//
// Per view: every vertex is projected onto the camera's right/up axes at a scale shared by all
// views, the scene is rasterized at `supersample` x `supersample` samples per pixel into a
// visibility buffer (geometry/rasterize.hpp), each sample is shaded from interpolated normals and
// colours, and the samples are averaged in linear light. Lights are fixed in the camera's frame, so
// front, side and back look alike: hemisphere ambient, a key light from the upper left, a fill
// from the right and a rim light from behind that separates the silhouette from the backdrop.
// Surfaces seen from behind (the inside of a garment) are lit with the flipped normal and darkened.
// Screen-space ambient occlusion darkens folds and the skin under a garment's edge.
// The floor shadow is the scene rendered from below into a height-above-floor map, turned into
// occlusion (falling off with height) and blurred; backdrop samples look it up where their view ray
// meets the floor plane.
#include <algorithm>
#include <array>
#include <cmath>
#include <numbers>
#include <stdexcept>

#include <Eigen/Geometry>
#include <fmt/format.h>

#include "drape/error.hpp"
#include "drape/render.hpp"
#include "geometry/rasterize.hpp"

namespace drape {

RenderItem body_item(const Mesh& body) {
  RenderItem item;
  item.mesh = &body;
  item.color = srgb8(226, 186, 160);
  return item;
}

RenderItem garment_item(const Mesh& garment, size_t index) {
  // Fabric colours that read well against skin and a light backdrop, outermost garments last.
  static constexpr int kPalette[][3] = {{58, 94, 140},  {176, 74, 60},  {96, 128, 92}, {70, 70, 78},
                                        {204, 156, 62}, {120, 80, 122}, {66, 140, 150}, {150, 120, 96}};
  const auto& c = kPalette[index % std::size(kPalette)];
  RenderItem item;
  item.mesh = &garment;
  item.color = srgb8(c[0], c[1], c[2]);
  return item;
}

RenderItem scalar_item(const Mesh& mesh, std::span<const float> values, const Legend& legend) {
  if (values.size() != mesh.positions.size())
    throw std::invalid_argument(fmt::format("render: fit map of '{}' has {} values for {} vertices", mesh.name,
                                            values.size(), mesh.positions.size()));
  RenderItem item;
  item.mesh = &mesh;
  item.vertex_colors = colorize(values, legend.map, legend.lo, legend.hi);
  return item;
}

std::vector<ViewSpec> parse_views(std::string_view comma_separated, const std::string& source) {
  std::vector<ViewSpec> views;
  size_t start = 0;
  while (start <= comma_separated.size()) {
    const size_t end = std::min(comma_separated.find(',', start), comma_separated.size());
    std::string name(comma_separated.substr(start, end - start));
    name.erase(0, name.find_first_not_of(' '));
    name.erase(name.find_last_not_of(' ') + 1);
    if (name == "front") views.push_back({name, 0.0f});
    else if (name == "back") views.push_back({name, 180.0f});
    else if (name == "left") views.push_back({name, 90.0f});
    else if (name == "right" || name == "side") views.push_back({name, 270.0f});
    else throw InputError(source, fmt::format("unknown view '{}' (expected front, side, back, left or right)", name));
    start = end + 1;
  }
  return views;
}

namespace {

// All items merged into one triangle soup with per-vertex normal and albedo.
struct Scene {
  std::vector<Vec3f> positions, normals, albedo;
  std::vector<Tri> triangles;
  Bounds box;
};

Scene gather(const std::vector<RenderItem>& items) {
  Scene s;
  for (const RenderItem& item : items) {
    if (item.mesh == nullptr || item.mesh->triangles.empty()) continue;
    const Mesh& m = *item.mesh;
    const auto base = static_cast<uint32_t>(s.positions.size());
    s.positions.insert(s.positions.end(), m.positions.begin(), m.positions.end());
    const std::vector<Vec3f> normals = m.normals.size() == m.positions.size() ? m.normals : vertex_normals(m.positions, m.triangles);
    s.normals.insert(s.normals.end(), normals.begin(), normals.end());
    for (size_t v = 0; v < m.positions.size(); ++v) {
      if (item.vertex_colors.size() == m.positions.size()) s.albedo.push_back(item.vertex_colors[v].head<3>());
      else if (m.colors.size() == m.positions.size()) s.albedo.push_back(m.colors[v].head<3>());
      else s.albedo.push_back(item.color);
    }
    for (const Tri& t : m.triangles) {
      if (t[0] >= m.positions.size() || t[1] >= m.positions.size() || t[2] >= m.positions.size())
        throw std::invalid_argument(fmt::format("render: mesh '{}' has a triangle with a vertex index out of range", m.name));
      s.triangles.push_back({t[0] + base, t[1] + base, t[2] + base});
    }
    for (const Vec3f& p : m.positions)
      if (p.allFinite()) s.box.extend(p);
  }
  if (s.triangles.empty() || s.box.empty()) throw std::invalid_argument("render: nothing to draw (no triangles)");
  return s;
}

// An orthographic camera looking at the scene from yaw/elevation.
struct Camera {
  Vec3f forward, right, up;
  float center_a = 0, center_b = 0;  // projected scene centre on right/up
  float extent_a = 0, extent_b = 0;
};

Camera make_camera(float yaw_degrees, float elevation_degrees, const Scene& s) {
  const float yaw = yaw_degrees * std::numbers::pi_v<float> / 180, el = elevation_degrees * std::numbers::pi_v<float> / 180;
  const Vec3f to_camera(std::cos(el) * std::sin(yaw), std::sin(el), std::cos(el) * std::cos(yaw));
  Camera c;
  c.forward = -to_camera;
  c.right = c.forward.cross(Vec3f::UnitY()).normalized();
  c.up = c.right.cross(c.forward);
  float a0 = 1e30f, a1 = -1e30f, b0 = 1e30f, b1 = -1e30f;
  for (const Vec3f& p : s.positions) {
    if (!p.allFinite()) continue;
    const float a = p.dot(c.right), b = p.dot(c.up);
    a0 = std::min(a0, a);
    a1 = std::max(a1, a);
    b0 = std::min(b0, b);
    b1 = std::max(b1, b);
  }
  c.center_a = 0.5f * (a0 + a1);
  c.center_b = 0.5f * (b0 + b1);
  c.extent_a = a1 - a0;
  c.extent_b = b1 - b0;
  return c;
}

// Occlusion of the floor plane y = floor_y by the scene above it, on a grid over x/z.
struct FloorShadow {
  float floor_y = 0, min_x = 0, min_z = 0, cell = 1;
  int nx = 0, nz = 0;
  std::vector<float> occlusion;

  float at(float x, float z) const {
    const float fx = (x - min_x) / cell - 0.5f, fz = (z - min_z) / cell - 0.5f;
    if (!(fx >= 0 && fz >= 0 && fx < static_cast<float>(nx - 1) && fz < static_cast<float>(nz - 1))) return 0.0f;
    const int i = static_cast<int>(fx), k = static_cast<int>(fz);
    const float u = fx - static_cast<float>(i), w = fz - static_cast<float>(k);
    const auto o = [&](int a, int b) { return occlusion[static_cast<size_t>(b) * static_cast<size_t>(nx) + static_cast<size_t>(a)]; };
    return (1 - w) * ((1 - u) * o(i, k) + u * o(i + 1, k)) + w * ((1 - u) * o(i, k + 1) + u * o(i + 1, k + 1));
  }
};

// Three box blurs approximate a Gaussian; separable, in place.
void blur(std::vector<float>& v, int nx, int nz, int radius) {
  std::vector<float> tmp(v.size());
  for (int pass = 0; pass < 3; ++pass)
    for (int axis = 0; axis < 2; ++axis) {
      const int n = axis == 0 ? nx : nz, lines = axis == 0 ? nz : nx;
      for (int line = 0; line < lines; ++line) {
        const auto at = [&](int k) -> float& {
          const int x = axis == 0 ? k : line, z = axis == 0 ? line : k;
          return v[static_cast<size_t>(z) * static_cast<size_t>(nx) + static_cast<size_t>(x)];
        };
        for (int k = 0; k < n; ++k) {
          float sum = 0;
          for (int d = -radius; d <= radius; ++d) {
            const int q = k + d;
            if (q >= 0 && q < n) sum += at(q);
          }
          tmp[static_cast<size_t>(k)] = sum / static_cast<float>(2 * radius + 1);
        }
        for (int k = 0; k < n; ++k) at(k) = tmp[static_cast<size_t>(k)];
      }
    }
}

FloorShadow make_floor_shadow(const Scene& s, VisibilityBuffer& vis) {
  FloorShadow f;
  const float height = std::max(s.box.size().y(), 1e-3f);
  const float margin = 0.35f * height;
  f.floor_y = s.box.min.y();
  f.min_x = s.box.min.x() - margin;
  f.min_z = s.box.min.z() - margin;
  const float span_x = s.box.size().x() + 2 * margin, span_z = s.box.size().z() + 2 * margin;
  f.cell = std::max(span_x, span_z) / 160.0f;
  f.nx = std::max(2, static_cast<int>(std::ceil(span_x / f.cell)));
  f.nz = std::max(2, static_cast<int>(std::ceil(span_z / f.cell)));
  // Seen from below: the depth is the height, so the lowest surface above each cell wins.
  std::vector<ScreenVertex> screen(s.positions.size());
  for (size_t v = 0; v < s.positions.size(); ++v) {
    const Vec3f& p = s.positions[v];
    screen[v] = {(p.x() - f.min_x) / f.cell, (p.z() - f.min_z) / f.cell, p.y(), 1.0f};
  }
  rasterize(screen, s.triangles, f.nx, f.nz, vis);
  const float falloff = 0.12f * height;
  f.occlusion.assign(vis.pixel_count(), 0.0f);
  for (size_t q = 0; q < vis.pixel_count(); ++q)
    if (vis.covered(q)) f.occlusion[q] = std::exp(-std::max(0.0f, vis.depth[q] - f.floor_y) / falloff);
  blur(f.occlusion, f.nx, f.nz, std::max(1, static_cast<int>(0.02f * height / f.cell)));
  return f;
}

struct Lights {
  Vec3f key, fill, rim, key_half;
};

Lights camera_lights(const Camera& c) {
  const Vec3f to_viewer = -c.forward;
  Lights l;
  l.key = (-0.55f * c.right + 0.75f * c.up + 0.9f * to_viewer).normalized();
  l.fill = (0.8f * c.right + 0.1f * c.up + 0.6f * to_viewer).normalized();
  l.rim = (0.4f * c.right + 0.6f * c.up - 0.7f * to_viewer).normalized();
  l.key_half = (l.key + to_viewer).normalized();
  return l;
}

Vec3f shade(const Vec3f& albedo_in, Vec3f n, const Vec3f& to_viewer, const Lights& l) {
  Vec3f albedo = albedo_in;
  const float len = n.norm();
  n = len > 0 ? Vec3f(n / len) : to_viewer;
  if (n.dot(to_viewer) < 0) {  // seen from behind: the inside of cloth
    n = -n;
    albedo *= 0.6f;
  }
  const float sky = 0.5f + 0.5f * n.y();
  const float ambient = 0.10f + 0.16f * sky;
  const float diffuse = ambient + 0.85f * std::max(0.0f, n.dot(l.key)) + 0.20f * std::max(0.0f, n.dot(l.fill)) +
                        0.22f * std::max(0.0f, n.dot(l.rim));
  float specular = std::max(0.0f, n.dot(l.key_half));
  for (int k = 0; k < 5; ++k) specular *= specular;  // ^32
  specular *= 0.05f;
  return albedo * diffuse + Vec3f::Constant(specular);
}

// Ambient occlusion in screen space ("Alchemy" style, McGuire et al. 2011): for each output pixel
// the visible surface point P with normal n is compared with the visible points Q in a disc of
// `radius` metres around it; points above P's tangent plane, (Q - P).n > 0, occlude it, weighted
// by the cosine and fading out with distance. Coplanar neighbours do not occlude, so tilted
// surfaces stay clean while folds, armpits and the skin just under a hem darken. Deterministic:
// a fixed spiral of samples, no noise.
std::vector<float> ambient_occlusion(const VisibilityBuffer& vis, const Scene& scene, const Camera& cam, int ss,
                                     int width, int height, float samples_per_metre, float radius) {
  const size_t pixels = static_cast<size_t>(width) * static_cast<size_t>(height);
  std::vector<Vec3f> position(pixels), normal(pixels);
  std::vector<uint8_t> covered(pixels, 0);
  const Vec3f to_viewer = -cam.forward;
  const int sw = width * ss, sh = height * ss;
  // Camera-space point and viewer-facing normal at the centre sample of every output pixel.
#pragma omp parallel for schedule(static)
  for (int y = 0; y < height; ++y)
    for (int x = 0; x < width; ++x) {
      const int px = x * ss + ss / 2, py = y * ss + ss / 2;
      const size_t q = static_cast<size_t>(py) * static_cast<size_t>(sw) + static_cast<size_t>(px);
      const size_t o = static_cast<size_t>(y) * static_cast<size_t>(width) + static_cast<size_t>(x);
      if (!vis.covered(q)) continue;
      Vec3f n = interpolate<Vec3f>(vis, q, scene.triangles, scene.normals);
      const float len = n.norm();
      n = len > 0 ? Vec3f(n / len) : to_viewer;
      if (n.dot(to_viewer) < 0) n = -n;
      position[o] = Vec3f((static_cast<float>(px) + 0.5f - 0.5f * static_cast<float>(sw)) / samples_per_metre,
                          (0.5f * static_cast<float>(sh) - static_cast<float>(py) - 0.5f) / samples_per_metre,
                          -vis.depth[q]);
      normal[o] = Vec3f(n.dot(cam.right), n.dot(cam.up), n.dot(to_viewer));
      covered[o] = 1;
    }
  // A golden-angle spiral of sample offsets in output pixels.
  constexpr int kSamples = 24;
  const float radius_px = radius * samples_per_metre / static_cast<float>(ss);
  std::array<std::array<int, 2>, kSamples> offsets{};
  for (int k = 0; k < kSamples; ++k) {
    const float r = radius_px * std::sqrt((static_cast<float>(k) + 0.5f) / kSamples);
    const float angle = 2.39996323f * static_cast<float>(k);
    offsets[static_cast<size_t>(k)] = {static_cast<int>(std::lround(r * std::cos(angle))),
                                       static_cast<int>(std::lround(r * std::sin(angle)))};
  }
  std::vector<float> occlusion(pixels, 0.0f);
  const float radius2 = radius * radius, bias = 0.01f * radius;
#pragma omp parallel for schedule(dynamic, 8)
  for (int y = 0; y < height; ++y)
    for (int x = 0; x < width; ++x) {
      const size_t o = static_cast<size_t>(y) * static_cast<size_t>(width) + static_cast<size_t>(x);
      if (!covered[o]) continue;
      float sum = 0;
      for (const auto& d : offsets) {
        const int qx = x + d[0], qy = y + d[1];
        if (qx < 0 || qy < 0 || qx >= width || qy >= height) continue;
        const size_t qo = static_cast<size_t>(qy) * static_cast<size_t>(width) + static_cast<size_t>(qx);
        if (!covered[qo]) continue;
        const Vec3f v = position[qo] - position[o];
        const float d2 = v.squaredNorm();
        if (d2 >= radius2 || d2 <= 0) continue;
        sum += std::max(0.0f, v.dot(normal[o]) - bias) / std::sqrt(d2) * (1.0f - d2 / radius2);
      }
      occlusion[o] = std::min(1.0f, 3.0f * sum / kSamples);
    }
  return occlusion;
}

// Linear light to an 8-bit sRGB value through a table (immutable once built; no pow per pixel).
uint8_t to_byte(float linear) {
  constexpr int kSteps = 4096;
  static const std::array<uint8_t, kSteps + 1> table = [] {
    std::array<uint8_t, kSteps + 1> t{};
    for (int k = 0; k <= kSteps; ++k)
      t[static_cast<size_t>(k)] = static_cast<uint8_t>(std::lround(255.0f * linear_to_srgb(static_cast<float>(k) / kSteps)));
    return t;
  }();
  const float x = linear > 0.0f ? std::min(linear, 1.0f) * kSteps : 0.0f;  // NaN -> 0
  return table[static_cast<size_t>(x + 0.5f)];
}

}  // namespace

Image render_views(const std::vector<RenderItem>& items, const RenderOptions& options) {
  if (options.views.empty()) throw std::invalid_argument("render: no views");
  if (options.width < 32 || options.height < 32 || options.width > 16384 || options.height > 16384)
    throw std::invalid_argument("render: picture size must be between 32 and 16384 pixels");
  if (static_cast<int64_t>(options.width) * options.height > (int64_t{1} << 26))
    throw std::invalid_argument("render: picture larger than 64 megapixels");
  if (options.supersample < 1 || options.supersample > 8) throw std::invalid_argument("render: supersample must be 1..8");
  if (!(std::abs(options.elevation_degrees) <= 80.0f))
    throw std::invalid_argument("render: camera elevation must be within +-80 degrees");
  const Scene scene = gather(items);

  // Layout: title band on top, view labels below the panels, legend strip on the right.
  const int text_scale = std::max(1, options.height / 300);
  const int title_h = options.title.empty() ? 0 : 16 * text_scale;
  const int label_h = options.view_labels ? 16 * text_scale : 0;
  std::vector<std::string> legend_ticks;
  int legend_w = 0;
  if (options.legend) {
    for (int k = 0; k <= 4; ++k)
      legend_ticks.push_back(fmt::format("{:.3g}", options.legend->lo + (options.legend->hi - options.legend->lo) * static_cast<float>(k) / 4));
    int widest = text_width(options.legend->title, text_scale);
    for (const auto& t : legend_ticks) widest = std::max(widest, 15 * text_scale + text_width(t, text_scale));
    legend_w = widest + 12 * text_scale;
  }
  const int panel_count = static_cast<int>(options.views.size());
  const int panel_w = (options.width - legend_w) / panel_count, panel_h = options.height - title_h - label_h;
  if (panel_w < 8 || panel_h < 8) throw std::invalid_argument("render: picture too small for its views and legend");

  // One scale for all views: the largest that fits every view with a margin.
  std::vector<Camera> cameras;
  float scale = std::numeric_limits<float>::max();  // output pixels per metre
  for (const ViewSpec& view : options.views) {
    cameras.push_back(make_camera(view.yaw_degrees, options.elevation_degrees, scene));
    const Camera& c = cameras.back();
    scale = std::min(scale, 0.88f * static_cast<float>(panel_w) / std::max(c.extent_a, 1e-6f));
    scale = std::min(scale, 0.90f * static_cast<float>(panel_h) / std::max(c.extent_b, 1e-6f));
  }
  if (options.pixels_per_metre > 0.0f) scale = options.pixels_per_metre;

  const bool shadow = options.floor_shadow && options.elevation_degrees > 0.5f;
  VisibilityBuffer vis;
  FloorShadow floor;
  if (shadow) floor = make_floor_shadow(scene, vis);

  Image image(options.width, options.height);
  // Backdrop of the whole picture (title, labels and legend sit on it too).
  for (int y = 0; y < options.height; ++y) {
    const float t = static_cast<float>(y) / static_cast<float>(options.height - 1);
    const Vec3f c = (1 - t) * options.background_top + t * options.background_bottom;
    for (int x = 0; x < options.width; ++x) {
      uint8_t* px = image.pixel(x, y);
      px[0] = to_byte(c.x());
      px[1] = to_byte(c.y());
      px[2] = to_byte(c.z());
    }
  }

  // Supersampling is lowered for very large pictures so a panel's sample buffers stay under
  // about half a gigabyte (2^25 samples of 16 bytes).
  constexpr double kMaxSamples = double(1 << 25);
  const double panel_pixels = static_cast<double>(panel_w) * static_cast<double>(panel_h);
  const int ss = std::max(1, std::min(options.supersample, static_cast<int>(std::sqrt(kMaxSamples / panel_pixels))));
  const int sw = panel_w * ss, sh = panel_h * ss;
  std::vector<ScreenVertex> screen(scene.positions.size());
  for (size_t k = 0; k < cameras.size(); ++k) {
    const Camera& cam = cameras[k];
    const float s = scale * static_cast<float>(ss);
    for (size_t v = 0; v < scene.positions.size(); ++v) {
      const Vec3f& p = scene.positions[v];
      screen[v] = {(p.dot(cam.right) - cam.center_a) * s + 0.5f * static_cast<float>(sw),
                   0.5f * static_cast<float>(sh) - (p.dot(cam.up) - cam.center_b) * s, p.dot(cam.forward), 1.0f};
    }
    rasterize(screen, scene.triangles, sw, sh, vis);
    const std::vector<float> occlusion =
        options.ambient_occlusion
            ? ambient_occlusion(vis, scene, cam, ss, panel_w, panel_h, s, 0.035f * std::max(scene.box.size().y(), 0.05f))
            : std::vector<float>();
    const Lights lights = camera_lights(cam);
    const Vec3f to_viewer = -cam.forward;
    const int x0 = static_cast<int>(k) * panel_w;

#pragma omp parallel for schedule(dynamic, 4)
    for (int y = 0; y < panel_h; ++y) {
      const float t = static_cast<float>(title_h + y) / static_cast<float>(options.height - 1);
      const Vec3f backdrop = (1 - t) * options.background_top + t * options.background_bottom;
      for (int x = 0; x < panel_w; ++x) {
        Vec3f sum = Vec3f::Zero();
        const float open =
            occlusion.empty() ? 1.0f : 1.0f - 0.6f * occlusion[static_cast<size_t>(y) * static_cast<size_t>(panel_w) + static_cast<size_t>(x)];
        for (int sy = 0; sy < ss; ++sy)
          for (int sx = 0; sx < ss; ++sx) {
            const int px = x * ss + sx, py = y * ss + sy;
            const size_t q = static_cast<size_t>(py) * static_cast<size_t>(sw) + static_cast<size_t>(px);
            if (vis.covered(q)) {
              const Vec3f n = interpolate<Vec3f>(vis, q, scene.triangles, scene.normals);
              const Vec3f albedo = interpolate<Vec3f>(vis, q, scene.triangles, scene.albedo);
              sum += open * shade(albedo, n, to_viewer, lights);
            } else if (shadow) {
              // Where this sample's view ray meets the floor plane.
              const float a = (static_cast<float>(px) + 0.5f - 0.5f * static_cast<float>(sw)) / s + cam.center_a;
              const float b = (0.5f * static_cast<float>(sh) - static_cast<float>(py) - 0.5f) / s + cam.center_b;
              const Vec3f on_plane = a * cam.right + b * cam.up;
              const float along = (floor.floor_y - on_plane.y()) / cam.forward.y();
              const Vec3f hit = on_plane + along * cam.forward;
              sum += backdrop * (1.0f - 0.6f * floor.at(hit.x(), hit.z()));
            } else {
              sum += backdrop;
            }
          }
        sum /= static_cast<float>(ss * ss);
        uint8_t* out = image.pixel(x0 + x, title_h + y);
        out[0] = to_byte(sum.x());
        out[1] = to_byte(sum.y());
        out[2] = to_byte(sum.z());
      }
    }
  }

  // Text and legend on top.
  const Vec3f ink = srgb8(60, 60, 64);
  if (!options.title.empty()) draw_text(image, 6 * text_scale, 4 * text_scale, options.title, ink, text_scale);
  if (options.view_labels)
    for (size_t k = 0; k < options.views.size(); ++k) {
      const std::string& label = options.views[k].label;
      const int x = static_cast<int>(k) * panel_w + (panel_w - text_width(label, text_scale)) / 2;
      draw_text(image, x, title_h + panel_h + 3 * text_scale, label, ink, text_scale);
    }
  if (options.legend) {
    const Legend& legend = *options.legend;
    const int bar_x = options.width - legend_w + 4 * text_scale, bar_w = 8 * text_scale;
    const int bar_top = title_h + panel_h / 6 + 14 * text_scale, bar_bottom = title_h + panel_h * 5 / 6;
    draw_text(image, options.width - legend_w, bar_top - 14 * text_scale, legend.title, ink, text_scale);
    for (int y = bar_top; y <= bar_bottom && bar_bottom > bar_top; ++y) {
      const float t = static_cast<float>(bar_bottom - y) / static_cast<float>(bar_bottom - bar_top);
      const Vec3f c = colormap(legend.map, t);
      for (int x = bar_x; x < bar_x + bar_w && x < options.width; ++x) {
        uint8_t* px = image.pixel(x, y);
        px[0] = to_byte(c.x());
        px[1] = to_byte(c.y());
        px[2] = to_byte(c.z());
      }
    }
    for (size_t k = 0; k < legend_ticks.size(); ++k) {
      const int y = bar_bottom - static_cast<int>(static_cast<float>(bar_bottom - bar_top) * static_cast<float>(k) / 4.0f);
      for (int x = bar_x + bar_w; x < std::min(options.width, bar_x + bar_w + 3 * text_scale); ++x) {
        uint8_t* px = image.pixel(x, std::clamp(y, 0, options.height - 1));
        px[0] = px[1] = px[2] = to_byte(0.05f);
      }
      draw_text(image, bar_x + bar_w + 6 * text_scale, y - 4 * text_scale, legend_ticks[k], ink, text_scale);
    }
  }
  return image;
}

}  // namespace drape
