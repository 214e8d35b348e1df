// Images: colour spaces, colour maps, text (stb_easy_font), composition and PNG encoding
// (stb_image_write into memory, then write_file_atomic).
#include <stb_easy_font.h>
#include <stb_image_write.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <stdexcept>

#include "drape/files.hpp"
#include "drape/render.hpp"

namespace drape {

Image::Image(int w, int h, const Vec3f& fill_linear) : width(w), height(h) {
  if (w <= 0 || h <= 0) throw std::invalid_argument("image: size must be positive");
  rgb.resize(static_cast<size_t>(w) * static_cast<size_t>(h) * 3);
  const uint8_t c[3] = {static_cast<uint8_t>(std::lround(255 * linear_to_srgb(fill_linear.x()))),
                        static_cast<uint8_t>(std::lround(255 * linear_to_srgb(fill_linear.y()))),
                        static_cast<uint8_t>(std::lround(255 * linear_to_srgb(fill_linear.z())))};
  for (size_t p = 0; p < rgb.size(); p += 3) std::copy(c, c + 3, rgb.begin() + static_cast<ptrdiff_t>(p));
}

float srgb_to_linear(float c) {
  if (!(c > 0.0f)) return 0.0f;  // also NaN
  c = std::min(c, 1.0f);
  return c <= 0.04045f ? c / 12.92f : std::pow((c + 0.055f) / 1.055f, 2.4f);
}

float linear_to_srgb(float c) {
  if (!(c > 0.0f)) return 0.0f;  // also NaN
  c = std::min(c, 1.0f);
  return c <= 0.0031308f ? 12.92f * c : 1.055f * std::pow(c, 1.0f / 2.4f) - 0.055f;
}

Vec3f srgb8(int r, int g, int b) {
  return {srgb_to_linear(static_cast<float>(r) / 255.0f), srgb_to_linear(static_cast<float>(g) / 255.0f),
          srgb_to_linear(static_cast<float>(b) / 255.0f)};
}

// ---- Colour maps: key colours (sRGB) interpolated in sRGB, as matplotlib and ColorBrewer define them.
namespace {
using Rgb8 = std::array<int, 3>;
constexpr std::array<Rgb8, 11> kViridis{{{68, 1, 84},
                                         {72, 36, 117},
                                         {65, 68, 135},
                                         {53, 95, 141},
                                         {42, 120, 142},
                                         {33, 145, 140},
                                         {34, 168, 132},
                                         {68, 191, 112},
                                         {122, 209, 81},
                                         {189, 223, 38},
                                         {253, 231, 37}}};
// ColorBrewer RdBu (7 classes), reversed: blue for low, red for high.
constexpr std::array<Rgb8, 7> kBlueWhiteRed{
    {{33, 102, 172}, {103, 169, 207}, {209, 229, 240}, {247, 247, 247}, {253, 219, 199}, {239, 138, 98}, {178, 24, 43}}};

template <size_t N>
Vec3f sample_keys(const std::array<Rgb8, N>& keys, float t) {
  const float x = t * static_cast<float>(N - 1);
  const auto k = std::min(static_cast<size_t>(x), N - 2);
  const float f = x - static_cast<float>(k);
  Vec3f srgb;
  for (int c = 0; c < 3; ++c)
    srgb[c] = ((1 - f) * static_cast<float>(keys[k][static_cast<size_t>(c)]) +
               f * static_cast<float>(keys[k + 1][static_cast<size_t>(c)])) / 255.0f;
  return {srgb_to_linear(srgb.x()), srgb_to_linear(srgb.y()), srgb_to_linear(srgb.z())};
}
}  // namespace

Vec3f colormap(ColorMap map, float t) {
  if (std::isnan(t)) return Vec3f::Constant(srgb_to_linear(0.5f));
  t = std::clamp(t, 0.0f, 1.0f);
  return map == ColorMap::kViridis ? sample_keys(kViridis, t) : sample_keys(kBlueWhiteRed, t);
}

std::vector<Vec4f> colorize(std::span<const float> values, ColorMap map, float lo, float hi) {
  std::vector<Vec4f> out(values.size());
  const float range = hi - lo;
  for (size_t i = 0; i < values.size(); ++i) {
    const float t = range != 0.0f ? (values[i] - lo) / range : 0.5f;
    out[i] << colormap(map, t), 1.0f;
  }
  return out;
}

// ---- Text: stb_easy_font turns a string into axis-aligned quads; each is filled with exact
// pixel coverage (anti-aliased at any scale).
namespace {
struct EasyFontVertex {
  float x, y, z;
  unsigned char color[4];
};
static_assert(sizeof(EasyFontVertex) == 16);

void blend(uint8_t* px, const Vec3f& srgb, float coverage) {
  for (int c = 0; c < 3; ++c) {
    const float value = (1 - coverage) * static_cast<float>(px[c]) + coverage * 255.0f * srgb[c];
    px[c] = static_cast<uint8_t>(std::lround(std::clamp(value, 0.0f, 255.0f)));
  }
}

// stb_easy_font indexes a table by character without checking: keep to printable ASCII.
std::string printable_ascii(std::string_view text) {
  std::string out(text);
  for (char& c : out)
    if (c != '\n' && (c < 32 || c > 126)) c = '?';
  return out;
}

}  // namespace

int text_width(std::string_view text, int scale) {
  std::string buffer = printable_ascii(text);
  return stb_easy_font_width(buffer.data()) * std::max(1, scale);
}

int draw_text(Image& image, int x, int y, std::string_view text, const Vec3f& color_linear, int scale) {
  scale = std::max(1, scale);
  std::string buffer = printable_ascii(text);
  // stb_easy_font emits at most about 270 bytes of quads per character.
  std::vector<EasyFontVertex> quads(buffer.size() * 80 + 64);
  unsigned char white[4] = {255, 255, 255, 255};
  const int quad_count = stb_easy_font_print(0, 0, buffer.data(), white, quads.data(),
                                             static_cast<int>(quads.size() * sizeof(EasyFontVertex)));
  const Vec3f srgb(linear_to_srgb(color_linear.x()), linear_to_srgb(color_linear.y()), linear_to_srgb(color_linear.z()));
  const auto s = static_cast<float>(scale);
  for (int q = 0; q < quad_count; ++q) {
    const EasyFontVertex* v = &quads[static_cast<size_t>(q) * 4];
    const float x0 = static_cast<float>(x) + s * std::min(v[0].x, v[2].x), x1 = static_cast<float>(x) + s * std::max(v[0].x, v[2].x);
    const float y0 = static_cast<float>(y) + s * std::min(v[0].y, v[2].y), y1 = static_cast<float>(y) + s * std::max(v[0].y, v[2].y);
    const int i0 = std::max(0, static_cast<int>(std::floor(x0))), i1 = std::min(image.width - 1, static_cast<int>(std::ceil(x1)) - 1);
    const int j0 = std::max(0, static_cast<int>(std::floor(y0))), j1 = std::min(image.height - 1, static_cast<int>(std::ceil(y1)) - 1);
    for (int j = j0; j <= j1; ++j) {
      const float cover_y = std::min(y1, static_cast<float>(j + 1)) - std::max(y0, static_cast<float>(j));
      for (int i = i0; i <= i1; ++i) {
        const float cover_x = std::min(x1, static_cast<float>(i + 1)) - std::max(x0, static_cast<float>(i));
        if (cover_x > 0 && cover_y > 0) blend(image.pixel(i, j), srgb, cover_x * cover_y);
      }
    }
  }
  return text_width(text, scale);
}

// ---- Composition
Image compose_side_by_side(const std::vector<Image>& images, const std::vector<std::string>& captions, int gap_pixels) {
  if (images.empty()) throw std::invalid_argument("compose_side_by_side: no images");
  if (!captions.empty() && captions.size() != images.size())
    throw std::invalid_argument("compose_side_by_side: need one caption per image");
  gap_pixels = std::max(0, gap_pixels);
  int width = gap_pixels, height = 0;
  for (const Image& im : images) {
    if (im.width <= 0 || im.height <= 0) throw std::invalid_argument("compose_side_by_side: empty image");
    width += im.width + gap_pixels;
    height = std::max(height, im.height);
  }
  const int scale = 2, caption_band = captions.empty() ? gap_pixels : 12 * scale + 2 * gap_pixels;
  Image out(width, height + caption_band + gap_pixels);
  int x = gap_pixels;
  for (size_t k = 0; k < images.size(); ++k) {
    const Image& im = images[k];
    if (!captions.empty()) {
      const int w = text_width(captions[k], scale);
      draw_text(out, x + (im.width - w) / 2, gap_pixels, captions[k], srgb8(40, 40, 40), scale);
    }
    for (int j = 0; j < im.height; ++j)
      std::copy(im.pixel(0, j), im.pixel(0, j) + 3 * im.width, out.pixel(x, caption_band + j));
    x += im.width + gap_pixels;
  }
  return out;
}

// ---- PNG
std::vector<uint8_t> encode_png(const Image& image) {
  if (image.width <= 0 || image.height <= 0 ||
      image.rgb.size() != static_cast<size_t>(image.width) * static_cast<size_t>(image.height) * 3)
    throw std::invalid_argument("encode_png: image has no pixels or the wrong size");
  std::vector<uint8_t> bytes;
  const auto append = [](void* context, void* data, int size) {
    auto* out = static_cast<std::vector<uint8_t>*>(context);
    const auto* first = static_cast<const uint8_t*>(data);
    out->insert(out->end(), first, first + size);
  };
  if (!stbi_write_png_to_func(append, &bytes, image.width, image.height, 3, image.rgb.data(), image.width * 3))
    throw std::runtime_error("encode_png: stb_image_write failed");
  return bytes;
}

void write_png(const std::filesystem::path& path, const Image& image) {
  const std::vector<uint8_t> bytes = encode_png(image);
  write_file_atomic(path, std::span<const unsigned char>(bytes.data(), bytes.size()));
}

}  // namespace drape
