// A size chart made from the pattern (drape/size_advice.hpp, docs/fit.md "A chart from the
// pattern"): each size's girths measured at the garment's own lines, less the ease it is drafted
// with, are the body it is cut for.
//
// The lines are found on the panels as placement puts them round a body, before sewing. Placement
// anchors every panel of a ring to one landmark, so the panels' heights relative to each other are
// the pattern's and a horizontal cut through them measures the sewn garment's girth at that height
// (the cut's length on the flat pattern, so the wrap round the body does not count). Which body
// they are placed on moves the lines, not the girths.
#include <fmt/format.h>

#include <Eigen/Geometry>

#include <algorithm>
#include <cmath>
#include <limits>
#include <map>
#include <numeric>

#include "drape/collision.hpp"
#include "drape/size_advice.hpp"
#include "dress/stages.hpp"

namespace drape {
namespace {

// Distances down the garment from its underarm (the top of its side seams) and from its top edge,
// to the lines the clothing industry measures a garment at. Chest: 2.5 cm below the armhole (ISO
// 8559-1's garment chest). Waist and hips of a top: the body's underarm-to-waist and
// underarm-to-hip depths of a size 12 block (Aldrich, Metric Pattern Cutting: 20 cm and 40 cm
// from the bust line's armhole depth); hips of a bottom: within a waist-to-hip depth (20 cm) of its
// top, above its crotch.
constexpr float kChestBelowUnderarm = 0.025f;
constexpr float kWaistBelowUnderarm = 0.20f;
constexpr float kHipsBelowUnderarm = 0.38f;
constexpr float kHipDepth = 0.20f;
// A top has a waist only where it is shaped: narrower there than at its chest and hips by this much.
constexpr float kShapedWaist = 0.04f;
// A bottom is sized by its hips only where it is fitted there: no wider than this times its waist
// (a body's hips are at most about 1.45 times its waist; a flared skirt is far wider).
constexpr float kFittedHips = 1.6f;
// The cut's reach from the body's axis: every panel of a ring, on bodies up to XXL.
constexpr float kReach = 0.8f;
constexpr float kStep = 0.005f;  // the search's step down the garment
// A side seam (one whose side runs farther down than across) runs at least this far down.
constexpr float kSideSeam = 0.15f;
// A ring whose top is within this under a bodice's bottom is the skirt sewn to it (placement may
// leave a gap between the two).
constexpr float kSeparated = 0.25f;
// A ring's top edge: its outline edges facing up (within 45 degrees) in each panel's top 15 cm, in
// chains that come within 3 cm of their panel's top.
constexpr float kTopEdgeDepth = 0.15f;
constexpr float kTopEdgeReach = 0.03f;
constexpr float kFacingUp = 0.7f;

}  // namespace

const SizeMeasurements& default_intended_ease() {
  // Wearing ease of a fitted woven garment (Aldrich, Metric Pattern Cutting: a close-fitting dress
  // block 5-10 cm at the bust, 2-4 cm at the waist, 5 cm at the hips).
  static const SizeMeasurements kEase{{"bust", 0.08}, {"waist", 0.03}, {"hips", 0.05}};
  return kEase;
}

double intended_ease(const GarmentSpec& spec, std::string_view key) {
  if (const auto it = spec.intended_ease.find(key); it != spec.intended_ease.end()) return it->second;
  const SizeMeasurements& d = default_intended_ease();
  const auto it = d.find(key);
  return it == d.end() ? 0.0 : it->second;
}

std::vector<PatternGirth> pattern_girths(const Body& body, const DressedGarment& placed, const Garment& garment,
                                         const GarmentSpec& spec) {
  const ClothModel& model = placed.model;
  const size_t n = model.particle_count();
  const std::span<const Vec3f> x = placed.state.x;
  const size_t panels = std::min(garment.panels.size(), placed.panel_first_vertex.empty() ? 0 : placed.panel_first_vertex.size() - 1);
  // Which particles are on a sleeve or a leg: as the fit reads them (fit_garment).
  const FitGarment flags = fit_garment(placed, garment);
  const std::vector<uint8_t>& arm = flags.on_arm;
  const std::vector<uint8_t>& leg = flags.on_leg;
  std::vector<uint32_t> panel_of(n, 0);
  for (size_t p = 0; p < panels; ++p)
    for (uint32_t i = placed.panel_first_vertex[p]; i < placed.panel_first_vertex[p + 1] && i < n; ++i)
      panel_of[i] = static_cast<uint32_t>(p);

  // The torso's panels in rings: panels sewn side to side by vertical seams (a seam whose side runs
  // farther down than across). A bodice and a skirt sewn at the waist are two rings, which
  // placement may put apart; heights are compared within a ring only.
  std::vector<uint32_t> ring(panels);
  std::iota(ring.begin(), ring.end(), 0u);
  const auto find = [&](uint32_t p) {
    while (ring[p] != p) p = ring[p] = ring[ring[p]];
    return p;
  };
  // Per seam between torso panels: its pairs' spread in height, mean distance from the middle,
  // highest point, and two of its panels.
  struct SeamExtent {
    float low = std::numeric_limits<float>::infinity(), high = -std::numeric_limits<float>::infinity(), off_middle = 0;
    // One side's extent in height: a level seam's side is level however far placement left the
    // other side.
    float side_low = std::numeric_limits<float>::infinity(), side_high = -std::numeric_limits<float>::infinity();
    Eigen::AlignedBox2f side_across;  // one side's extent across (x, z)
    size_t ends = 0;
    uint32_t panel_a = 0, panel_b = 0;
    float length() const { return side_high - side_low; }
    bool vertical() const { return length() > side_across.sizes().maxCoeff(); }
  };
  std::map<uint32_t, SeamExtent> seams;
  Vec3f centre = Vec3f::Zero();  // the axis the panels were placed round
  size_t count = 0;
  for (size_t v = 0; v < n; ++v)
    if (!arm[v]) {
      centre += x[v];
      ++count;
    }
  if (count == 0) return {};
  centre /= static_cast<float>(count);
  for (size_t k = 0; k < placed.seam_pairs.size() && k < placed.seam_of_pair.size(); ++k) {
    const auto [a, b] = placed.seam_pairs[k];
    if (arm[a] || arm[b]) continue;
    SeamExtent& s = seams[placed.seam_of_pair[k]];
    for (uint32_t v : {a, b}) {
      s.low = std::min(s.low, x[v].y());
      s.high = std::max(s.high, x[v].y());
      s.off_middle += std::abs(x[v].x() - centre.x());
      ++s.ends;
    }
    s.side_low = std::min(s.side_low, x[a].y());
    s.side_high = std::max(s.side_high, x[a].y());
    s.side_across.extend(Vec2f(x[a].x(), x[a].z()));
    s.panel_a = panel_of[a];
    s.panel_b = panel_of[b];
  }
  for (const auto& [id, s] : seams)
    if (s.vertical()) ring[find(s.panel_a)] = find(s.panel_b);

  struct Ring {
    std::vector<uint8_t> triangles;
    float top = -std::numeric_limits<float>::infinity(), bottom = std::numeric_limits<float>::infinity();
    // Above this a cut crosses every panel of the ring: the highest panel bottom.
    float full_bottom = std::numeric_limits<float>::infinity();
  };
  std::map<uint32_t, Ring> rings;
  std::vector<float> panel_top(panels, -std::numeric_limits<float>::infinity());
  for (size_t p = 0; p < panels; ++p) {
    const uint32_t first = placed.panel_first_vertex[p], end = placed.panel_first_vertex[p + 1];
    if (first >= end || arm[first]) continue;
    float& top = panel_top[p];
    float bottom = std::numeric_limits<float>::infinity();
    for (uint32_t v = first; v < end && v < n; ++v) {
      top = std::max(top, x[v].y());
      bottom = std::min(bottom, x[v].y());
    }
    Ring& r = rings[find(static_cast<uint32_t>(p))];
    r.top = std::max(r.top, top);
    r.bottom = std::min(r.bottom, bottom);
    r.full_bottom = r.full_bottom == std::numeric_limits<float>::infinity() ? bottom : std::max(r.full_bottom, bottom);
  }
  for (auto& [id, r] : rings) r.triangles.assign(model.triangles.size(), 0);
  for (size_t t = 0; t < model.triangles.size(); ++t) {
    const Tri& tri = model.triangles[t];
    if (arm[tri[0]] || arm[tri[1]] || arm[tri[2]]) continue;
    const auto it = rings.find(find(panel_of[tri[0]]));
    if (it != rings.end()) it->second.triangles[t] = 1;
  }

  const auto girth_at = [&](const Ring& r, float y) {
    return cut_garment(model, x, Vec3f(centre.x(), y, centre.z()), Vec3f::UnitY(), kReach, r.triangles).pattern_m;
  };
  // The largest (or smallest) girth of a ring between two heights, and where.
  const auto extreme = [&](const Ring& r, float hi, float lo, bool largest) {
    std::pair<float, float> best{largest ? 0.0f : std::numeric_limits<float>::infinity(), hi};
    for (float y = hi; y >= lo; y -= kStep) {
      const float g = girth_at(r, y);
      if (g > 0 && (largest ? g > best.first : g < best.first)) best = {g, y};
    }
    return best;
  };
  std::vector<PatternGirth> out;
  const auto add = [&](const char* key, float girth, std::string line) {
    if (!(girth > 0) || !std::isfinite(girth)) return;
    PatternGirth g;
    g.key = key;
    g.line = std::move(line);
    g.girth_m = girth;
    g.ease_m = static_cast<float>(intended_ease(spec, key));
    out.push_back(std::move(g));
  };
  // A ring's top edge (a waistline, curved as it may be): the length on the pattern of its outline
  // edges that face up, in its upper part, and their mean height.
  const auto top_edge = [&](const Ring& r) {
    std::map<std::pair<uint32_t, uint32_t>, std::pair<int, uint32_t>> edges;  // uses, opposite vertex
    for (size_t t = 0; t < model.triangles.size(); ++t) {
      if (!r.triangles[t]) continue;
      const Tri& tri = model.triangles[t];
      for (int k = 0; k < 3; ++k) {
        const uint32_t a = tri[static_cast<size_t>(k)], b = tri[static_cast<size_t>((k + 1) % 3)];
        auto& e = edges[{std::min(a, b), std::max(a, b)}];
        ++e.first;
        e.second = tri[static_cast<size_t>((k + 2) % 3)];
      }
    }
    // The edges facing up, in chains; the chains that reach their panel's top are its edge (a
    // flared hem's ends may face up too, lower down; placement may leave panels at different
    // heights).
    std::vector<std::pair<uint32_t, uint32_t>> up;
    std::map<uint32_t, uint32_t> chain;
    const auto root = [&](uint32_t v) {
      while (chain.at(v) != v) v = chain[v] = chain.at(chain.at(v));
      return v;
    };
    for (const auto& [ab, use] : edges) {
      if (use.first != 1) continue;
      const auto [a, b] = ab;
      if (std::min(x[a].y(), x[b].y()) < panel_top[panel_of[a]] - kTopEdgeDepth) continue;
      const Vec3f e = x[b] - x[a];
      const Vec3f away = (x[a] - x[use.second]) - e * ((x[a] - x[use.second]).dot(e) / std::max(e.squaredNorm(), 1e-12f));
      if (away.y() < kFacingUp * away.norm()) continue;
      up.push_back(ab);
      chain.try_emplace(a, a);
      chain.try_emplace(b, b);
      chain[root(a)] = root(b);
    }
    std::map<uint32_t, float> chain_top;
    for (const auto& [v, parent] : chain) {
      float& t = chain_top.try_emplace(root(v), -std::numeric_limits<float>::infinity()).first->second;
      t = std::max(t, x[v].y());
    }
    float length = 0, height = 0;
    for (const auto& [a, b] : up) {
      if (chain_top.at(root(a)) < panel_top[panel_of[a]] - kTopEdgeReach) continue;
      const float flat = (model.flat_position[b] - model.flat_position[a]).norm();
      length += flat;
      height += flat * 0.5f * (x[a].y() + x[b].y());
    }
    return std::pair<float, float>{length, length > 0 ? height / length : r.top};
  };
  // A ring hanging from its top edge (a skirt, trousers, a dress's skirt): its hips, its widest
  // within a hip depth of the top, above its crotch (the lowest pair sewing a left-leg panel to a
  // right-leg one) where it has legs; left out where it is flared.
  const auto hips_below_waist = [&](const Ring& r, float waist_y, float waist) {
    float crotch = std::numeric_limits<float>::infinity();
    for (const auto& [a, b] : placed.seam_pairs)
      if (leg[a] != 0 && leg[b] != 0 && leg[a] != leg[b]) crotch = std::min({crotch, x[a].y(), x[b].y()});
    const float lowest = std::max({waist_y - kHipDepth, r.full_bottom + 0.01f, std::isfinite(crotch) ? crotch + 0.03f : -1e9f});
    const auto [hips, at] = extreme(r, waist_y - 0.02f, lowest, true);
    if (hips <= kFittedHips * waist) add("hips", hips, fmt::format("its widest, {:.0f} cm below its waist", 100 * (waist_y - at)));
  };

  // A top reaches above the body's bust; a bottom hangs from its waist or hips.
  const auto highest = std::max_element(rings.begin(), rings.end(), [](const auto& a, const auto& b) { return a.second.top < b.second.top; });
  if (highest == rings.end()) return out;
  const float bust_y = 0.5f * (body.landmarks.left_bust.y() + body.landmarks.right_bust.y());
  if (highest->second.top <= bust_y) {
    // Its hips may lie in a ring sewn under its top one (a skirt under a waistband).
    const auto [waist, waist_y] = top_edge(highest->second);
    add("waist", waist, "its top edge");
    Ring whole;
    whole.triangles.assign(model.triangles.size(), 0);
    for (const auto& [id, r] : rings) {
      for (size_t t = 0; t < r.triangles.size(); ++t) whole.triangles[t] |= r.triangles[t];
      whole.full_bottom = std::min(whole.full_bottom, r.full_bottom);
    }
    hips_below_waist(whole, waist_y, waist);
    return out;
  }

  // A top: its underarm is the top of its side seams, the vertical seams joining torso panels
  // farthest from the middle (a centre back seam runs up the middle, princess seams in between).
  float widest = -1, underarm = -std::numeric_limits<float>::infinity();
  uint32_t upper = 0;
  for (const auto& [id, s] : seams)
    if (s.vertical() && s.length() > kSideSeam) widest = std::max(widest, s.off_middle / static_cast<float>(s.ends));
  for (const auto& [id, s] : seams)
    if (s.vertical() && s.length() > kSideSeam && s.off_middle / static_cast<float>(s.ends) > widest - 0.03f && s.high > underarm) {
      underarm = s.high;
      upper = find(s.panel_a);
    }
  if (!std::isfinite(underarm)) return out;
  const Ring& bodice = rings.at(upper);
  add("bust", girth_at(bodice, underarm - kChestBelowUnderarm), fmt::format("{:.1f} cm below the armhole", 100 * kChestBelowUnderarm));
  // A ring sewn under this one (a skirt at the waist seam) starts at the waist.
  const Ring* skirt = nullptr;
  for (const auto& [id, r] : rings)
    if (id != upper && r.top < bodice.top && r.top > bodice.bottom - kSeparated && (!skirt || r.top > skirt->top)) skirt = &r;
  if (skirt && bodice.bottom > underarm - kHipsBelowUnderarm) {
    const auto [waist, waist_y] = top_edge(*skirt);
    add("waist", waist, "its waist seam");
    hips_below_waist(*skirt, waist_y, waist);
    return out;
  }
  const float hips_y = underarm - kHipsBelowUnderarm;
  const float hips = hips_y > bodice.full_bottom + 0.03f ? girth_at(bodice, hips_y) : 0.0f;
  const float waist_y = underarm - kWaistBelowUnderarm;
  if (waist_y > bodice.full_bottom + 0.03f) {
    const float chest = out.empty() ? 0.0f : out.back().girth_m;
    const auto [waist, at] = extreme(bodice, waist_y + 0.06f, std::max(waist_y - 0.06f, bodice.full_bottom + 0.03f), false);
    if (waist < chest - kShapedWaist && (hips <= 0 || waist < hips - kShapedWaist))
      add("waist", waist, fmt::format("its narrowest, {:.0f} cm below the armhole", 100 * (underarm - at)));
  }
  add("hips", hips, fmt::format("{:.0f} cm below the armhole", 100 * kHipsBelowUnderarm));
  return out;
}

std::vector<PatternSize> measure_pattern(const Body& body, const GarmentSpec& spec, const DressOptions& options) {
  std::vector<PatternSize> out;
  BodyColliderOptions few_queries;  // placement only: straight from the tree
  few_queries.candidate_grid = false;
  const auto collider = make_body_collider(body.mesh, options.collision, few_queries);
  for (const std::string& size : spec.sizes) {
    const Garment garment = garment_in_size(spec, size);
    const DressedGarment placed = dressing::prepare_garment(body, garment, *collider, options, dressing::PlacementUse::measuring);
    out.push_back({size, pattern_girths(body, placed, garment, spec)});
  }
  return out;
}

std::vector<SizeMeasurements> chart_from_pattern(std::span<const PatternSize> sizes) {
  std::vector<SizeMeasurements> chart;
  for (const PatternSize& s : sizes) {
    SizeMeasurements m;
    for (const PatternGirth& g : s.girths)
      if (g.body_m() > 0.05f) m[g.key] = g.body_m();
    chart.push_back(std::move(m));
  }
  return chart;
}

}  // namespace drape
