#include "geometry/rasterize.hpp"

#include <algorithm>
#include <cmath>
#include <stdexcept>

namespace drape {
namespace {

using raster_detail::TriangleSetup;

constexpr int kSubpixelBits = 8;
constexpr int64_t kSubpixel = int64_t{1} << kSubpixelBits;
// Vertices farther than this many pixels outside the buffer are refused: it keeps every edge
// function product below 2^62 (fixed-point coordinates below 2^29).
constexpr float kGuardBandPixels = float(1 << 20);

int64_t floor_div(int64_t a, int64_t b) { return a >= 0 ? a / b : -((-a + b - 1) / b); }

// Top-left rule for an edge of a counter-clockwise triangle running along d: exactly one of d and
// -d owns the samples on the line, so a shared edge is drawn by exactly one of its triangles.
bool edge_owns_samples(int64_t dx, int64_t dy) { return dy > 0 || (dy == 0 && dx < 0); }

// Edge function of a -> b at p: twice the signed area of (a, b, p), positive left of a -> b.
int64_t edge(int64_t ax, int64_t ay, int64_t bx, int64_t by, int64_t px, int64_t py) {
  return (bx - ax) * (py - ay) - (by - ay) * (px - ax);
}

TriangleSetup setup_triangle(std::span<const ScreenVertex> vertices, const Tri& t, int width, int height,
                             FaceCulling culling) {
  TriangleSetup s{};
  s.j0 = 1;
  s.j1 = 0;  // culled unless set below
  ScreenVertex v[3];
  for (int k = 0; k < 3; ++k) {
    if (t[static_cast<size_t>(k)] >= vertices.size()) return s;
    v[k] = vertices[t[static_cast<size_t>(k)]];
    const bool finite = std::isfinite(v[k].x) && std::isfinite(v[k].y) && std::isfinite(v[k].z) &&
                        std::isfinite(v[k].inv_w);
    if (!finite || v[k].x < -kGuardBandPixels || v[k].y < -kGuardBandPixels ||
        v[k].x > kGuardBandPixels + static_cast<float>(width) || v[k].y > kGuardBandPixels + static_cast<float>(height))
      return s;
  }
  for (int k = 0; k < 3; ++k) {
    s.x[k] = static_cast<int32_t>(std::floor(static_cast<double>(v[k].x) * kSubpixel + 0.5));
    s.y[k] = static_cast<int32_t>(std::floor(static_cast<double>(v[k].y) * kSubpixel + 0.5));
    s.z[k] = v[k].z;
    s.inv_w[k] = v[k].inv_w;
  }
  int64_t area = edge(s.x[0], s.y[0], s.x[1], s.y[1], s.x[2], s.y[2]);
  static_assert(kSubpixelBits + 21 < 31, "fixed-point corners must fit in 32 bits");
  if (area == 0) return s;
  if (area < 0) {
    if (culling == FaceCulling::kBack) return s;
    std::swap(s.x[1], s.x[2]);
    std::swap(s.y[1], s.y[2]);
    std::swap(s.z[1], s.z[2]);
    std::swap(s.inv_w[1], s.inv_w[2]);
    s.swapped = true;
    area = -area;
  }
  s.inv_area = static_cast<float>(1.0 / static_cast<double>(area));
  // Edge k is the one opposite corner k: from corner k+1 to corner k+2.
  for (int k = 0; k < 3; ++k) {
    const int a = (k + 1) % 3, b = (k + 2) % 3;
    s.bias[k] = edge_owns_samples(int64_t{s.x[b]} - s.x[a], int64_t{s.y[b]} - s.y[a]) ? 0 : -1;
  }
  // Pixels whose centre (i + 0.5) * kSubpixel lies within the fixed-point bounding box.
  const int64_t half = kSubpixel / 2;
  const int64_t min_x = std::min({s.x[0], s.x[1], s.x[2]}), max_x = std::max({s.x[0], s.x[1], s.x[2]});
  const int64_t min_y = std::min({s.y[0], s.y[1], s.y[2]}), max_y = std::max({s.y[0], s.y[1], s.y[2]});
  // (min/max of int32 promoted to int64 for the pixel arithmetic below)
  const int64_t i0 = std::max<int64_t>(0, floor_div(min_x - half + kSubpixel - 1, kSubpixel));
  const int64_t i1 = std::min<int64_t>(width - 1, floor_div(max_x - half, kSubpixel));
  const int64_t j0 = std::max<int64_t>(0, floor_div(min_y - half + kSubpixel - 1, kSubpixel));
  const int64_t j1 = std::min<int64_t>(height - 1, floor_div(max_y - half, kSubpixel));
  if (i0 > i1 || j0 > j1) return s;
  s.i0 = static_cast<int>(i0);
  s.i1 = static_cast<int>(i1);
  s.j0 = static_cast<int>(j0);
  s.j1 = static_cast<int>(j1);
  return s;
}

// Draws one triangle into rows [row_begin, row_end) with a strict depth test.
void draw_rows(const TriangleSetup& s, uint32_t triangle_index, int row_begin, int row_end, int width,
               VisibilityBuffer& out) {
  const int j_begin = std::max(s.j0, row_begin), j_end = std::min(s.j1 + 1, row_end);
  const int64_t half = kSubpixel / 2;
  const bool perspective = s.inv_w[0] != 1.0f || s.inv_w[1] != 1.0f || s.inv_w[2] != 1.0f;
  // Per-edge step when moving one pixel right: d/dx of edge(a, b, p) = -(by - ay).
  int64_t step_x[3];
  for (int k = 0; k < 3; ++k) {
    const int a = (k + 1) % 3, b = (k + 2) % 3;
    step_x[k] = -(int64_t{s.y[b]} - s.y[a]) * kSubpixel;
  }
  const float dz1 = s.z[1] - s.z[0], dz2 = s.z[2] - s.z[0];
  for (int j = j_begin; j < j_end; ++j) {
    const int64_t py = j * kSubpixel + half, px = s.i0 * kSubpixel + half;
    int64_t e[3];
    for (int k = 0; k < 3; ++k) {
      const int a = (k + 1) % 3, b = (k + 2) % 3;
      e[k] = edge(s.x[a], s.y[a], s.x[b], s.y[b], px, py) + s.bias[k];
    }
    size_t pixel = static_cast<size_t>(j) * static_cast<size_t>(width) + static_cast<size_t>(s.i0);
    for (int i = s.i0; i <= s.i1; ++i, ++pixel) {
      if ((e[0] | e[1] | e[2]) >= 0) {
        // Screen-space weights (bias removed) give the depth; attributes get 1/w correction.
        float b1 = static_cast<float>(e[1] - s.bias[1]) * s.inv_area;
        float b2 = static_cast<float>(e[2] - s.bias[2]) * s.inv_area;
        const float z = s.z[0] + b1 * dz1 + b2 * dz2;
        if (z < out.depth[pixel]) {
          if (perspective) {
            const float w0 = (1.0f - b1 - b2) * s.inv_w[0], w1 = b1 * s.inv_w[1], w2 = b2 * s.inv_w[2];
            const float inv_sum = 1.0f / (w0 + w1 + w2);
            b1 = w1 * inv_sum;
            b2 = w2 * inv_sum;
          }
          out.depth[pixel] = z;
          out.triangle[pixel] = triangle_index;
          out.bary1[pixel] = s.swapped ? b2 : b1;
          out.bary2[pixel] = s.swapped ? b1 : b2;
        }
      }
      e[0] += step_x[0];
      e[1] += step_x[1];
      e[2] += step_x[2];
    }
  }
}

}  // namespace

void rasterize(std::span<const ScreenVertex> vertices, std::span<const Tri> triangles, int width, int height,
               VisibilityBuffer& out, const RasterOptions& options) {
  if (width <= 0 || height <= 0 || width > (1 << 20) || height > (1 << 20))
    throw std::invalid_argument("rasterize: buffer size out of range");
  const size_t pixels = static_cast<size_t>(width) * static_cast<size_t>(height);
  out.width = width;
  out.height = height;
  out.depth.resize(pixels);
  out.triangle.resize(pixels);
  out.bary1.resize(pixels);
  out.bary2.resize(pixels);

  // Set every triangle up once (independent work).
  const auto triangle_count = static_cast<int64_t>(triangles.size());
  out.setups.resize(triangles.size());
  // Threads only pay off on real work: small jobs (a test quad, a text label) stay on one thread.
  const bool parallel = triangle_count > 4096 || pixels > (size_t{1} << 18);
#pragma omp parallel for schedule(static) if (parallel)
  for (int64_t t = 0; t < triangle_count; ++t)
    out.setups[static_cast<size_t>(t)] =
        setup_triangle(vertices, triangles[static_cast<size_t>(t)], width, height, options.culling);

  // Bin triangles to bands of rows, in index order (counting sort).
  const int band_rows = std::max(1, options.band_rows);
  const int bands = (height + band_rows - 1) / band_rows;
  out.band_offsets.assign(static_cast<size_t>(bands) + 1, 0);
  for (const TriangleSetup& s : out.setups) {
    if (s.j0 > s.j1) continue;
    for (int b = s.j0 / band_rows; b <= s.j1 / band_rows; ++b) ++out.band_offsets[static_cast<size_t>(b) + 1];
  }
  for (size_t b = 0; b < static_cast<size_t>(bands); ++b) out.band_offsets[b + 1] += out.band_offsets[b];
  out.band_triangles.resize(out.band_offsets.back());
  {
    // band_offsets[b] serves as band b's write cursor, then is restored from its neighbour.
    for (size_t t = 0; t < out.setups.size(); ++t) {
      const TriangleSetup& s = out.setups[t];
      if (s.j0 > s.j1) continue;
      for (int b = s.j0 / band_rows; b <= s.j1 / band_rows; ++b)
        out.band_triangles[out.band_offsets[static_cast<size_t>(b)]++] = static_cast<uint32_t>(t);
    }
    for (size_t b = static_cast<size_t>(bands); b > 0; --b) out.band_offsets[b] = out.band_offsets[b - 1];
    out.band_offsets[0] = 0;
  }

  // Each band clears and draws its own rows: no two threads touch the same pixel.
#pragma omp parallel for schedule(dynamic, 1) if (parallel)
  for (int b = 0; b < bands; ++b) {
    const int row_begin = b * band_rows, row_end = std::min(height, row_begin + band_rows);
    const size_t first = static_cast<size_t>(row_begin) * static_cast<size_t>(width);
    const size_t last = static_cast<size_t>(row_end) * static_cast<size_t>(width);
    std::fill(out.depth.begin() + static_cast<ptrdiff_t>(first), out.depth.begin() + static_cast<ptrdiff_t>(last),
              std::numeric_limits<float>::infinity());
    std::fill(out.triangle.begin() + static_cast<ptrdiff_t>(first),
              out.triangle.begin() + static_cast<ptrdiff_t>(last), kNoTriangle);
    std::fill(out.bary1.begin() + static_cast<ptrdiff_t>(first), out.bary1.begin() + static_cast<ptrdiff_t>(last), 0.0f);
    std::fill(out.bary2.begin() + static_cast<ptrdiff_t>(first), out.bary2.begin() + static_cast<ptrdiff_t>(last), 0.0f);
    for (uint32_t k = out.band_offsets[static_cast<size_t>(b)]; k < out.band_offsets[static_cast<size_t>(b) + 1]; ++k) {
      const uint32_t t = out.band_triangles[k];
      draw_rows(out.setups[t], t, row_begin, row_end, width, out);
    }
  }
}

void render_depth_normal(std::span<const Vec3f> positions, std::span<const Tri> triangles,
                         std::span<const Vec3f> vertex_normals, ViewDirection view, Vec2f origin, float pixel_size,
                         int width, int height, DepthNormalMap& out, VisibilityBuffer& scratch) {
  if (!(pixel_size > 0.0f)) throw std::invalid_argument("render_depth_normal: pixel size must be positive");
  if (vertex_normals.size() != positions.size())
    throw std::invalid_argument("render_depth_normal: need one normal per vertex");
  const bool front = view == ViewDirection::kFront;

  // Orthographic projection along Z; the front view sees the largest z, so its depth is -z.
  std::vector<ScreenVertex>& screen = scratch.projected;
  screen.resize(positions.size());
  const float inv_pixel = 1.0f / pixel_size;
  const auto vertex_count = static_cast<int64_t>(positions.size());
#pragma omp parallel for schedule(static) if (vertex_count > 8192)
  for (int64_t v = 0; v < vertex_count; ++v) {
    const Vec3f& p = positions[static_cast<size_t>(v)];
    screen[static_cast<size_t>(v)] = {(p.x() - origin.x()) * inv_pixel, (p.y() - origin.y()) * inv_pixel,
                                      front ? -p.z() : p.z(), 1.0f};
  }
  rasterize(screen, triangles, width, height, scratch);

  out.width = width;
  out.height = height;
  out.origin = origin;
  out.pixel_size = pixel_size;
  out.view = view;
  const size_t pixels = scratch.pixel_count();
  out.depth.resize(pixels);
  out.normal.resize(pixels);
  out.triangle.resize(pixels);
  const auto pixel_count = static_cast<int64_t>(pixels);
#pragma omp parallel for schedule(static) if (pixel_count > (int64_t{1} << 16))
  for (int64_t q = 0; q < pixel_count; ++q) {
    const auto p = static_cast<size_t>(q);
    out.triangle[p] = scratch.triangle[p];
    if (!scratch.covered(p)) {
      out.depth[p] = front ? -std::numeric_limits<float>::infinity() : std::numeric_limits<float>::infinity();
      out.normal[p] = Vec3f::Zero();
      continue;
    }
    out.depth[p] = front ? -scratch.depth[p] : scratch.depth[p];
    const Vec3f n = interpolate(scratch, p, triangles, vertex_normals);
    const float len = n.norm();
    out.normal[p] = len > 0.0f ? Vec3f(n / len) : Vec3f::Zero();
  }
}

DepthNormalMap render_depth_normal(std::span<const Vec3f> positions, std::span<const Tri> triangles,
                                   std::span<const Vec3f> vertex_normals, ViewDirection view, Vec2f origin,
                                   float pixel_size, int width, int height) {
  DepthNormalMap map;
  VisibilityBuffer scratch;
  render_depth_normal(positions, triangles, vertex_normals, view, origin, pixel_size, width, height, map, scratch);
  return map;
}

FrontBackMaps render_front_back(std::span<const Vec3f> positions, std::span<const Tri> triangles,
                                std::span<const Vec3f> vertex_normals, float pixel_size, float margin) {
  if (positions.empty()) throw std::invalid_argument("render_front_back: empty mesh");
  if (!(pixel_size > 0.0f)) throw std::invalid_argument("render_front_back: pixel size must be positive");
  Bounds box;
  for (const Vec3f& p : positions) box.extend(p);
  const Vec2f origin(box.min.x() - margin, box.min.y() - margin);
  const int width = static_cast<int>(std::ceil((box.max.x() - box.min.x() + 2 * margin) / pixel_size));
  const int height = static_cast<int>(std::ceil((box.max.y() - box.min.y() + 2 * margin) / pixel_size));
  FrontBackMaps maps;
  VisibilityBuffer scratch;
  render_depth_normal(positions, triangles, vertex_normals, ViewDirection::kFront, origin, pixel_size,
                      std::max(1, width), std::max(1, height), maps.front, scratch);
  render_depth_normal(positions, triangles, vertex_normals, ViewDirection::kBack, origin, pixel_size,
                      std::max(1, width), std::max(1, height), maps.back, scratch);
  return maps;
}

}  // namespace drape
