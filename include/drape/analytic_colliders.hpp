#pragma once
// Analytic obstacles behind the drape::Collider interface: plane, sphere, box (a table top) and
// capsule (a limb), cylinder (a support disc). Each may translate at a constant velocity (a moving obstacle for the sec. 5
// force response); its distance is exact, so tests and reports can also use it as the inside test.
#include <string>

#include "drape/collider.hpp"
#include "drape/mesh.hpp"

namespace drape {

class AnalyticCollider : public Collider {
 public:
  // Exact signed distance (> 0 outside) and outward normal at time of the last update().
  virtual float signed_distance(const Vec3f& p, Vec3f* normal) const = 0;
  // A triangle mesh of the surface at the current time, for pictures and output files.
  virtual Mesh mesh() const = 0;

  void update(double t) override { offset_ = velocity_ * static_cast<float>(t); }
  void query(std::span<const Vec3f> points, float radius, std::span<ContactSample> out) const override;

  void set_velocity(const Vec3f& velocity) { velocity_ = velocity; }
  const Vec3f& velocity() const { return velocity_; }

 protected:
  Vec3f offset_ = Vec3f::Zero();  // translation since t = 0
  Vec3f velocity_ = Vec3f::Zero();
};

class PlaneCollider final : public AnalyticCollider {
 public:
  PlaneCollider(const Vec3f& point, const Vec3f& normal, float display_size = 2.0f);
  std::string_view name() const override { return "plane"; }
  float signed_distance(const Vec3f& p, Vec3f* normal) const override;
  Mesh mesh() const override;

 private:
  Vec3f point_, normal_;
  float display_size_;
};

class SphereCollider final : public AnalyticCollider {
 public:
  SphereCollider(const Vec3f& centre, float radius);
  std::string_view name() const override { return "sphere"; }
  float signed_distance(const Vec3f& p, Vec3f* normal) const override;
  Mesh mesh() const override;
  Vec3f centre() const { return centre_ + offset_; }
  float radius() const { return radius_; }

 private:
  Vec3f centre_;
  float radius_;
};

// An axis-aligned box, e.g. a table top.
class BoxCollider final : public AnalyticCollider {
 public:
  BoxCollider(const Vec3f& centre, const Vec3f& half_extent);
  std::string_view name() const override { return "box"; }
  float signed_distance(const Vec3f& p, Vec3f* normal) const override;
  Mesh mesh() const override;

 private:
  Vec3f centre_, half_;
};

// All points within `radius` of the segment [a, b].
class CapsuleCollider final : public AnalyticCollider {
 public:
  CapsuleCollider(const Vec3f& a, const Vec3f& b, float radius);
  std::string_view name() const override { return "capsule"; }
  float signed_distance(const Vec3f& p, Vec3f* normal) const override;
  Mesh mesh() const override;

 private:
  Vec3f a_, b_;
  float radius_;
};

// A solid upright cylinder (axis along y) with flat ends, e.g. the support disc of a drape tester.
class CylinderCollider final : public AnalyticCollider {
 public:
  CylinderCollider(const Vec3f& top_centre, float radius, float height);
  std::string_view name() const override { return "cylinder"; }
  float signed_distance(const Vec3f& p, Vec3f* normal) const override;
  Mesh mesh() const override;
  float radius() const { return radius_; }

 private:
  Vec3f top_;
  float radius_, height_;
};

}  // namespace drape
