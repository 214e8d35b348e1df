// Image-space body collider; see image_collider.hpp.
#include "collision/image_collider.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <limits>
#include <stdexcept>

#include "collision/bvh_collider.hpp"

namespace drape::collision {
namespace {
constexpr int kHiddenGrowPixels = 2;
}

ImageCollider::ImageCollider(const Mesh& body, const BodyColliderOptions& options)
    : options_(options), surface_(body.positions, body.triangles) {
  if (!(options.pixel_size > 0)) throw std::invalid_argument("image collider: pixel size must be positive");
  if (options_.hidden_region_handling) {
    bvh_ = std::make_unique<TriangleBvh>(surface_, /*refit=*/true);
    reversed_.reserve(surface_.triangle_count());
    for (const Tri& t : surface_.triangles()) reversed_.push_back({t[0], t[2], t[1]});
  }
  render_maps();
  if (bvh_ && options_.candidate_grid) {
    // The tree answers only over hidden pixels (sample()), so the candidate grid lists only the
    // cells above them (on mean_all the grid's build 0.75 -> 0.51 s, 61 -> 46 MB with the maps:
    // the side walls are hidden along their whole depth). A cell counts when its box, grown by a
    // pixel for the rounding of cell and pixel indices, meets a hidden pixel.
    const float h = options_.pixel_size;
    bvh_->build_candidate_grid(TriangleBvh::kGridCell, TriangleBvh::kGridBand, [this, h](const Bounds& cell) {
      const int i0 = std::max(0, static_cast<int>(std::floor((cell.min.x() - origin_.x()) / h)) - 1);
      const int j0 = std::max(0, static_cast<int>(std::floor((cell.min.y() - origin_.y()) / h)) - 1);
      const int i1 = std::min(width_ - 1, static_cast<int>(std::floor((cell.max.x() - origin_.x()) / h)) + 1);
      const int j1 = std::min(height_ - 1, static_cast<int>(std::floor((cell.max.y() - origin_.y()) / h)) + 1);
      for (int j = j0; j <= j1; ++j)
        for (int i = i0; i <= i1; ++i)
          if (hidden_[static_cast<size_t>(j) * static_cast<size_t>(width_) + static_cast<size_t>(i)]) return true;
      return false;
    });
    stats_.memory_bytes += bvh_->candidate_grid()->memory_bytes();
  }
}

void ImageCollider::set_surface(std::span<const Vec3f> positions, double t) {
  surface_.set_positions(positions, t);
  if (bvh_) bvh_->update();
  render_maps();
}

void ImageCollider::render_maps() {
  const auto start = std::chrono::steady_clock::now();
  const float h = options_.pixel_size;
  inverse_pixel_ = 1.0f / h;
  const auto positions = surface_.positions();
  Bounds box;
  for (const Vec3f& p : positions) box.extend(p);
  const float margin = std::max(4 * h, 0.01f);
  origin_ = Vec2f(box.min.x() - margin, box.min.y() - margin);
  width_ = std::max(1, static_cast<int>(std::ceil((box.max.x() - box.min.x() + 2 * margin) / h)));
  height_ = std::max(1, static_cast<int>(std::ceil((box.max.y() - box.min.y() + 2 * margin) / h)));
  render_depth_normal(positions, surface_.triangles(), surface_.smooth_normals(), ViewDirection::kFront, origin_, h,
                      width_, height_, front_, visibility_);
  render_depth_normal(positions, surface_.triangles(), surface_.smooth_normals(), ViewDirection::kBack, origin_, h,
                      width_, height_, back_, visibility_);

  const size_t pixels = static_cast<size_t>(width_) * static_cast<size_t>(height_);
  texels_.resize(pixels);
  for (size_t p = 0; p < pixels; ++p)
    texels_[p] = {front_.depth[p], back_.depth[p], front_.normal[p], back_.normal[p]};

  // A moving body keeps the visible triangles for the surface velocity.
  moving_ = std::any_of(surface_.velocities().begin(), surface_.velocities().end(),
                        [](const Vec3f& v) { return v.squaredNorm() > 0.0f; });
  if (moving_) {
    front_triangle_.assign(front_.triangle.begin(), front_.triangle.end());
    back_triangle_.assign(back_.triangle.begin(), back_.triangle.end());
  } else {
    front_triangle_.clear();
    back_triangle_.clear();
  }

  size_t covered = 0, hidden_covered = 0;
  for (size_t p = 0; p < pixels; ++p) covered += front_.triangle[p] != kNoTriangle;
  if (options_.hidden_region_handling) {
    // First exit along each ray from the front: only surfaces facing away from the front viewer.
    screen_.resize(positions.size());
    for (size_t v = 0; v < positions.size(); ++v)
      screen_[v] = {(positions[v].x() - origin_.x()) / h, (positions[v].y() - origin_.y()) / h, -positions[v].z(), 1.0f};
    RasterOptions cull_front_facing;
    cull_front_facing.culling = FaceCulling::kBack;
    rasterize(screen_, reversed_, width_, height_, visibility_, cull_front_facing);

    // Hidden: several layers along the ray, a surface seen edge-on in either view, or the
    // silhouette (a covered pixel beside an empty one). At the silhouette the maps cannot answer:
    // a point just beyond it is over an empty pixel ("no body along this ray") however near the
    // body's side it is, and one just inside it is judged by a pixel-centre normal that may not be
    // edge-on enough for the test above. Cloth hanging beside a leg was pushed 4 mm out whenever it
    // drifted over the silhouette and not seen at all once beside it, and trembled so for ever.
    const float layer_tolerance = 1e-4f;
    const auto empty = [&](int i, int j) {
      return i < 0 || j < 0 || i >= width_ || j >= height_ ||
             front_.triangle[static_cast<size_t>(j) * static_cast<size_t>(width_) + static_cast<size_t>(i)] == kNoTriangle;
    };
    hidden_.assign(pixels, 0);
    for (int j = 0; j < height_; ++j)
      for (int i = 0; i < width_; ++i) {
        const size_t p = static_cast<size_t>(j) * static_cast<size_t>(width_) + static_cast<size_t>(i);
        if (front_.triangle[p] == kNoTriangle) continue;
        const bool layers = visibility_.covered(p) && -visibility_.depth[p] > back_.depth[p] + layer_tolerance;
        const bool edge_on = std::abs(front_.normal[p].z()) < options_.edge_on_cosine ||
                             std::abs(back_.normal[p].z()) < options_.edge_on_cosine;
        const bool silhouette = empty(i - 1, j) || empty(i + 1, j) || empty(i, j - 1) || empty(i, j + 1);
        hidden_[p] = layers || edge_on || silhouette;
      }
    // Grow by kHiddenGrowPixels (a square max filter, rows then columns), also over empty pixels
    // next to the silhouette, where points beside an edge-on wall land.
    dilated_.assign(pixels, 0);
    for (int j = 0; j < height_; ++j)
      for (int i = 0; i < width_; ++i) {
        if (!hidden_[static_cast<size_t>(j) * static_cast<size_t>(width_) + static_cast<size_t>(i)]) continue;
        for (int di = std::max(0, i - kHiddenGrowPixels); di <= std::min(width_ - 1, i + kHiddenGrowPixels); ++di)
          dilated_[static_cast<size_t>(j) * static_cast<size_t>(width_) + static_cast<size_t>(di)] = 1;
      }
    hidden_.assign(pixels, 0);
    for (int j = 0; j < height_; ++j)
      for (int i = 0; i < width_; ++i) {
        if (!dilated_[static_cast<size_t>(j) * static_cast<size_t>(width_) + static_cast<size_t>(i)]) continue;
        for (int dj = std::max(0, j - kHiddenGrowPixels); dj <= std::min(height_ - 1, j + kHiddenGrowPixels); ++dj)
          hidden_[static_cast<size_t>(dj) * static_cast<size_t>(width_) + static_cast<size_t>(i)] = 1;
      }
    for (size_t p = 0; p < pixels; ++p)
      if (hidden_[p]) {
        hidden_covered += front_.triangle[p] != kNoTriangle;
        texels_[p].z_front = std::numeric_limits<float>::quiet_NaN();
      }
  }
  stats_.hidden_fraction = covered ? static_cast<double>(hidden_covered) / static_cast<double>(covered) : 0.0;
  stats_.memory_bytes = pixels * sizeof(Texel) + (front_triangle_.size() + back_triangle_.size()) * sizeof(uint32_t) +
                        (bvh_ && bvh_->candidate_grid() ? bvh_->candidate_grid()->memory_bytes() : 0);
  stats_.build_seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
}

ContactSample ImageCollider::sample(const Vec3f& p, float radius) const {
  const float infinity = std::numeric_limits<float>::infinity();
  ContactSample out{infinity, Vec3f::Zero(), Vec3f::Zero()};
  const float h = options_.pixel_size;
  const float fi = (p.x() - origin_.x()) * inverse_pixel_, fj = (p.y() - origin_.y()) * inverse_pixel_;
  if (!(fi >= 0.0f && fj >= 0.0f && fi < static_cast<float>(width_) && fj < static_cast<float>(height_))) return out;
  const int i = static_cast<int>(fi), j = static_cast<int>(fj);
  const size_t pixel = static_cast<size_t>(j) * static_cast<size_t>(width_) + static_cast<size_t>(i);
  const Texel& texel = texels_[pixel];
  if (std::isnan(texel.z_front)) {  // hidden from both views: exact answer
    exact_sample(*bvh_, p, radius, out);
    return out;
  }
  if (texel.z_front == -infinity) return out;  // no body along this ray

  // The visible surface points of both views at the pixel centre, with their interpolated normals.
  // In front of the front surface or behind the back one, that surface is the nearer; inside, the
  // one whose tangent plane is nearer.
  const Vec2f centre(origin_.x() + (static_cast<float>(i) + 0.5f) * h, origin_.y() + (static_cast<float>(j) + 0.5f) * h);
  const float front_distance = (p - Vec3f(centre.x(), centre.y(), texel.z_front)).dot(texel.n_front);
  const float back_distance = (p - Vec3f(centre.x(), centre.y(), texel.z_back)).dot(texel.n_back);
  const bool inside = p.z() < texel.z_front && p.z() > texel.z_back;
  const bool front = inside ? std::abs(front_distance) <= std::abs(back_distance)
                            : p.z() >= 0.5f * (texel.z_front + texel.z_back);
  const float plane_distance = std::abs(front ? front_distance : back_distance);
  const float distance = inside ? -plane_distance : plane_distance;
  const Vec3f& normal = front ? texel.n_front : texel.n_back;
  if (!(distance <= radius)) return out;
  out.distance = distance;
  out.normal = normal;
  if (moving_) out.velocity = surface_.velocity(surface_.closest_on(front ? front_triangle_[pixel] : back_triangle_[pixel], p));
  return out;
}

void ImageCollider::query(std::span<const Vec3f> points, float radius, std::span<ContactSample> out) const {
  for (size_t i = 0; i < points.size(); ++i) out[i] = sample(points[i], radius);
}

}  // namespace drape::collision
