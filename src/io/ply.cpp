// PLY (Stanford polygon format): ascii, binary little endian and binary big endian, read and write.
//
// Hand-written on purpose: Debian 12 packages no maintained PLY library (happly and miniply are not
// packaged; libply/rply handle no big-endian writing and report errors through callbacks that cannot
// name an element). The format is a text header and a flat table of typed values, so a careful reader
// is about as long as the glue to such a library, and it bounds every count by the bytes actually
// present before allocating (a fuzzed header cannot ask for terabytes).
#include <fmt/format.h>

#include <algorithm>
#include <bit>
#include <charconv>
#include <cmath>
#include <cstring>
#include <optional>

#include "drape/error.hpp"
#include "geometry/topology.hpp"
#include "io/formats.hpp"

namespace drape::io {
namespace {

enum class Encoding { Ascii, Little, Big };
enum class Type { Int8, UInt8, Int16, UInt16, Int32, UInt32, Float32, Float64 };

std::optional<Type> type_named(std::string_view name) {
  if (name == "char" || name == "int8") return Type::Int8;
  if (name == "uchar" || name == "uint8") return Type::UInt8;
  if (name == "short" || name == "int16") return Type::Int16;
  if (name == "ushort" || name == "uint16") return Type::UInt16;
  if (name == "int" || name == "int32") return Type::Int32;
  if (name == "uint" || name == "uint32") return Type::UInt32;
  if (name == "float" || name == "float32") return Type::Float32;
  if (name == "double" || name == "float64") return Type::Float64;
  return std::nullopt;
}

size_t size_of(Type t) {
  switch (t) {
    case Type::Int8:
    case Type::UInt8:
      return 1;
    case Type::Int16:
    case Type::UInt16:
      return 2;
    case Type::Int32:
    case Type::UInt32:
    case Type::Float32:
      return 4;
    case Type::Float64:
      return 8;
  }
  return 0;
}

bool is_integer(Type t) {
  return t != Type::Float32 && t != Type::Float64;
}

struct Property {
  std::string name;
  Type type = Type::Float32;
  bool is_list = false;
  Type count_type = Type::UInt8;  // lists only
};

struct Element {
  std::string name;
  size_t count = 0;
  std::vector<Property> properties;
};

struct Header {
  Encoding encoding = Encoding::Ascii;
  std::vector<Element> elements;
  size_t body_offset = 0;
};

std::vector<std::string_view> words(std::string_view line) {
  std::vector<std::string_view> out;
  size_t i = 0;
  while (i < line.size()) {
    while (i < line.size() && (line[i] == ' ' || line[i] == '\t' || line[i] == '\r')) ++i;
    size_t j = i;
    while (j < line.size() && line[j] != ' ' && line[j] != '\t' && line[j] != '\r') ++j;
    if (j > i) out.push_back(line.substr(i, j - i));
    i = j;
  }
  return out;
}

Header parse_header(std::string_view data, const std::string& source) {
  const auto fail = [&](size_t line, const std::string& what) {
    throw InputError(source, fmt::format("PLY header line {}: {}", line, what));
  };
  if (data.substr(0, 3) != "ply" || data.size() < 4 || (data[3] != '\n' && data[3] != '\r'))
    throw InputError(source, "not a PLY file (missing 'ply' magic)");
  Header header;
  bool have_format = false;
  size_t pos = 0, line_number = 0;
  while (true) {
    const size_t end = data.find('\n', pos);
    if (end == std::string_view::npos) throw InputError(source, "truncated PLY header (no end_header)");
    const std::string_view line = data.substr(pos, end - pos);
    pos = end + 1;
    ++line_number;
    const auto w = words(line);
    if (line_number == 1 || w.empty() || w[0] == "comment" || w[0] == "obj_info") continue;
    if (w[0] == "end_header") break;
    if (w[0] == "format") {
      if (w.size() != 3 || w[2] != "1.0") fail(line_number, "expected 'format <encoding> 1.0'");
      if (w[1] == "ascii")
        header.encoding = Encoding::Ascii;
      else if (w[1] == "binary_little_endian")
        header.encoding = Encoding::Little;
      else if (w[1] == "binary_big_endian")
        header.encoding = Encoding::Big;
      else
        fail(line_number, fmt::format("unknown encoding '{}'", printable(w[1])));
      have_format = true;
    } else if (w[0] == "element") {
      size_t count = 0;
      if (w.size() != 3 || std::from_chars(w[2].data(), w[2].data() + w[2].size(), count).ec != std::errc() ||
          std::from_chars(w[2].data(), w[2].data() + w[2].size(), count).ptr != w[2].data() + w[2].size())
        fail(line_number, "expected 'element <name> <count>'");
      header.elements.push_back({std::string(w[1]), count, {}});
    } else if (w[0] == "property") {
      if (header.elements.empty()) fail(line_number, "property before any element");
      Property p;
      if (w.size() == 5 && w[1] == "list") {
        const auto count_type = type_named(w[2]), item_type = type_named(w[3]);
        if (!count_type || !item_type || !is_integer(*count_type))
          fail(line_number, fmt::format("bad list types '{} {}'", printable(w[2]), printable(w[3])));
        p = {std::string(w[4]), *item_type, true, *count_type};
      } else if (w.size() == 3) {
        const auto type = type_named(w[1]);
        if (!type) fail(line_number, fmt::format("unknown property type '{}'", printable(w[1])));
        p = {std::string(w[2]), *type, false, Type::UInt8};
      } else {
        fail(line_number, "expected 'property <type> <name>' or 'property list <count type> <type> <name>'");
      }
      header.elements.back().properties.push_back(p);
    } else {
      fail(line_number, fmt::format("unknown keyword '{}'", printable(w[0])));
    }
  }
  if (!have_format) throw InputError(source, "PLY header has no 'format' line");
  for (const Element& e : header.elements)
    if (e.count > 0 && e.properties.empty())
      throw InputError(source, fmt::format("PLY element '{}' has no properties", printable(e.name)));
  header.body_offset = pos;
  return header;
}

// Reads the values of the body one at a time, in either encoding.
class BodyReader {
 public:
  BodyReader(std::string_view body, Encoding encoding, const std::string& source)
      : body_(body), encoding_(encoding), source_(source) {}

  // One value of the given type, as a double (exact for every PLY type).
  double read(Type type, const char* what) {
    if (encoding_ == Encoding::Ascii) return read_ascii(type, what);
    const size_t n = size_of(type);
    if (pos_ + n > body_.size()) throw InputError(source_, fmt::format("truncated PLY data (in {})", what));
    unsigned char b[8];
    std::memcpy(b, body_.data() + pos_, n);
    pos_ += n;
    if ((encoding_ == Encoding::Big) != (std::endian::native == std::endian::big)) std::reverse(b, b + n);
    switch (type) {
      case Type::Int8:
        return static_cast<int8_t>(b[0]);
      case Type::UInt8:
        return b[0];
      case Type::Int16:
        return load<int16_t>(b);
      case Type::UInt16:
        return load<uint16_t>(b);
      case Type::Int32:
        return load<int32_t>(b);
      case Type::UInt32:
        return load<uint32_t>(b);
      case Type::Float32:
        return load<float>(b);
      case Type::Float64:
        return load<double>(b);
    }
    return 0;
  }

  // Bytes left: every remaining value needs at least one.
  size_t remaining() const { return body_.size() - pos_; }

 private:
  template <class T>
  static T load(const unsigned char* b) {
    T v;
    std::memcpy(&v, b, sizeof(T));
    return v;
  }

  double read_ascii(Type type, const char* what) {
    while (pos_ < body_.size() && std::isspace(static_cast<unsigned char>(body_[pos_]))) ++pos_;
    size_t end = pos_;
    while (end < body_.size() && !std::isspace(static_cast<unsigned char>(body_[end]))) ++end;
    if (end == pos_) throw InputError(source_, fmt::format("truncated PLY data (in {})", what));
    std::string_view token = body_.substr(pos_, end - pos_);
    pos_ = end;
    if (!token.empty() && token.front() == '+') token.remove_prefix(1);
    double v = 0;
    const auto [ptr, ec] = std::from_chars(token.data(), token.data() + token.size(), v);
    if (ec != std::errc() || ptr != token.data() + token.size())
      throw InputError(source_, fmt::format("{}: '{}' is not a number", what, printable(token)));
    if (is_integer(type) && v != std::floor(v))
      throw InputError(source_, fmt::format("{}: '{}' is not an integer", what, printable(token)));
    return v;
  }

  std::string_view body_;
  size_t pos_ = 0;
  Encoding encoding_;
  const std::string& source_;
};

int property_index(const Element& e, std::initializer_list<std::string_view> names) {
  for (size_t i = 0; i < e.properties.size(); ++i)
    for (std::string_view n : names)
      if (e.properties[i].name == n && !e.properties[i].is_list) return static_cast<int>(i);
  return -1;
}

}  // namespace

Scene parse_ply(std::span<const unsigned char> bytes, const std::string& source, MeshCheck& check) {
  const std::string_view data(reinterpret_cast<const char*>(bytes.data()), bytes.size());
  const Header header = parse_header(data, source);
  BodyReader reader(data.substr(header.body_offset), header.encoding, source);

  Mesh mesh;
  bool have_vertices = false, have_faces = false;
  std::vector<std::vector<uint32_t>> polygons;
  for (const Element& e : header.elements) {
    if (e.count == 0) continue;
    // Each element takes at least one byte per property: a larger count cannot be in the file.
    if (e.count > reader.remaining() / e.properties.size())
      throw InputError(source,
                       fmt::format("truncated PLY data: header promises {} '{}' elements, the file is too "
                                   "short for them",
                                   e.count, printable(e.name)));
    const bool is_vertex = e.name == "vertex" && !have_vertices;
    const bool is_face = e.name == "face" && !have_faces;
    // Columns of interest; -1 when absent.
    int xyz[3] = {-1, -1, -1}, nxyz[3] = {-1, -1, -1}, uv[2] = {-1, -1}, rgba[4] = {-1, -1, -1, -1};
    int indices = -1;
    if (is_vertex) {
      have_vertices = true;
      xyz[0] = property_index(e, {"x"}), xyz[1] = property_index(e, {"y"}), xyz[2] = property_index(e, {"z"});
      if (xyz[0] < 0 || xyz[1] < 0 || xyz[2] < 0)
        throw InputError(source, "PLY vertex element lacks x, y or z");
      nxyz[0] = property_index(e, {"nx"}), nxyz[1] = property_index(e, {"ny"}),
      nxyz[2] = property_index(e, {"nz"});
      uv[0] = property_index(e, {"u", "s", "texture_u", "texture_s"});
      uv[1] = property_index(e, {"v", "t", "texture_v", "texture_t"});
      rgba[0] = property_index(e, {"red"}), rgba[1] = property_index(e, {"green"});
      rgba[2] = property_index(e, {"blue"}), rgba[3] = property_index(e, {"alpha"});
      mesh.positions.resize(e.count);
      if (nxyz[0] >= 0 && nxyz[1] >= 0 && nxyz[2] >= 0) mesh.normals.resize(e.count);
      if (uv[0] >= 0 && uv[1] >= 0) mesh.uvs.resize(e.count);
      if (rgba[0] >= 0 && rgba[1] >= 0 && rgba[2] >= 0) mesh.colors.assign(e.count, Vec4f::Ones());
    } else if (is_face) {
      have_faces = true;
      for (size_t i = 0; i < e.properties.size(); ++i)
        if (e.properties[i].is_list &&
            (e.properties[i].name == "vertex_indices" || e.properties[i].name == "vertex_index"))
          indices = static_cast<int>(i);
      if (indices < 0) throw InputError(source, "PLY face element lacks a vertex_indices list");
      if (!is_integer(e.properties[static_cast<size_t>(indices)].type))
        throw InputError(source, "PLY face vertex_indices are not integers");
      polygons.resize(e.count);
    }

    std::vector<double> row(e.properties.size());
    for (size_t i = 0; i < e.count; ++i) {
      const std::string what = fmt::format("{} {}", printable(e.name), i);
      for (size_t k = 0; k < e.properties.size(); ++k) {
        const Property& p = e.properties[k];
        if (!p.is_list) {
          row[k] = reader.read(p.type, what.c_str());
          continue;
        }
        const double count = reader.read(p.count_type, what.c_str());
        if (count < 0 || count > static_cast<double>(reader.remaining()))
          throw InputError(source, fmt::format("{}: bad list length {}", what, count));
        const bool keep = is_face && static_cast<int>(k) == indices;
        for (size_t j = 0; j < static_cast<size_t>(count); ++j) {
          const double index = reader.read(p.type, what.c_str());
          if (!keep) continue;
          if (index < 0 || index > 4294967295.0)
            throw InputError(source, fmt::format("{}: negative or huge vertex index {}", what, index));
          polygons[i].push_back(static_cast<uint32_t>(index));
        }
      }
      if (is_vertex) {
        const auto col = [&](int c) { return static_cast<float>(row[static_cast<size_t>(c)]); };
        mesh.positions[i] = {col(xyz[0]), col(xyz[1]), col(xyz[2])};
        if (!mesh.normals.empty()) mesh.normals[i] = {col(nxyz[0]), col(nxyz[1]), col(nxyz[2])};
        if (!mesh.uvs.empty()) mesh.uvs[i] = {col(uv[0]), col(uv[1])};
        if (!mesh.colors.empty())
          for (int c = 0; c < 4; ++c)
            if (rgba[c] >= 0) {
              const Type t = e.properties[static_cast<size_t>(rgba[c])].type;
              mesh.colors[i][c] = t == Type::UInt8 ? col(rgba[c]) / 255.0f : col(rgba[c]);
            }
      }
    }
  }
  if (!have_vertices) throw InputError(source, "PLY file has no vertex element");
  if (!have_faces || polygons.empty())
    throw InputError(source, "PLY file has no faces (a point cloud is not a mesh)");

  // Faces: indices in range, then triangulated; fewer than three corners count as degenerate.
  for (size_t f = 0; f < polygons.size(); ++f) {
    for (uint32_t v : polygons[f])
      if (v >= mesh.positions.size())
        throw InputError(source, fmt::format("face {}: vertex index {} out of range ({} vertices)", f, v,
                                             mesh.positions.size()));
    if (polygons[f].size() < 3) {
      ++check.degenerate_faces_removed;
      continue;
    }
    if (polygons[f].size() > 3) ++check.non_triangle_faces_triangulated;
    geometry::triangulate_polygon(mesh.positions, polygons[f], mesh.triangles);
  }
  for (Vec3f& n : mesh.normals)
    if (n.allFinite() && n.norm() > 0.0f) n.normalize();

  return single_mesh_scene(std::move(mesh));
}

}  // namespace drape::io

namespace drape {

namespace {

// Appends a value in the file's byte order.
template <class T>
void put(std::vector<unsigned char>& out, T value, PlyEncoding encoding) {
  unsigned char b[sizeof(T)];
  std::memcpy(b, &value, sizeof(T));
  if ((encoding == PlyEncoding::BinaryBigEndian) != (std::endian::native == std::endian::big))
    std::reverse(b, b + sizeof(T));
  out.insert(out.end(), b, b + sizeof(T));
}

}  // namespace

std::vector<unsigned char> encode_ply(const Mesh& mesh, PlyEncoding encoding) {
  const size_t n = mesh.positions.size();
  const bool normals = !mesh.normals.empty() && mesh.normals.size() == n;
  const bool uvs = !mesh.uvs.empty() && mesh.uvs.size() == n;
  const bool colors = !mesh.colors.empty() && mesh.colors.size() == n;
  const char* format = encoding == PlyEncoding::Ascii                ? "ascii"
                       : encoding == PlyEncoding::BinaryLittleEndian ? "binary_little_endian"
                                                                     : "binary_big_endian";
  std::string header = fmt::format("ply\nformat {} 1.0\ncomment written by drape {}\nelement vertex {}\n",
                                   format, DRAPE_VERSION, n);
  header += "property float x\nproperty float y\nproperty float z\n";
  if (normals) header += "property float nx\nproperty float ny\nproperty float nz\n";
  if (uvs) header += "property float s\nproperty float t\n";
  if (colors)
    header += "property uchar red\nproperty uchar green\nproperty uchar blue\nproperty uchar alpha\n";
  header += fmt::format("element face {}\nproperty list uchar uint vertex_indices\nend_header\n",
                        mesh.triangles.size());

  std::vector<unsigned char> out(header.begin(), header.end());
  const auto color_byte = [](float c) {
    return static_cast<uint8_t>(std::lround(std::clamp(c, 0.0f, 1.0f) * 255.0f));
  };
  if (encoding == PlyEncoding::Ascii) {
    fmt::memory_buffer buf;
    for (size_t i = 0; i < n; ++i) {
      const Vec3f& p = mesh.positions[i];
      fmt::format_to(std::back_inserter(buf), "{} {} {}", p.x(), p.y(), p.z());
      if (normals)
        fmt::format_to(std::back_inserter(buf), " {} {} {}", mesh.normals[i].x(), mesh.normals[i].y(),
                       mesh.normals[i].z());
      if (uvs) fmt::format_to(std::back_inserter(buf), " {} {}", mesh.uvs[i].x(), mesh.uvs[i].y());
      if (colors)
        for (int c = 0; c < 4; ++c)
          fmt::format_to(std::back_inserter(buf), " {}", color_byte(mesh.colors[i][c]));
      buf.push_back('\n');
    }
    for (const Tri& t : mesh.triangles)
      fmt::format_to(std::back_inserter(buf), "3 {} {} {}\n", t[0], t[1], t[2]);
    out.insert(out.end(), buf.data(), buf.data() + buf.size());
    return out;
  }
  out.reserve(out.size() + n * 48 + mesh.triangles.size() * 13);
  for (size_t i = 0; i < n; ++i) {
    for (int c = 0; c < 3; ++c) put(out, mesh.positions[i][c], encoding);
    if (normals)
      for (int c = 0; c < 3; ++c) put(out, mesh.normals[i][c], encoding);
    if (uvs)
      for (int c = 0; c < 2; ++c) put(out, mesh.uvs[i][c], encoding);
    if (colors)
      for (int c = 0; c < 4; ++c) out.push_back(color_byte(mesh.colors[i][c]));
  }
  for (const Tri& t : mesh.triangles) {
    out.push_back(3);
    for (uint32_t v : t) put(out, v, encoding);
  }
  return out;
}

}  // namespace drape
