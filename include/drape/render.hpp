#pragma once
// Pictures of the dressed body: preview.png (front, side and back side by side), fit maps
// (a scalar per vertex through a colour map, with a legend), comparisons of several renders with
// captions. Everything is drawn on the CPU by drape's own rasterizer (geometry/rasterize.hpp):
// orthographic views, Lambert + hemisphere ambient with a key, a fill and a rim light, two-sided
// lighting for cloth, supersampled anti-aliasing, a soft contact shadow on the floor, text from
// stb_easy_font. Colours are linear RGB in [0, 1]; images are 8-bit sRGB.
//
//   drape::RenderOptions opt;                          // 1200 x 600, front/side/back
//   auto picture = drape::render_views({drape::body_item(body), drape::garment_item(shirt, 0)}, opt);
//   drape::write_png("out/preview.png", picture);
#include <filesystem>
#include <optional>
#include <span>
#include <string>
#include <string_view>
#include <vector>

#include "drape/mesh.hpp"

namespace drape {

// An 8-bit sRGB picture, rows top to bottom, 3 bytes per pixel.
struct Image {
  int width = 0, height = 0;
  std::vector<uint8_t> rgb;

  Image() = default;
  Image(int w, int h, const Vec3f& fill_linear = Vec3f::Ones());
  uint8_t* pixel(int x, int y) { return rgb.data() + 3 * (static_cast<size_t>(y) * static_cast<size_t>(width) + static_cast<size_t>(x)); }
  const uint8_t* pixel(int x, int y) const {
    return rgb.data() + 3 * (static_cast<size_t>(y) * static_cast<size_t>(width) + static_cast<size_t>(x));
  }
};

// sRGB <-> linear for one channel in [0, 1], and an 8-bit sRGB colour to linear RGB.
float srgb_to_linear(float c);
float linear_to_srgb(float c);
Vec3f srgb8(int r, int g, int b);

// ---- Colour maps for per-vertex scalars (strain, ease, pressure) ----
enum class ColorMap {
  kViridis,       // sequential, perceptually uniform (magnitudes: pressure, |strain|)
  kBlueWhiteRed,  // diverging, white in the middle (signed: strain, ease)
};
// Linear RGB of `t` in [0, 1] (clamped; NaN gives mid grey).
Vec3f colormap(ColorMap map, float t);
// One linear RGBA colour per value, `lo` and `hi` mapping to the ends of the map.
std::vector<Vec4f> colorize(std::span<const float> values, ColorMap map, float lo, float hi);

// ---- What to draw ----
struct RenderItem {
  const Mesh* mesh = nullptr;        // positions and triangles; its normals when complete; not owned
  Vec3f color = srgb8(200, 200, 200);  // linear RGB used when there are no per-vertex colours
  std::vector<Vec4f> vertex_colors;  // linear RGBA per vertex (e.g. colorize(strain)); overrides mesh->colors
};
// The body in a neutral skin tone, and a garment in the index-th colour of a fabric palette.
RenderItem body_item(const Mesh& body);
RenderItem garment_item(const Mesh& garment, size_t index);

// A camera direction around the vertical axis: yaw 0 looks at the body's front (camera on +Z),
// 90 at its left side (camera on +X), 180 at its back.
struct ViewSpec {
  std::string label;
  float yaw_degrees = 0.0f;
};
// "front", "back", "left", "right" and "side" (= right: the body faces right in the picture).
// Throws InputError(source, ...) naming the unknown view.
std::vector<ViewSpec> parse_views(std::string_view comma_separated, const std::string& source = "--views");

// A colour bar beside the views for a scalar map drawn with colorize(values, map, lo, hi).
struct Legend {
  std::string title;  // e.g. "strain"
  ColorMap map = ColorMap::kViridis;
  float lo = 0.0f, hi = 1.0f;
};

// A fit map: one scalar per vertex (strain, ease in metres, pressure) coloured through the
// legend's map and range; pass the same legend in RenderOptions::legend to explain the colours.
RenderItem scalar_item(const Mesh& mesh, std::span<const float> values, const Legend& legend);

struct RenderOptions {
  int width = 1200, height = 600;  // the whole picture, panels side by side
  std::vector<ViewSpec> views{{"front", 0.0f}, {"side", 270.0f}, {"back", 180.0f}};
  int supersample = 3;             // samples per pixel along each axis (anti-aliasing); lowered for huge pictures
  float elevation_degrees = 6.0f;  // camera looks slightly down, so the floor shows (|e| <= 80)
  // Scale in picture pixels per metre; 0 fits the scene. Fix it to compare pictures of different
  // scenes (frames of an animation, two simulation methods) at the same size.
  float pixels_per_metre = 0.0f;
  bool floor_shadow = true;
  bool ambient_occlusion = true;   // darken folds, creases and skin just under a garment's edge
  bool view_labels = true;         // the view's name under each panel
  std::string title;               // optional caption at the top left
  std::optional<Legend> legend;
  Vec3f background_top = srgb8(246, 246, 244), background_bottom = srgb8(218, 218, 214);
};

// Renders the items from every view into one picture. All views share one scale, so sizes compare.
// Throws std::invalid_argument when there is nothing to draw (no item with a triangle) or the
// options are out of range.
Image render_views(const std::vector<RenderItem>& items, const RenderOptions& options);

// Several pictures in a row on a white background with a caption above each (e.g. "no limit" vs
// "velocity modification"). `captions` is empty or one per image.
Image compose_side_by_side(const std::vector<Image>& images, const std::vector<std::string>& captions,
                           int gap_pixels = 16);

// Text drawn with stb_easy_font (ASCII; about 6 x 12 pixels per character at scale 1).
// (x, y) is the top left of the first line. Returns the width in pixels.
int draw_text(Image& image, int x, int y, std::string_view text, const Vec3f& color_linear, int scale = 1);
int text_width(std::string_view text, int scale = 1);

// PNG bytes of the image, and the image written as a PNG file atomically.
std::vector<uint8_t> encode_png(const Image& image);
void write_png(const std::filesystem::path& path, const Image& image);

}  // namespace drape
