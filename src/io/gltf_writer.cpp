#include "io/gltf_writer.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <limits>
#include <string>
#include <vector>

namespace oocsimp {

namespace {

// glTF 2.0 §3.6.2.2 (accessor component types), §3.6.1.1 (buffer view targets) and
// §4.4.3 (chunk types); the hosts are little-endian, as the format is.
constexpr std::uint32_t kFloat = 5126, kUnsignedInt = 5125;
constexpr std::uint32_t kArrayBuffer = 34962, kElementArrayBuffer = 34963;
constexpr std::uint32_t kMagic = 0x46546C67, kJsonChunk = 0x4E4F534A, kBinChunk = 0x004E4942;

// The shortest text of a float that reads back as it.
std::string float_text(float v) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%.9g", double(v));
  return buf;
}

// One accessor of the BIN chunk and its buffer view.
struct Block {
  std::string type;  // "VEC3", "VEC4", "SCALAR"
  std::uint32_t component = kFloat, target = kArrayBuffer;
  std::uint64_t count = 0, bytes = 0, offset = 0;
  std::string bounds;  // ,"min":[...],"max":[...] for POSITION
};

// The JSON string of `text`: quotes, backslashes and control bytes escaped.
std::string json_string(const std::string& text) {
  std::string out = "\"";
  for (const char c : text) {
    if (c == '"' || c == '\\') {
      out += '\\';
      out += c;
    } else if (static_cast<unsigned char>(c) < 0x20) {
      char escaped[8];
      std::snprintf(escaped, sizeof escaped, "\\u%04x", unsigned(static_cast<unsigned char>(c)));
      out += escaped;
    } else {
      out += c;
    }
  }
  return out + "\"";
}

// `primitives`: one "{...}" per primitive, each naming its indices' accessor;
// `materials` and `extras` the root's members of those names, or empty.
std::string json_of(const std::vector<Block>& blocks, const std::string& primitives, const std::string& materials,
                    const std::string& extras, std::uint64_t bin_bytes) {
  std::string views, accessors;
  for (std::size_t i = 0; i < blocks.size(); ++i) {
    const Block& b = blocks[i];
    views += std::string(i ? "," : "") + "{\"buffer\":0,\"byteOffset\":" + std::to_string(b.offset) +
             ",\"byteLength\":" + std::to_string(b.bytes) + ",\"target\":" + std::to_string(b.target) + "}";
    accessors += std::string(i ? "," : "") + "{\"bufferView\":" + std::to_string(i) +
                 ",\"componentType\":" + std::to_string(b.component) + ",\"count\":" + std::to_string(b.count) +
                 ",\"type\":\"" + b.type + "\"" + b.bounds + "}";
  }
  return "{\"asset\":{\"version\":\"2.0\",\"generator\":\"oocsimp\"},\"scene\":0,\"scenes\":[{\"nodes\":[0]}],"
         "\"nodes\":[{\"mesh\":0}],\"meshes\":[{\"primitives\":[" +
         primitives + "]}]," + (materials.empty() ? "" : "\"materials\":[" + materials + "],") +
         "\"buffers\":[{\"byteLength\":" + std::to_string(bin_bytes) + "}],\"bufferViews\":[" + views +
         "],\"accessors\":[" + accessors + "]" + (extras.empty() ? "" : ",\"extras\":" + extras) + "}";
}

void put_u32(ByteSink& sink, std::uint32_t v) { sink.write(&v, 4); }

// Floats of the vertices, a row of `width` at a time, through a small buffer.
template <class Row>
void write_rows(ByteSink& sink, std::size_t vertices, std::size_t width, Row&& row) {
  std::vector<float> buffer;
  buffer.reserve(4096 * width);
  for (std::size_t i = 0; i < vertices; ++i) {
    const std::size_t at = buffer.size();
    buffer.resize(at + width);
    row(i, &buffer[at]);
    if (buffer.size() >= 4096 * width) {
      sink.write(buffer.data(), buffer.size() * sizeof(float));
      buffer.clear();
    }
  }
  sink.write(buffer.data(), buffer.size() * sizeof(float));
}

}  // namespace

void write_glb(ByteSink& sink, const GlbArrays& m) {
  const bool mesh = m.vertex_count > 0 && m.triangle_count > 0;
  const bool normals = m.normal[0] >= 0 && m.normal[1] >= 0 && m.normal[2] >= 0;
  const bool colours = m.colour[0] >= 0 && m.colour[1] >= 0 && m.colour[2] >= 0;
  const std::size_t colour_width = colours && m.colour[3] >= 0 ? 4 : 3;
  const bool texture = m.uv[0] >= 0 && m.uv[1] >= 0;
  // The triangles of each material, then those of none: one primitive each (one for
  // all of them without materials).
  const std::size_t groups = m.face_materials ? m.material_names.size() + 1 : 1;
  const auto group_of = [&](std::size_t t) -> std::size_t {
    if (!m.face_materials) return 0;
    const std::uint32_t k = m.face_materials[t];
    return k < m.material_names.size() ? k : groups - 1;
  };
  std::vector<std::uint64_t> group_triangles(groups, 0);
  if (mesh)
    for (std::size_t t = 0; t < m.triangle_count; ++t) ++group_triangles[group_of(t)];
  // With materials each primitive has vertices of its own, those its triangles use in
  // the vertices' order (a reader that copies each primitive's vertices then copies
  // no others); without, the one primitive has them all.
  std::vector<std::vector<std::uint32_t>> group_vertices(groups);
  if (mesh && m.face_materials) {
    std::vector<std::uint32_t> seen(m.vertex_count, 0);  // g + 1 once group g has the vertex
    for (std::size_t g = 0; g < groups; ++g) {
      if (group_triangles[g] == 0) continue;
      std::vector<std::uint32_t>& used = group_vertices[g];
      for (std::size_t t = 0; t < m.triangle_count; ++t) {
        if (group_of(t) != g) continue;
        for (std::size_t c = 0; c < 3; ++c) {
          const std::uint32_t v = m.triangles[3 * t + c];
          if (seen[v] != g + 1) seen[v] = std::uint32_t(g + 1), used.push_back(v);
        }
      }
      std::sort(used.begin(), used.end());
    }
  }
  const auto vertex_count = [&](std::size_t g) { return m.face_materials ? group_vertices[g].size() : m.vertex_count; };
  const auto vertex_at = [&](std::size_t g, std::size_t i) -> std::size_t {
    return m.face_materials ? group_vertices[g][i] : i;
  };

  std::vector<Block> blocks;
  std::uint64_t bin = 0;
  std::string attributes;  // of the primitive being described
  auto add = [&](Block b, const std::string& name) {
    b.offset = bin;
    bin += b.bytes;
    if (!name.empty())
      attributes += std::string(attributes.empty() ? "" : ",") + "\"" + name + "\":" + std::to_string(blocks.size());
    blocks.push_back(b);
  };
  std::string primitives, materials, extras;
  for (std::size_t g = 0; mesh && g < groups; ++g) {
    if (group_triangles[g] == 0) continue;
    const std::uint64_t n = vertex_count(g);
    // The bounds of the positions as written (floats), which POSITION must give.
    float lo[3], hi[3];
    for (int k = 0; k < 3; ++k) lo[k] = std::numeric_limits<float>::infinity(), hi[k] = -lo[k];
    for (std::size_t i = 0; i < n; ++i)
      for (int k = 0; k < 3; ++k) {
        const float v = float(m.positions[3 * vertex_at(g, i) + std::size_t(k)]);
        lo[k] = std::min(lo[k], v);
        hi[k] = std::max(hi[k], v);
      }
    attributes.clear();
    Block position{"VEC3", kFloat, kArrayBuffer, n, 12 * n, 0, ""};
    position.bounds = ",\"min\":[" + float_text(lo[0]) + "," + float_text(lo[1]) + "," + float_text(lo[2]) +
                      "],\"max\":[" + float_text(hi[0]) + "," + float_text(hi[1]) + "," + float_text(hi[2]) + "]";
    add(position, "POSITION");
    if (normals) add({"VEC3", kFloat, kArrayBuffer, n, 12 * n, 0, ""}, "NORMAL");
    if (texture) add({"VEC2", kFloat, kArrayBuffer, n, 8 * n, 0, ""}, "TEXCOORD_0");
    if (colours)
      add({colour_width == 4 ? "VEC4" : "VEC3", kFloat, kArrayBuffer, n, 4 * colour_width * n, 0, ""}, "COLOR_0");
    primitives += std::string(primitives.empty() ? "" : ",") + "{\"attributes\":{" + attributes +
                  "},\"indices\":" + std::to_string(blocks.size()) +
                  (m.face_materials && g + 1 < groups ? ",\"material\":" + std::to_string(g) : std::string()) +
                  ",\"mode\":4}";
    add({"SCALAR", kUnsignedInt, kElementArrayBuffer, 3 * group_triangles[g], 12 * group_triangles[g], 0, ""}, "");
  }
  if (mesh && m.face_materials)
    for (const std::string& name : m.material_names)
      materials += std::string(materials.empty() ? "" : ",") + "{\"name\":" + json_string(name) + "}";
  if (mesh && !m.material_libraries.empty()) {
    for (const std::string& library : m.material_libraries)
      extras += std::string(extras.empty() ? "{\"mtllib\":[" : ",") + json_string(library);
    extras += "]}";
  }
  std::string json = mesh ? json_of(blocks, primitives, materials, extras, bin)
                          : std::string(
                                "{\"asset\":{\"version\":\"2.0\",\"generator\":\"oocsimp\"},\"scene\":0,"
                                "\"scenes\":[{\"nodes\":[]}]}");
  json.resize((json.size() + 3) / 4 * 4, ' ');  // §4.4.3.1: padded with spaces
  const std::uint64_t total = 12 + 8 + json.size() + (mesh ? 8 + bin : 0);
  put_u32(sink, kMagic);
  put_u32(sink, 2);
  put_u32(sink, std::uint32_t(total));
  put_u32(sink, std::uint32_t(json.size()));
  put_u32(sink, kJsonChunk);
  sink.write(json);
  if (!mesh) return;
  put_u32(sink, std::uint32_t(bin));
  put_u32(sink, kBinChunk);
  const auto value = [&](std::size_t i, int k) { return m.attributes[i * m.attribute_width + std::size_t(k)]; };
  std::vector<std::uint32_t> local;  // a vertex's index within its group's primitive
  if (m.face_materials) local.resize(m.vertex_count);
  std::vector<std::uint32_t> buffer;
  for (std::size_t g = 0; g < groups; ++g) {
    if (group_triangles[g] == 0) continue;
    const std::size_t n = vertex_count(g);
    write_rows(sink, n, 3, [&](std::size_t i, float* out) {
      const std::size_t v = vertex_at(g, i);
      for (std::size_t k = 0; k < 3; ++k) out[k] = float(m.positions[3 * v + k]);
    });
    if (normals)
      write_rows(sink, n, 3, [&](std::size_t i, float* out) {
        const std::size_t v = vertex_at(g, i);
        const double d[3] = {value(v, m.normal[0]), value(v, m.normal[1]), value(v, m.normal[2])};
        const double l = std::sqrt(d[0] * d[0] + d[1] * d[1] + d[2] * d[2]);
        for (int k = 0; k < 3; ++k) out[k] = l > 0 ? float(d[k] / l) : k == 2 ? 1.0f : 0.0f;  // NORMAL is unit
      });
    if (texture)
      write_rows(sink, n, 2, [&](std::size_t i, float* out) {
        const std::size_t v = vertex_at(g, i);
        out[0] = float(value(v, m.uv[0]));
        out[1] = float(1.0 - value(v, m.uv[1]));
      });
    if (colours)
      write_rows(sink, n, colour_width, [&](std::size_t i, float* out) {
        const std::size_t v = vertex_at(g, i);
        for (std::size_t k = 0; k < colour_width; ++k)
          out[k] = float(std::clamp(value(v, m.colour[k]) / m.colour_scale[k], 0.0, 1.0));
      });
    if (!m.face_materials) {
      sink.write(m.triangles, 12 * m.triangle_count);
      continue;
    }
    for (std::size_t i = 0; i < n; ++i) local[group_vertices[g][i]] = std::uint32_t(i);
    buffer.reserve(3 * 4096);
    for (std::size_t t = 0; t < m.triangle_count; ++t) {
      if (group_of(t) != g) continue;
      for (std::size_t c = 0; c < 3; ++c) buffer.push_back(local[m.triangles[3 * t + c]]);
      if (buffer.size() >= 3 * 4096) {
        sink.write(buffer.data(), 4 * buffer.size());
        buffer.clear();
      }
    }
    sink.write(buffer.data(), 4 * buffer.size());
    buffer.clear();
  }
}

}  // namespace oocsimp
