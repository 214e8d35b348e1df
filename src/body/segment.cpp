// Per-vertex body parts from landmarks. Arms are grown over the mesh from each fingertip and stop at
// the armscye plane (through the armpit and the shoulder point, containing the front-back axis),
// so a hip that sticks out as far as the armpit is not taken for an arm. Legs are everything below
// a horizontal cut a little above the crotch (2.3 % of the height, where garment bodies put the
// leg/torso boundary), split by side. The head is everything above the narrowest neck section.
#include <algorithm>
#include <cmath>
#include <exception>
#include <queue>

#include "drape/body.hpp"
#include "body/analysis.hpp"

namespace drape {

std::string_view body_part_name(BodyPart part) {
  switch (part) {
    case BodyPart::Head: return "head";
    case BodyPart::Torso: return "torso";
    case BodyPart::LeftArm: return "left_arm";
    case BodyPart::RightArm: return "right_arm";
    case BodyPart::LeftLeg: return "left_leg";
    case BodyPart::RightLeg: return "right_leg";
  }
  return "torso";
}

std::vector<BodyPart> segment_body(const Mesh& mesh, const Landmarks& lm) {
  const auto& p = mesh.positions;
  const size_t n = p.size();
  std::vector<BodyPart> parts(n, BodyPart::Torso);
  std::vector<std::vector<uint32_t>> neighbours(n);
  for (const Tri& t : mesh.triangles)
    for (int e = 0; e < 3; ++e) {
      neighbours[t[e]].push_back(t[(e + 1) % 3]);
      neighbours[t[(e + 1) % 3]].push_back(t[e]);
    }

  const float height = lm.crown.y();
  const float leg_top = lm.crotch.y() + 0.023f * height;
  for (size_t v = 0; v < n; ++v) {
    if (p[v].y() > lm.neck.y()) parts[v] = BodyPart::Head;
    else if (p[v].y() < leg_top) parts[v] = p[v].x() >= 0 ? BodyPart::LeftLeg : BodyPart::RightLeg;
  }

  // Arms: flood fill from the vertex nearest the fingertip, on the outer side of the armscye plane.
  auto grow_arm = [&](const Vec3f& tip, const Vec3f& armpit, const Vec3f& shoulder, BodyPart label) {
    const Vec3f along = (shoulder - armpit).normalized();
    Vec3f normal = along.cross(Vec3f::UnitZ()).normalized();
    if (normal.x() * (tip.x() - armpit.x()) < 0) normal = -normal;
    auto outside = [&](uint32_t v) { return (p[v] - armpit).dot(normal) > 0 && p[v].y() < lm.neck.y(); };
    uint32_t seed = 0;
    float best = std::numeric_limits<float>::max();
    for (uint32_t v = 0; v < n; ++v) {
      const float d = (p[v] - tip).squaredNorm();
      if (d < best) {
        best = d;
        seed = v;
      }
    }
    std::vector<char> seen(n, 0);
    std::queue<uint32_t> queue;
    queue.push(seed);
    seen[seed] = 1;
    while (!queue.empty()) {
      const uint32_t v = queue.front();
      queue.pop();
      parts[v] = label;
      for (uint32_t w : neighbours[v])
        if (!seen[w] && outside(w)) {
          seen[w] = 1;
          queue.push(w);
        }
    }
  };
  grow_arm(lm.left_fingertip, lm.left_armpit, lm.left_shoulder, BodyPart::LeftArm);
  grow_arm(lm.right_fingertip, lm.right_armpit, lm.right_shoulder, BodyPart::RightArm);
  return parts;
}

void analyse_body(Body& body, const std::string& source) { body::analyse_body(body, source, nullptr); }

void body::analyse_body(Body& body, const std::string& source, const SliceTopology* topology) {
  const Slicer indexed(body.mesh, topology);  // indexed once for the search and the measurements
  body.landmarks = find_landmarks(indexed, source);
  // The tape and the segmentation read the same landmarks and write apart: one on each core.
  std::exception_ptr failed[2];  // none may leave a parallel region
#pragma omp parallel sections
  {
#pragma omp section
    try {
      body.measurements = measure_body(indexed, body.landmarks, MeasurementSet().set());
    } catch (...) {
      failed[0] = std::current_exception();
    }
#pragma omp section
    try {
      body.parts = segment_body(body.mesh, body.landmarks);
    } catch (...) {
      failed[1] = std::current_exception();
    }
  }
  for (const auto& e : failed)
    if (e) std::rethrow_exception(e);
}

}  // namespace drape
