#include "io/gltf_writer.hpp"

#include <algorithm>
#include <cmath>
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

std::string json_of(const std::vector<Block>& blocks, const std::string& attributes, std::uint64_t bin_bytes) {
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
         "\"nodes\":[{\"mesh\":0}],\"meshes\":[{\"primitives\":[{\"attributes\":{" +
         attributes + "},\"indices\":" + std::to_string(blocks.size() - 1) +
         ",\"mode\":4}]}],\"buffers\":[{\"byteLength\":" + std::to_string(bin_bytes) + "}],\"bufferViews\":[" + views +
         "],\"accessors\":[" + accessors + "]}";
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
  std::vector<Block> blocks;
  std::string attributes;
  std::uint64_t bin = 0;
  auto add = [&](Block b, const std::string& name) {
    b.offset = bin;
    bin += b.bytes;
    if (!name.empty())
      attributes += std::string(attributes.empty() ? "" : ",") + "\"" + name + "\":" + std::to_string(blocks.size());
    blocks.push_back(b);
  };
  if (mesh) {
    // The bounds of the positions as written (floats), which POSITION must give.
    float lo[3], hi[3];
    for (int k = 0; k < 3; ++k) lo[k] = std::numeric_limits<float>::infinity(), hi[k] = -lo[k];
    for (std::size_t i = 0; i < m.vertex_count; ++i)
      for (int k = 0; k < 3; ++k) {
        const float v = float(m.positions[3 * i + std::size_t(k)]);
        lo[k] = std::min(lo[k], v);
        hi[k] = std::max(hi[k], v);
      }
    Block position{"VEC3", kFloat, kArrayBuffer, m.vertex_count, 12 * std::uint64_t(m.vertex_count), 0, ""};
    position.bounds = ",\"min\":[" + float_text(lo[0]) + "," + float_text(lo[1]) + "," + float_text(lo[2]) +
                      "],\"max\":[" + float_text(hi[0]) + "," + float_text(hi[1]) + "," + float_text(hi[2]) + "]";
    add(position, "POSITION");
    if (normals)
      add({"VEC3", kFloat, kArrayBuffer, m.vertex_count, 12 * std::uint64_t(m.vertex_count), 0, ""}, "NORMAL");
    if (texture)
      add({"VEC2", kFloat, kArrayBuffer, m.vertex_count, 8 * std::uint64_t(m.vertex_count), 0, ""}, "TEXCOORD_0");
    if (colours)
      add({colour_width == 4 ? "VEC4" : "VEC3", kFloat, kArrayBuffer, m.vertex_count,
           4 * colour_width * std::uint64_t(m.vertex_count), 0, ""},
          "COLOR_0");
    add({"SCALAR", kUnsignedInt, kElementArrayBuffer, 3 * std::uint64_t(m.triangle_count),
         12 * std::uint64_t(m.triangle_count), 0, ""},
        "");
  }
  std::string json = mesh ? json_of(blocks, attributes, bin)
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
  write_rows(sink, m.vertex_count, 3, [&](std::size_t i, float* out) {
    for (std::size_t k = 0; k < 3; ++k) out[k] = float(m.positions[3 * i + k]);
  });
  const auto value = [&](std::size_t i, int k) { return m.attributes[i * m.attribute_width + std::size_t(k)]; };
  if (normals)
    write_rows(sink, m.vertex_count, 3, [&](std::size_t i, float* out) {
      const double n[3] = {value(i, m.normal[0]), value(i, m.normal[1]), value(i, m.normal[2])};
      const double l = std::sqrt(n[0] * n[0] + n[1] * n[1] + n[2] * n[2]);
      for (int k = 0; k < 3; ++k) out[k] = l > 0 ? float(n[k] / l) : k == 2 ? 1.0f : 0.0f;  // NORMAL is unit
    });
  if (texture)
    write_rows(sink, m.vertex_count, 2, [&](std::size_t i, float* out) {
      out[0] = float(value(i, m.uv[0]));
      out[1] = float(1.0 - value(i, m.uv[1]));
    });
  if (colours)
    write_rows(sink, m.vertex_count, colour_width, [&](std::size_t i, float* out) {
      for (std::size_t k = 0; k < colour_width; ++k)
        out[k] = float(std::clamp(value(i, m.colour[k]) / m.colour_scale[k], 0.0, 1.0));
    });
  sink.write(m.triangles, 12 * m.triangle_count);
}

}  // namespace oocsimp
