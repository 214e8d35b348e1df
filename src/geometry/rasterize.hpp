#pragma once
// CPU triangle rasterizer shared by the image-space collision maps (Vassilev & Spanlang sec. 4.2:
// the body rendered from the front and the back into depth buffers and per-pixel interpolated
// normal buffers) and the preview pictures (src/render).
//
// Why hand-written and not OSMesa/EGL software GL: the engine needs depth and attribute buffers
// in its own memory, in a server process and in tests with no GL context or display; results
// must be bit-identical across runs and thread counts (determinism hashes); and a small
// bounding-box/edge-function rasterizer is fast enough (front and back maps of a 50k-triangle body
// at 2 mm pixels in about 16 ms on one core, bench/bench_render.cpp) in a few hundred lines.
//
// Design:
//  - Vertices are snapped to a fixed-point grid (1/256 pixel) and edge functions are evaluated
//    exactly in 64-bit integers, incrementally across each row. Pixel (i, j) is covered when its
//    centre (i + 0.5, j + 0.5) lies inside the triangle; samples exactly on an edge follow a
//    top-left fill rule, so two triangles sharing an edge never both cover a pixel and never both
//    miss it.
//  - The output is a visibility buffer: per pixel the nearest triangle (smallest depth), its depth
//    and the perspective-correct barycentric weights. Callers interpolate any per-vertex attribute
//    from it afterwards (interpolate()), so attributes are computed once per visible pixel.
//  - Threads: the image is cut into horizontal bands of rows; triangles are binned to bands in
//    index order and each band is rasterized by one thread. A pixel is only ever written by its
//    band, and within a band triangles are drawn in index order with a strict depth test (ties
//    keep the lower triangle index), so the result does not depend on the thread count.
#include <cstdint>
#include <limits>
#include <span>
#include <vector>

#include "drape/mesh.hpp"

namespace drape {

// A vertex after projection. x, y are in pixels: pixel (i, j) covers [i, i+1) x [j, j+1), row j
// is the j-th row of the buffer. z is the depth (smaller wins); it is interpolated linearly in
// screen space, as post-projection depth is. inv_w = 1/w of the clip-space vertex for
// perspective-correct attribute interpolation (1 for orthographic projection).
struct ScreenVertex {
  float x = 0.0f, y = 0.0f, z = 0.0f;
  float inv_w = 1.0f;
};

inline constexpr uint32_t kNoTriangle = std::numeric_limits<uint32_t>::max();

namespace raster_detail {
// A triangle prepared for rasterization: fixed-point corners (1/256 pixel), counter-clockwise.
struct TriangleSetup {
  int32_t x[3], y[3];           // fixed-point corners (below 2^29 in magnitude)
  int32_t i0, i1, j0, j1;       // covered pixel bounds, inclusive and clamped; j0 > j1 when culled
  float z[3], inv_w[3];
  float inv_area;               // 1 / (twice the fixed-point area)
  int8_t bias[3];               // 0 for edges that own their samples (top-left rule), -1 otherwise
  bool swapped;                 // corners 1 and 2 were exchanged to make it counter-clockwise
};
}  // namespace raster_detail

// Per-pixel result of rasterize(): the visible triangle and where on it the pixel centre lies.
struct VisibilityBuffer {
  int width = 0, height = 0;
  std::vector<float> depth;        // +infinity where no triangle covers the pixel
  std::vector<uint32_t> triangle;  // index into the triangle list, kNoTriangle where empty
  std::vector<float> bary1, bary2; // perspective-correct weights of corners 1 and 2 (corner 0: 1 - b1 - b2)

  size_t pixel_count() const { return depth.size(); }
  bool covered(size_t pixel) const { return triangle[pixel] != kNoTriangle; }

  // Working memory of rasterize(), kept so repeated calls do not allocate.
  std::vector<raster_detail::TriangleSetup> setups;
  std::vector<uint32_t> band_offsets, band_triangles;
  // Room for a caller's projected vertices (render_depth_normal projects into it); rasterize()
  // only reads its `vertices` argument and never touches this.
  std::vector<ScreenVertex> projected;
};

enum class FaceCulling {
  kNone,  // draw both windings (closed meshes, cloth)
  kBack,  // skip triangles that are clockwise in (x, y) buffer coordinates
};

struct RasterOptions {
  FaceCulling culling = FaceCulling::kNone;
  // Rows per work item for the threads; results do not depend on it.
  int band_rows = 16;
};

// Rasterizes `triangles` over `vertices` into `out` (resized and cleared; reuse it across frames to
// avoid allocation). Triangles with a non-finite vertex or one farther than about a million pixels
// outside the buffer are skipped (no clipping: callers frame their geometry).
void rasterize(std::span<const ScreenVertex> vertices, std::span<const Tri> triangles, int width, int height,
               VisibilityBuffer& out, const RasterOptions& options = {});

// The attribute `values` (one per vertex) interpolated at a covered pixel.
template <class T>
T interpolate(const VisibilityBuffer& vis, size_t pixel, std::span<const Tri> triangles, std::span<const T> values) {
  const Tri& t = triangles[vis.triangle[pixel]];
  const float b1 = vis.bary1[pixel], b2 = vis.bary2[pixel];
  return values[t[0]] * (1.0f - b1 - b2) + values[t[1]] * b1 + values[t[2]] * b2;
}

// ---------------------------------------------------------------------------------------------
// Depth and normal maps for image-space collision (paper sec. 4.2).
//
// The body is projected orthographically along Z onto the world rectangle
// [origin.x, origin.x + width * pixel_size) x [origin.y, origin.y + height * pixel_size).
// Pixel (i, j) is centred on world (origin.x + (i + 0.5) * pixel_size, origin.y + (j + 0.5) * pixel_size):
// row 0 is the lowest row, and the front and back maps use the same (x, y) -> pixel mapping, so
// one index_of() serves both.
enum class ViewDirection {
  kFront,  // seen from +Z (the body faces +Z): the visible surface is the largest z at each pixel
  kBack,   // seen from -Z: the smallest z at each pixel
};

struct DepthNormalMap {
  int width = 0, height = 0;
  Vec2f origin = Vec2f::Zero();  // world (x, y) of the lower-left corner of pixel (0, 0)
  float pixel_size = 0.0f;       // metres per pixel
  ViewDirection view = ViewDirection::kFront;

  // World z of the visible surface. Empty pixels hold -infinity in the front map and +infinity in
  // the back map, so the "behind the surface" tests (z < depth in front, z > depth at the back)
  // are false there without a special case.
  std::vector<float> depth;
  std::vector<Vec3f> normal;       // unit interpolated vertex normal; zero where empty
  std::vector<uint32_t> triangle;  // visible triangle, kNoTriangle where empty

  bool covered(int index) const { return triangle[static_cast<size_t>(index)] != kNoTriangle; }
  // Pixel index of world (x, y), or -1 outside the map. O(1).
  int index_of(float x, float y) const {
    const float fi = (x - origin.x()) / pixel_size, fj = (y - origin.y()) / pixel_size;
    if (!(fi >= 0.0f && fj >= 0.0f && fi < static_cast<float>(width) && fj < static_cast<float>(height))) return -1;
    return static_cast<int>(fj) * width + static_cast<int>(fi);
  }
  // World (x, y) of a pixel's centre.
  Vec2f pixel_center(int i, int j) const {
    return origin + Vec2f((static_cast<float>(i) + 0.5f) * pixel_size, (static_cast<float>(j) + 0.5f) * pixel_size);
  }
};

// Renders the mesh's depth and interpolated normal map seen from `view`. `vertex_normals` is one
// unit normal per vertex (drape::vertex_normals). Reuse `out` and `scratch` across frames of an
// animated body to avoid allocation.
void render_depth_normal(std::span<const Vec3f> positions, std::span<const Tri> triangles,
                         std::span<const Vec3f> vertex_normals, ViewDirection view, Vec2f origin, float pixel_size,
                         int width, int height, DepthNormalMap& out, VisibilityBuffer& scratch);
DepthNormalMap render_depth_normal(std::span<const Vec3f> positions, std::span<const Tri> triangles,
                                   std::span<const Vec3f> vertex_normals, ViewDirection view, Vec2f origin,
                                   float pixel_size, int width, int height);

// Both maps over the mesh's (x, y) bounds grown by `margin` metres on every side, at `pixel_size`.
struct FrontBackMaps {
  DepthNormalMap front, back;
};
FrontBackMaps render_front_back(std::span<const Vec3f> positions, std::span<const Tri> triangles,
                                std::span<const Vec3f> vertex_normals, float pixel_size, float margin);

}  // namespace drape
