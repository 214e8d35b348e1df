// glTF 2.0 / GLB, read and written with tinygltf (JSON via nlohmann_json; images are not decoded).
//
// tinygltf parses the JSON and the GLB container, but it does not check that an accessor's bytes lie
// inside its buffer, nor that node, mesh, skin and sampler indices are in range. Every such reference
// is checked here before it is followed, so a malformed file is an InputError, never a crash.
// The writer produces files the Khronos glTF validator accepts with zero errors: POSITION accessors
// carry min/max, normals are unit, skin weights sum to one, joints are unsigned byte/short, rotations
// are unit quaternions, animation inputs carry min/max, buffer views are 4-byte aligned.
#define TINYGLTF_IMPLEMENTATION
#define TINYGLTF_NO_STB_IMAGE
#define TINYGLTF_NO_STB_IMAGE_WRITE
#define TINYGLTF_NO_EXTERNAL_IMAGE
#include <fmt/format.h>
#include <tiny_gltf.h>

#include <Eigen/Geometry>
#include <algorithm>
#include <memory>
#include <cmath>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <sstream>

#include "drape/error.hpp"
#include "io/formats.hpp"

namespace drape::io {
namespace {

// Images are not needed (drape renders its own materials): accept them undecoded.
bool skip_image(tinygltf::Image*, const int, std::string*, std::string*, int, int, const unsigned char*, int,
                void*) {
  return true;
}

// External buffers: only regular files are read (never a device or a pipe, which could hang), and
// nothing is ever written.
bool regular_file_exists(const std::string& path, void*) {
  std::error_code ec;
  return std::filesystem::is_regular_file(path, ec);
}
std::string keep_path(const std::string& path, void*) {
  return path;
}
bool read_regular_file(std::vector<unsigned char>* out, std::string* err, const std::string& path, void*) {
  std::error_code ec;
  if (!std::filesystem::is_regular_file(path, ec)) {
    if (err) *err += "external buffer '" + path + "' is not a readable file";
    return false;
  }
  std::ifstream in(path, std::ios::binary | std::ios::ate);
  const std::streamoff size = in ? static_cast<std::streamoff>(in.tellg()) : -1;
  if (size < 0) {
    if (err) *err += "cannot read external buffer '" + path + "'";
    return false;
  }
  out->resize(static_cast<size_t>(size));
  in.seekg(0);
  in.read(reinterpret_cast<char*>(out->data()), size);
  if (!in) {
    if (err) *err += "cannot read external buffer '" + path + "'";
    return false;
  }
  return true;
}
bool refuse_write(std::string* err, const std::string&, const std::vector<unsigned char>&, void*) {
  if (err) *err += "writing is not allowed while reading";
  return false;
}

// A validated, strided view of one accessor's elements.
struct AccessorView {
  const unsigned char* data = nullptr;  // null: all zeros (an accessor without a buffer view)
  std::shared_ptr<const std::vector<unsigned char>> owned;  // a sparse accessor's values, made dense
  size_t count = 0;
  size_t stride = 0;
  size_t components = 0;
  int component_type = 0;
  bool normalized = false;
};

class GltfReader {
 public:
  GltfReader(const tinygltf::Model& model, const std::string& source) : model_(model), source_(source) {}

  Scene read(MeshCheck& check);

 private:
  [[noreturn]] void fail(const std::string& what) const { throw InputError(source_, what); }

  // `length` bytes at `offset` of buffer view `view_index`, all inside it and its buffer.
  const unsigned char* bytes(int view_index, size_t offset, size_t length, const std::string& what) const;
  // `v` with a sparse accessor's values put in (a dense copy).
  AccessorView with_sparse(const tinygltf::Accessor& a, AccessorView v, const std::string& where) const;
  AccessorView view(int index, const std::string& what, std::initializer_list<int> types,
                    std::initializer_list<int> component_types) const;
  std::vector<float> floats(const AccessorView& v) const;
  std::vector<uint32_t> uints(const AccessorView& v) const;
  Mesh read_mesh(size_t index, MeshCheck& check) const;
  void read_nodes(Scene& scene) const;
  void read_skins(Scene& scene) const;
  void read_animations(Scene& scene) const;

  const tinygltf::Model& model_;
  const std::string& source_;
};

const char* type_name(int type) {
  switch (type) {
    case TINYGLTF_TYPE_SCALAR:
      return "SCALAR";
    case TINYGLTF_TYPE_VEC2:
      return "VEC2";
    case TINYGLTF_TYPE_VEC3:
      return "VEC3";
    case TINYGLTF_TYPE_VEC4:
      return "VEC4";
    case TINYGLTF_TYPE_MAT4:
      return "MAT4";
    default:
      return "other";
  }
}

AccessorView GltfReader::view(int index, const std::string& what, std::initializer_list<int> types,
                              std::initializer_list<int> component_types) const {
  if (index < 0 || static_cast<size_t>(index) >= model_.accessors.size())
    fail(fmt::format("{}: accessor {} does not exist", what, index));
  const tinygltf::Accessor& a = model_.accessors[static_cast<size_t>(index)];
  const std::string where = fmt::format("{} (accessor {})", what, index);
  if (std::find(types.begin(), types.end(), a.type) == types.end())
    fail(fmt::format("{}: unexpected type {}", where, type_name(a.type)));
  if (std::find(component_types.begin(), component_types.end(), a.componentType) == component_types.end())
    fail(fmt::format("{}: unexpected component type {}", where, a.componentType));
  if (a.count == 0) fail(where + ": count is 0");
  AccessorView v;
  v.components = static_cast<size_t>(tinygltf::GetNumComponentsInType(static_cast<uint32_t>(a.type)));
  v.component_type = a.componentType;
  v.normalized = a.normalized;
  v.count = a.count;
  const size_t element =
      v.components *
      static_cast<size_t>(tinygltf::GetComponentSizeInBytes(static_cast<uint32_t>(a.componentType)));
  v.stride = element;
  if (a.bufferView < 0) {
    // Zeros, per the spec; never more of them than the file's buffers hold bytes, so a few bytes of
    // JSON cannot ask for gigabytes.
    size_t held = 0;
    for (const tinygltf::Buffer& b : model_.buffers) held += b.data.size();
    if (a.count > held / element)
      fail(fmt::format("{}: {} elements without a buffer view, more than the file's {} bytes of buffers hold",
                       where, a.count, held));
    return a.sparse.isSparse ? with_sparse(a, v, where) : v;
  }
  if (static_cast<size_t>(a.bufferView) >= model_.bufferViews.size())
    fail(fmt::format("{}: buffer view {} does not exist", where, a.bufferView));
  const tinygltf::BufferView& bv = model_.bufferViews[static_cast<size_t>(a.bufferView)];
  if (bv.buffer < 0 || static_cast<size_t>(bv.buffer) >= model_.buffers.size())
    fail(fmt::format("{}: buffer {} does not exist", where, bv.buffer));
  const std::vector<unsigned char>& buffer = model_.buffers[static_cast<size_t>(bv.buffer)].data;
  if (bv.byteStride != 0) {
    if (bv.byteStride < element)
      fail(fmt::format("{}: byte stride {} is smaller than an element", where, bv.byteStride));
    v.stride = bv.byteStride;
  }
  // Everything read must lie inside the view, and the view inside its buffer (no overflow: count is
  // bounded by the buffer size first).
  if (bv.byteOffset > buffer.size() || bv.byteLength > buffer.size() - bv.byteOffset)
    fail(fmt::format("{}: buffer view {} runs past the end of its buffer", where, a.bufferView));
  if (a.count > bv.byteLength || a.byteOffset > bv.byteLength ||
      (a.count - 1) * v.stride + element > bv.byteLength - a.byteOffset)
    fail(fmt::format("{}: {} elements do not fit in buffer view {}", where, a.count, a.bufferView));
  v.data = buffer.data() + bv.byteOffset + a.byteOffset;
  return a.sparse.isSparse ? with_sparse(a, v, where) : v;
}

const unsigned char* GltfReader::bytes(int view_index, size_t offset, size_t length, const std::string& what) const {
  if (view_index < 0 || static_cast<size_t>(view_index) >= model_.bufferViews.size())
    fail(fmt::format("{}: buffer view {} does not exist", what, view_index));
  const tinygltf::BufferView& bv = model_.bufferViews[static_cast<size_t>(view_index)];
  if (bv.buffer < 0 || static_cast<size_t>(bv.buffer) >= model_.buffers.size())
    fail(fmt::format("{}: buffer {} does not exist", what, bv.buffer));
  const std::vector<unsigned char>& buffer = model_.buffers[static_cast<size_t>(bv.buffer)].data;
  if (bv.byteOffset > buffer.size() || bv.byteLength > buffer.size() - bv.byteOffset || offset > bv.byteLength ||
      length > bv.byteLength - offset)
    fail(fmt::format("{}: {} bytes do not fit in buffer view {}", what, length, view_index));
  return buffer.data() + bv.byteOffset + offset;
}

AccessorView GltfReader::with_sparse(const tinygltf::Accessor& a, AccessorView v, const std::string& where) const {
  const size_t element = v.components * static_cast<size_t>(tinygltf::GetComponentSizeInBytes(static_cast<uint32_t>(a.componentType)));
  const auto& s = a.sparse;
  if (s.count < 1 || static_cast<size_t>(s.count) > a.count)
    fail(fmt::format("{}: {} sparse values for {} elements", where, s.count, a.count));
  const size_t count = static_cast<size_t>(s.count);
  size_t index_size = 0;
  switch (s.indices.componentType) {
    case TINYGLTF_COMPONENT_TYPE_UNSIGNED_BYTE: index_size = 1; break;
    case TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT: index_size = 2; break;
    case TINYGLTF_COMPONENT_TYPE_UNSIGNED_INT: index_size = 4; break;
    default: fail(fmt::format("{}: sparse indices of component type {}", where, s.indices.componentType));
  }
  if (s.indices.byteOffset < 0 || s.values.byteOffset < 0) fail(where + ": a sparse byte offset is negative");
  const unsigned char* indices =
      bytes(s.indices.bufferView, static_cast<size_t>(s.indices.byteOffset), count * index_size, where + " sparse indices");
  const unsigned char* values =
      bytes(s.values.bufferView, static_cast<size_t>(s.values.byteOffset), count * element, where + " sparse values");
  auto dense = std::make_shared<std::vector<unsigned char>>(a.count * element, 0);
  if (v.data)
    for (size_t i = 0; i < a.count; ++i) std::memcpy(dense->data() + i * element, v.data + i * v.stride, element);
  uint32_t previous = 0;
  for (size_t k = 0; k < count; ++k) {
    uint32_t index = 0;
    if (index_size == 1) {
      index = indices[k];
    } else if (index_size == 2) {
      uint16_t i16;
      std::memcpy(&i16, indices + 2 * k, 2);
      index = i16;
    } else {
      std::memcpy(&index, indices + 4 * k, 4);
    }
    if (index >= a.count) fail(fmt::format("{}: sparse index {} of {} elements", where, index, a.count));
    if (k > 0 && index <= previous) fail(fmt::format("{}: sparse indices not increasing ({} after {})", where, index, previous));
    previous = index;
    std::memcpy(dense->data() + index * element, values + k * element, element);
  }
  v.owned = dense;
  v.data = dense->data();
  v.stride = element;
  return v;
}

// Component values as floats; normalised integers mapped to [0, 1] or [-1, 1] as the spec says.
std::vector<float> GltfReader::floats(const AccessorView& v) const {
  std::vector<float> out(v.count * v.components, 0.0f);
  if (!v.data) return out;
  for (size_t i = 0; i < v.count; ++i) {
    const unsigned char* e = v.data + i * v.stride;
    for (size_t c = 0; c < v.components; ++c) {
      float x = 0;
      switch (v.component_type) {
        case TINYGLTF_COMPONENT_TYPE_FLOAT:
          std::memcpy(&x, e + 4 * c, 4);
          break;
        case TINYGLTF_COMPONENT_TYPE_UNSIGNED_BYTE:
          x = e[c] / (v.normalized ? 255.0f : 1.0f);
          break;
        case TINYGLTF_COMPONENT_TYPE_BYTE: {
          const auto s = static_cast<int8_t>(e[c]);
          x = v.normalized ? std::max(s / 127.0f, -1.0f) : s;
          break;
        }
        case TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT: {
          uint16_t s;
          std::memcpy(&s, e + 2 * c, 2);
          x = s / (v.normalized ? 65535.0f : 1.0f);
          break;
        }
        case TINYGLTF_COMPONENT_TYPE_SHORT: {
          int16_t s;
          std::memcpy(&s, e + 2 * c, 2);
          x = v.normalized ? std::max(s / 32767.0f, -1.0f) : s;
          break;
        }
        default:
          fail("unsupported float component type");
      }
      out[i * v.components + c] = x;
    }
  }
  return out;
}

std::vector<uint32_t> GltfReader::uints(const AccessorView& v) const {
  std::vector<uint32_t> out(v.count * v.components, 0u);
  if (!v.data) return out;
  for (size_t i = 0; i < v.count; ++i) {
    const unsigned char* e = v.data + i * v.stride;
    for (size_t c = 0; c < v.components; ++c) {
      uint32_t x = 0;
      switch (v.component_type) {
        case TINYGLTF_COMPONENT_TYPE_UNSIGNED_BYTE:
          x = e[c];
          break;
        case TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT: {
          uint16_t s;
          std::memcpy(&s, e + 2 * c, 2);
          x = s;
          break;
        }
        case TINYGLTF_COMPONENT_TYPE_UNSIGNED_INT:
          std::memcpy(&x, e + 4 * c, 4);
          break;
        default:
          fail("unsupported integer component type");
      }
      out[i * v.components + c] = x;
    }
  }
  return out;
}

constexpr int kFloat = TINYGLTF_COMPONENT_TYPE_FLOAT;
constexpr int kUByte = TINYGLTF_COMPONENT_TYPE_UNSIGNED_BYTE;
constexpr int kUShort = TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT;
constexpr int kUInt = TINYGLTF_COMPONENT_TYPE_UNSIGNED_INT;
constexpr int kByte = TINYGLTF_COMPONENT_TYPE_BYTE;
constexpr int kShort = TINYGLTF_COMPONENT_TYPE_SHORT;

// One mesh: its triangle primitives concatenated (attributes kept where every primitive has them).
Mesh GltfReader::read_mesh(size_t index, MeshCheck& check) const {
  const tinygltf::Mesh& gm = model_.meshes[index];
  Mesh mesh;
  mesh.name = gm.name;
  const auto has = [&](const tinygltf::Primitive& p, const char* name) {
    return p.attributes.count(name) > 0;
  };
  const auto every = [&](const char* name) {
    return std::all_of(gm.primitives.begin(), gm.primitives.end(),
                       [&](const auto& p) { return has(p, name); });
  };
  const bool normals = every("NORMAL"), uvs = every("TEXCOORD_0"), colors = every("COLOR_0");
  const bool skinned = every("JOINTS_0") && every("WEIGHTS_0");
  if (gm.primitives.empty()) fail(element_name("mesh", index, gm.name) + " has no primitives");
  const size_t target_count = gm.primitives[0].targets.size();
  mesh.morph_targets.resize(target_count);

  for (size_t pi = 0; pi < gm.primitives.size(); ++pi) {
    const tinygltf::Primitive& prim = gm.primitives[pi];
    const std::string what = fmt::format("{} primitive {}", element_name("mesh", index, gm.name), pi);
    const int mode = prim.mode < 0 ? TINYGLTF_MODE_TRIANGLES : prim.mode;
    if (mode != TINYGLTF_MODE_TRIANGLES && mode != TINYGLTF_MODE_TRIANGLE_STRIP &&
        mode != TINYGLTF_MODE_TRIANGLE_FAN)
      fail(fmt::format("{}: mode {} is not triangles (points and lines are not meshes)", what, mode));
    if (!has(prim, "POSITION")) fail(what + " has no POSITION attribute");
    const auto attribute = [&](const char* name, std::initializer_list<int> types,
                               std::initializer_list<int> comps) {
      const AccessorView v = view(prim.attributes.at(name), what + " " + name, types, comps);
      return v;
    };
    const AccessorView pos = attribute("POSITION", {TINYGLTF_TYPE_VEC3}, {kFloat});
    const size_t n = pos.count;
    const auto offset = static_cast<uint32_t>(mesh.positions.size());
    const auto require_count = [&](const AccessorView& v, const char* name) {
      if (v.count != n)
        fail(fmt::format("{}: {} has {} elements but POSITION has {}", what, name, v.count, n));
    };
    const std::vector<float> p = floats(pos);
    for (size_t i = 0; i < n; ++i) mesh.positions.emplace_back(p[3 * i], p[3 * i + 1], p[3 * i + 2]);
    if (normals) {
      const AccessorView v = attribute("NORMAL", {TINYGLTF_TYPE_VEC3}, {kFloat});
      require_count(v, "NORMAL");
      const std::vector<float> f = floats(v);
      for (size_t i = 0; i < n; ++i) mesh.normals.emplace_back(f[3 * i], f[3 * i + 1], f[3 * i + 2]);
    }
    if (uvs) {
      const AccessorView v = attribute("TEXCOORD_0", {TINYGLTF_TYPE_VEC2}, {kFloat, kUByte, kUShort});
      require_count(v, "TEXCOORD_0");
      const std::vector<float> f = floats(v);
      for (size_t i = 0; i < n; ++i) mesh.uvs.emplace_back(f[2 * i], f[2 * i + 1]);
    }
    if (colors) {
      const AccessorView v =
          attribute("COLOR_0", {TINYGLTF_TYPE_VEC3, TINYGLTF_TYPE_VEC4}, {kFloat, kUByte, kUShort});
      require_count(v, "COLOR_0");
      const std::vector<float> f = floats(v);
      for (size_t i = 0; i < n; ++i)
        mesh.colors.emplace_back(f[v.components * i], f[v.components * i + 1], f[v.components * i + 2],
                                 v.components == 4 ? f[v.components * i + 3] : 1.0f);
    }
    if (skinned) {
      const AccessorView j = attribute("JOINTS_0", {TINYGLTF_TYPE_VEC4}, {kUByte, kUShort});
      const AccessorView w = attribute("WEIGHTS_0", {TINYGLTF_TYPE_VEC4}, {kFloat, kUByte, kUShort});
      require_count(j, "JOINTS_0");
      require_count(w, "WEIGHTS_0");
      const std::vector<uint32_t> ji = uints(j);
      const std::vector<float> wf = floats(w);
      for (size_t i = 0; i < n; ++i) {
        mesh.joints.push_back({static_cast<uint16_t>(ji[4 * i]), static_cast<uint16_t>(ji[4 * i + 1]),
                               static_cast<uint16_t>(ji[4 * i + 2]), static_cast<uint16_t>(ji[4 * i + 3])});
        mesh.weights.emplace_back(wf[4 * i], wf[4 * i + 1], wf[4 * i + 2], wf[4 * i + 3]);
      }
    }
    // Morph targets: every primitive must have the same number.
    if (prim.targets.size() != target_count)
      fail(fmt::format("{} has {} morph targets, primitive 0 has {}", what, prim.targets.size(),
                       target_count));
    for (size_t t = 0; t < target_count; ++t) {
      MorphTarget& target = mesh.morph_targets[t];
      const auto& attrs = prim.targets[t];
      const auto read_deltas = [&](const char* name, std::vector<Vec3f>& out, bool keep) {
        const auto it = attrs.find(name);
        if (it == attrs.end()) {
          out.resize(out.size() + n, Vec3f::Zero());
          return;
        }
        const AccessorView v = view(it->second, fmt::format("{} morph target {} {}", what, t, name),
                                    {TINYGLTF_TYPE_VEC3}, {kFloat, kByte, kShort});
        require_count(v, name);
        const std::vector<float> f = floats(v);
        if (keep)
          for (size_t i = 0; i < n; ++i) out.emplace_back(f[3 * i], f[3 * i + 1], f[3 * i + 2]);
      };
      read_deltas("POSITION", target.position_deltas, true);
      read_deltas("NORMAL", target.normal_deltas, normals);
    }
    // Indices (or 0..n-1), as triangles.
    std::vector<uint32_t> idx;
    if (prim.indices >= 0) {
      const AccessorView v =
          view(prim.indices, what + " indices", {TINYGLTF_TYPE_SCALAR}, {kUByte, kUShort, kUInt});
      idx = uints(v);
    } else {
      idx.resize(n);
      for (size_t i = 0; i < n; ++i) idx[i] = static_cast<uint32_t>(i);
    }
    for (size_t i = 0; i < idx.size(); ++i)
      if (idx[i] >= n)
        fail(fmt::format("{}: index {} is {} but there are only {} vertices", what, i, idx[i], n));
    const auto tri = [&](uint32_t a, uint32_t b, uint32_t c) {
      mesh.triangles.push_back({a + offset, b + offset, c + offset});
    };
    if (mode == TINYGLTF_MODE_TRIANGLES) {
      if (idx.size() % 3 != 0)
        fail(fmt::format("{}: {} indices is not a whole number of triangles", what, idx.size()));
      for (size_t i = 0; i + 2 < idx.size(); i += 3) tri(idx[i], idx[i + 1], idx[i + 2]);
    } else {
      if (idx.size() < 3) fail(what + ": fewer than 3 indices");
      check.non_triangle_faces_triangulated += 1;
      for (size_t i = 2; i < idx.size(); ++i) {
        if (mode == TINYGLTF_MODE_TRIANGLE_FAN)
          tri(idx[0], idx[i - 1], idx[i]);
        else if (i % 2 == 0)
          tri(idx[i - 2], idx[i - 1], idx[i]);
        else
          tri(idx[i - 1], idx[i - 2], idx[i]);
      }
    }
  }
  for (MorphTarget& t : mesh.morph_targets)
    if (!normals) t.normal_deltas.clear();
  // Target names (a common extras convention) and default weights.
  if (gm.extras.Has("targetNames") && gm.extras.Get("targetNames").IsArray()) {
    const tinygltf::Value& names = gm.extras.Get("targetNames");
    for (size_t t = 0; t < target_count && t < names.ArrayLen(); ++t)
      if (names.Get(static_cast<int>(t)).IsString())
        mesh.morph_targets[t].name = names.Get(static_cast<int>(t)).Get<std::string>();
  }
  if (!gm.weights.empty() && gm.weights.size() != target_count)
    fail(fmt::format("{} has {} default weights for {} morph targets", element_name("mesh", index, gm.name),
                     gm.weights.size(), target_count));
  mesh.morph_weights.assign(target_count, 0.0f);
  for (size_t t = 0; t < gm.weights.size(); ++t) mesh.morph_weights[t] = static_cast<float>(gm.weights[t]);
  if (target_count == 0) mesh.morph_weights.clear();
  for (Vec3f& nrm : mesh.normals)
    if (nrm.allFinite() && nrm.norm() > 0.0f) nrm.normalize();
  return mesh;
}

void GltfReader::read_nodes(Scene& scene) const {
  const size_t count = model_.nodes.size();
  scene.nodes.resize(count);
  for (size_t i = 0; i < count; ++i) {
    const tinygltf::Node& gn = model_.nodes[i];
    Node& node = scene.nodes[i];
    const std::string what = element_name("node", i, gn.name);
    node.name = gn.name;
    if (gn.mesh >= 0 && static_cast<size_t>(gn.mesh) >= model_.meshes.size())
      fail(fmt::format("{}: mesh {} does not exist", what, gn.mesh));
    if (gn.skin >= 0 && static_cast<size_t>(gn.skin) >= model_.skins.size())
      fail(fmt::format("{}: skin {} does not exist", what, gn.skin));
    node.mesh = gn.mesh < 0 ? -1 : gn.mesh;
    node.skin = gn.skin < 0 || gn.mesh < 0 ? -1 : gn.skin;
    const auto finite = [](const std::vector<double>& v) {
      return std::all_of(v.begin(), v.end(), [](double x) { return std::isfinite(x); });
    };
    if (!gn.matrix.empty()) {
      if (gn.matrix.size() != 16 || !finite(gn.matrix)) fail(what + ": matrix must be 16 finite numbers");
      Mat4f m;
      for (int k = 0; k < 16; ++k) m(k % 4, k / 4) = static_cast<float>(gn.matrix[static_cast<size_t>(k)]);
      // Decompose into TRS (glTF allows only such matrices on nodes).
      Eigen::Matrix3f linear = m.topLeftCorner<3, 3>();
      Vec3f scale(linear.col(0).norm(), linear.col(1).norm(), linear.col(2).norm());
      if (linear.determinant() < 0.0f) scale.x() = -scale.x();
      if ((scale.array() == 0.0f).any()) fail(what + ": matrix has a zero scale");
      node.translation = m.topRightCorner<3, 1>();
      node.scale = scale;
      node.rotation =
          Eigen::Quaternionf(Eigen::Matrix3f(linear * scale.cwiseInverse().asDiagonal())).normalized();
    } else {
      if (!gn.translation.empty()) {
        if (gn.translation.size() != 3 || !finite(gn.translation))
          fail(what + ": translation must be 3 finite numbers");
        node.translation = Vec3f(static_cast<float>(gn.translation[0]), static_cast<float>(gn.translation[1]),
                                 static_cast<float>(gn.translation[2]));
      }
      if (!gn.rotation.empty()) {
        if (gn.rotation.size() != 4 || !finite(gn.rotation))
          fail(what + ": rotation must be 4 finite numbers");
        node.rotation =
            Eigen::Quaternionf(static_cast<float>(gn.rotation[3]), static_cast<float>(gn.rotation[0]),
                               static_cast<float>(gn.rotation[1]), static_cast<float>(gn.rotation[2]));
        if (node.rotation.norm() == 0.0f) fail(what + ": rotation is a zero quaternion");
        node.rotation.normalize();
      }
      if (!gn.scale.empty()) {
        if (gn.scale.size() != 3 || !finite(gn.scale)) fail(what + ": scale must be 3 finite numbers");
        node.scale = Vec3f(static_cast<float>(gn.scale[0]), static_cast<float>(gn.scale[1]),
                           static_cast<float>(gn.scale[2]));
      }
    }
  }
  // Parents from children lists: each node at most one parent, no cycles.
  for (size_t i = 0; i < count; ++i)
    for (int child : model_.nodes[i].children) {
      if (child < 0 || static_cast<size_t>(child) >= count)
        fail(fmt::format("node {}: child {} does not exist", i, child));
      Node& c = scene.nodes[static_cast<size_t>(child)];
      if (c.parent >= 0 || static_cast<size_t>(child) == i)
        fail(fmt::format("node {} has more than one parent", child));
      c.parent = static_cast<int>(i);
    }
  for (size_t i = 0; i < count; ++i) {
    int n = static_cast<int>(i);
    for (size_t steps = 0; n >= 0; ++steps) {
      if (steps > count) fail(fmt::format("node hierarchy has a cycle through node {}", i));
      n = scene.nodes[static_cast<size_t>(n)].parent;
    }
  }
}

void GltfReader::read_skins(Scene& scene) const {
  for (size_t s = 0; s < model_.skins.size(); ++s) {
    const tinygltf::Skin& gs = model_.skins[s];
    const std::string what = element_name("skin", s, gs.name);
    Skin skin;
    skin.name = gs.name;
    if (gs.joints.empty()) fail(what + " has no joints");
    for (int j : gs.joints) {
      if (j < 0 || static_cast<size_t>(j) >= scene.nodes.size())
        fail(fmt::format("{}: joint node {} does not exist", what, j));
      skin.joints.push_back(j);
    }
    if (gs.skeleton >= 0 && static_cast<size_t>(gs.skeleton) >= scene.nodes.size())
      fail(fmt::format("{}: skeleton node {} does not exist", what, gs.skeleton));
    skin.skeleton = gs.skeleton;
    skin.inverse_bind_matrices.assign(skin.joints.size(), Mat4f::Identity());
    if (gs.inverseBindMatrices >= 0) {
      const AccessorView v =
          view(gs.inverseBindMatrices, what + " inverse bind matrices", {TINYGLTF_TYPE_MAT4}, {kFloat});
      if (v.count < skin.joints.size())
        fail(fmt::format("{}: {} inverse bind matrices for {} joints", what, v.count, skin.joints.size()));
      const std::vector<float> f = floats(v);
      for (size_t j = 0; j < skin.joints.size(); ++j) {
        for (int k = 0; k < 16; ++k)
          skin.inverse_bind_matrices[j](k % 4, k / 4) = f[16 * j + static_cast<size_t>(k)];
        if (!skin.inverse_bind_matrices[j].allFinite())
          fail(fmt::format("{}: inverse bind matrix {} is not finite", what, j));
      }
    }
    scene.skins.push_back(std::move(skin));
  }
  // Joint indices of skinned meshes must name joints of their node's skin.
  for (size_t i = 0; i < scene.nodes.size(); ++i) {
    const Node& node = scene.nodes[i];
    if (node.skin < 0) continue;
    const Mesh& mesh = scene.meshes[static_cast<size_t>(node.mesh)];
    const size_t joints = scene.skins[static_cast<size_t>(node.skin)].joints.size();
    for (size_t v = 0; v < mesh.joints.size(); ++v)
      for (int k = 0; k < 4; ++k)
        if (mesh.joints[v][static_cast<size_t>(k)] >= joints && mesh.weights[v][k] != 0.0f)
          fail(fmt::format("{}: vertex {} uses joint {} but skin {} has {} joints",
                           element_name("mesh", static_cast<size_t>(node.mesh), mesh.name), v,
                           mesh.joints[v][static_cast<size_t>(k)], node.skin, joints));
  }
}

void GltfReader::read_animations(Scene& scene) const {
  for (size_t a = 0; a < model_.animations.size(); ++a) {
    const tinygltf::Animation& ga = model_.animations[a];
    Animation animation;
    animation.name = ga.name;
    for (size_t c = 0; c < ga.channels.size(); ++c) {
      const tinygltf::AnimationChannel& gc = ga.channels[c];
      const std::string what = fmt::format("{} channel {}", element_name("animation", a, ga.name), c);
      if (gc.target_node < 0) continue;  // allowed by the spec (an extension may target something else)
      if (static_cast<size_t>(gc.target_node) >= scene.nodes.size())
        fail(fmt::format("{}: node {} does not exist", what, gc.target_node));
      if (gc.sampler < 0 || static_cast<size_t>(gc.sampler) >= ga.samplers.size())
        fail(fmt::format("{}: sampler {} does not exist", what, gc.sampler));
      const tinygltf::AnimationSampler& gs = ga.samplers[static_cast<size_t>(gc.sampler)];
      AnimationChannel channel;
      channel.node = gc.target_node;
      size_t width = 0;
      int type = TINYGLTF_TYPE_VEC3;
      std::initializer_list<int> comps = {kFloat};
      if (gc.target_path == "translation")
        channel.path = AnimationPath::Translation, width = 3;
      else if (gc.target_path == "scale")
        channel.path = AnimationPath::Scale, width = 3;
      else if (gc.target_path == "rotation")
        channel.path = AnimationPath::Rotation, width = 4, type = TINYGLTF_TYPE_VEC4;
      else if (gc.target_path == "weights") {
        channel.path = AnimationPath::Weights, type = TINYGLTF_TYPE_SCALAR;
        const int mesh = scene.nodes[static_cast<size_t>(gc.target_node)].mesh;
        if (mesh < 0) fail(what + ": animates morph weights of a node without a mesh");
        width = scene.meshes[static_cast<size_t>(mesh)].morph_targets.size();
        if (width == 0) fail(what + ": animates morph weights of a mesh without morph targets");
      } else
        fail(fmt::format("{}: unknown path '{}'", what, printable(gc.target_path)));
      if (gs.interpolation == "LINEAR")
        channel.interpolation = Interpolation::Linear;
      else if (gs.interpolation == "STEP")
        channel.interpolation = Interpolation::Step;
      else if (gs.interpolation == "CUBICSPLINE")
        channel.interpolation = Interpolation::CubicSpline;
      else
        fail(fmt::format("{}: unknown interpolation '{}'", what, printable(gs.interpolation)));
      const AccessorView in = view(gs.input, what + " input", {TINYGLTF_TYPE_SCALAR}, {kFloat});
      const AccessorView out = view(gs.output, what + " output", {type},
                                    channel.path == AnimationPath::Rotation
                                        ? std::initializer_list<int>{kFloat, kByte, kShort, kUByte, kUShort}
                                        : comps);
      channel.times = floats(in);
      channel.values = floats(out);
      for (size_t k = 0; k < channel.times.size(); ++k)
        if (!std::isfinite(channel.times[k]) || (k > 0 && !(channel.times[k] > channel.times[k - 1])))
          fail(fmt::format("{}: key times must be finite and increasing (key {})", what, k));
      const size_t per_key = width * (channel.interpolation == Interpolation::CubicSpline ? 3 : 1);
      if (channel.values.size() != channel.times.size() * per_key)
        fail(fmt::format("{}: {} output values for {} keys (expected {} per key)", what,
                         channel.values.size(), channel.times.size(), per_key));
      for (float x : channel.values)
        if (!std::isfinite(x)) fail(what + ": non-finite output value");
      animation.channels.push_back(std::move(channel));
    }
    scene.animations.push_back(std::move(animation));
  }
}

Scene GltfReader::read(MeshCheck& check) {
  Scene scene;
  for (size_t m = 0; m < model_.meshes.size(); ++m) scene.meshes.push_back(read_mesh(m, check));
  read_nodes(scene);
  read_skins(scene);
  read_animations(scene);
  return scene;
}

}  // namespace

Scene parse_gltf(std::span<const unsigned char> bytes, bool binary, const std::string& source,
                 const std::string& base_dir, MeshCheck& check) {
  if (binary && (bytes.size() < 4 || std::memcmp(bytes.data(), "glTF", 4) != 0))
    throw InputError(source, "not a GLB file (bad magic)");
  if (bytes.size() > 0xffffffffu) throw InputError(source, "file larger than 4 GiB");
  if (binary) {
    // The GLB container (header, then chunks of declared length), so a cut file says so.
    const auto u32 = [&](size_t at) {
      uint32_t v = 0;
      std::memcpy(&v, bytes.data() + at, 4);
      return v;
    };
    if (bytes.size() < 20)
      throw InputError(source, fmt::format("truncated GLB: {} bytes, not even a header", bytes.size()));
    if (u32(4) != 2)
      throw InputError(source,
                       fmt::format("GLB container version {} is not supported (drape reads 2)", u32(4)));
    if (u32(8) != bytes.size())
      throw InputError(source, fmt::format("GLB header says {} bytes but the file has {} (truncated?)",
                                           u32(8), bytes.size()));
    if (u32(16) != 0x4E4F534Au) throw InputError(source, "GLB does not start with a JSON chunk");
    if (u32(12) > bytes.size() - 20) throw InputError(source, "GLB JSON chunk runs past the end of the file");
  }
  tinygltf::TinyGLTF loader;
  loader.SetImageLoader(skip_image, nullptr);
  loader.SetFsCallbacks({regular_file_exists, keep_path, read_regular_file, refuse_write, nullptr});
  tinygltf::Model model;
  std::string err, warn;
  const auto size = static_cast<unsigned int>(bytes.size());
  const bool ok = binary
                      ? loader.LoadBinaryFromMemory(&model, &err, &warn, bytes.data(), size, base_dir)
                      : loader.LoadASCIIFromString(
                            &model, &err, &warn, reinterpret_cast<const char*>(bytes.data()), size, base_dir);
  if (!ok) throw InputError(source, one_line(err.empty() ? "not a valid glTF file" : err));
  if (model.asset.version.rfind("2.", 0) != 0)
    throw InputError(source, fmt::format("glTF version '{}' is not supported (drape reads 2.0)",
                                         printable(model.asset.version)));
  return GltfReader(model, source).read(check);
}

}  // namespace drape::io

// ---------------------------------------------------------------------------------------------------
// Writing.
namespace drape {
namespace {

using io::kFloat;

std::vector<float> flatten(const auto& vectors) {
  std::vector<float> out;
  for (const auto& v : vectors)
    for (int c = 0; c < v.size(); ++c) out.push_back(v[c]);
  return out;
}

// Builds a tinygltf model with one buffer; every view starts 4-byte aligned.
class GltfWriter {
 public:
  GltfWriter() {
    model_.asset.version = "2.0";
    model_.asset.generator = "drape " DRAPE_VERSION;
    model_.buffers.emplace_back();
  }

  int view(const void* data, size_t bytes, int target) {
    std::vector<unsigned char>& buf = model_.buffers[0].data;
    while (buf.size() % 4) buf.push_back(0);
    tinygltf::BufferView bv;
    bv.buffer = 0;
    bv.byteOffset = buf.size();
    bv.byteLength = bytes;
    bv.target = target;
    const auto* p = static_cast<const unsigned char*>(data);
    buf.insert(buf.end(), p, p + bytes);
    model_.bufferViews.push_back(bv);
    return static_cast<int>(model_.bufferViews.size()) - 1;
  }

  // An accessor over tightly packed data; min/max are written when `bounds` is set.
  int accessor(const void* data, size_t count, int type, int component_type, int target, bool bounds = false,
               bool normalized = false) {
    const size_t components =
        static_cast<size_t>(tinygltf::GetNumComponentsInType(static_cast<uint32_t>(type)));
    const size_t size =
        static_cast<size_t>(tinygltf::GetComponentSizeInBytes(static_cast<uint32_t>(component_type)));
    tinygltf::Accessor a;
    a.bufferView = view(data, count * components * size, target);
    a.byteOffset = 0;
    a.componentType = component_type;
    a.count = count;
    a.type = type;
    a.normalized = normalized;
    if (bounds && component_type == TINYGLTF_COMPONENT_TYPE_FLOAT) {
      const auto* f = static_cast<const float*>(data);
      a.minValues.assign(components, std::numeric_limits<double>::max());
      a.maxValues.assign(components, -std::numeric_limits<double>::max());
      for (size_t i = 0; i < count; ++i)
        for (size_t c = 0; c < components; ++c) {
          a.minValues[c] = std::min(a.minValues[c], static_cast<double>(f[i * components + c]));
          a.maxValues[c] = std::max(a.maxValues[c], static_cast<double>(f[i * components + c]));
        }
    }
    model_.accessors.push_back(a);
    return static_cast<int>(model_.accessors.size()) - 1;
  }

  // A morph target's position deltas: sparse where fewer than half the vertices move (a body that
  // gives way in a few regions), with no data at all where none does (the spec's zeros).
  int deltas_accessor(const std::vector<Vec3f>& deltas) {
    std::vector<uint32_t> moved;
    for (size_t i = 0; i < deltas.size(); ++i)
      if (deltas[i] != Vec3f::Zero()) moved.push_back(static_cast<uint32_t>(i));
    if (2 * moved.size() >= deltas.size()) {
      const std::vector<float> dense = flatten(deltas);
      return accessor(dense.data(), deltas.size(), TINYGLTF_TYPE_VEC3, TINYGLTF_COMPONENT_TYPE_FLOAT,
                      TINYGLTF_TARGET_ARRAY_BUFFER, true);
    }
    tinygltf::Accessor a;
    a.bufferView = -1;
    a.componentType = TINYGLTF_COMPONENT_TYPE_FLOAT;
    a.count = deltas.size();
    a.type = TINYGLTF_TYPE_VEC3;
    a.minValues.assign(3, 0.0);  // the unmoved vertices' zeros count
    a.maxValues.assign(3, 0.0);
    if (!moved.empty()) {
      std::vector<float> values;
      for (const uint32_t i : moved)
        for (int c = 0; c < 3; ++c) {
          const float v = deltas[i][c];
          values.push_back(v);
          a.minValues[static_cast<size_t>(c)] = std::min(a.minValues[static_cast<size_t>(c)], static_cast<double>(v));
          a.maxValues[static_cast<size_t>(c)] = std::max(a.maxValues[static_cast<size_t>(c)], static_cast<double>(v));
        }
      a.sparse.isSparse = true;
      a.sparse.count = static_cast<int>(moved.size());
      a.sparse.indices.bufferView = view(moved.data(), 4 * moved.size(), 0);
      a.sparse.indices.byteOffset = 0;
      a.sparse.indices.componentType = TINYGLTF_COMPONENT_TYPE_UNSIGNED_INT;
      a.sparse.values.bufferView = view(values.data(), 4 * values.size(), 0);
      a.sparse.values.byteOffset = 0;
    }
    model_.accessors.push_back(a);
    return static_cast<int>(model_.accessors.size()) - 1;
  }

  int add_mesh(const Mesh& mesh);
  void add_scene(const Scene& scene);
  tinygltf::Model& model() { return model_; }

 private:
  tinygltf::Model model_;
};

constexpr int kArrayBuffer = TINYGLTF_TARGET_ARRAY_BUFFER;
constexpr int kElementBuffer = TINYGLTF_TARGET_ELEMENT_ARRAY_BUFFER;

int GltfWriter::add_mesh(const Mesh& mesh) {
  const size_t n = mesh.positions.size();
  tinygltf::Primitive prim;
  prim.mode = TINYGLTF_MODE_TRIANGLES;
  const std::vector<float> positions = flatten(mesh.positions);
  prim.attributes["POSITION"] = accessor(positions.data(), n, TINYGLTF_TYPE_VEC3, kFloat, kArrayBuffer, true);
  if (mesh.normals.size() == n && n > 0) {
    // Unit length, as the validator requires; a zero normal (isolated vertex) becomes +Y.
    std::vector<Vec3f> unit(mesh.normals);
    for (Vec3f& v : unit) v = v.norm() > 0.0f && v.allFinite() ? Vec3f(v.normalized()) : Vec3f::UnitY();
    const std::vector<float> f = flatten(unit);
    prim.attributes["NORMAL"] = accessor(f.data(), n, TINYGLTF_TYPE_VEC3, kFloat, kArrayBuffer);
  }
  if (mesh.uvs.size() == n && n > 0) {
    const std::vector<float> f = flatten(mesh.uvs);
    prim.attributes["TEXCOORD_0"] = accessor(f.data(), n, TINYGLTF_TYPE_VEC2, kFloat, kArrayBuffer);
  }
  if (mesh.colors.size() == n && n > 0) {
    std::vector<float> f = flatten(mesh.colors);
    for (float& c : f) c = std::clamp(c, 0.0f, 1.0f);
    prim.attributes["COLOR_0"] = accessor(f.data(), n, TINYGLTF_TYPE_VEC4, kFloat, kArrayBuffer);
  }
  if (mesh.joints.size() == n && mesh.weights.size() == n && n > 0) {
    // Weights normalised to sum to one (the remainder goes to the largest); unused slots joint 0.
    std::vector<float> w(4 * n);
    std::vector<uint16_t> j(4 * n);
    uint16_t max_joint = 0;
    for (size_t i = 0; i < n; ++i) {
      Vec4f wi = mesh.weights[i].cwiseMax(0.0f);
      const float sum = wi.sum();
      wi = sum > 0.0f ? Vec4f(wi / sum) : Vec4f(1, 0, 0, 0);
      int largest = 0;
      wi.maxCoeff(&largest);
      wi[largest] += 1.0f - (wi[0] + wi[1] + wi[2] + wi[3]);
      for (int k = 0; k < 4; ++k) {
        w[4 * i + static_cast<size_t>(k)] = wi[k];
        j[4 * i + static_cast<size_t>(k)] = wi[k] > 0.0f ? mesh.joints[i][static_cast<size_t>(k)] : 0;
        max_joint = std::max(max_joint, j[4 * i + static_cast<size_t>(k)]);
      }
    }
    if (max_joint < 256) {
      std::vector<uint8_t> j8(j.begin(), j.end());
      prim.attributes["JOINTS_0"] =
          accessor(j8.data(), n, TINYGLTF_TYPE_VEC4, TINYGLTF_COMPONENT_TYPE_UNSIGNED_BYTE, kArrayBuffer);
    } else {
      prim.attributes["JOINTS_0"] =
          accessor(j.data(), n, TINYGLTF_TYPE_VEC4, TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT, kArrayBuffer);
    }
    prim.attributes["WEIGHTS_0"] = accessor(w.data(), n, TINYGLTF_TYPE_VEC4, kFloat, kArrayBuffer);
  }
  for (const MorphTarget& target : mesh.morph_targets) {
    std::map<std::string, int> attrs;
    if (target.position_deltas.size() == n) attrs["POSITION"] = deltas_accessor(target.position_deltas);
    if (target.normal_deltas.size() == n && prim.attributes.count("NORMAL")) {
      const std::vector<float> f = flatten(target.normal_deltas);
      attrs["NORMAL"] = accessor(f.data(), n, TINYGLTF_TYPE_VEC3, kFloat, kArrayBuffer);
    }
    prim.targets.push_back(attrs);
  }
  // Indices: the smallest unsigned type that holds them.
  std::vector<uint32_t> idx;
  idx.reserve(3 * mesh.triangles.size());
  for (const Tri& t : mesh.triangles) idx.insert(idx.end(), t.begin(), t.end());
  if (!idx.empty()) {
    if (n <= 65535) {
      std::vector<uint16_t> i16(idx.begin(), idx.end());
      prim.indices = accessor(i16.data(), i16.size(), TINYGLTF_TYPE_SCALAR,
                              TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT, kElementBuffer);
    } else {
      prim.indices = accessor(idx.data(), idx.size(), TINYGLTF_TYPE_SCALAR,
                              TINYGLTF_COMPONENT_TYPE_UNSIGNED_INT, kElementBuffer);
    }
  }
  tinygltf::Mesh gm;
  gm.name = mesh.name;
  gm.primitives.push_back(prim);
  if (!mesh.morph_targets.empty()) {
    for (size_t t = 0; t < mesh.morph_targets.size(); ++t)
      gm.weights.push_back(t < mesh.morph_weights.size() ? mesh.morph_weights[t] : 0.0);
    tinygltf::Value::Array names;
    for (const MorphTarget& t : mesh.morph_targets) names.emplace_back(t.name);
    tinygltf::Value::Object extras;
    extras["targetNames"] = tinygltf::Value(names);
    gm.extras = tinygltf::Value(extras);
  }
  model_.meshes.push_back(gm);
  return static_cast<int>(model_.meshes.size()) - 1;
}

void GltfWriter::add_scene(const Scene& scene) {
  for (const Mesh& mesh : scene.meshes) add_mesh(mesh);
  tinygltf::Scene gs;
  for (size_t i = 0; i < scene.nodes.size(); ++i) {
    const Node& node = scene.nodes[i];
    tinygltf::Node gn;
    gn.name = node.name;
    if (node.mesh >= 0) gn.mesh = node.mesh;
    if (node.skin >= 0 && node.mesh >= 0) gn.skin = node.skin;
    if (node.translation != Vec3f::Zero())
      gn.translation = {node.translation.x(), node.translation.y(), node.translation.z()};
    const Eigen::Quaternionf q = node.rotation.normalized();
    if (!q.coeffs().isApprox(Eigen::Quaternionf::Identity().coeffs(), 0.0f))
      gn.rotation = {q.x(), q.y(), q.z(), q.w()};
    if (node.scale != Vec3f::Ones()) gn.scale = {node.scale.x(), node.scale.y(), node.scale.z()};
    for (size_t c = 0; c < scene.nodes.size(); ++c)
      if (scene.nodes[c].parent == static_cast<int>(i)) gn.children.push_back(static_cast<int>(c));
    if (node.parent < 0) gs.nodes.push_back(static_cast<int>(i));
    // tinygltf writes a node with no property at all as null, which no reader accepts: an unnamed,
    // empty node (a bare joint or group) says its identity translation instead.
    if (gn.name.empty() && gn.mesh < 0 && gn.children.empty() && gn.translation.empty() && gn.rotation.empty() &&
        gn.scale.empty())
      gn.translation = {0.0, 0.0, 0.0};
    model_.nodes.push_back(gn);
  }
  // A mesh on no node would be invisible (and merge_scene places it at the origin): give it a root node.
  for (size_t m = 0; m < scene.meshes.size(); ++m) {
    const bool placed = std::any_of(scene.nodes.begin(), scene.nodes.end(),
                                    [&](const Node& n) { return n.mesh == static_cast<int>(m); });
    if (placed) continue;
    tinygltf::Node gn;
    gn.name = scene.meshes[m].name;
    gn.mesh = static_cast<int>(m);
    gs.nodes.push_back(static_cast<int>(model_.nodes.size()));
    model_.nodes.push_back(gn);
  }
  // tinygltf writes a scene without nodes as null, which no reader accepts: only non-empty scenes.
  if (!gs.nodes.empty()) {
    model_.scenes.push_back(gs);
    model_.defaultScene = 0;
  }

  for (const Skin& skin : scene.skins) {
    tinygltf::Skin gk;
    gk.name = skin.name;
    gk.joints = skin.joints;
    gk.skeleton = skin.skeleton;
    std::vector<float> ibm;
    for (size_t j = 0; j < skin.joints.size(); ++j) {
      Mat4f m = j < skin.inverse_bind_matrices.size() ? skin.inverse_bind_matrices[j] : Mat4f::Identity();
      m.row(3) = Eigen::RowVector4f(0, 0, 0, 1);  // exactly affine, as the validator checks
      for (int k = 0; k < 16; ++k) ibm.push_back(m(k % 4, k / 4));
    }
    if (!skin.joints.empty())
      gk.inverseBindMatrices = accessor(ibm.data(), skin.joints.size(), TINYGLTF_TYPE_MAT4, kFloat, 0);
    model_.skins.push_back(gk);
  }

  for (const Animation& animation : scene.animations) {
    tinygltf::Animation ga;
    ga.name = animation.name;
    for (const AnimationChannel& channel : animation.channels) {
      if (channel.times.empty()) continue;
      tinygltf::AnimationSampler sampler;
      sampler.interpolation = channel.interpolation == Interpolation::Linear ? "LINEAR"
                              : channel.interpolation == Interpolation::Step ? "STEP"
                                                                             : "CUBICSPLINE";
      sampler.input =
          accessor(channel.times.data(), channel.times.size(), TINYGLTF_TYPE_SCALAR, kFloat, 0, true);
      std::vector<float> values = channel.values;
      int type = TINYGLTF_TYPE_VEC3;
      size_t width = 3;
      if (channel.path == AnimationPath::Rotation) {
        type = TINYGLTF_TYPE_VEC4, width = 4;
        // Key values are unit quaternions; cubic-spline tangents (first and third of each triple) are not.
        const bool cubic = channel.interpolation == Interpolation::CubicSpline;
        for (size_t k = 0; k + 4 <= values.size(); k += 4) {
          if (cubic && (k / 4) % 3 != 1) continue;
          Eigen::Map<Vec4f> q(values.data() + k);
          if (q.norm() > 0.0f) q.normalize();
        }
      } else if (channel.path == AnimationPath::Weights) {
        type = TINYGLTF_TYPE_SCALAR, width = 1;
      }
      sampler.output = accessor(values.data(), values.size() / width, type, kFloat, 0);
      ga.samplers.push_back(sampler);
      tinygltf::AnimationChannel gc;
      gc.sampler = static_cast<int>(ga.samplers.size()) - 1;
      gc.target_node = channel.node;
      gc.target_path = channel.path == AnimationPath::Translation ? "translation"
                       : channel.path == AnimationPath::Rotation  ? "rotation"
                       : channel.path == AnimationPath::Scale     ? "scale"
                                                                  : "weights";
      ga.channels.push_back(gc);
    }
    if (!ga.channels.empty()) model_.animations.push_back(ga);
  }
  if (model_.buffers[0].data.empty())
    model_.buffers.clear();
  else
    model_.buffers[0].data.resize((model_.buffers[0].data.size() + 3) / 4 * 4, 0);
}

std::string serialize(const Scene& scene, bool binary) {
  GltfWriter writer;
  writer.add_scene(scene);
  tinygltf::TinyGLTF gltf;
  std::ostringstream out;
  if (!gltf.WriteGltfSceneToStream(&writer.model(), out, !binary, binary))
    throw std::runtime_error("glTF serialisation failed");
  return out.str();
}

}  // namespace

std::vector<unsigned char> encode_glb(const Scene& scene) {
  const std::string bytes = serialize(scene, true);
  return {bytes.begin(), bytes.end()};
}

std::string encode_gltf(const Scene& scene) {
  return serialize(scene, false);
}

}  // namespace drape
