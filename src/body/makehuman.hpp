#pragma once
// MakeHuman's CC0 body as drape packs it (tools/pack_makehuman.cpp -> assets/bodies/makehuman.bin,
// compiled into drape_body): the base mesh's body in metres, the young-adult macro and height
// targets per sex, the measurement targets, and two skeletons (MakeHuman's default reduced to
// drape's CMU-named joints, and cmu_mb) with their skin weights. See docs/bodies.md.
#include <array>
#include <cstdint>
#include <span>
#include <string>
#include <string_view>
#include <vector>

#include "body/slicing.hpp"
#include "drape/body.hpp"

namespace drape::body {

// A sparse displacement of the packed vertices (metres), to be scaled by the target's weight.
struct MhTarget {
  std::string name;
  std::vector<uint32_t> vertex;
  std::vector<Vec3f> delta;
};

struct MhJoint {
  std::string name;
  int parent = -1;
  std::vector<uint32_t> group;  // the joint is the mean of these packed vertices
};

struct MhSkeleton {
  std::string name;  // "default" (drape's joint names) or "cmu_mb"
  std::vector<MhJoint> joints;
  std::vector<std::array<uint16_t, 4>> vertex_joints;  // per body vertex, top 4
  std::vector<Vec4f> vertex_weights;                   // normalised
};

struct MhModel {
  uint32_t body_vertices = 0;  // the mesh is vertices [0, body_vertices); helpers follow
  std::vector<Vec3f> base;     // body + helper vertices, metres, base.obj's frame (+Y up, facing +Z)
  std::vector<Tri> triangles;  // closed, genus 0, counter-clockwise from outside
  SliceTopology topology;      // of the triangles, for slicing the bodies made of them
  std::vector<MhTarget> targets;
  std::vector<MhSkeleton> skeletons;

  const MhTarget& target(std::string_view name) const;  // std::out_of_range when absent
  const MhSkeleton& skeleton(std::string_view name) const;
};

// std::runtime_error when the bytes are not a well-formed pack.
MhModel decode_makehuman(std::span<const unsigned char> bytes);
// The pack compiled into drape, decoded on first use and shared (immutable).
const MhModel& makehuman_model();

// The measurement targets drape solves for, one per measurement key but height (which the height
// macro and a uniform scale set). Leg and arm lengths move two MakeHuman targets each.
enum MhMeasure : int {
  kMhNeck, kMhBust, kMhUnderbust, kMhWaist, kMhHips, kMhThigh, kMhUpperArm, kMhWrist, kMhInseam, kMhArmLength,
  kMhShoulderWidth, kMhBackLength, kMhMeasureCount
};
// The measurement key each target is solved for ("neck", "bust", ...).
std::string_view mh_measure_key(int measure);

// Where a MakeHuman body is in its parameter space. weight and height are MakeHuman's macro values
// (0 = min, 0.5 = average, 1 = max; weight above 1 extrapolates the max-weight target); measure
// weights select the -decr (< 0) or -incr (> 0) target, MakeHuman's range being [-1, 1].
struct MhShape {
  Sex sex = Sex::Female;
  float weight = 0.5f;
  float height = 0.5f;
  float scale = 1.0f;  // uniform, about the feet: heights beyond the macro's range
  std::array<float, kMhMeasureCount> measure{};
};

// Positions of every packed vertex (body + helpers) of that shape, feet (the body's lowest vertex)
// on y = 0, in base.obj's frame otherwise. `out` is resized and overwritten.
void mh_positions(const MhModel& model, const MhShape& shape, std::vector<Vec3f>& out);

// Pairs of triangles (ascending indices) that share no vertex and cross each other; with a focus,
// only those near the focus triangles (within about a centimetre).
std::vector<std::pair<uint32_t, uint32_t>> crossing_triangles(const Mesh& mesh, std::span<const uint32_t> focus = {});
// Pulls the vertices of crossing triangles inwards along their normals, 0.5 mm a round, until
// nothing crosses or max_rounds have passed; returns the crossings left.
size_t untangle(Mesh& mesh, int max_rounds = 40);

// The body of that shape in drape's frame (placement normalised as load_body does), analysed, with
// the chosen skeleton placed on it (joints at the means of their vertex groups) and its skin weights.
Body mh_body(const MhShape& shape, BodySkeleton skeleton = BodySkeleton::Drape);

// The shape whose body measures as requested (make_human_body's solve: the weight and height macros
// and one measurement target per requested key; docs/bodies.md). InputError("measurements") for a
// combination no human body has.
MhShape solve_human_shape(Sex sex, const MeasurementRequest& request);

}  // namespace drape::body
