// Shared CGAL constrained Delaunay helpers for the panel meshers (see cdt.hpp).
#include "pattern/cdt.hpp"

#include <fmt/format.h>

#include <deque>
#include <map>
#include <stdexcept>

namespace drape::pattern {

void insert_outline(Cdt& cdt, const BoundaryLoop& boundary) {
  const size_t n = boundary.points.size();
  std::vector<Cdt::Vertex_handle> handles(n);
  for (size_t i = 0; i < n; ++i) {
    handles[i] = cdt.insert(Cdt::Point(boundary.points[i].x(), boundary.points[i].y()));
    if (handles[i]->info().value >= 0 && handles[i]->info().value != static_cast<int64_t>(i))
      throw std::runtime_error(fmt::format("outline points {} and {} coincide", handles[i]->info().value, i));
    handles[i]->info().value = static_cast<int64_t>(i);
  }
  for (size_t i = 0; i < n; ++i) cdt.insert_constraint(handles[i], handles[(i + 1) % n]);
}

void mark_domain(Cdt& cdt) {
  // Breadth-first over faces; crossing a constrained edge increases the nesting depth.
  for (auto f = cdt.all_faces_begin(); f != cdt.all_faces_end(); ++f) f->set_in_domain(false);
  std::map<Cdt::Face_handle, int> depth;
  std::deque<Cdt::Face_handle> queue{cdt.infinite_face()};
  depth[cdt.infinite_face()] = 0;
  // Faces across a constraint, with the depth they get: one more than the face we came from.
  std::vector<std::pair<Cdt::Face_handle, int>> next_level;
  while (!queue.empty()) {
    while (!queue.empty()) {
      const Cdt::Face_handle f = queue.front();
      queue.pop_front();
      const int d = depth[f];
      for (int i = 0; i < 3; ++i) {
        const Cdt::Face_handle g = f->neighbor(i);
        if (depth.count(g)) continue;
        if (cdt.is_constrained(Cdt::Edge(f, i))) {
          next_level.emplace_back(g, d + 1);
        } else {
          depth[g] = d;
          queue.push_back(g);
        }
      }
    }
    for (const auto& [g, d] : next_level) {
      if (depth.count(g)) continue;
      depth[g] = d;
      queue.push_back(g);
    }
    next_level.clear();
  }
  for (auto f = cdt.finite_faces_begin(); f != cdt.finite_faces_end(); ++f) f->set_in_domain(depth[f] % 2 == 1);
}

PanelTriangulation collect_triangulation(Cdt& cdt, std::vector<Vec2d> points) {
  PanelTriangulation out;
  for (auto v = cdt.finite_vertices_begin(); v != cdt.finite_vertices_end(); ++v) {
    if (v->info().value < 0) {
      v->info().value = static_cast<int64_t>(points.size());
      points.emplace_back(v->point().x(), v->point().y());
    }
  }
  for (auto f = cdt.finite_faces_begin(); f != cdt.finite_faces_end(); ++f) {
    if (!f->is_in_domain()) continue;
    out.triangles.push_back({static_cast<uint32_t>(f->vertex(0)->info().value),
                             static_cast<uint32_t>(f->vertex(1)->info().value),
                             static_cast<uint32_t>(f->vertex(2)->info().value)});
  }
  out.points = std::move(points);
  return out;
}

}  // namespace drape::pattern
