// Binary glTF 2.0 reader (.glb; Khronos glTF 2.0 specification §4.4): the triangle
// primitives of the default scene's nodes, each placed by its node's world transform
// (§3.5.3), concatenated into one mesh: POSITION, and NORMAL, TEXCOORD_0 and COLOR_0
// as the vertex attributes nx, ny, nz, u, v, and red, green, blue (alpha). A
// primitive's material is carried as OBJ's usemtl groups are (Materials in
// oocsimp/attributes.hpp): the material's name, and material_K on its vertices (each
// placed primitive has vertices of its own, so no vertex is split); the root's
// extras.mtllib, which the glb writer leaves there, is the material library.
//
// The JSON chunk is parsed whole (it describes, the data is elsewhere); the BIN chunk
// is mapped, the input itself when it is an uncompressed regular file, else a copy in
// a temporary file, so the arrays never enter the heap. A buffer given as a base64
// data URI in the JSON (as Open3D writes them) is decoded into a temporary file and
// mapped too. Positions are converted once (the transforms), and the triangle stream
// reads the index accessors in place.
//
// What the format allows but this reader refuses, each naming the file and the JSON
// element: buffers in other files (a uri that is not data), sparse accessors,
// quantized positions (KHR_mesh_quantization) and required extensions (Draco, meshopt
// compression). Points, lines, strips and fans are skipped with a note.
#include <nlohmann/json.hpp>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstring>
#include <memory>
#include <string>
#include <utility>
#include <vector>

#include "io/attribute_array.hpp"
#include "io/byte_sink.hpp"
#include "io/error_text.hpp"
#include "io/mapped_file.hpp"
#include "io/position_array.hpp"
#include "io/readers.hpp"
#include "io/temp_file.hpp"
#include "oocsimp/error.hpp"

namespace oocsimp {

namespace {

using Json = nlohmann::json;

// §4.4.2 and §4.4.3: the header and the chunk types.
constexpr std::uint32_t kMagic = 0x46546C67, kJsonChunk = 0x4E4F534A, kBinChunk = 0x004E4942;
// §3.6.2.2: accessor component types.
constexpr int kByte = 5120, kUnsignedByte = 5121, kShort = 5122, kUnsignedShort = 5123, kUnsignedInt = 5125,
              kFloat = 5126;
// A JSON chunk larger than this is refused: it only describes the data (a scene of
// thousands of nodes takes a few MB), and its parsed form takes several times its size.
constexpr std::uint32_t kMaxJson = 64u << 20;

std::uint32_t le32(const unsigned char* p) {
  std::uint32_t v;
  std::memcpy(&v, p, 4);
  return v;
}

// A buffer's bytes, mapped, with what keeps the mapping valid.
struct Buffer {
  std::unique_ptr<TempFile> copy;  // a data URI decoded, or the BIN chunk of compressed or streamed input
  std::unique_ptr<MappedFile> map;
  const unsigned char* data = nullptr;
  std::uint64_t size = 0;
};
using Buffers = std::vector<Buffer>;

// One accessor resolved against the BIN chunk: element i's component k is at
// data + i * stride + k * component_size.
struct View {
  const unsigned char* data = nullptr;
  std::uint64_t count = 0, stride = 0;
  int component = kFloat, width = 1;
  bool normalized = false;

  // Component k of element i as a double (normalized integers into [0, 1] or [-1, 1],
  // §3.11).
  double get(std::uint64_t i, int k) const {
    const unsigned char* p = data + i * stride;
    switch (component) {
      case kFloat: {
        float f;
        std::memcpy(&f, p + 4 * k, 4);
        return f;
      }
      case kUnsignedByte:
        return normalized ? p[k] / 255.0 : p[k];
      case kByte: {
        const double v = double(std::int8_t(p[k]));
        return normalized ? std::max(v / 127.0, -1.0) : v;
      }
      case kUnsignedShort: {
        std::uint16_t u;
        std::memcpy(&u, p + 2 * k, 2);
        return normalized ? u / 65535.0 : u;
      }
      case kShort: {
        std::int16_t s;
        std::memcpy(&s, p + 2 * k, 2);
        return normalized ? std::max(s / 32767.0, -1.0) : s;
      }
      default: {
        std::uint32_t u;
        std::memcpy(&u, p + 4 * k, 4);
        return u;
      }
    }
  }
  std::uint64_t index(std::uint64_t i) const {
    const unsigned char* p = data + i * stride;
    if (component == kUnsignedByte) return *p;
    if (component == kUnsignedShort) {
      std::uint16_t u;
      std::memcpy(&u, p, 2);
      return u;
    }
    std::uint32_t u;
    std::memcpy(&u, p, 4);
    return u;
  }
};

int component_size(int component) {
  switch (component) {
    case kByte:
    case kUnsignedByte:
      return 1;
    case kShort:
    case kUnsignedShort:
      return 2;
    case kUnsignedInt:
    case kFloat:
      return 4;
    default:
      return 0;
  }
}

int type_width(const std::string& type) {
  if (type == "SCALAR") return 1;
  if (type == "VEC2") return 2;
  if (type == "VEC3") return 3;
  if (type == "VEC4") return 4;
  return 0;
}

// A JSON value for a message: a number or a string as it is (cut to 40 bytes), else
// its type. Never the dump of a nested value, whose depth the file chooses.
std::string shown(const Json& v) {
  if (v.is_number() || v.is_boolean() || v.is_null()) return v.dump();
  if (v.is_string()) {
    const std::string& t = v.get_ref<const std::string&>();
    std::size_t cut = std::min<std::size_t>(t.size(), 40);
    while (cut > 0 && cut < t.size() && (static_cast<unsigned char>(t[cut]) & 0xC0) == 0x80) --cut;  // whole UTF-8
    return "\"" + t.substr(0, cut) + (cut < t.size() ? "...\"" : "\"");
  }
  return std::string("(") + v.type_name() + ")";
}

// More placed primitives than this is refused: each costs a few hundred bytes of
// description, and a tree of nodes that names one mesh many times could ask for
// millions.
constexpr std::size_t kMaxInstances = std::size_t(1) << 20;

using Matrix = std::array<double, 16>;  // column-major, as glTF writes it (§3.5.3)

Matrix identity() { return {1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1}; }

Matrix multiply(const Matrix& a, const Matrix& b) {
  Matrix c{};
  for (int col = 0; col < 4; ++col)
    for (int row = 0; row < 4; ++row) {
      double s = 0;
      for (int k = 0; k < 4; ++k) s += a[std::size_t(k * 4 + row)] * b[std::size_t(col * 4 + k)];
      c[std::size_t(col * 4 + row)] = s;
    }
  return c;
}

// A triangle primitive placed in the scene.
struct Instance {
  View positions, normals, texcoords, colours, indices;
  bool indexed = false;
  Matrix transform = identity();
  // The transform turns the surface inside out (a negative determinant): the corners'
  // order is reversed, as glTF 2.0 §3.7.4 asks, and the normals' turn is negated.
  bool mirrored = false;
  std::uint64_t first_vertex = 0;  // its vertices' offset in the whole mesh
  std::int64_t material = -1;      // its index into the JSON's materials, -1 for none
};

// Reads the JSON of a .glb and resolves what the mesh needs.
class GlbScene {
 public:
  GlbScene(const Json& json, const Buffers& buffers, const std::string& path)
      : json_(json), buffers_(buffers), path_(path) {}

  // The triangle primitives of the default scene (or of every scene's root nodes when
  // there is none, or of every mesh when there are no nodes), in node order.
  std::vector<Instance> instances(std::vector<std::string>* notes) {
    notes_ = notes;
    check_extensions();
    std::vector<Instance> out;
    const Json* nodes = member(json_, "nodes");
    if (!nodes) {
      const Json* meshes = member(json_, "meshes");
      for (std::size_t m = 0; meshes && m < array(*meshes, "meshes").size(); ++m) add_mesh(m, identity(), &out);
      return out;
    }
    std::vector<std::size_t> roots;
    const Json* scenes = member(json_, "scenes");
    if (scenes && !array(*scenes, "scenes").empty()) {
      const std::size_t scene = json_.contains("scene") ? index_of(json_["scene"], "scene", scenes->size()) : 0;
      const Json* listed = member((*scenes)[scene], "nodes");
      const std::string where = "scenes[" + std::to_string(scene) + "].nodes";
      for (std::size_t i = 0; listed && i < array(*listed, where).size(); ++i)
        roots.push_back(index_of((*listed)[i], where, nodes->size()));
    } else {
      // No scene: every node that is no other's child is a root.
      std::vector<char> child(array(*nodes, "nodes").size(), 0);
      for (std::size_t n = 0; n < nodes->size(); ++n)
        if (const Json* c = member((*nodes)[n], "children"))
          for (const Json& i : array(*c, "nodes[" + std::to_string(n) + "].children"))
            child[index_of(i, "nodes[" + std::to_string(n) + "].children", nodes->size())] = 1;
      for (std::size_t n = 0; n < nodes->size(); ++n)
        if (!child[n]) roots.push_back(n);
    }
    std::vector<char> visited(nodes->size(), 0);
    std::vector<Matrix> world(nodes->size());
    for (std::size_t r : roots) add_tree(r, &visited, &world, &out);
    return out;
  }

 private:
  [[noreturn]] void fail(const std::string& where, const std::string& what) const {
    throw InputError(path_ + ": " + where + ": " + what);
  }
  const Json* member(const Json& object, const char* key) const {
    return object.is_object() && object.contains(key) ? &object[key] : nullptr;
  }
  const Json& array(const Json& value, const std::string& where) const {
    if (!value.is_array()) fail(where, "not an array");
    return value;
  }
  std::size_t index_of(const Json& value, const std::string& where, std::size_t count) const {
    if (!value.is_number_unsigned() || value.get<std::uint64_t>() >= count)
      fail(where, "index " + shown(value) + " is not below " + std::to_string(count));
    return std::size_t(value.get<std::uint64_t>());
  }
  std::uint64_t number(const Json& object, const char* key, const std::string& where, std::uint64_t fallback) const {
    if (!object.contains(key)) return fallback;
    const Json& v = object[key];
    if (!v.is_number_unsigned()) fail(where + "." + key, "not a non-negative integer: " + shown(v));
    return v.get<std::uint64_t>();
  }
  const Json& element(const char* kind, std::size_t i) const {
    const Json* all = member(json_, kind);
    if (!all || !all->is_array() || i >= all->size())
      fail(std::string(kind) + "[" + std::to_string(i) + "]", "missing");
    return (*all)[i];
  }

  void check_extensions() const {
    if (const Json* required = member(json_, "extensionsRequired"))
      for (const Json& e : array(*required, "extensionsRequired"))
        fail("extensionsRequired", "the extension " + shown(e) + " is not supported (decode it first, e.g. gltfpack)");
  }

  // The tree under root `r` in depth-first order, children in their order, with an
  // explicit stack (a file's nesting must not reach the call stack). The nodes form
  // strict trees (§3.5.1): a node met twice, through two parents or a cycle, is refused.
  //
  // A node is marked when it is put on the stack, so the stack never holds more than
  // the nodes, and the world transforms wait in one array over them.
  void add_tree(std::size_t r, std::vector<char>* visited, std::vector<Matrix>* world, std::vector<Instance>* out) {
    const auto enter = [&](std::size_t n, const Matrix& parent, const std::string& where) {
      if ((*visited)[n])
        fail(where, "nodes[" + std::to_string(n) +
                        "] is listed twice, has two parents, or is its own ancestor (nodes must form trees)");
      (*visited)[n] = 1;
      (*world)[n] = parent;  // the parent's world transform, until the node is taken
    };
    std::vector<std::size_t> stack;
    enter(r, identity(), "scene");
    stack.push_back(r);
    while (!stack.empty()) {
      const std::size_t n = stack.back();
      stack.pop_back();
      const std::string where = "nodes[" + std::to_string(n) + "]";
      const Json& node = element("nodes", n);
      const Matrix placed = multiply((*world)[n], local_transform(node, where));
      if (node.contains("mesh")) add_mesh(index_of(node["mesh"], where + ".mesh", count_of("meshes")), placed, out);
      if (const Json* children = member(node, "children")) {
        const Json& list = array(*children, where + ".children");
        for (std::size_t i = list.size(); i-- > 0;) {  // reversed: the first child comes off the stack first
          const std::size_t c = index_of(list[i], where + ".children", count_of("nodes"));
          enter(c, placed, where + ".children");
          stack.push_back(c);
        }
      }
    }
  }

  std::size_t count_of(const char* kind) const {
    const Json* all = member(json_, kind);
    return all && all->is_array() ? all->size() : 0;
  }

  // §3.5.3: a matrix, or translation x rotation x scale.
  Matrix local_transform(const Json& node, const std::string& where) const {
    const auto numbers = [&](const char* key, std::size_t count) {
      std::vector<double> v;
      const Json& a = array(node[key], where + "." + key);
      if (a.size() != count) fail(where + "." + key, "expected " + std::to_string(count) + " numbers");
      for (const Json& x : a) {
        if (!x.is_number() || !std::isfinite(x.get<double>())) fail(where + "." + key, "not a finite number");
        v.push_back(x.get<double>());
      }
      return v;
    };
    if (node.contains("matrix")) {
      const std::vector<double> m = numbers("matrix", 16);
      Matrix out{};
      std::copy(m.begin(), m.end(), out.begin());
      return out;
    }
    Matrix m = identity();
    if (node.contains("scale")) {
      const std::vector<double> s = numbers("scale", 3);
      for (std::size_t k = 0; k < 3; ++k)
        for (std::size_t r = 0; r < 3; ++r) m[k * 4 + r] *= s[k];
    }
    if (node.contains("rotation")) {
      const std::vector<double> q = numbers("rotation", 4);  // x, y, z, w
      const double x = q[0], y = q[1], z = q[2], w = q[3];
      const Matrix r = {1 - 2 * (y * y + z * z),
                        2 * (x * y + z * w),
                        2 * (x * z - y * w),
                        0,
                        2 * (x * y - z * w),
                        1 - 2 * (x * x + z * z),
                        2 * (y * z + x * w),
                        0,
                        2 * (x * z + y * w),
                        2 * (y * z - x * w),
                        1 - 2 * (x * x + y * y),
                        0,
                        0,
                        0,
                        0,
                        1};
      m = multiply(r, m);
    }
    if (node.contains("translation")) {
      const std::vector<double> t = numbers("translation", 3);
      for (std::size_t k = 0; k < 3; ++k) m[12 + k] += t[k];
    }
    return m;
  }

  void add_mesh(std::size_t m, const Matrix& world, std::vector<Instance>* out) {
    const std::string where = "meshes[" + std::to_string(m) + "]";
    const Json& mesh = element("meshes", m);
    const Json* primitives = member(mesh, "primitives");
    if (!primitives) fail(where, "has no primitives");
    for (std::size_t p = 0; p < array(*primitives, where + ".primitives").size(); ++p) {
      const std::string at = where + ".primitives[" + std::to_string(p) + "]";
      const Json& primitive = (*primitives)[p];
      const std::uint64_t mode = number(primitive, "mode", at, 4);
      if (mode != 4) {
        notes_->push_back(path_ + ": " + at + ": mode " + std::to_string(mode) +
                          " (points, lines, strips or fans) is skipped: only triangles (mode 4) are read");
        continue;
      }
      const Json* attributes = member(primitive, "attributes");
      if (!attributes || !attributes->contains("POSITION")) fail(at, "has no POSITION attribute");
      Instance in;
      in.transform = world;
      const auto w = [&](int r, int c) { return world[std::size_t(c * 4 + r)]; };
      in.mirrored = w(0, 0) * (w(1, 1) * w(2, 2) - w(1, 2) * w(2, 1)) -
                        w(0, 1) * (w(1, 0) * w(2, 2) - w(1, 2) * w(2, 0)) +
                        w(0, 2) * (w(1, 0) * w(2, 1) - w(1, 1) * w(2, 0)) <
                    0;
      in.positions = accessor((*attributes)["POSITION"], at + ".attributes.POSITION", {kFloat}, {3});
      if (attributes->contains("NORMAL"))
        in.normals = accessor((*attributes)["NORMAL"], at + ".attributes.NORMAL", {kFloat}, {3});
      if (attributes->contains("TEXCOORD_0"))
        in.texcoords = accessor((*attributes)["TEXCOORD_0"], at + ".attributes.TEXCOORD_0",
                                {kFloat, kUnsignedByte, kUnsignedShort}, {2});
      if (attributes->contains("COLOR_0"))
        in.colours = accessor((*attributes)["COLOR_0"], at + ".attributes.COLOR_0",
                              {kFloat, kUnsignedByte, kUnsignedShort}, {3, 4});
      for (const View* v : {&in.normals, &in.texcoords, &in.colours})
        if (v->data && v->count != in.positions.count)
          fail(at, "an attribute has " + std::to_string(v->count) + " elements where POSITION has " +
                       std::to_string(in.positions.count));
      if (primitive.contains("indices")) {
        in.indexed = true;
        in.indices =
            accessor(primitive["indices"], at + ".indices", {kUnsignedByte, kUnsignedShort, kUnsignedInt}, {1});
        if (in.indices.count % 3 != 0)
          fail(at + ".indices", std::to_string(in.indices.count) + " indices are not whole triangles");
      } else if (in.positions.count % 3 != 0) {
        fail(at, std::to_string(in.positions.count) + " unindexed vertices are not whole triangles");
      }
      if (primitive.contains("material")) {
        const Json* materials = member(json_, "materials");
        in.material = std::int64_t(index_of(primitive["material"], at + ".material",
                                            materials && materials->is_array() ? materials->size() : 0));
      }
      if (out->size() == kMaxInstances)
        fail(at, "more than " + std::to_string(kMaxInstances) + " placed primitives (nodes naming meshes)");
      out->push_back(in);
    }
  }

  // Accessor `ref`, checked against its buffer view and the BIN chunk (§3.6.2.4:
  // byteOffset + (count - 1) * stride + element size within the view).
  View accessor(const Json& ref, const std::string& where, std::initializer_list<int> components,
                std::initializer_list<int> widths) const {
    const std::size_t a = index_of(ref, where, count_of("accessors"));
    const std::string at = "accessors[" + std::to_string(a) + "]";
    const Json& acc = element("accessors", a);
    if (acc.contains("sparse")) fail(at, "sparse accessors are not supported");
    View v;
    v.component = int(number(acc, "componentType", at, 0));
    v.width = acc.contains("type") && acc["type"].is_string() ? type_width(acc["type"].get<std::string>()) : 0;
    v.normalized = acc.contains("normalized") && acc["normalized"].is_boolean() && acc["normalized"].get<bool>();
    v.count = number(acc, "count", at, 0);
    if (std::find(components.begin(), components.end(), v.component) == components.end())
      fail(at, "componentType " + std::to_string(v.component) + " is not one " + where +
                   " may have here (KHR_mesh_quantization is not supported)");
    if (std::find(widths.begin(), widths.end(), v.width) == widths.end())
      fail(at,
           "type " + (acc.contains("type") ? shown(acc["type"]) : std::string("(none)")) + " does not fit " + where);
    if (!acc.contains("bufferView")) fail(at, "has no bufferView (all zeros is not supported)");
    const std::size_t b = index_of(acc["bufferView"], at + ".bufferView", count_of("bufferViews"));
    const std::string view_at = "bufferViews[" + std::to_string(b) + "]";
    const Json& view = element("bufferViews", b);
    if (!view.contains("buffer")) fail(view_at, "has no buffer");
    const Buffer& bin = buffers_[index_of(view["buffer"], view_at + ".buffer", buffers_.size())];
    const std::uint64_t view_offset = number(view, "byteOffset", view_at, 0),
                        view_length = number(view, "byteLength", view_at, 0);
    if (view_offset > bin.size || view_length > bin.size - view_offset)
      fail(view_at, "bytes " + std::to_string(view_offset) + " to " + std::to_string(view_offset + view_length) +
                        " are beyond its buffer's " + std::to_string(bin.size));
    const std::uint64_t element_size = std::uint64_t(component_size(v.component)) * std::uint64_t(v.width);
    v.stride = number(view, "byteStride", view_at, element_size);
    if (v.stride < element_size) fail(view_at, "byteStride " + std::to_string(v.stride) + " is below an element");
    const std::uint64_t offset = number(acc, "byteOffset", at, 0);
    if (v.count > 0) {
      // Compared by division: offset + (count - 1) * stride may wrap around 2^64.
      if (offset > view_length || element_size > view_length - offset ||
          (v.count - 1) > (view_length - offset - element_size) / v.stride)
        fail(at, std::to_string(v.count) + " elements from byte " + std::to_string(offset) + " do not fit " + view_at +
                     "'s " + std::to_string(view_length) + " bytes");
      v.data = bin.data + view_offset + offset;
    }
    return v;
  }

  const Json& json_;
  const Buffers& buffers_;
  std::string path_;
  std::vector<std::string>* notes_ = nullptr;
};

// The triangles of the instances, in order, each index checked against its
// primitive's vertex count.
class GlbTriangleStream : public TriangleStream {
 public:
  GlbTriangleStream(std::shared_ptr<const std::vector<Instance>> instances, std::shared_ptr<const Buffers> buffers,
                    std::string path)
      : instances_(std::move(instances)), buffers_(std::move(buffers)), path_(std::move(path)) {}

  std::size_t read(std::uint64_t* out, std::size_t max) override {
    std::size_t n = 0;
    while (n < max && at_ < instances_->size()) {
      const Instance& in = (*instances_)[at_];
      const std::uint64_t corners = in.indexed ? in.indices.count : in.positions.count;
      if (corner_ >= corners) {
        ++at_;
        corner_ = 0;
        continue;
      }
      for (int k = 0; k < 3; ++k) {
        const std::uint64_t i = in.indexed ? in.indices.index(corner_ + std::uint64_t(k)) : corner_ + std::uint64_t(k);
        if (i >= in.positions.count)
          throw InputError(path_ + ": index " + std::to_string(i) + " of triangle " +
                           std::to_string((corner_ + std::uint64_t(k)) / 3) + " of primitive " + std::to_string(at_) +
                           " is not below its " + std::to_string(in.positions.count) + " vertices");
        // Mirrored: corners 1 and 2 trade places.
        out[3 * n + std::size_t(in.mirrored && k > 0 ? 3 - k : k)] = in.first_vertex + i;
      }
      corner_ += 3;
      ++n;
    }
    return n;
  }
  std::uint64_t bytes_consumed() const override { return 0; }

 private:
  std::shared_ptr<const std::vector<Instance>> instances_;
  std::shared_ptr<const Buffers> buffers_;  // keeps the arrays mapped
  std::string path_;
  std::size_t at_ = 0;
  std::uint64_t corner_ = 0;
};

// The BIN chunk's bytes: the input mapped where it is a regular uncompressed file, else
// copied into a temporary file and mapped.
Buffer map_bin(ByteSource& src, std::uint64_t length, const std::string& temp_dir) {
  Buffer b;
  Buffer* bin = &b;
  bin->size = length;
  if (length == 0) return b;
  if (src.content_size_known()) {
    const std::uint64_t at = src.offset();
    if (at > src.file_size() || length > src.file_size() - at)
      throw InputError(at_byte(src.path(), src.file_size(),
                               "file ends inside the BIN chunk (" + std::to_string(length) + " bytes from byte " +
                                   std::to_string(at) + ")"));
    bin->map = std::make_unique<MappedFile>(src.input()->fd(), src.file_size(), src.path());
    bin->data = bin->map->data() + at;
    return b;
  }
  bin->copy = std::make_unique<TempFile>(temp_dir, "oocsimp-glb");
  {
    ByteSink sink(bin->copy->fd(), bin->copy->path(), false);
    std::vector<unsigned char> buffer(1 << 20);
    for (std::uint64_t left = length; left > 0;) {
      const std::size_t n = std::size_t(std::min<std::uint64_t>(left, buffer.size()));
      src.read_exact(buffer.data(), n, "the BIN chunk");
      sink.write(buffer.data(), n);
      left -= n;
    }
    sink.finish();
  }
  bin->copy->close();
  bin->map = std::make_unique<MappedFile>(bin->copy->path());
  bin->data = bin->map->data();
  return b;
}

// The value of a base64 digit (RFC 4648 §4), -1 for any other byte.
int base64_digit(unsigned char c) {
  if (c >= 'A' && c <= 'Z') return c - 'A';
  if (c >= 'a' && c <= 'z') return c - 'a' + 26;
  if (c >= '0' && c <= '9') return c - '0' + 52;
  if (c == '+') return 62;
  if (c == '/') return 63;
  return -1;
}

// A buffer from its data URI ("data:...;base64,..."), decoded into a temporary file;
// `what` names it for messages.
Buffer decode_data_uri(const std::string& uri, const std::string& temp_dir, const std::string& what) {
  const std::size_t comma = uri.find(',');
  if (uri.compare(0, 5, "data:") != 0)
    throw InputError(what + ": data in another file (" + uri.substr(0, 64) +
                     ") is not read: embed it in the .glb (e.g. gltfpack, or Blender's glb export)");
  if (comma == std::string::npos || comma < 7 || uri.compare(comma - 7, 7, ";base64") != 0)
    throw InputError(what + ": a data URI that is not base64");
  Buffer b;
  b.copy = std::make_unique<TempFile>(temp_dir, "oocsimp-glb");
  {
    ByteSink sink(b.copy->fd(), b.copy->path(), false);
    std::vector<unsigned char> out;
    out.reserve(1 << 16);
    std::uint32_t bits = 0;
    int held = 0;
    for (std::size_t i = comma + 1; i < uri.size(); ++i) {
      const unsigned char c = static_cast<unsigned char>(uri[i]);
      if (c == '=') break;
      const int d = base64_digit(c);
      if (d < 0) throw InputError(what + ": byte " + std::to_string(i) + " of its data URI is not base64");
      bits = bits << 6 | std::uint32_t(d);
      held += 6;
      if (held >= 8) {
        held -= 8;
        out.push_back(static_cast<unsigned char>(bits >> held));
        bits &= (1u << held) - 1;
      }
      if (out.size() == out.capacity()) {
        sink.write(out.data(), out.size());
        b.size += out.size();
        out.clear();
      }
    }
    sink.write(out.data(), out.size());
    b.size += out.size();
    sink.finish();
  }
  b.copy->close();
  if (b.size > 0) {
    b.map = std::make_unique<MappedFile>(b.copy->path());
    b.data = b.map->data();
  }
  return b;
}

// Every buffer of the JSON: the BIN chunk for the first when it has no uri, data URIs
// decoded; each at least as long as it says.
std::shared_ptr<Buffers> resolve_buffers(const Json& json, Buffer bin, const std::string& temp_dir,
                                         const std::string& path) {
  auto buffers = std::make_shared<Buffers>();
  if (!json.contains("buffers")) return buffers;
  const Json& list = json["buffers"];
  if (!list.is_array()) throw InputError(path + ": buffers: not an array");
  for (std::size_t i = 0; i < list.size(); ++i) {
    const std::string what = path + ": buffers[" + std::to_string(i) + "]";
    const Json& b = list[i];
    if (b.is_object() && b.contains("uri")) {
      if (!b["uri"].is_string()) throw InputError(what + ": uri is not a string");
      buffers->push_back(decode_data_uri(b["uri"].get<std::string>(), temp_dir, what));
    } else if (i == 0) {
      buffers->push_back(std::move(bin));
    } else {
      throw InputError(what + ": no uri, and only the first buffer is the BIN chunk");
    }
    const Json* length = b.is_object() && b.contains("byteLength") ? &b["byteLength"] : nullptr;
    if (!length || !length->is_number_unsigned() || length->get<std::uint64_t>() > buffers->back().size)
      throw InputError(what + ": byteLength " + (length ? shown(*length) : std::string("(none)")) +
                       " is not within its " + std::to_string(buffers->back().size) + " bytes");
  }
  return buffers;
}

}  // namespace

bool looks_like_glb(const unsigned char* head) { return head && le32(head) == kMagic; }

void open_glb(ByteSource& src, const OpenOptions& options, ProgressPhase& progress, MeshInput& out) {
  out.info.format = "glb";
  unsigned char header[12];
  src.read_exact(header, 12, "the glTF header");
  if (le32(header) != kMagic) throw InputError(at_byte(src.path(), 0, "not a binary glTF file (no \"glTF\" magic)"));
  if (le32(header + 4) != 2)
    throw InputError(at_byte(src.path(), 4, "glTF version " + std::to_string(le32(header + 4)) + ", where 2 is read"));
  unsigned char chunk[8];
  src.read_exact(chunk, 8, "the JSON chunk's header");
  const std::uint32_t json_length = le32(chunk);
  if (le32(chunk + 4) != kJsonChunk) throw InputError(at_byte(src.path(), 16, "the first chunk is not JSON"));
  if (json_length > kMaxJson)
    throw InputError(at_byte(
        src.path(), 12, "a JSON chunk of " + std::to_string(json_length) + " bytes (more than 64 MiB of description)"));
  std::string text(json_length, '\0');
  src.read_exact(text.data(), json_length, "the JSON chunk");
  Json json;
  try {
    json = Json::parse(text);
  } catch (const Json::parse_error& e) {
    throw InputError(at_byte(src.path(), 20 + e.byte - (e.byte > 0 ? 1 : 0), "malformed JSON chunk"));
  } catch (const Json::exception& e) {  // a number beyond double's range, ...
    throw InputError(at_byte(src.path(), 20, std::string("JSON chunk: ") + e.what()));
  }
  if (!json.is_object()) throw InputError(at_byte(src.path(), 20, "the JSON chunk is not an object"));
  std::string().swap(text);
  // The BIN chunk, when there is one (a file whose buffers are empty may have none).
  std::uint64_t bin_length = 0;
  if (const unsigned char* next = src.peek(8)) {
    if (le32(next + 4) == kBinChunk) {
      bin_length = le32(next);
      src.consume(8);
    }
  }
  std::shared_ptr<const Buffers> buffers =
      resolve_buffers(json, map_bin(src, bin_length, options.temp_dir), options.temp_dir, src.path());
  progress.set(src.raw_consumed());

  auto instances = std::make_shared<std::vector<Instance>>();
  try {
    *instances = GlbScene(json, *buffers, src.path()).instances(&out.info.not_carried);
  } catch (const Json::exception& e) {  // a value of an unexpected type the checks let through
    throw InputError(src.path() + ": JSON chunk: " + e.what());
  }
  // The primitives' materials by name, in the order of first use (two materials of one
  // name are one group, as two usemtl lines of one name are), and the library.
  std::vector<std::int64_t> group_of_material;  // the JSON's material index -> K, -1 when unused
  if (const Json* materials = json.contains("materials") ? &json["materials"] : nullptr;
      materials && materials->is_array())
    group_of_material.assign(materials->size(), -1);
  for (const Instance& in : *instances) {
    if (in.material < 0 || group_of_material[std::size_t(in.material)] >= 0) continue;
    const Json& material = json["materials"][std::size_t(in.material)];
    std::string name = "material" + std::to_string(in.material);  // one without a name
    if (material.is_object() && material.contains("name") && material["name"].is_string() &&
        !material["name"].get_ref<const std::string&>().empty())
      name = material["name"].get<std::string>();
    std::vector<std::string>& names = out.info.materials.names;
    const auto same = std::find(names.begin(), names.end(), name);
    group_of_material[std::size_t(in.material)] = same - names.begin();
    if (same == names.end()) names.push_back(name);
  }
  if (json.contains("extras") && json["extras"].is_object() && json["extras"].contains("mtllib")) {
    const Json& libraries = json["extras"]["mtllib"];
    if (libraries.is_string()) out.info.materials.libraries.push_back(libraries.get<std::string>());
    if (libraries.is_array())
      for (const Json& library : libraries)
        if (library.is_string()) out.info.materials.libraries.push_back(library.get<std::string>());
  }
  std::uint64_t vertices = 0, faces = 0;
  bool normals = false, texcoords = false, colours = false, alpha = false;
  for (Instance& in : *instances) {
    in.first_vertex = vertices;
    vertices += in.positions.count;
    faces += (in.indexed ? in.indices.count : in.positions.count) / 3;
    normals = normals || in.normals.data;
    texcoords = texcoords || in.texcoords.data;
    colours = colours || in.colours.data;
    alpha = alpha || (in.colours.data && in.colours.width == 4);
  }
  if (vertices > (std::uint64_t(1) << 32))
    throw InputError(src.path() + ": " + std::to_string(vertices) + " vertices, more than 2^32");

  // The attributes offered, and which are carried.
  std::vector<AttributeCandidate> offered;
  if (colours)
    for (const char* c : {"red", "green", "blue"}) offered.push_back({c, AttributeType::f32});
  if (alpha) offered.push_back({"alpha", AttributeType::f32});
  if (normals)
    for (const char* c : {"nx", "ny", "nz"}) offered.push_back({c, AttributeType::f32});
  if (texcoords)
    for (const char* c : {"u", "v"}) offered.push_back({c, AttributeType::f32});
  const std::size_t first_material = offered.size(), material_count = out.info.materials.names.size();
  std::size_t offered_materials = 0;
  if (material_count > kMostMaterials) {
    out.info.not_carried.push_back(src.path() + ": " + std::to_string(material_count) + " materials, more than the " +
                                   std::to_string(kMostMaterials) + " carried; the faces' materials are dropped");
  } else {
    for (std::size_t k = 0; k < material_count; ++k)
      offered.push_back({material_attribute_name(k), AttributeType::f32});
    offered_materials = material_count;
  }
  const std::vector<std::size_t> carried =
      carried_attributes(offered, options.attributes, src.path(), &out.info.not_carried);
  std::vector<VertexAttribute> attrs;
  for (std::size_t i : carried) attrs.push_back({offered[i].name, offered[i].type, 0, 0});

  PositionArrayBuilder positions(options.temp_dir, src.path());
  AttributeArrayBuilder attributes(options.temp_dir, src.path(), attrs);
  std::vector<double> all(offered.size()), record(carried.size());
  for (std::size_t p = 0; p < instances->size(); ++p) {
    const Instance& in = (*instances)[p];
    const Matrix& m = in.transform;
    // Normals turn with the inverse transpose of the transform's 3 x 3 part (its
    // cofactors, up to a scale that the unit length takes out).
    const auto at = [&](int r, int c) { return m[std::size_t(c * 4 + r)]; };
    const auto cofactor = [&](int r, int c) {
      const int r1 = (r + 1) % 3, r2 = (r + 2) % 3, c1 = (c + 1) % 3, c2 = (c + 2) % 3;
      return at(r1, c1) * at(r2, c2) - at(r1, c2) * at(r2, c1);
    };
    for (std::uint64_t i = 0; i < in.positions.count; ++i) {
      const double x = in.positions.get(i, 0), y = in.positions.get(i, 1), z = in.positions.get(i, 2);
      positions.add(at(0, 0) * x + at(0, 1) * y + at(0, 2) * z + at(0, 3),
                    at(1, 0) * x + at(1, 1) * y + at(1, 2) * z + at(1, 3),
                    at(2, 0) * x + at(2, 1) * y + at(2, 2) * z + at(2, 3),
                    [&] { return "vertex " + std::to_string(i) + " of primitive " + std::to_string(p); });
      if (attrs.empty()) continue;
      std::size_t k = 0;
      if (colours)
        for (int c = 0; c < 3; ++c) all[k++] = in.colours.data ? in.colours.get(i, c) : 1.0;
      if (alpha) all[k++] = in.colours.data && in.colours.width == 4 ? in.colours.get(i, 3) : 1.0;
      if (normals) {
        double n[3] = {0, 0, 0};
        if (in.normals.data)
          for (int r = 0; r < 3; ++r)
            for (int c = 0; c < 3; ++c) n[r] += cofactor(r, c) * in.normals.get(i, c);
        // The cofactors are det x the inverse transpose: a mirroring transform's
        // negative determinant is taken out with the length.
        const double l = std::sqrt(n[0] * n[0] + n[1] * n[1] + n[2] * n[2]) * (in.mirrored ? -1.0 : 1.0);
        for (double c : n) all[k++] = l != 0 ? c / l + 0.0 : 0.0;  // + 0: no -0 from the sign
      }
      if (texcoords) {
        // glTF's origin is the image's top left (§3.7.2.1); the other formats' the bottom left.
        all[k++] = in.texcoords.data ? in.texcoords.get(i, 0) : 0.0;
        all[k++] = in.texcoords.data ? 1.0 - in.texcoords.get(i, 1) : 0.0;
      }
      for (std::size_t g = 0; g < offered_materials; ++g)
        all[first_material + g] = in.material >= 0 && group_of_material[std::size_t(in.material)] == std::int64_t(g);
      for (std::size_t j = 0; j < carried.size(); ++j) record[j] = all[carried[j]];
      attributes.add(record.data());
    }
  }
  positions.finish(out);
  attributes.finish(out);
  out.info.vertex_count = vertices;
  out.info.face_count = faces;
  out.info.elements = {"primitives " + std::to_string(instances->size()), "vertices " + std::to_string(vertices),
                       "triangles " + std::to_string(faces)};
  const std::string path = src.path();
  reader_state(out).make_triangles = [instances, buffers, path]() -> std::unique_ptr<TriangleStream> {
    return std::make_unique<GlbTriangleStream>(instances, buffers, path);
  };
}

}  // namespace oocsimp
