// Embree point queries for the nearest body triangle; see triangle_bvh.hpp.
#include "collision/triangle_bvh.hpp"

#include <algorithm>
#include <limits>
#include <stdexcept>
#include <string>

namespace drape::collision {
namespace {

struct QueryState {
  const BodySurface* surface;
  SurfaceHit* hit;
  bool found;
};

// Embree calls this for every triangle whose box meets the query sphere; it shrinks the sphere to
// the best distance so far, which prunes the rest of the traversal.
bool visit_triangle(RTCPointQueryFunctionArguments* args) {
  auto* state = static_cast<QueryState*>(args->userPtr);
  const Vec3f p(args->query->x, args->query->y, args->query->z);
  const SurfaceHit candidate = state->surface->closest_on(args->primID, p);
  if (candidate.distance < args->query->radius) {
    args->query->radius = candidate.distance;
    *state->hit = candidate;
    state->found = true;
    return true;
  }
  return false;
}

struct WithinState {
  const BodySurface* surface;
  std::vector<SurfaceHit>* hits;
};

// Collects every triangle within the (fixed) query radius, with its nearest point.
bool collect_triangle(RTCPointQueryFunctionArguments* args) {
  auto* state = static_cast<WithinState*>(args->userPtr);
  const Vec3f p(args->query->x, args->query->y, args->query->z);
  const SurfaceHit hit = state->surface->closest_on(args->primID, p);
  if (hit.distance <= args->query->radius) state->hits->push_back(hit);
  return false;
}

// An Embree point query: everything within `radius` of p.
RTCPointQuery point_query(const Vec3f& p, float radius) {
  RTCPointQuery query;
  query.x = p.x();
  query.y = p.y();
  query.z = p.z();
  query.time = 0.0f;
  query.radius = radius;
  return query;
}

}  // namespace

TriangleBvh::TriangleBvh(const BodySurface& surface, bool refit) : surface_(surface) {
  device_ = rtcNewDevice(nullptr);
  if (!device_) throw std::runtime_error("Embree: cannot create a device");
  scene_ = rtcNewScene(device_);
  // Embree refits a geometry's BVH (RTC_BUILD_QUALITY_REFIT) only in a scene of low build quality,
  // its two-level structure; in any other scene every commit rebuilt the body's BVH (8 ms of the 12
  // ms a moving 47.5k-triangle body took per update, against 1 ms refitted; queries as fast).
  rtcSetSceneBuildQuality(scene_, refit ? RTC_BUILD_QUALITY_LOW : RTC_BUILD_QUALITY_HIGH);
  if (refit) rtcSetSceneFlags(scene_, RTC_SCENE_FLAG_DYNAMIC);
  geometry_ = rtcNewGeometry(device_, RTC_GEOMETRY_TYPE_TRIANGLE);
  if (refit) rtcSetGeometryBuildQuality(geometry_, RTC_BUILD_QUALITY_REFIT);
  // Embree reads up to 16 bytes past the last vertex: one spare vertex.
  vertices_ = static_cast<float*>(rtcSetNewGeometryBuffer(geometry_, RTC_BUFFER_TYPE_VERTEX, 0, RTC_FORMAT_FLOAT3,
                                                          3 * sizeof(float), surface_.vertex_count() + 1));
  auto* indices = static_cast<unsigned*>(rtcSetNewGeometryBuffer(geometry_, RTC_BUFFER_TYPE_INDEX, 0, RTC_FORMAT_UINT3,
                                                                  3 * sizeof(unsigned), surface_.triangle_count()));
  if (!vertices_ || !indices) throw std::runtime_error("Embree: cannot allocate the body's buffers");
  for (size_t t = 0; t < surface_.triangle_count(); ++t)
    for (int k = 0; k < 3; ++k) indices[3 * t + static_cast<size_t>(k)] = surface_.triangle(static_cast<uint32_t>(t))[static_cast<size_t>(k)];
  upload_vertices();
  rtcCommitGeometry(geometry_);
  rtcAttachGeometry(scene_, geometry_);
  rtcCommitScene(scene_);
  if (rtcGetDeviceError(device_) != RTC_ERROR_NONE) throw std::runtime_error("Embree: building the body BVH failed");
}

TriangleBvh::~TriangleBvh() {
  if (geometry_) rtcReleaseGeometry(geometry_);
  if (scene_) rtcReleaseScene(scene_);
  if (device_) rtcReleaseDevice(device_);
}

void TriangleBvh::upload_vertices() {
  const auto positions = surface_.positions();
  for (size_t v = 0; v < positions.size(); ++v)
    for (int k = 0; k < 3; ++k) vertices_[3 * v + static_cast<size_t>(k)] = positions[v][k];
}

void TriangleBvh::update() {
  grid_.reset();
  upload_vertices();
  rtcUpdateGeometryBuffer(geometry_, RTC_BUFFER_TYPE_VERTEX, 0);
  rtcCommitGeometry(geometry_);
  rtcCommitScene(scene_);
}

void TriangleBvh::build_candidate_grid(float cell, float band, const CandidateGrid::CellFilter& wanted) {
  grid_.reset();
  grid_ = std::make_unique<CandidateGrid>(*this, cell, band, wanted);
}

bool TriangleBvh::finish(CandidateGrid::Answer answer, const Vec3f& p, float radius, SurfaceHit& hit) const {
  using Answer = CandidateGrid::Answer;
  if (answer == Answer::kFound || answer == Answer::kNone) return answer == Answer::kFound;
  if (answer == Answer::kTruncatedFound) {  // the tree looks only for something nearer than the best so far
    SurfaceHit nearer;
    if (closest_in_tree(p, hit.distance, nearer)) hit = nearer;
    return true;
  }
  return closest_in_tree(p, radius, hit);
}

bool TriangleBvh::closest(const Vec3f& p, float radius, SurfaceHit& hit) const {
  if (grid_) return finish(grid_->closest(p, radius, hit), p, radius, hit);
  return closest_in_tree(p, radius, hit);
}

void TriangleBvh::closest_batch(std::span<const Vec3f> points, float radius, std::span<SurfaceHit> hits,
                                std::span<uint8_t> found) const {
  if (!grid_) {
    for (size_t i = 0; i < points.size(); ++i) found[i] = closest_in_tree(points[i], radius, hits[i]);
    return;
  }
  // Per chunk: every point's cell, then three rounds of prefetches (offsets, lists, triangles),
  // each issued for the whole chunk before the next round reads what the previous one fetched.
  constexpr size_t kChunk = 32;
  size_t cells[kChunk];
  for (size_t start = 0; start < points.size(); start += kChunk) {
    const size_t n = std::min(kChunk, points.size() - start);
    const Vec3f* p = points.data() + start;
    for (size_t j = 0; j < n; ++j) {
      cells[j] = grid_->cell_of(p[j]);
      grid_->prefetch_offsets(cells[j]);
    }
    for (size_t j = 0; j < n; ++j) grid_->prefetch_list(cells[j]);
    for (size_t j = 0; j < n; ++j) grid_->prefetch_triangles(cells[j]);
    for (size_t j = 0; j < n; ++j) {
      SurfaceHit& hit = hits[start + j];
      found[start + j] = finish(grid_->closest_in(cells[j], p[j], radius, hit), p[j], radius, hit);
    }
  }
}

void TriangleBvh::within(const Vec3f& p, float radius, std::vector<SurfaceHit>& hits) const {
  hits.clear();
  RTCPointQuery query = point_query(p, radius);
  RTCPointQueryContext context;
  rtcInitPointQueryContext(&context);
  WithinState state{&surface_, &hits};
  rtcPointQuery(scene_, &query, &context, collect_triangle, &state);
  // A tree may reference a triangle from several leaves.
  const auto by_triangle = [](const SurfaceHit& a, const SurfaceHit& b) { return a.triangle < b.triangle; };
  std::sort(hits.begin(), hits.end(), by_triangle);
  hits.erase(std::unique(hits.begin(), hits.end(), [](const SurfaceHit& a, const SurfaceHit& b) { return a.triangle == b.triangle; }),
             hits.end());
}

bool TriangleBvh::first_hit(const Vec3f& origin, const Vec3f& direction, float max_distance, float& distance) const {
  RTCIntersectContext context;
  rtcInitIntersectContext(&context);
  RTCRayHit ray{};
  ray.ray.org_x = origin.x();
  ray.ray.org_y = origin.y();
  ray.ray.org_z = origin.z();
  ray.ray.dir_x = direction.x();
  ray.ray.dir_y = direction.y();
  ray.ray.dir_z = direction.z();
  ray.ray.tnear = 0.0f;
  ray.ray.tfar = max_distance;
  ray.ray.mask = ~0u;
  ray.hit.geomID = RTC_INVALID_GEOMETRY_ID;
  rtcIntersect1(scene_, &context, &ray);
  if (ray.hit.geomID == RTC_INVALID_GEOMETRY_ID) return false;
  distance = ray.ray.tfar;
  return true;
}

bool TriangleBvh::closest_in_tree(const Vec3f& p, float radius, SurfaceHit& hit) const {
  RTCPointQuery query = point_query(p, radius);
  RTCPointQueryContext context;
  rtcInitPointQueryContext(&context);
  QueryState state{&surface_, &hit, false};
  rtcPointQuery(scene_, &query, &context, visit_triangle, &state);
  return state.found;
}

}  // namespace drape::collision
