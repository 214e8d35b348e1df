// Outline curves of pattern panels: evaluation, arc length, equal-length sampling, exact area.
// Lengths and areas use composite Gauss-Legendre quadrature (5 points on 16 sub-intervals): exact
// for the polynomial area integrands of Bezier curves, and far below a micrometre for arc lengths.
#include <algorithm>
#include <cmath>
#include <numbers>

#include "drape/garment.hpp"

namespace drape {
namespace {

constexpr int kSubIntervals = 16;
constexpr std::array<double, 5> kGaussNodes = {-0.9061798459386640, -0.5384693101056831, 0.0,
                                               0.5384693101056831, 0.9061798459386640};
constexpr std::array<double, 5> kGaussWeights = {0.2369268850561891, 0.4786286704993665,
                                                 0.5688888888888889, 0.4786286704993665,
                                                 0.2369268850561891};

// Integrates f over [a, b] with the composite rule.
template <class F>
double integrate(F&& f, double a, double b) {
  double sum = 0;
  const double h = (b - a) / kSubIntervals;
  for (int k = 0; k < kSubIntervals; ++k) {
    const double mid = a + (k + 0.5) * h;
    for (size_t q = 0; q < kGaussNodes.size(); ++q) sum += kGaussWeights[q] * f(mid + 0.5 * h * kGaussNodes[q]);
  }
  return sum * 0.5 * h;
}

// Polyline helpers: cumulative lengths and the point at a fraction of the total.
std::vector<double> cumulative_lengths(const std::vector<Vec2d>& pts) {
  std::vector<double> acc(pts.size(), 0.0);
  for (size_t i = 1; i < pts.size(); ++i) acc[i] = acc[i - 1] + (pts[i] - pts[i - 1]).norm();
  return acc;
}

size_t polyline_segment(const std::vector<double>& acc, double s) {
  const auto it = std::upper_bound(acc.begin(), acc.end(), s);
  const size_t i = it == acc.begin() ? 0 : static_cast<size_t>(it - acc.begin()) - 1;
  return std::min(i, acc.size() - 2);
}

}  // namespace

Vec2d Curve::point(double t) const {
  const double u = 1 - t;
  switch (kind) {
    case EdgeCurve::line:
      return u * start + t * end;
    case EdgeCurve::quadratic:
      return u * u * start + 2 * u * t * control[0] + t * t * end;
    case EdgeCurve::cubic:
      return u * u * u * start + 3 * u * u * t * control[0] + 3 * u * t * t * control[1] + t * t * t * end;
    case EdgeCurve::arc: {
      if (t <= 0) return start;  // exact end points, so consecutive edges meet exactly
      if (t >= 1) return end;
      const double a = start_angle + t * sweep;
      return centre + radius * Vec2d(std::cos(a), std::sin(a));
    }
    case EdgeCurve::polyline: {
      const auto acc = cumulative_lengths(points);
      if (acc.back() <= 0) return start;
      const double s = std::clamp(t, 0.0, 1.0) * acc.back();
      const size_t i = polyline_segment(acc, s);
      const double seg = acc[i + 1] - acc[i];
      const double f = seg > 0 ? (s - acc[i]) / seg : 0.0;
      return (1 - f) * points[i] + f * points[i + 1];
    }
  }
  return start;
}

Vec2d Curve::tangent(double t) const {
  const double u = 1 - t;
  switch (kind) {
    case EdgeCurve::line:
      return end - start;
    case EdgeCurve::quadratic:
      return 2 * u * (control[0] - start) + 2 * t * (end - control[0]);
    case EdgeCurve::cubic:
      return 3 * u * u * (control[0] - start) + 6 * u * t * (control[1] - control[0]) + 3 * t * t * (end - control[1]);
    case EdgeCurve::arc: {
      const double a = start_angle + t * sweep;
      return radius * sweep * Vec2d(-std::sin(a), std::cos(a));
    }
    case EdgeCurve::polyline: {
      const auto acc = cumulative_lengths(points);
      if (acc.back() <= 0) return Vec2d::Zero();
      const size_t i = polyline_segment(acc, std::clamp(t, 0.0, 1.0) * acc.back());
      const Vec2d d = points[i + 1] - points[i];
      const double n = d.norm();
      return n > 0 ? Vec2d(d * (acc.back() / n)) : Vec2d::Zero();
    }
  }
  return end - start;
}

double Curve::length() const {
  switch (kind) {
    case EdgeCurve::line:
      return (end - start).norm();
    case EdgeCurve::arc:
      return radius * std::abs(sweep);
    case EdgeCurve::polyline:
      return cumulative_lengths(points).back();
    default:
      return integrate([&](double t) { return tangent(t).norm(); }, 0.0, 1.0);
  }
}

std::vector<Vec2d> Curve::sample_by_length(size_t count) const {
  count = std::max<size_t>(count, 1);
  std::vector<Vec2d> out;
  out.reserve(count + 1);
  if (kind == EdgeCurve::line || kind == EdgeCurve::arc || kind == EdgeCurve::polyline) {
    // These are parametrised by arc length already.
    for (size_t k = 0; k <= count; ++k) out.push_back(point(static_cast<double>(k) / static_cast<double>(count)));
    return out;
  }
  // Bezier: tabulate arc length on a fine parameter grid and invert it piecewise linearly.
  constexpr int kTable = 512;
  std::array<double, kTable + 1> acc{};
  for (int i = 0; i < kTable; ++i) {
    const double t0 = static_cast<double>(i) / kTable, t1 = static_cast<double>(i + 1) / kTable;
    double seg = 0;  // one 5-point Gauss-Legendre rule per table interval
    for (size_t q = 0; q < kGaussNodes.size(); ++q)
      seg += kGaussWeights[q] * tangent(0.5 * (t0 + t1) + 0.5 * (t1 - t0) * kGaussNodes[q]).norm();
    acc[static_cast<size_t>(i) + 1] = acc[static_cast<size_t>(i)] + 0.5 * (t1 - t0) * seg;
  }
  const double total = acc[kTable];
  size_t i = 0;
  for (size_t k = 0; k <= count; ++k) {
    if (k == 0) { out.push_back(start); continue; }
    if (k == count) { out.push_back(end); continue; }
    const double s = total * static_cast<double>(k) / static_cast<double>(count);
    while (i + 1 < static_cast<size_t>(kTable) && acc[i + 1] < s) ++i;
    const double seg = acc[i + 1] - acc[i];
    const double f = seg > 0 ? (s - acc[i]) / seg : 0.0;
    out.push_back(point((static_cast<double>(i) + f) / kTable));
  }
  return out;
}

double Panel::signed_area() const {
  // Green's theorem: A = 1/2 * closed integral of (x dy - y dx), summed edge by edge.
  double twice = 0;
  for (const Curve& c : edges) {
    if (c.kind == EdgeCurve::line || c.kind == EdgeCurve::polyline) {
      const std::vector<Vec2d> pts = c.kind == EdgeCurve::line ? std::vector<Vec2d>{c.start, c.end} : c.points;
      for (size_t i = 0; i + 1 < pts.size(); ++i) twice += pts[i].x() * pts[i + 1].y() - pts[i + 1].x() * pts[i].y();
    } else {
      twice += integrate([&](double t) {
        const Vec2d p = c.point(t), d = c.tangent(t);
        return p.x() * d.y() - p.y() * d.x();
      }, 0.0, 1.0);
    }
  }
  return 0.5 * twice;
}

double Panel::perimeter() const {
  double sum = 0;
  for (const Curve& c : edges) sum += c.length();
  return sum;
}

std::vector<Vec2d> Panel::polygon(double spacing) const {
  std::vector<Vec2d> out;
  for (const Curve& c : edges) {
    if (c.kind == EdgeCurve::line) {
      out.push_back(c.start);
    } else if (c.kind == EdgeCurve::polyline) {
      out.insert(out.end(), c.points.begin(), c.points.end() - 1);
    } else {
      const auto n = static_cast<size_t>(std::max(2.0, std::ceil(c.length() / spacing)));
      auto pts = c.sample_by_length(n);
      out.insert(out.end(), pts.begin(), pts.end() - 1);
    }
  }
  return out;
}

const char* to_string(BodyRegion part) {
  switch (part) {
    case BodyRegion::torso: return "torso";
    case BodyRegion::left_arm: return "left_arm";
    case BodyRegion::right_arm: return "right_arm";
    case BodyRegion::left_leg: return "left_leg";
    case BodyRegion::right_leg: return "right_leg";
  }
  return "?";
}

const char* to_string(PanelSide side) {
  switch (side) {
    case PanelSide::front: return "front";
    case PanelSide::back: return "back";
    case PanelSide::left: return "left";
    case PanelSide::right: return "right";
  }
  return "?";
}

const char* to_string(Landmark landmark) {
  switch (landmark) {
    case Landmark::neck: return "neck";
    case Landmark::shoulder: return "shoulder";
    case Landmark::bust: return "bust";
    case Landmark::waist: return "waist";
    case Landmark::hip: return "hip";
    case Landmark::crotch: return "crotch";
    case Landmark::knee: return "knee";
    case Landmark::ankle: return "ankle";
    case Landmark::elbow: return "elbow";
    case Landmark::wrist: return "wrist";
  }
  return "?";
}

const char* to_string(EdgeCurve curve) {
  switch (curve) {
    case EdgeCurve::line: return "line";
    case EdgeCurve::quadratic: return "quadratic";
    case EdgeCurve::cubic: return "cubic";
    case EdgeCurve::arc: return "arc";
    case EdgeCurve::polyline: return "polyline";
  }
  return "?";
}

double Garment::seam_side_length(const SeamSide& side) const {
  const Panel& p = panels.at(side.panel);
  double sum = 0;
  for (uint32_t k = 0; k < side.edge_count; ++k) sum += p.edges[(side.first_edge + k) % p.edges.size()].length();
  return sum;
}

size_t GarmentMesh::vertex_count() const {
  size_t n = 0;
  for (const auto& p : panels) n += p.mesh.vertex_count();
  return n;
}

size_t GarmentMesh::triangle_count() const {
  size_t n = 0;
  for (const auto& p : panels) n += p.mesh.triangle_count();
  return n;
}

}  // namespace drape
