#include "server/model/gltf_model.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <fstream>
#include <limits>
#include <map>
#include <new>
#include <sstream>
#include <system_error>
#include <utility>
#include <vector>

#include <glm/geometric.hpp>
#include <glm/gtc/matrix_inverse.hpp>
#include <glm/gtc/matrix_transform.hpp>
#include <glm/gtc/quaternion.hpp>
#include <glm/gtc/type_ptr.hpp>
#include <glm/mat3x3.hpp>
#include <glm/mat4x4.hpp>
#include "server/encode/image_decoder.hpp"
#include "server/model/tinygltf.hpp"

#include "server/model/materials.hpp"
#include "server/sim/file_name.hpp"

namespace downpour::model {

namespace {

std::string lower(std::string s) {
  std::transform(s.begin(), s.end(), s.begin(),
                 [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
  return s;
}

bool has(const std::string& s, std::initializer_list<const char*> words) {
  return std::any_of(words.begin(), words.end(),
                     [&](const char* w) { return s.find(w) != std::string::npos; });
}

// --- before tinygltf sees the bytes ---------------------------------------------------------

std::uint32_t u32(std::string_view b, std::size_t at) {
  std::uint32_t v = 0;
  std::memcpy(&v, b.data() + at, 4);
  return v;  // glTF is little-endian, as this machine
}

// Binary glTF's container: a 12-byte header, a JSON chunk, and an optional binary chunk, each of
// the lengths it says. Returns the JSON chunk.
std::string_view glb_json(std::string_view b) {
  if (b.size() < 20) throw ModelError("binary glTF shorter than its header");
  if (u32(b, 4) != 2)
    throw ModelError("binary glTF version " + std::to_string(u32(b, 4)) + ", not 2");
  if (u32(b, 8) != b.size())
    throw ModelError("binary glTF says it holds " + std::to_string(u32(b, 8)) +
                     " bytes; the file has " + std::to_string(b.size()));
  const std::uint32_t json_len = u32(b, 12);
  if (u32(b, 16) != 0x4E4F534Au || json_len > b.size() - 20)
    throw ModelError("binary glTF's first chunk is not JSON of a length within the file");
  const std::size_t next = 20 + static_cast<std::size_t>(json_len);
  if (next < b.size()) {
    if (b.size() - next < 8 || u32(b, next + 4) != 0x004E4942u ||
        u32(b, next) > b.size() - next - 8)
      throw ModelError("binary glTF's second chunk is not binary data within the file");
  }
  return b.substr(20, json_len);
}

// How deep the JSON's arrays and objects nest (tinygltf reads "extras" by recursion).
void check_json_depth(std::string_view json, int max_depth) {
  int depth = 0;
  bool in_string = false, escaped = false;
  for (char c : json) {
    if (in_string) {
      if (escaped)
        escaped = false;
      else if (c == '\\')
        escaped = true;
      else if (c == '"')
        in_string = false;
    } else if (c == '"') {
      in_string = true;
    } else if (c == '[' || c == '{') {
      if (++depth > max_depth)
        throw ModelError("JSON nests deeper than " + std::to_string(max_depth));
    } else if (c == ']' || c == '}') {
      --depth;
    }
  }
}

// tinygltf's file system: only bare names in `dir`, within the byte budget left.
struct Files {
  std::filesystem::path dir;
  std::size_t budget = 0;

  std::optional<std::filesystem::path> resolve(const std::string& path) const {
    if (dir.empty()) return std::nullopt;
    const std::string prefix = dir.string() + "/";
    if (path.rfind(prefix, 0) != 0) return std::nullopt;
    const std::string name = path.substr(prefix.size());
    if (!sim::plain_file_name(name, 255)) return std::nullopt;
    return dir / name;
  }
};

bool file_exists(const std::string& path, void* user) {
  const auto* files = static_cast<const Files*>(user);
  const auto p = files->resolve(path);
  std::error_code ec;
  return p && std::filesystem::is_regular_file(*p, ec);
}

std::string expand_path(const std::string& path, void*) { return path; }

bool read_file(std::vector<unsigned char>* out, std::string* err, const std::string& path,
               void* user) {
  auto* files = static_cast<Files*>(user);
  const auto p = files->resolve(path);
  std::error_code ec;
  const auto size = p ? std::filesystem::file_size(*p, ec) : 0;
  if (!p || ec) {
    *err = "not a file beside the model";
    return false;
  }
  if (size > files->budget) {
    *err = "over the model's byte limit";
    return false;
  }
  std::ifstream in(*p, std::ios::binary);
  out->resize(size);
  if (!in.read(reinterpret_cast<char*>(out->data()), static_cast<std::streamsize>(size))) {
    *err = "unreadable";
    return false;
  }
  files->budget -= size;
  return true;
}

bool write_file(std::string* err, const std::string&, const std::vector<unsigned char>&, void*) {
  *err = "models are not written to files here";
  return false;
}

// The loader's images are kept as their file's bytes (PNG or JPEG); the reader decodes those a
// material takes as its base colour, with their size checked first (encode/image_decoder.hpp).
bool keep_image(tinygltf::Image* image, const int, std::string*, std::string*, int, int,
                const unsigned char* bytes, int size, void*) {
  // An image in a buffer view: tinygltf hands over the view's range unchecked against its buffer;
  // the reader takes those bytes itself, checked (Reader::image_bytes).
  if (image->bufferView >= 0) return true;
  image->image.assign(bytes, bytes + std::max(size, 0));
  image->width = image->height = image->component = 0;
  return true;
}

// sRGB-encoded 8 bits to linear light, and back (the texture's resampling averages light).
float srgb_to_linear(int c) {
  const float x = static_cast<float>(c) / 255.0f;
  return x <= 0.04045f ? x / 12.92f : std::pow((x + 0.055f) / 1.055f, 2.4f);
}
std::uint8_t linear_to_srgb(float x) {
  x = std::clamp(x, 0.0f, 1.0f);
  const float c = x <= 0.0031308f ? 12.92f * x : 1.055f * std::pow(x, 1.0f / 2.4f) - 0.055f;
  return static_cast<std::uint8_t>(std::lround(c * 255.0f));
}

// A decoded picture (BGRX, rows bottom-up) as a layer: each texel the mean of the pixels its
// square covers (at least the nearest one), in linear light; RGBA, rows from the top.
ModelTexture to_layer(const encode::BgrxPixels& p) {
  static const std::array<float, 256> lut = [] {
    std::array<float, 256> t{};
    for (int i = 0; i < 256; ++i) t[i] = srgb_to_linear(i);
    return t;
  }();
  constexpr int n = kModelTextureSide;
  std::vector<std::uint8_t> rgba(static_cast<std::size_t>(n) * n * 4);
  for (int y = 0; y < n; ++y) {
    const int sy0 = y * p.height / n, sy1 = std::max(sy0 + 1, (y + 1) * p.height / n);
    for (int x = 0; x < n; ++x) {
      const int sx0 = x * p.width / n, sx1 = std::max(sx0 + 1, (x + 1) * p.width / n);
      float sum[3] = {0.0f, 0.0f, 0.0f}, alpha = 0.0f;
      for (int sy = sy0; sy < sy1; ++sy) {
        // (rows bottom-up: the picture's row sy from the top)
        const std::uint8_t* row =
            &p.bgrx[static_cast<std::size_t>(p.height - 1 - sy) * p.width * 4];
        for (int sx = sx0; sx < sx1; ++sx) {
          const std::uint8_t* q = row + static_cast<std::size_t>(sx) * 4;
          sum[0] += lut[q[2]], sum[1] += lut[q[1]], sum[2] += lut[q[0]], alpha += q[3];
        }
      }
      const float k = 1.0f / static_cast<float>((sy1 - sy0) * (sx1 - sx0));
      std::uint8_t* o = &rgba[(static_cast<std::size_t>(y) * n + x) * 4];
      for (int c = 0; c < 3; ++c) o[c] = linear_to_srgb(sum[c] * k);
      o[3] = static_cast<std::uint8_t>(std::lround(alpha * k));
    }
  }
  return {std::make_shared<const std::vector<std::uint8_t>>(std::move(rgba))};
}

// --- from tinygltf's model to ours ------------------------------------------------------------

// One accessor's elements as floats (`components` each) or as indices, every byte checked to lie
// in its buffer.
class Accessors {
 public:
  explicit Accessors(const tinygltf::Model& m) : m_(m) {}

  std::vector<float> floats(int index, int type, const char* what) const {
    const tinygltf::Accessor& a = accessor(index, what);
    if (a.type != type || a.componentType != TINYGLTF_COMPONENT_TYPE_FLOAT)
      throw ModelError(std::string(what) + " must be floats of " +
                       std::to_string(tinygltf::GetNumComponentsInType(type)) + " components");
    const int n = tinygltf::GetNumComponentsInType(type);
    const auto [data, stride] = locate(a, 4 * n, what);  // (its count checked before it is used)
    std::vector<float> out(a.count * n);
    for (std::size_t i = 0; i < a.count; ++i) std::memcpy(&out[i * n], data + i * stride, 4 * n);
    for (float v : out)
      if (!std::isfinite(v)) throw ModelError(std::string(what) + " holds a number not finite");
    return out;
  }

  // TEXCOORD_n: two floats, or two normalized unsigned bytes or shorts.
  std::vector<float> texcoords(int index, const char* what) const {
    const tinygltf::Accessor& a = accessor(index, what);
    if (a.componentType == TINYGLTF_COMPONENT_TYPE_FLOAT)
      return floats(index, TINYGLTF_TYPE_VEC2, what);
    const int size = a.componentType == TINYGLTF_COMPONENT_TYPE_UNSIGNED_BYTE    ? 1
                     : a.componentType == TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT ? 2
                                                                                 : 0;
    if (a.type != TINYGLTF_TYPE_VEC2 || size == 0 || !a.normalized)
      throw ModelError(std::string(what) +
                       " must be two floats, or two normalized unsigned bytes or shorts");
    const auto [data, stride] = locate(a, 2 * size, what);
    std::vector<float> out(a.count * 2);
    for (std::size_t i = 0; i < a.count; ++i) {
      for (int c = 0; c < 2; ++c) {
        const unsigned char* q = data + i * stride + c * size;
        out[2 * i + c] =
            size == 1 ? q[0] / 255.0f : static_cast<float>(q[0] | q[1] << 8) / 65535.0f;
      }
    }
    return out;
  }

  std::vector<std::uint32_t> indices(int index, std::size_t vertex_count) const {
    const tinygltf::Accessor& a = accessor(index, "indices");
    const int size = a.componentType == TINYGLTF_COMPONENT_TYPE_UNSIGNED_BYTE    ? 1
                     : a.componentType == TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT ? 2
                     : a.componentType == TINYGLTF_COMPONENT_TYPE_UNSIGNED_INT   ? 4
                                                                                 : 0;
    if (a.type != TINYGLTF_TYPE_SCALAR || size == 0)
      throw ModelError("indices must be unsigned bytes, shorts or ints");
    const auto [data, stride] = locate(a, size, "indices");
    std::vector<std::uint32_t> out(a.count);
    for (std::size_t i = 0; i < a.count; ++i) {
      const unsigned char* p = data + i * stride;
      std::uint32_t v = p[0];
      if (size == 2) v = static_cast<std::uint32_t>(p[0] | p[1] << 8);
      if (size == 4) std::memcpy(&v, p, 4);
      if (v >= vertex_count)
        throw ModelError("an index (" + std::to_string(v) + ") past the primitive's " +
                         std::to_string(vertex_count) + " vertices");
      out[i] = v;
    }
    return out;
  }

 private:
  const tinygltf::Accessor& accessor(int index, const char* what) const {
    if (index < 0 || static_cast<std::size_t>(index) >= m_.accessors.size())
      throw ModelError(std::string(what) + " names no accessor");
    const tinygltf::Accessor& a = m_.accessors[index];
    if (a.sparse.isSparse) throw ModelError(std::string(what) + ": sparse accessors are not read");
    return a;
  }

  std::pair<const unsigned char*, std::size_t> locate(const tinygltf::Accessor& a,
                                                      std::size_t element, const char* what) const {
    if (a.bufferView < 0 || static_cast<std::size_t>(a.bufferView) >= m_.bufferViews.size())
      throw ModelError(std::string(what) + " has no buffer view");
    const tinygltf::BufferView& v = m_.bufferViews[a.bufferView];
    if (v.buffer < 0 || static_cast<std::size_t>(v.buffer) >= m_.buffers.size())
      throw ModelError(std::string(what) + "'s buffer view has no buffer");
    const std::vector<unsigned char>& data = m_.buffers[v.buffer].data;
    const std::size_t stride = v.byteStride != 0 ? v.byteStride : element;
    if (stride < element || stride > 252) throw ModelError(std::string(what) + ": a bad stride");
    if (v.byteOffset > data.size() || v.byteLength > data.size() - v.byteOffset)
      throw ModelError(std::string(what) + "'s buffer view lies outside its buffer");
    if (a.count == 0) throw ModelError(std::string(what) + " is empty");
    // The last element's end, within the view: checked against overflow.
    const std::size_t max_count = (std::numeric_limits<std::size_t>::max() / 2) / stride;
    if (a.count > max_count || a.byteOffset > v.byteLength ||
        (a.count - 1) * stride + element > v.byteLength - a.byteOffset)
      throw ModelError(std::string(what) + " runs past its buffer view");
    return {data.data() + v.byteOffset + a.byteOffset, stride};
  }

  const tinygltf::Model& m_;
};

glm::dmat4 local_matrix(const tinygltf::Node& n) {
  if (n.matrix.size() == 16) return glm::make_mat4(n.matrix.data());
  glm::dmat4 m(1.0);
  if (n.translation.size() == 3) m = glm::translate(m, glm::make_vec3(n.translation.data()));
  if (n.rotation.size() == 4) {
    const glm::dquat q(n.rotation[3], n.rotation[0], n.rotation[1], n.rotation[2]);
    if (glm::length(q) > 1e-9) m *= glm::mat4_cast(glm::normalize(q));
  }
  if (n.scale.size() == 3) m = glm::scale(m, glm::make_vec3(n.scale.data()));
  return m;
}

// glTF's axes (x left, y up, z forward) to the vehicle frame's (x forward, y left, z up).
glm::dvec3 to_vehicle(const glm::dvec3& g) { return {g.z, g.x, g.y}; }
glm::dvec3 to_gltf(const glm::dvec3& v) { return {v.y, v.z, v.x}; }

struct Shade {
  float material = material::kTrim;
  float colour = 0.0f;  // pack_trim_colour, or 0
  bool windshield = false;
  int texture = -1;  // the glTF texture of its base colour (on TEXCOORD_0), or -1
};

Shade shade_of(const tinygltf::Model& m, int index, ModelKind kind) {
  if (index < 0 || static_cast<std::size_t>(index) >= m.materials.size()) return {};
  const tinygltf::Material& mat = m.materials[index];
  const std::string name = lower(mat.name);
  if (has(name, {"windshield", "windscreen"}))
    return {material::kGlass, 0.0f, kind == ModelKind::kCabin};
  if (has(name, {"glass", "window"})) return {material::kGlass};
  if (has(name, {"tyre", "tire", "rubber"})) return {material::kTyre};
  if (has(name, {"headlamp", "headlight"})) return {material::kHeadlamp};
  if (has(name, {"indicator_left", "blinker_left", "turn_left"})) return {material::kIndicatorLeft};
  if (has(name, {"indicator_right", "blinker_right", "turn_right"}))
    return {material::kIndicatorRight};
  if (has(name, {"tail", "brake"})) return {material::kLamp};
  // A base-colour texture on the first uv set: the texture times the colour (paint: times the
  // vehicle's own colour).
  const tinygltf::TextureInfo& base = mat.pbrMetallicRoughness.baseColorTexture;
  const int texture = base.index >= 0 && base.texCoord == 0 ? base.index : -1;
  const std::vector<double>& c = mat.pbrMetallicRoughness.baseColorFactor;
  const bool white = c.size() < 3 || (c[0] == 1.0 && c[1] == 1.0 && c[2] == 1.0);
  if (has(name, {"paint", "body"})) return {material::kBody, 0.0f, false, texture};
  if (texture >= 0)
    return {material::kTrim,
            white ? pack_trim_colour(1.0, 1.0, 1.0) : pack_trim_colour(c[0], c[1], c[2]), false,
            texture};
  // Its own colour; glTF's default, white, is the built-in dark trim.
  if (!white) return {material::kTrim, pack_trim_colour(c[0], c[1], c[2])};
  return {};
}

// The triangles gathered from the scene, by part: the fixed parts (-1) and each wheel node.
struct Gathered {
  std::vector<render::MeshVertex> vertices;
  std::map<int, std::vector<std::uint32_t>> parts;  // wheel number (or -1) -> indices
  std::vector<glm::dvec3> windshield;               // its triangles' corners, in threes
  std::size_t triangles = 0;
  std::vector<render::VertexTexture> texcoords;  // one a vertex
  std::vector<ModelTexture> textures;
};

class Reader {
 public:
  Reader(const tinygltf::Model& m, ModelKind kind, const ModelLimits& limits)
      : m_(m), kind_(kind), limits_(limits), accessors_(m) {}

  Gathered gather() {
    for (const std::string& ext : m_.extensionsRequired)
      throw ModelError("the model requires the extension " + ext + ", which is not read");
    std::vector<int> roots;
    if (!m_.scenes.empty()) {
      const int s = m_.defaultScene >= 0 ? m_.defaultScene : 0;
      if (static_cast<std::size_t>(s) >= m_.scenes.size())
        throw ModelError("the default scene does not exist");
      roots = m_.scenes[s].nodes;
    } else {  // no scene: every node no other names as a child
      std::vector<bool> child(m_.nodes.size(), false);
      for (const tinygltf::Node& n : m_.nodes)
        for (int c : n.children)
          if (c >= 0 && static_cast<std::size_t>(c) < child.size()) child[c] = true;
      for (std::size_t i = 0; i < m_.nodes.size(); ++i)
        if (!child[i]) roots.push_back(static_cast<int>(i));
    }
    std::vector<int> path;
    for (int r : roots) visit(r, glm::dmat4(1.0), -1, path);
    if (out_.triangles == 0) throw ModelError("the model has no mesh of triangles");
    return std::move(out_);
  }

 private:
  void visit(int index, const glm::dmat4& parent, int wheel, std::vector<int>& path) {
    if (index < 0 || static_cast<std::size_t>(index) >= m_.nodes.size())
      throw ModelError("a node names a node that does not exist");
    if (std::find(path.begin(), path.end(), index) != path.end())
      throw ModelError("the node hierarchy has a cycle");
    if (static_cast<int>(path.size()) >= limits_.max_depth)
      throw ModelError("the node hierarchy is deeper than " + std::to_string(limits_.max_depth));
    if (++visits_ > limits_.max_node_visits)
      throw ModelError("the node hierarchy holds more than " +
                       std::to_string(limits_.max_node_visits) + " node instances");
    const tinygltf::Node& node = m_.nodes[index];
    const glm::dmat4 world = parent * local_matrix(node);
    if (wheel < 0 && lower(node.name).rfind("wheel", 0) == 0) wheel = wheels_++;
    if (node.mesh >= 0) add_mesh(node.mesh, world, wheel);
    path.push_back(index);
    for (int c : node.children) visit(c, world, wheel, path);
    path.pop_back();
  }

  void add_mesh(int index, const glm::dmat4& world, int wheel) {
    if (static_cast<std::size_t>(index) >= m_.meshes.size())
      throw ModelError("a node names a mesh that does not exist");
    const glm::dmat3 normal_matrix = glm::inverseTranspose(glm::dmat3(world));
    const bool flip = glm::determinant(glm::dmat3(world)) < 0.0;
    for (const tinygltf::Primitive& p : m_.meshes[index].primitives) {
      if (p.mode != TINYGLTF_MODE_TRIANGLES) continue;  // points and lines: nothing to draw
      const auto position = p.attributes.find("POSITION");
      if (position == p.attributes.end()) throw ModelError("a primitive has no positions");
      const std::vector<float> pos =
          accessors_.floats(position->second, TINYGLTF_TYPE_VEC3, "POSITION");
      const std::size_t n = pos.size() / 3;
      std::vector<float> nor;
      if (const auto it = p.attributes.find("NORMAL"); it != p.attributes.end()) {
        nor = accessors_.floats(it->second, TINYGLTF_TYPE_VEC3, "NORMAL");
        if (nor.size() != pos.size()) throw ModelError("NORMAL and POSITION counts differ");
      }
      std::vector<std::uint32_t> idx;
      if (p.indices >= 0) {
        idx = accessors_.indices(p.indices, n);
      } else {
        idx.resize(n);
        for (std::size_t i = 0; i < n; ++i) idx[i] = static_cast<std::uint32_t>(i);
      }
      if (idx.size() % 3 != 0)
        throw ModelError("a triangle list's index count is not a multiple of 3");
      out_.triangles += idx.size() / 3;
      if (out_.triangles > limits_.max_triangles)
        throw ModelError("the model has more than " + std::to_string(limits_.max_triangles) +
                         " triangles");
      const Shade shade = shade_of(m_, p.material, kind_);
      std::vector<glm::dvec3> v(n);
      for (std::size_t i = 0; i < n; ++i)
        v[i] = to_vehicle(
            glm::dvec3(world * glm::dvec4(pos[3 * i], pos[3 * i + 1], pos[3 * i + 2], 1.0)));
      if (shade.windshield) {
        for (std::uint32_t i : idx) out_.windshield.push_back(v[i]);
        continue;  // the simulated glass is drawn in its place
      }
      std::vector<std::uint32_t>& part = out_.parts[wheel];
      const glm::vec2 uv(shade.material, shade.colour);
      // Where each vertex reads the texture, if the material has one.
      std::vector<float> tex;
      float layer = -1.0f;
      if (shade.texture >= 0) {
        if (const auto it = p.attributes.find("TEXCOORD_0"); it != p.attributes.end()) {
          tex = accessors_.texcoords(it->second, "TEXCOORD_0");
          if (tex.size() != 2 * n) throw ModelError("TEXCOORD_0 and POSITION counts differ");
          layer = static_cast<float>(layer_of(shade.texture));
        }
      }
      auto texcoord = [&](std::size_t i) {
        return layer < 0.0f ? render::VertexTexture{}
                            : render::VertexTexture{{tex[2 * i], tex[2 * i + 1]}, layer};
      };
      if (nor.empty()) {  // flat normals: each triangle its own corners
        for (std::size_t t = 0; t < idx.size(); t += 3) {
          std::uint32_t ia = idx[t], ib = idx[t + 1], ic = idx[t + 2];
          if (flip) std::swap(ib, ic);
          const glm::dvec3 a = v[ia], b = v[ib], c = v[ic];
          glm::dvec3 nn = glm::cross(b - a, c - a);
          const double len = glm::length(nn);
          nn = len > 0.0 ? nn / len : glm::dvec3(0.0, 0.0, 1.0);
          for (const std::uint32_t q : {ia, ib, ic}) {
            part.push_back(static_cast<std::uint32_t>(out_.vertices.size()));
            out_.vertices.push_back({glm::vec3(v[q]), glm::vec3(nn), uv});
            out_.texcoords.push_back(texcoord(q));
          }
        }
        continue;
      }
      const auto base = static_cast<std::uint32_t>(out_.vertices.size());
      for (std::size_t i = 0; i < n; ++i) {
        glm::dvec3 nn =
            to_vehicle(normal_matrix * glm::dvec3(nor[3 * i], nor[3 * i + 1], nor[3 * i + 2]));
        const double len = glm::length(nn);
        nn = len > 0.0 ? nn / len : glm::dvec3(0.0, 0.0, 1.0);
        out_.vertices.push_back({glm::vec3(v[i]), glm::vec3(nn), uv});
        out_.texcoords.push_back(texcoord(i));
      }
      for (std::size_t t = 0; t < idx.size(); t += 3) {
        part.push_back(base + idx[t]);
        part.push_back(base + idx[t + (flip ? 2 : 1)]);
        part.push_back(base + idx[t + (flip ? 1 : 2)]);
      }
    }
  }

  // An image's file bytes: kept by keep_image, or its buffer view's, within its buffer.
  std::string_view image_bytes(const tinygltf::Image& image, int index) const {
    if (image.bufferView < 0)
      return {reinterpret_cast<const char*>(image.image.data()), image.image.size()};
    const std::string what = "image " + std::to_string(index);
    if (static_cast<std::size_t>(image.bufferView) >= m_.bufferViews.size())
      throw ModelError(what + " names no buffer view");
    const tinygltf::BufferView& v = m_.bufferViews[image.bufferView];
    if (v.buffer < 0 || static_cast<std::size_t>(v.buffer) >= m_.buffers.size())
      throw ModelError(what + "'s buffer view has no buffer");
    const std::vector<unsigned char>& data = m_.buffers[v.buffer].data;
    if (v.byteOffset > data.size() || v.byteLength > data.size() - v.byteOffset)
      throw ModelError(what + "'s buffer view lies outside its buffer");
    return {reinterpret_cast<const char*>(data.data() + v.byteOffset), v.byteLength};
  }

  // The model's layer for glTF texture t: its image decoded and resampled the first time.
  int layer_of(int t) {
    if (static_cast<std::size_t>(t) >= m_.textures.size())
      throw ModelError("a material names a texture that does not exist");
    const int source = m_.textures[t].source;
    if (source < 0 || static_cast<std::size_t>(source) >= m_.images.size())
      throw ModelError("texture " + std::to_string(t) + " names no image");
    if (const auto it = layers_.find(source); it != layers_.end()) return it->second;
    if (static_cast<int>(out_.textures.size()) >= limits_.max_textures)
      throw ModelError("the model has more than " + std::to_string(limits_.max_textures) +
                       " base-colour textures");
    const std::string_view bytes = image_bytes(m_.images[source], source);
    encode::BgrxPixels pixels;
    try {
      // What the model's images may still hold, checked from the image's header.
      pixels = encode::decode_bgrx_up_to(bytes, limits_.max_image_side,
                                         limits_.max_image_pixels - image_pixels_);
    } catch (const encode::DecodeError& e) {
      throw ModelError("image " + std::to_string(source) + ": " + e.what());
    }
    image_pixels_ += static_cast<std::size_t>(pixels.width) * pixels.height;
    out_.textures.push_back(to_layer(pixels));
    const int layer = static_cast<int>(out_.textures.size()) - 1;
    layers_[source] = layer;
    return layer;
  }

  const tinygltf::Model& m_;
  ModelKind kind_;
  const ModelLimits& limits_;
  Accessors accessors_;
  Gathered out_;
  std::map<int, int> layers_;  // image -> layer
  std::size_t image_pixels_ = 0;
  std::size_t visits_ = 0;
  int wheels_ = 0;
};

// The windshield's outline from its triangles: its plane by the least squares of its corners, its
// lowest and highest edges along the plane's upward direction.
WindshieldOutline outline(const std::vector<glm::dvec3>& pts) {
  glm::dvec3 centre(0.0);
  for (const glm::dvec3& p : pts) centre += p;
  centre /= static_cast<double>(pts.size());
  // The plane's normal: the area-weighted mean of the triangles' normals, pointing forward.
  glm::dvec3 n(0.0);
  for (std::size_t t = 0; t + 2 < pts.size(); t += 3) {
    glm::dvec3 c = glm::cross(pts[t + 1] - pts[t], pts[t + 2] - pts[t]);
    if (c.x < 0.0) c = -c;
    n += c;
  }
  if (glm::length(n) < 1e-9) throw ModelError("the windshield's triangles have no area");
  n = glm::normalize(n);
  const glm::dvec3 across(0.0, -1.0, 0.0);                // the glass's u: towards the right
  glm::dvec3 up = glm::normalize(glm::cross(n, across));  // up the glass, back and up
  if (up.z < 0.0) up = -up;
  double v_lo = 1e30, v_hi = -1e30, bow = 0.0;
  for (const glm::dvec3& p : pts) {
    const double v = glm::dot(p - centre, up);
    v_lo = std::min(v_lo, v);
    v_hi = std::max(v_hi, v);
    bow = std::max(bow, std::abs(glm::dot(p - centre, n)));
  }
  const double band = 0.05 * (v_hi - v_lo);  // the corners within 5% of an edge
  double bl = -1e30, br = 1e30, tl = -1e30, tr = 1e30;
  for (const glm::dvec3& p : pts) {
    const double v = glm::dot(p - centre, up);
    if (v < v_lo + band) bl = std::max(bl, p.y), br = std::min(br, p.y);
    if (v > v_hi - band) tl = std::max(tl, p.y), tr = std::min(tr, p.y);
  }
  WindshieldOutline o;
  o.height_mm = 1000.0 * (v_hi - v_lo);
  o.bottom_width_mm = 1000.0 * (bl - br);
  o.top_width_mm = 1000.0 * (tl - tr);
  o.rake_deg = glm::degrees(std::acos(std::clamp(up.z, -1.0, 1.0)));
  o.bow_mm = 1000.0 * bow;
  // The bottom edge's left end: on the plane at the lowest v, at the edge's leftmost y.
  o.bottom_left_m = centre + v_lo * up;
  o.bottom_left_m.y = bl;
  return o;
}

VehicleModel assemble(Gathered g, ModelKind kind) {
  VehicleModel out;
  // Place it: the vehicle frame's origin on the ground under the rear axle, centred across.
  glm::dvec3 lo(g.vertices.empty() ? 0.0 : 1e30), hi(g.vertices.empty() ? 0.0 : -1e30);
  for (const render::MeshVertex& v : g.vertices) {
    lo = glm::min(lo, glm::dvec3(v.position));
    hi = glm::max(hi, glm::dvec3(v.position));
  }
  if (g.vertices.empty() && (kind == ModelKind::kVehicle || g.windshield.empty()))
    throw ModelError("the model has no mesh of triangles");
  // The wheels' centres and radii, in the model's own coordinates.
  std::vector<std::pair<glm::dvec3, double>> wheels;
  for (const auto& [wheel, indices] : g.parts) {
    if (wheel < 0 || indices.empty()) continue;
    glm::dvec3 wlo(1e30), whi(-1e30);
    for (std::uint32_t i : indices) {
      wlo = glm::min(wlo, glm::dvec3(g.vertices[i].position));
      whi = glm::max(whi, glm::dvec3(g.vertices[i].position));
    }
    wheels.push_back({0.5 * (wlo + whi), 0.5 * (whi.z - wlo.z)});
  }
  const glm::dvec3 size = hi - lo;
  glm::dvec3 origin(lo.x + 0.2 * size.x, 0.5 * (lo.y + hi.y), lo.z);
  if (kind == ModelKind::kCabin) {
    origin = glm::dvec3(0.0);  // a cabin is drawn in the vehicle frame as it was made
  } else if (!wheels.empty()) {
    // The rear axle: the wheels behind the middle (a tandem's two: between them), or the rearmost.
    double sum = 0.0, rearmost = 1e30;
    int n = 0;
    for (const auto& w : wheels) {
      rearmost = std::min(rearmost, w.first.x);
      if (w.first.x < 0.5 * (lo.x + hi.x)) sum += w.first.x, ++n;
    }
    origin.x = n > 0 ? sum / n : rearmost;
  }
  if (kind == ModelKind::kVehicle) {
    if (size.x < 0.5 || size.x > 30.0 || size.y < 0.2 || size.y > 5.0 || size.z < 0.3 ||
        size.z > 6.0) {
      std::ostringstream s;
      s.precision(3);
      s << "the model measures " << size.x << " x " << size.y << " x " << size.z
        << " m (length, width, height): not a road vehicle in metres";
      throw ModelError(s.str());
    }
  }
  const glm::vec3 shift(-origin);
  for (render::MeshVertex& v : g.vertices) out.mesh.add_vertex(v.position + shift, v.normal, v.uv);
  if (!g.textures.empty()) {
    out.mesh.texcoords = std::move(g.texcoords);
    out.textures = std::move(g.textures);
  }
  std::uint32_t at = 0;
  auto append = [&](const std::vector<std::uint32_t>& indices) {
    out.mesh.indices.insert(out.mesh.indices.end(), indices.begin(), indices.end());
    at += static_cast<std::uint32_t>(indices.size());
  };
  if (const auto fixed = g.parts.find(-1); fixed != g.parts.end()) append(fixed->second);
  out.fixed_index_count = at;
  std::size_t w = 0;
  for (const auto& [wheel, indices] : g.parts) {
    if (wheel < 0 || indices.empty()) continue;
    Wheel entry;
    entry.centre = glm::vec3(wheels[w].first) + shift;
    entry.radius_m = static_cast<float>(std::max(wheels[w].second, 0.01));
    entry.first_index = at;
    entry.index_count = static_cast<std::uint32_t>(indices.size());
    append(indices);
    out.wheels.push_back(entry);
    ++w;
  }
  if (kind == ModelKind::kCabin && !g.windshield.empty()) {
    for (glm::dvec3& p : g.windshield) p += glm::dvec3(shift);
    out.windshield = outline(g.windshield);
  }
  return out;
}

}  // namespace

VehicleModel read_gltf(std::string_view bytes, ModelKind kind, const ModelLimits& limits,
                       const std::filesystem::path& beside) {
  if (bytes.size() > limits.max_bytes)
    throw ModelError("the model is " + std::to_string(bytes.size()) + " bytes, over the limit of " +
                     std::to_string(limits.max_bytes));
  const bool binary = bytes.size() >= 4 && bytes.substr(0, 4) == "glTF";
  check_json_depth(binary ? glb_json(bytes) : bytes, limits.max_depth);
  Files files{beside, limits.max_bytes - bytes.size()};
  tinygltf::TinyGLTF loader;
  loader.SetFsCallbacks({&file_exists, &expand_path, &read_file, &write_file, &files});
  loader.SetImageLoader(&keep_image, nullptr);
  tinygltf::Model m;
  std::string err, warn;
  const std::string base = beside.empty() ? std::string() : beside.string();
  bool ok = false;
  try {  // (the parser's own exceptions, and memory that cannot be had, are a refusal too)
    ok = binary ? loader.LoadBinaryFromMemory(&m, &err, &warn,
                                              reinterpret_cast<const unsigned char*>(bytes.data()),
                                              static_cast<unsigned>(bytes.size()), base)
                : loader.LoadASCIIFromString(&m, &err, &warn, bytes.data(),
                                             static_cast<unsigned>(bytes.size()), base);
  } catch (const std::exception& e) {
    err = e.what();
  }
  if (!ok) {
    while (!err.empty() && (err.back() == '\n' || err.back() == ' ')) err.pop_back();
    if (err.size() > 300) err = err.substr(0, 300) + "...";
    throw ModelError("not a glTF 2.0 model: " + (err.empty() ? std::string("unreadable") : err));
  }
  try {
    return assemble(Reader(m, kind, limits).gather(), kind);
  } catch (const std::bad_alloc&) {
    throw ModelError("the model is too large to hold");
  }
}

VehicleModel read_gltf_file(const std::filesystem::path& path, ModelKind kind,
                            const ModelLimits& limits) {
  std::error_code ec;
  const auto size = std::filesystem::file_size(path, ec);
  if (ec) throw ModelError("no model file " + path.filename().string());
  if (size > limits.max_bytes)
    throw ModelError("the model is " + std::to_string(size) + " bytes, over the limit of " +
                     std::to_string(limits.max_bytes));
  std::ifstream in(path, std::ios::binary);
  std::string bytes(size, '\0');
  if (!in.read(bytes.data(), static_cast<std::streamsize>(size)))
    throw ModelError("the model file " + path.filename().string() + " is unreadable");
  return read_gltf(bytes, kind, limits, path.parent_path());
}

// --- writing ------------------------------------------------------------------------------

namespace {

const char* material_name(float id) {
  switch (static_cast<int>(id + 0.5f)) {
    case 0:
      return "paint";
    case 1:
      return "glass";
    case 2:
      return "tyre";
    case 3:
      return "tail_lamp";
    case 5:
      return "headlamp";
    case 6:
      return "indicator_left";
    case 7:
      return "indicator_right";
    default:
      return "trim";
  }
}

struct Writer {
  tinygltf::Model g;
  std::vector<unsigned char>& bin;
  std::map<std::pair<float, float>, int> materials;

  explicit Writer(std::vector<unsigned char>& b) : bin(b) {}

  int material(float id, float colour) {
    const auto key = std::make_pair(id, colour);
    if (const auto it = materials.find(key); it != materials.end()) return it->second;
    tinygltf::Material m;
    m.name = material_name(id);
    const auto c = unpack_trim_colour(colour);
    m.pbrMetallicRoughness.baseColorFactor = {c[0], c[1], c[2], 1.0};
    m.pbrMetallicRoughness.metallicFactor = 0.0;
    m.pbrMetallicRoughness.roughnessFactor = id == material::kGlass ? 0.05 : 0.5;
    if (colour > 0.0f) m.name = "trim_" + std::to_string(g.materials.size());
    g.materials.push_back(m);
    return materials[key] = static_cast<int>(g.materials.size() - 1);
  }

  int view(const void* data, std::size_t bytes, int target) {
    while (bin.size() % 4 != 0) bin.push_back(0);
    tinygltf::BufferView v;
    v.buffer = 0;
    v.byteOffset = bin.size();
    v.byteLength = bytes;
    v.target = target;
    const auto* p = static_cast<const unsigned char*>(data);
    bin.insert(bin.end(), p, p + bytes);
    g.bufferViews.push_back(v);
    return static_cast<int>(g.bufferViews.size() - 1);
  }

  int accessor(int view_index, int component, int type, std::size_t count,
               std::vector<double> min = {}, std::vector<double> max = {}) {
    tinygltf::Accessor a;
    a.bufferView = view_index;
    a.componentType = component;
    a.type = type;
    a.count = count;
    a.minValues = std::move(min);
    a.maxValues = std::move(max);
    g.accessors.push_back(a);
    return static_cast<int>(g.accessors.size() - 1);
  }

  // A mesh of the model's triangles [first, first + count), a primitive per material.
  int mesh(const VehicleModel& model, std::uint32_t first, std::uint32_t count,
           const std::string& name) {
    std::map<std::pair<float, float>, std::vector<std::uint32_t>> by_material;
    for (std::uint32_t i = first; i < first + count; i += 3) {
      const glm::vec2 uv = model.mesh.vertices[model.mesh.indices[i]].uv;
      auto& list = by_material[{uv.x, uv.y}];
      for (int k = 0; k < 3; ++k) list.push_back(model.mesh.indices[i + k]);
    }
    tinygltf::Mesh mesh;
    mesh.name = name;
    for (const auto& [key, indices] : by_material) {
      // The primitive's own vertices, renumbered.
      std::map<std::uint32_t, std::uint32_t> renumber;
      std::vector<float> pos, nor;
      std::vector<std::uint32_t> idx;
      std::vector<double> lo(3, 1e30), hi(3, -1e30);
      for (std::uint32_t i : indices) {
        auto [it, added] = renumber.try_emplace(i, static_cast<std::uint32_t>(renumber.size()));
        if (added) {
          const render::MeshVertex& v = model.mesh.vertices[i];
          const glm::dvec3 p = to_gltf(glm::dvec3(v.position)), n = to_gltf(glm::dvec3(v.normal));
          for (int k = 0; k < 3; ++k) {
            pos.push_back(static_cast<float>(p[k]));
            nor.push_back(static_cast<float>(n[k]));
            lo[k] = std::min(lo[k], static_cast<double>(static_cast<float>(p[k])));
            hi[k] = std::max(hi[k], static_cast<double>(static_cast<float>(p[k])));
          }
        }
        idx.push_back(it->second);
      }
      tinygltf::Primitive prim;
      prim.mode = TINYGLTF_MODE_TRIANGLES;
      prim.material = material(key.first, key.second);
      prim.attributes["POSITION"] =
          accessor(view(pos.data(), pos.size() * 4, TINYGLTF_TARGET_ARRAY_BUFFER),
                   TINYGLTF_COMPONENT_TYPE_FLOAT, TINYGLTF_TYPE_VEC3, pos.size() / 3, lo, hi);
      prim.attributes["NORMAL"] =
          accessor(view(nor.data(), nor.size() * 4, TINYGLTF_TARGET_ARRAY_BUFFER),
                   TINYGLTF_COMPONENT_TYPE_FLOAT, TINYGLTF_TYPE_VEC3, nor.size() / 3);
      prim.indices =
          accessor(view(idx.data(), idx.size() * 4, TINYGLTF_TARGET_ELEMENT_ARRAY_BUFFER),
                   TINYGLTF_COMPONENT_TYPE_UNSIGNED_INT, TINYGLTF_TYPE_SCALAR, idx.size());
      mesh.primitives.push_back(prim);
    }
    g.meshes.push_back(mesh);
    return static_cast<int>(g.meshes.size() - 1);
  }
};

}  // namespace

std::string write_glb(const VehicleModel& model) {
  std::vector<unsigned char> bin;
  Writer w(bin);
  tinygltf::Scene scene;
  auto add_node = [&](const std::string& name, int mesh) {
    tinygltf::Node n;
    n.name = name;
    n.mesh = mesh;
    w.g.nodes.push_back(n);
    scene.nodes.push_back(static_cast<int>(w.g.nodes.size() - 1));
  };
  if (model.fixed_index_count > 0)
    add_node("body", w.mesh(model, 0, model.fixed_index_count, "body"));
  for (std::size_t i = 0; i < model.wheels.size(); ++i) {
    const std::string name = "wheel_" + std::to_string(i);
    add_node(name, w.mesh(model, model.wheels[i].first_index, model.wheels[i].index_count, name));
  }
  if (model.windshield) {  // a cabin's: where the simulated glass lies, as the reader finds it
    const sim::GlassConfig g = glass_of(*model.windshield);
    const double inset = g.inset_mm(g.height_mm);
    VehicleModel quad;
    const glm::vec3 n(g.normal());
    const glm::vec2 uv(material::kGlass, 0.0f);
    for (const glm::dvec2 p :
         {glm::dvec2(0.0, 0.0), glm::dvec2(g.bottom_width_mm, 0.0),
          glm::dvec2(g.bottom_width_mm - inset, g.height_mm), glm::dvec2(inset, g.height_mm)})
      quad.mesh.add_vertex(glm::vec3(g.to_vehicle(p)), n, uv);
    quad.mesh.add_quad(0, 1, 2, 3);
    const int mesh = w.mesh(quad, 0, 6, "windshield");
    tinygltf::Material glass = w.g.materials[w.g.meshes[mesh].primitives[0].material];
    glass.name = "windshield";
    w.g.materials.push_back(glass);
    w.g.meshes[mesh].primitives[0].material = static_cast<int>(w.g.materials.size() - 1);
    add_node("windshield", mesh);
  }
  tinygltf::Buffer buffer;
  buffer.data = std::move(bin);
  w.g.buffers.push_back(std::move(buffer));
  w.g.scenes.push_back(scene);
  w.g.defaultScene = 0;
  w.g.asset.version = "2.0";
  w.g.asset.generator = "downpour";
  std::ostringstream out;
  tinygltf::TinyGLTF saver;
  if (!saver.WriteGltfSceneToStream(&w.g, out, false, true))
    throw ModelError("the model could not be written");
  return out.str();
}

}  // namespace downpour::model
