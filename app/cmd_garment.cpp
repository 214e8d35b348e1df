// `drape garments`: the built-in garments. `drape garment check FILE`: validate a garment file (drape
// JSON, GarmentCode, 2021 template or DXF) in every size and print what it holds. `drape garment
// mesh FILE -o panels.obj|.glb`: the flat meshed panels, laid out side by side, with the seam
// vertex pairs (OBJ: one `l` element per pair between the panels' vertices). `drape garment chart
// FILE`: the body each size is cut for, measured on its pattern.
#include <fmt/format.h>

#include <Eigen/Geometry>
#include <cmath>
#include <memory>

#include "commands.hpp"
#include "drape/error.hpp"
#include "drape/files.hpp"
#include "drape/garment.hpp"
#include "drape/io.hpp"
#include "drape/size_advice.hpp"

namespace drape::app {
namespace {

std::string side_text(const Garment& g, const SeamSide& side) {
  const Panel& p = g.panels[side.panel];
  const auto edge_name = [&](uint32_t e) {
    const std::string& n = p.edge_names[e];
    return n.empty() ? fmt::format("{}", e) : fmt::format("{} \"{}\"", e, n);
  };
  if (side.edge_count == 1) return fmt::format("'{}' edge {}", p.name, edge_name(side.first_edge));
  const auto last = static_cast<uint32_t>((side.first_edge + side.edge_count - 1) % p.edges.size());
  return fmt::format("'{}' edges {}..{}", p.name, edge_name(side.first_edge), edge_name(last));
}

void run_list() {
  for (const BuiltinGarment& b : builtin_garments()) {
    std::string sizes;
    for (const std::string& s : b.sizes) sizes += (sizes.empty() ? "" : " ") + s;
    // A garment with a size chart is made in the size drafted for the body being dressed
    // (choose_size); its base size is what `garment check` and `garment mesh` show.
    const std::optional<GarmentSpec> spec = builtin_garment(b.name);
    const bool charted = spec && !spec->size_chart.empty();
    fmt::print("{:<10} sizes {:<18} ({} {}){}\n           {}\n", b.name, sizes,
               charted ? "size from the body's measurements by its size chart; base" : "default", b.default_size,
               b.name == default_garment_name() ? " [default garment]" : "", b.description);
  }
}

void run_check(const std::string& file, const std::string& size) {
  const GarmentSpec spec = load_garment(file);  // validates every size
  const Garment g = garment_in_size(spec, size);
  std::string sizes;
  for (const std::string& s : spec.sizes) sizes += (sizes.empty() ? "" : " ") + s;
  fmt::print("{}: garment '{}' ({} format), fabric {}, layer {}\n", file, spec.name, spec.format, spec.fabric, spec.layer);
  if (!spec.description.empty()) fmt::print("  {}\n", spec.description);
  fmt::print("  sizes: {} (valid); showing {}\n", sizes, g.size);
  fmt::print("  {} panels, {} seams\n", g.panels.size(), g.seams.size());
  for (const Panel& p : g.panels) {
    Eigen::AlignedBox2d box;
    for (const Vec2d& q : p.polygon(0.005)) box.extend(q);
    fmt::print("  panel '{}': {} edges, area {:.4f} m^2, perimeter {:.3f} m, {:.3f} x {:.3f} m, grain ({:.2f}, {:.2f}), {}",
               p.name, p.edges.size(), std::abs(p.signed_area()), p.perimeter(), box.sizes().x(), box.sizes().y(),
               p.grain.x(), p.grain.y(), p.signed_area() > 0 ? "counter-clockwise" : "clockwise");
    if (p.placement)
      fmt::print(", wraps {} ({}) at {}", to_string(p.placement->body_part), to_string(p.placement->side),
                 to_string(p.placement->landmark));
    fmt::print("\n");
    for (size_t e = 0; e < p.edges.size(); ++e)
      fmt::print("    edge {:>2} {:<10} {:.4f} m{}\n", e, to_string(p.edges[e].kind), p.edges[e].length(),
                 p.edge_names[e].empty() ? "" : fmt::format("  \"{}\"", p.edge_names[e]));
  }
  for (const SeamSpec& s : g.seams)
    fmt::print("  seam '{}': {} ({:.4f} m) <-> {} ({:.4f} m), {}{}\n", s.name, side_text(g, s.a), g.seam_side_length(s.a),
               side_text(g, s.b), g.seam_side_length(s.b), s.same_direction ? "same direction" : "reversed",
               s.ease > 0 ? fmt::format(", ease {:.1f} %", 100 * s.ease) : "");
  if (g.seams.empty() && g.panels.size() > 1)
    fmt::print("  note: no seams (DXF pieces only); name them in a companion garment file to sew the pieces\n");
}

// Each size's girths at the garment's own lines and the body they are cut for (the chart a
// pattern without one gets), beside the file's chart where it has one.
void run_chart(const std::string& file, const std::string& body_name) {
  const GarmentSpec spec = load_garment(file);
  const Body body = load_command_body(body_name, "", LoadOptions{});
  const std::vector<PatternSize> sizes = measure_pattern(body, spec, DressOptions{});
  const std::vector<SizeMeasurements> made = chart_from_pattern(sizes);
  fmt::print("{}: the body each size is cut for, from its girths at its own lines less its intended ease\n", spec.name);
  fmt::print("(measured on the panels placed round the {} body, before sewing)\n", body_name);
  for (size_t k = 0; k < sizes.size(); ++k) {
    fmt::print("  {}:\n", sizes[k].size);
    if (sizes[k].girths.empty()) fmt::print("    no girth found (a top needs side seams, a bottom a top edge)\n");
    for (const PatternGirth& g : sizes[k].girths) {
      std::string file_chart;
      if (k < spec.size_chart.size())
        if (const auto it = spec.size_chart[k].find(g.key); it != spec.size_chart[k].end())
          file_chart = fmt::format("; the garment's chart: {:.3f} m", it->second);
      fmt::print("    {:<6} {:.3f} m: garment {:.3f} m at {}, less {:.0f} cm ease{}\n", g.key, made[k].at(g.key), g.girth_m,
                 g.line, 100 * g.ease_m, file_chart);
    }
  }
}

struct MeshArgs {
  std::string file, size, mesher = "grid", out;
  double edge = 0.01;
};

std::string encode_panels_obj(const Garment& g, const GarmentMesh& gm, const std::vector<Vec3f>& offsets) {
  std::string s = fmt::format("# drape garment '{}' size {}: {} panels, {} seam vertex pairs\n"
                              "# v: panels laid out side by side (metres); vt: flat pattern position (metres)\n",
                              g.name, g.size, gm.panels.size(), gm.seam_pairs.size());
  std::vector<size_t> base;
  size_t next = 1;
  for (size_t p = 0; p < gm.panels.size(); ++p) {
    const Mesh& m = gm.panels[p].mesh;
    base.push_back(next);
    s += fmt::format("o {}\n", m.name);
    for (const Vec3f& v : m.positions) s += fmt::format("v {:.6f} {:.6f} {:.6f}\n", v.x() + offsets[p].x(), v.y(), v.z());
    for (const Vec2f& t : m.uvs) s += fmt::format("vt {:.6f} {:.6f}\n", t.x(), t.y());
    for (const Tri& t : m.triangles)
      s += fmt::format("f {0}/{0} {1}/{1} {2}/{2}\n", t[0] + next, t[1] + next, t[2] + next);
    next += m.positions.size();
  }
  s += "o seams\n";
  for (const SeamVertexPair& sp : gm.seam_pairs) s += fmt::format("l {} {}\n", base[sp.panel_a] + sp.vertex_a, base[sp.panel_b] + sp.vertex_b);
  return s;
}

void run_mesh(const MeshArgs& args) {
  const GarmentSpec spec = load_garment(args.file);
  const Garment g = garment_in_size(spec, args.size);
  MeshOptions options;
  if (args.mesher == "grid") options.mesher = Mesher::grid;
  else if (args.mesher == "triangle") options.mesher = Mesher::triangle;
  else throw InputError("--mesher", "expected grid or triangle");
  if (!(args.edge >= 0.001 && args.edge <= 0.2)) throw InputError("--edge", "edge length must be between 0.001 and 0.2 m");
  options.edge_length = args.edge;
  const std::filesystem::path out = args.out;
  std::string ext = out.extension().string();
  for (char& c : ext) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
  if (ext != ".obj" && ext != ".glb") throw InputError(args.out, "output must be .obj or .glb");

  const GarmentMesh gm = mesh_garment(g, options);
  // Panels side by side along x with 5 cm between them.
  std::vector<Vec3f> offsets;
  float x = 0;
  for (const PanelMesh& pm : gm.panels) {
    const Bounds b = bounds(pm.mesh.positions);
    offsets.emplace_back(x - b.min.x(), 0.0f, 0.0f);
    x += b.size().x() + 0.05f;
  }
  if (ext == ".obj") {
    write_file_atomic(out, encode_panels_obj(g, gm, offsets));
  } else {
    Scene scene;
    for (size_t p = 0; p < gm.panels.size(); ++p) {
      Mesh m = gm.panels[p].mesh;
      for (Vec3f& v : m.positions) v += offsets[p];
      add_mesh_node(scene, std::move(m), gm.panels[p].mesh.name);
    }
    write_scene(out, scene);
  }
  fmt::print("{}: {} panels, {} vertices, {} triangles, {} seam vertex pairs ({} mesher, edge {:.4f} m, size {})\n",
             args.out, gm.panels.size(), gm.vertex_count(), gm.triangle_count(), gm.seam_pairs.size(), args.mesher,
             options.edge_length, g.size);
}

}  // namespace

void add_garment_command(CLI::App& app) {
  CLI::App* list = app.add_subcommand("garments", "List the built-in garments and their sizes");
  list->callback([] { run_list(); });

  CLI::App* garment = app.add_subcommand("garment", "Check or mesh a garment file (drape JSON, GarmentCode, DXF)");
  garment->require_subcommand(1);

  auto check_file = std::make_shared<std::string>();
  auto check_size = std::make_shared<std::string>();
  CLI::App* check = garment->add_subcommand("check", "Validate a garment file in every size and print a summary");
  check->add_option("FILE", *check_file, "Garment file or built-in garment name")->required();
  check->add_option("--size", *check_size, "Size to summarise (default: the base size)");
  check->callback([check_file, check_size] { run_check(*check_file, *check_size); });

  auto chart_file = std::make_shared<std::string>();
  auto chart_body = std::make_shared<std::string>("female");
  CLI::App* chart = garment->add_subcommand(
      "chart", "The body each size is cut for, measured on the pattern (the size chart a garment without one gets)");
  chart->add_option("FILE", *chart_file, "Garment file or built-in garment name")->required();
  chart->add_option("--body", *chart_body, "Body the panels are placed round: female, male or a body file")->capture_default_str();
  chart->callback([chart_file, chart_body] { run_chart(*chart_file, *chart_body); });

  auto args = std::make_shared<MeshArgs>();
  CLI::App* mesh = garment->add_subcommand("mesh", "Mesh a garment's panels flat and write them with their seams");
  mesh->add_option("FILE", args->file, "Garment file or built-in garment name")->required();
  mesh->add_option("--size", args->size, "Size (default: the base size)");
  mesh->add_option("--mesher", args->mesher, "grid (the paper's rectangular grid) or triangle (Delaunay refinement)")
      ->capture_default_str();
  mesh->add_option("--edge", args->edge, "Grid spacing / target edge length, metres")->capture_default_str();
  mesh->add_option("-o,--output", args->out, "Output file: .obj (with seam lines) or .glb")->required();
  mesh->callback([args] { run_mesh(*args); });
}

}  // namespace drape::app
