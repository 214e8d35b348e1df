// Bodies from measurements, made on MakeHuman's body (body/makehuman.hpp).
//
// The shape is MakeHuman's: the weight and height macros set the overall build, and one measurement
// target per requested key (bust-circ for the bust, upperleg- and lowerleg-height for the inseam, ...)
// moves that part. The target weights are solved for so that drape's own tape measurements of the
// mesh (find_landmarks + measure_body, the same code that measures a scan) hit the request.
//
// Landmarks are found by searches (the narrowest section, the fold under the bust), so where they
// lie jumps as the shape changes, and measurements that depend on where (back length, underbust)
// jump with them: no derivative sees that. The solve therefore alternates: find the landmarks,
// pin each to the nearest vertex (the mesh's topology never changes, so a vertex is a material
// point), and solve for the target weights with the tape taken at the pinned landmarks, which moves
// smoothly with the shape (a bounded Levenberg-Marquardt with a finite-difference Jacobian updated
// by Broyden's rule, and a small pull of every weight towards MakeHuman's average so that what the
// request leaves free stays average); then find the landmarks again, until the real measurements
// agree. Pinned measuring skips the landmark search, which is most of the cost of measuring.
#include <algorithm>
#include <array>
#include <cmath>
#include <exception>
#include <optional>
#include <string_view>

#include <Eigen/Dense>

#include "body/analysis.hpp"
#include "body/makehuman.hpp"
#include "drape/body.hpp"
#include "drape/error.hpp"

namespace drape {
namespace {

using body::MhModel;
using body::MhShape;

constexpr float kCm = 0.01f;
constexpr double kTolerance = 0.5;  // cm: done when every requested key is this close
constexpr double kMaxMove = 0.4;    // the largest change of one unknown in one step
constexpr int kRounds = 8;          // landmark searches at most
constexpr int kSteps = 12;          // solver steps per round at most
constexpr int kPolish = 6;          // single-key corrections at most

// One unknown of the solve: a field of MhShape with its bounds, prior, cost of leaving the prior
// (per unit squared, in the residuals' unit, cm squared) and finite-difference step.
struct Unknown {
  enum Kind { kWeight, kHeight, kScale, kMeasure } kind;
  int measure = 0;
  float lo, hi, prior, cost, step;
  float& in(MhShape& s) const {
    switch (kind) {
      case kWeight: return s.weight;
      case kHeight: return s.height;
      case kScale: return s.scale;
      case kMeasure: break;
    }
    return s.measure[static_cast<size_t>(measure)];
  }
};

// Every unknown, in a fixed order: weight, height, scale, then the measurement targets. Targets
// may go to twice MakeHuman's range (the largest and smallest sizes need it).
Unknown unknown(int i) {
  if (i == 0) return {Unknown::kWeight, 0, 0.0f, 1.5f, 0.5f, 0.05f, 0.05f};
  if (i == 1) return {Unknown::kHeight, 0, 0.0f, 1.0f, 0.5f, 0.05f, 0.05f};
  if (i == 2) return {Unknown::kScale, 0, 0.8f, 1.25f, 1.0f, 200.0f, 0.01f};
  return {Unknown::kMeasure, i - 3, -2.5f, 2.5f, 0.0f, 0.1f, 0.1f};
}

// Landmarks pinned to vertices: each is its nearest vertex plus a fixed offset.
constexpr std::array<Vec3f Landmarks::*, 23> kLandmarkFields{
    &Landmarks::crown,          &Landmarks::neck_base,      &Landmarks::neck,           &Landmarks::left_shoulder,
    &Landmarks::right_shoulder, &Landmarks::left_armpit,    &Landmarks::right_armpit,   &Landmarks::left_bust,
    &Landmarks::right_bust,     &Landmarks::underbust,      &Landmarks::waist,          &Landmarks::hip,
    &Landmarks::crotch,         &Landmarks::left_knee,      &Landmarks::right_knee,     &Landmarks::left_ankle,
    &Landmarks::right_ankle,    &Landmarks::left_elbow,     &Landmarks::right_elbow,    &Landmarks::left_wrist,
    &Landmarks::right_wrist,    &Landmarks::left_fingertip, &Landmarks::right_fingertip};
struct Pins {
  std::array<uint32_t, kLandmarkFields.size()> vertex{};
  std::array<Vec3f, kLandmarkFields.size()> offset{};
};

Pins pin(const Mesh& mesh, const Landmarks& lm) {
  Pins pins;
  for (size_t i = 0; i < kLandmarkFields.size(); ++i) {
    const Vec3f& at = lm.*kLandmarkFields[i];
    uint32_t best = 0;
    float best_d = std::numeric_limits<float>::max();
    for (uint32_t v = 0; v < mesh.positions.size(); ++v)
      if (const float d = (mesh.positions[v] - at).squaredNorm(); d < best_d) {
        best_d = d;
        best = v;
      }
    pins.vertex[i] = best;
    pins.offset[i] = at - mesh.positions[best];
  }
  return pins;
}

Landmarks place(const Pins& pins, const Mesh& mesh) {
  Landmarks lm;
  for (size_t i = 0; i < kLandmarkFields.size(); ++i) lm.*kLandmarkFields[i] = mesh.positions[pins.vertex[i]] + pins.offset[i];
  return lm;
}

// The mesh of a shape (body vertices only, feet on y = 0, not centred: the solve needs no more).
class Shaper {
 public:
  explicit Shaper(const MhModel& model) : model_(model) {
    mesh_.positions.resize(model.body_vertices);
    mesh_.triangles = model.triangles;
  }
  const Mesh& operator()(const MhShape& shape) {
    body::mh_positions(model_, shape, all_);
    std::copy(all_.begin(), all_.begin() + model_.body_vertices, mesh_.positions.begin());
    return mesh_;
  }

 private:
  const MhModel& model_;
  Mesh mesh_;
  std::vector<Vec3f> all_;
};

using Keys = std::vector<std::pair<float Measurements::*, float>>;

// Residuals (cm) of the requested keys.
Eigen::VectorXd residuals(const Measurements& m, const Keys& keys) {
  Eigen::VectorXd r(static_cast<Eigen::Index>(keys.size()));
  for (size_t i = 0; i < keys.size(); ++i) r[static_cast<Eigen::Index>(i)] = (m.*keys[i].first - keys[i].second) / kCm;
  return r;
}

// Refuses requests no body can have, before solving.
void check_consistent(const MeasurementRequest& r) {
  auto has = [&](const char* k) { return r.count(k) != 0; };
  if (has("underbust") && has("bust") && r.at("underbust") > r.at("bust"))
    throw InputError("measurements", "underbust is larger than bust");
  if (has("waist") && has("hips") && (r.at("waist") > 1.5f * r.at("hips") || r.at("hips") > 2.2f * r.at("waist")))
    throw InputError("measurements", "waist and hips are too far apart for a human body");
  if (has("inseam") && (r.at("inseam") > 0.56f * r.at("height") || r.at("inseam") < 0.36f * r.at("height")))
    throw InputError("measurements", "inseam must be 36-56 % of the height");
  if (has("wrist") && has("upper_arm") && r.at("wrist") >= r.at("upper_arm"))
    throw InputError("measurements", "wrist is not smaller than the upper arm");
  if (has("thigh") && has("hips") && 2 * r.at("thigh") > 1.6f * r.at("hips"))
    throw InputError("measurements", "two thighs are much larger than the hips");
}

}  // namespace

Body body::mh_body(const MhShape& shape, BodySkeleton skeleton) {
  const MhModel& model = makehuman_model();
  std::vector<Vec3f> all;
  mh_positions(model, shape, all);
  Body b;
  b.sex = shape.sex;
  b.mesh.name = "body";
  b.mesh.positions.assign(all.begin(), all.begin() + model.body_vertices);
  b.mesh.triangles = model.triangles;
  untangle(b.mesh);  // the toes touch: part them
  const Eigen::Affine3f placed = normalise_body_placement(b.mesh, "made body");
  b.mesh.normals = vertex_normals(b.mesh.positions, b.mesh.triangles);
  body::analyse_body(b, "made body", &model.topology);
  // The skeleton follows the shape: each joint is the mean of its vertex group on this body.
  const body::MhSkeleton& rig = model.skeleton(skeleton == BodySkeleton::CmuMb ? "cmu_mb" : "default");
  for (const auto& j : rig.joints) {
    Vec3f sum = Vec3f::Zero();
    for (uint32_t v : j.group) sum += all[v];
    b.skeleton.joints.push_back({j.name, j.parent, placed * Vec3f(sum / static_cast<float>(j.group.size()))});
  }
  b.mesh.joints = rig.vertex_joints;
  b.mesh.weights = rig.vertex_weights;
  return b;
}

body::MhShape body::solve_human_shape(Sex sex, const MeasurementRequest& given) {
  const MhModel& model = body::makehuman_model();
  // Height is always fitted (the average adult's when not given); other keys only when given.
  MeasurementRequest request = given;
  if (!request.count("height")) request["height"] = default_measurements(sex).at("height");
  check_consistent(request);

  Keys keys;
  std::vector<std::string_view> key_names;
  body::MeasurementSet measured;  // only the requested keys are measured
  for (size_t row = 0; row < measurement_table().size(); ++row)
    if (const auto it = request.find(measurement_table()[row].key); it != request.end()) {
      keys.emplace_back(measurement_table()[row].field, it->second);
      key_names.push_back(measurement_table()[row].key);
      measured.set(row);
    }
  const body::SliceTopology& topology = model.topology;  // every candidate body has the same triangles
  auto search = [&](const body::Slicer& mesh) { return body::find_landmarks(mesh, "made body"); };
  auto measure = [&](const body::Slicer& mesh, const Landmarks& lm) {
    return residuals(body::measure_body(mesh, lm, measured), keys);
  };
  std::vector<Unknown> unknowns{unknown(0), unknown(1), unknown(2)};
  for (int m = 0; m < body::kMhMeasureCount; ++m)
    if (request.count(body::mh_measure_key(m))) unknowns.push_back(unknown(3 + m));
  // Each key's own unknown: its measurement target, the height macro for the height.
  std::vector<Eigen::Index> own(key_names.size(), 1);
  for (size_t i = 0; i < key_names.size(); ++i)
    for (size_t u = 3; u < unknowns.size(); ++u)
      if (body::mh_measure_key(unknowns[u].measure) == key_names[i]) own[i] = static_cast<Eigen::Index>(u);
  const auto n = static_cast<Eigen::Index>(unknowns.size());
  const auto k = static_cast<Eigen::Index>(keys.size());

  MhShape base;
  base.sex = sex;
  Eigen::VectorXd x(n), prior(n), cost(n);
  for (Eigen::Index i = 0; i < n; ++i) {
    x[i] = prior[i] = unknowns[static_cast<size_t>(i)].prior;
    cost[i] = unknowns[static_cast<size_t>(i)].cost;
  }
  auto shape_at = [&](const Eigen::VectorXd& v) {
    MhShape s = base;
    for (Eigen::Index i = 0; i < n; ++i) unknowns[static_cast<size_t>(i)].in(s) = static_cast<float>(v[i]);
    return s;
  };
  Shaper shaper(model);
  // Start at the height macro (or beyond its range the scale) that gives the requested height: the
  // height is the mesh's, no landmark needed, and piecewise linear in the macro.
  {
    std::array<float, 3> heights{};
    for (int i = 0; i < 3; ++i) {
      MhShape s = base;
      s.height = 0.5f * static_cast<float>(i);
      heights[static_cast<size_t>(i)] = bounds(shaper(s).positions).size().y();
    }
    const float want = request.at("height");
    const float t = want <= heights[1] ? 0.5f * std::clamp((want - heights[0]) / (heights[1] - heights[0]), 0.0f, 1.0f)
                                       : 0.5f + 0.5f * std::clamp((want - heights[1]) / (heights[2] - heights[1]), 0.0f, 1.0f);
    const float reached = t <= 0.5f ? heights[0] + 2 * t * (heights[1] - heights[0]) : heights[1] + (2 * t - 1) * (heights[2] - heights[1]);
    x[1] = t;
    x[2] = std::clamp(want / reached, unknowns[2].lo, unknowns[2].hi);
  }
  auto objective = [&](const Eigen::VectorXd& r, const Eigen::VectorXd& v) {
    return r.squaredNorm() + (cost.array() * (v - prior).array().square()).sum();
  };

  Eigen::MatrixXd jac;
  Eigen::VectorXd best_x = x;
  double best_miss = std::numeric_limits<double>::max();
  int backtracks = 0;
  for (int round = 0; round < kRounds; ++round) {
    // The real measurements, landmarks searched for.
    const Mesh& mesh = shaper(shape_at(x));
    const body::Slicer indexed(mesh, &topology);
    std::optional<Landmarks> lm;
    try {
      lm = search(indexed);
    } catch (const InputError&) {
      if (round == 0) throw InputError("measurements", "no standing body could be made at this height");
    }
    Eigen::VectorXd r = lm ? measure(indexed, *lm) : Eigen::VectorXd::Constant(k, 1e3);
    const double miss = r.cwiseAbs().maxCoeff();
    if (miss < best_miss) {
      best_miss = miss;
      best_x = x;
    } else if (backtracks < 2 || !lm) {
      if (backtracks >= 2) break;  // not a standing body even halfway: keep the best
      // The landmarks moved under the last solve and it missed worse: back halfway to the best.
      x = best_x + 0.5 * (x - best_x);
      ++backtracks;
      continue;
    }
    if (miss < kTolerance) break;
    // Solve with the landmarks pinned where they are now.
    const Pins pins = pin(mesh, *lm);
    // The underbust, the waist and the hip are searched again (their searches are cheap): the
    // waist is the narrowest level and the hip the fullest, so widening a pinned waist could leave
    // a narrower level elsewhere, and a flat chest's underbust flips between its two rules. An
    // underbust that is not requested is not searched for: only whether there is one matters.
    // Only the requested keys are measured.
    auto pinned_on = [&](Shaper& own_shaper, const Eigen::VectorXd& v) {
      const Mesh& m = own_shaper(shape_at(v));
      Landmarks at = place(pins, m);
      Landmarks searched = at;
      const body::Slicer slicer(m, &topology);
      const bool below_bust = request.count("underbust") ? body::find_underbust(slicer, searched, at.crown.y())
                                                      : body::torso_below_bust(slicer, searched, at.crown.y());
      if (below_bust && body::find_waist_and_hip(slicer, searched) == body::WaistAndHip::kFound)
        at = searched;
      return residuals(body::measure_body(slicer, at, measured), keys);
    };
    auto pinned = [&](const Eigen::VectorXd& v) { return pinned_on(shaper, v); };
    // The columns are independent measurements of shapes one step apart: on every core, each
    // thread shaping into its own mesh; each column is computed the same way on any thread count.
    auto fresh_jacobian = [&]() {
      jac.resize(k, n);
      std::vector<std::exception_ptr> failed(static_cast<size_t>(n));  // none may leave a parallel region
#pragma omp parallel
      {
        Shaper own_shaper(model);
#pragma omp for schedule(dynamic, 1)
        for (Eigen::Index i = 0; i < n; ++i) {
          try {
            const Unknown& u = unknowns[static_cast<size_t>(i)];
            Eigen::VectorXd y = x;
            const double h = x[i] + u.step <= u.hi ? u.step : -u.step;
            y[i] += h;
            jac.col(i) = (pinned_on(own_shaper, y) - r) / h;
          } catch (...) {
            failed[static_cast<size_t>(i)] = std::current_exception();
          }
        }
      }
      for (const auto& e : failed)
        if (e) std::rethrow_exception(e);
    };
    if (jac.size() == 0) fresh_jacobian();
    double f = objective(r, x);
    double mu = 1e-3;
    bool fresh = round == 0;
    for (int step_count = 0; step_count < kSteps && r.cwiseAbs().maxCoeff() > 0.2 * kTolerance; ++step_count) {
      const Eigen::MatrixXd jtj = jac.transpose() * jac;
      Eigen::MatrixXd a = jtj;
      a.diagonal() += cost + mu * (jtj.diagonal().array() + 1e-3).matrix();
      Eigen::VectorXd delta = -a.ldlt().solve(jac.transpose() * r + (cost.array() * (x - prior).array()).matrix());
      if (const double big = delta.cwiseAbs().maxCoeff(); big > kMaxMove) delta *= kMaxMove / big;
      Eigen::VectorXd y = x + delta;
      for (Eigen::Index i = 0; i < n; ++i)
        y[i] = std::clamp(y[i], double{unknowns[static_cast<size_t>(i)].lo}, double{unknowns[static_cast<size_t>(i)].hi});
      const Eigen::VectorXd step = y - x;
      if (step.norm() < 1e-6) {
        if (fresh) break;  // a true Jacobian's step is nothing: bounds or the prior hold it here
        fresh_jacobian();
        fresh = true;
        continue;
      }
      const Eigen::VectorXd ry = pinned(y);
      const double fy = objective(ry, y);
      jac += ((ry - r) - jac * step) * step.transpose() / step.squaredNorm();
      if (fy < f) {
        x = y;
        r = ry;
        f = fy;
        mu = std::max(mu / 3, 1e-6);
      } else if (!fresh) {
        fresh_jacobian();  // the updated Jacobian misled: measure a true one
        fresh = true;
      } else if ((mu *= 4) > 1e3) {
        break;
      }
    }
  }
  // Where a landmark flips between two places as the shape changes (a flat chest's fold, a flat
  // waist), the rounds can end between them: the worst key is then moved alone by its own unknown,
  // on the real measurements, with the slope the solve last saw.
  for (int polish = 0; polish < kPolish && best_miss > kTolerance && jac.size() > 0; ++polish) {
    const body::Slicer indexed(shaper(shape_at(best_x)), &topology);
    const Eigen::VectorXd r = measure(indexed, search(indexed));
    Eigen::Index worst = 0;
    r.cwiseAbs().maxCoeff(&worst);
    const Eigen::Index u = own[static_cast<size_t>(worst)];
    if (std::abs(jac(worst, u)) < 1e-6) break;
    bool better = false;
    for (double fraction : {1.0, 0.5, 1.5}) {
      Eigen::VectorXd y = best_x;
      y[u] = std::clamp(y[u] - fraction * r[worst] / jac(worst, u), double{unknowns[static_cast<size_t>(u)].lo},
                        double{unknowns[static_cast<size_t>(u)].hi});
      const body::Slicer candidate(shaper(shape_at(y)), &topology);
      std::optional<Landmarks> lm;
      try {
        lm = search(candidate);
      } catch (const InputError&) {
        continue;
      }
      const double miss = measure(candidate, *lm).cwiseAbs().maxCoeff();
      if (miss < best_miss) {
        best_miss = miss;
        best_x = y;
        better = true;
        break;
      }
    }
    if (!better) break;
  }
  return shape_at(best_x);
}

MeasurementRequest default_body_request(Sex sex) {
  MeasurementRequest request = default_measurements(sex);
  request.erase("shoulder_width");
  request.erase("back_length");
  return request;
}

Body make_human_body(Sex sex, const MeasurementRequest& request, const BodyBuildOptions& options) {
  return body::mh_body(body::solve_human_shape(sex, request), options.skeleton);
}

}  // namespace drape
