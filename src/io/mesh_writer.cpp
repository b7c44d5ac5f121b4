#include "io/mesh_writer_output.hpp"

#include <charconv>
#include <cmath>
#include <cstring>

#include "common/vec3_math.hpp"
#include "io/attribute_array.hpp"
#include "io/byte_sink.hpp"
#include "io/gltf_writer.hpp"
#include "oocsimp/error.hpp"
#include "io/temp_file.hpp"

namespace oocsimp {

namespace {

// The shortest text that reads back as the same value: of the float for f32 (our
// reader keeps such text as float, see decimal_fits_float in io/text_scan.hpp), of the
// double for f64.
void append_coord(std::string& s, double v, ScalarType precision) {
  char buf[32];
  std::to_chars_result r = precision == ScalarType::f64 ? std::to_chars(buf, buf + sizeof buf, v)
                                                        : std::to_chars(buf, buf + sizeof buf, float(v));
  s.append(buf, r.ptr);
}

void append_uint(std::string& s, std::uint64_t v) {
  char buf[24];
  auto r = std::to_chars(buf, buf + sizeof buf, v);
  s.append(buf, r.ptr);
}

// Text written through the sink in pieces of about 64 KiB.
class TextOut {
 public:
  explicit TextOut(ByteSink& sink) : sink_(sink) {}
  std::string& text() { return text_; }
  void maybe_flush() {
    if (text_.size() > (1 << 16)) flush();
  }
  void flush() {
    sink_.write(text_);
    text_.clear();
  }

 private:
  ByteSink& sink_;
  std::string text_;
};

// What the writers read: the arrays of a SimplifiedMesh or an OutputMesh.
struct MeshArrays {
  const double* pos;  // 3 per vertex
  std::size_t vertex_count;
  const std::uint32_t* tri;  // 3 per triangle
  std::size_t triangle_count;
  ScalarType precision;
  const std::vector<VertexAttribute>* attribute_names;  // null or empty: positions only
  const double* attribute_values;                       // attribute_count() per vertex
  const ThickPrimitives* primitives;                    // null or empty: triangles only
  const Materials* materials;                           // null or empty: none
  std::size_t edges() const { return primitives ? primitives->edge_count() : 0; }
  std::size_t points() const { return primitives ? primitives->point_count() : 0; }
  std::size_t attribute_count() const { return attribute_names ? attribute_names->size() : 0; }
  double attribute(std::size_t i, std::size_t k) const { return attribute_values[attribute_count() * i + k]; }
  const VertexAttribute& attribute_info(std::size_t k) const { return (*attribute_names)[k]; }
  // " a b c" of vertex i's attributes, integers as integers.
  void append_attributes(std::string& s, std::size_t i) const {
    for (std::size_t k = 0; k < attribute_count(); ++k) {
      s += ' ';
      const double v = attribute(i, k);
      const AttributeType t = attribute_info(k).type;
      if (is_integer_type(t)) {
        char buf[24];
        auto r = std::to_chars(buf, buf + sizeof buf, std::int64_t(v));
        s.append(buf, r.ptr);
      } else {
        append_coord(s, v, t == AttributeType::f64 ? ScalarType::f64 : ScalarType::f32);
      }
    }
  }
  // The attribute named `name` (OBJ's colours "red", "green", "blue" and normals "nx",
  // "ny", "nz"), or -1.
  int colour_index(const char* name) const {
    for (std::size_t k = 0; k < attribute_count(); ++k)
      if (attribute_info(k).name == name) return int(k);
    return -1;
  }
  std::size_t vertices() const { return vertex_count; }
  std::size_t triangles() const { return triangle_count; }
  // "x y z" of vertex i.
  void append_vertex(std::string& s, std::size_t i) const {
    append_coord(s, pos[3 * i], precision);
    s += ' ';
    append_coord(s, pos[3 * i + 1], precision);
    s += ' ';
    append_coord(s, pos[3 * i + 2], precision);
  }
  // The indices of triangle t, each plus `base`, separated by blanks.
  void append_triangle(std::string& s, std::size_t t, std::uint64_t base) const {
    append_uint(s, tri[3 * t] + base);
    s += ' ';
    append_uint(s, tri[3 * t + 1] + base);
    s += ' ';
    append_uint(s, tri[3 * t + 2] + base);
  }
};

// The texture coordinates among `attributes`: the first pair of the spellings PLY
// files use (u v, s t, texture_u texture_v, ...), their positions in *u and *v; false
// when there is none.
bool texture_coordinate_pair(const std::vector<VertexAttribute>& attributes, int* u = nullptr, int* v = nullptr) {
  static const char* const kPairs[][2] = {{"u", "v"},
                                          {"s", "t"},
                                          {"texture_u", "texture_v"},
                                          {"texture_s", "texture_t"},
                                          {"texcoord_u", "texcoord_v"},
                                          {"tex_u", "tex_v"}};
  const auto find = [&](const char* name) {
    for (std::size_t k = 0; k < attributes.size(); ++k)
      if (attributes[k].name == name) return int(k);
    return -1;
  };
  for (const auto& pair : kPairs) {
    const int a = find(pair[0]), b = find(pair[1]);
    if (a < 0 || b < 0) continue;
    if (u) *u = a;
    if (v) *v = b;
    return true;
  }
  return false;
}

bool texture_pair(const MeshArrays& m, int* u, int* v) {
  return m.attribute_names && texture_coordinate_pair(*m.attribute_names, u, v);
}

// The divisor that takes a colour of type `t` into [0, 1]: 255 for uchar, 65535 for
// ushort, 1 for floating point (stored as [0, 1] already).
double colour_scale(AttributeType t) {
  switch (t) {
    case AttributeType::u8:
      return 255.0;
    case AttributeType::u16:
      return 65535.0;
    case AttributeType::i8:
      return 127.0;
    case AttributeType::i16:
      return 32767.0;
    default:
      return 1.0;
  }
}

// The material_K attributes of `m` that name one of its materials: for each, K and
// the attribute's column.
std::vector<std::pair<std::size_t, std::size_t>> material_columns(const MeshArrays& m) {
  std::vector<std::pair<std::size_t, std::size_t>> columns;
  if (!m.materials) return columns;
  for (std::size_t c = 0; c < m.attribute_count(); ++c) {
    const std::string& name = m.attribute_info(c).name;
    if (!is_material_attribute(name)) continue;
    const std::size_t k = std::size_t(std::stoull(name.substr(9)));
    if (k < m.materials->names.size()) columns.push_back({k, c});
  }
  return columns;
}

// The material of triangle t by the rule in Materials: the one of `columns` whose
// attribute its corners sum highest, the first on a tie, `current` (the material of
// the triangle before) when they carry none.
std::size_t face_material(const MeshArrays& m, const std::vector<std::pair<std::size_t, std::size_t>>& columns,
                          std::size_t t, std::size_t current) {
  double best = 0;
  std::size_t chosen = current;
  for (const auto& [k, column] : columns) {
    double sum = 0;
    for (int c = 0; c < 3; ++c) sum += m.attribute(m.tri[3 * t + std::size_t(c)], column);
    if (sum > best) best = sum, chosen = k;
  }
  return chosen;
}

void write_obj(ByteSink& sink, const MeshArrays& m) {
  TextOut out(sink);
  out.text() = "# oocsimp\n";
  // The material library, and per face the material its corners carry most of (the
  // rule in Materials), a usemtl line where it changes.
  const std::vector<std::pair<std::size_t, std::size_t>> materials = material_columns(m);
  if (m.materials)
    for (const std::string& library : m.materials->libraries) out.text() += "mtllib " + library + "\n";
  std::size_t current_material = ~std::size_t(0);
  // "v x y z r g b", the colour extension MeshLab and most scanners read.
  const int rgb[3] = {m.colour_index("red"), m.colour_index("green"), m.colour_index("blue")};
  const bool colours = rgb[0] >= 0 && rgb[1] >= 0 && rgb[2] >= 0;
  // Vertex normals as "vn", one per vertex in the vertices' order, which the faces
  // name with the vertex's own index ("f a//a b//b c//c").
  const int nxyz[3] = {m.colour_index("nx"), m.colour_index("ny"), m.colour_index("nz")};
  const bool normals = nxyz[0] >= 0 && nxyz[1] >= 0 && nxyz[2] >= 0;
  // Texture coordinates as "vt", one per vertex likewise.
  int uv[2];
  const bool texture = texture_pair(m, &uv[0], &uv[1]);
  // "KEY a b ...": vertex i's attributes `columns`, as floats.
  const auto attribute_line = [&](const char* key, const int* columns, int count, std::size_t i) {
    out.text() += key;
    for (int k = 0; k < count; ++k) {
      out.text() += ' ';
      append_coord(out.text(), m.attribute(i, std::size_t(columns[k])), ScalarType::f32);
    }
    out.text() += '\n';
  };
  for (std::size_t i = 0; i < m.vertices(); ++i) {
    out.text() += "v ";
    m.append_vertex(out.text(), i);
    if (colours)
      for (int c : rgb) {
        out.text() += ' ';
        append_coord(out.text(), m.attribute(i, std::size_t(c)) / colour_scale(m.attribute_info(std::size_t(c)).type),
                     ScalarType::f32);
      }
    out.text() += '\n';
    if (normals) attribute_line("vn", nxyz, 3, i);
    if (texture) attribute_line("vt", uv, 2, i);
    out.maybe_flush();
  }
  for (std::size_t t = 0; t < m.triangles(); ++t) {
    if (!materials.empty()) {
      const std::size_t chosen = face_material(m, materials, t, current_material);
      if (chosen != current_material) {
        out.text() += "usemtl " + m.materials->names[chosen] + "\n";
        current_material = chosen;
      }
    }
    out.text() += "f ";
    if (normals || texture) {
      for (int k = 0; k < 3; ++k) {
        if (k) out.text() += ' ';
        const std::uint64_t v = std::uint64_t(m.tri[3 * t + std::size_t(k)]) + 1;
        append_uint(out.text(), v);
        out.text() += '/';
        if (texture) append_uint(out.text(), v);
        if (normals) {
          out.text() += '/';
          append_uint(out.text(), v);
        }
      }
    } else {
      m.append_triangle(out.text(), t, 1);
    }
    out.text() += '\n';
    out.maybe_flush();
  }
  for (std::size_t e = 0; e < m.edges(); ++e) {
    out.text() += "l ";
    append_uint(out.text(), std::uint64_t(m.primitives->edges[2 * e]) + 1);
    out.text() += ' ';
    append_uint(out.text(), std::uint64_t(m.primitives->edges[2 * e + 1]) + 1);
    out.text() += '\n';
    out.maybe_flush();
  }
  for (std::size_t p = 0; p < m.points(); ++p) {
    out.text() += "p ";
    append_uint(out.text(), std::uint64_t(m.primitives->points[p]) + 1);
    out.text() += '\n';
    out.maybe_flush();
  }
  out.flush();
}

// PLY's edge records "vertex1 vertex2 thickness" and point records "vertex thickness",
// as text lines (ascii) or little-endian int32 and float32.
void write_ply_primitives(ByteSink& sink, const MeshArrays& m, bool ascii) {
  if (!m.primitives) return;
  const ThickPrimitives& p = *m.primitives;
  if (ascii) {
    TextOut out(sink);
    for (std::size_t e = 0; e < m.edges(); ++e) {
      append_uint(out.text(), p.edges[2 * e]);
      out.text() += ' ';
      append_uint(out.text(), p.edges[2 * e + 1]);
      out.text() += ' ';
      append_coord(out.text(), p.edge_thickness[e], ScalarType::f32);
      out.text() += '\n';
      out.maybe_flush();
    }
    for (std::size_t i = 0; i < m.points(); ++i) {
      append_uint(out.text(), p.points[i]);
      out.text() += ' ';
      append_coord(out.text(), p.point_thickness[i], ScalarType::f32);
      out.text() += '\n';
      out.maybe_flush();
    }
    out.flush();
    return;
  }
  for (std::size_t e = 0; e < m.edges(); ++e) {
    unsigned char rec[12];
    std::memcpy(rec, &p.edges[2 * e], 8);
    std::memcpy(rec + 8, &p.edge_thickness[e], 4);
    sink.write(rec, sizeof rec);
  }
  for (std::size_t i = 0; i < m.points(); ++i) {
    unsigned char rec[8];
    std::memcpy(rec, &p.points[i], 4);
    std::memcpy(rec + 4, &p.point_thickness[i], 4);
    sink.write(rec, sizeof rec);
  }
}

// OFF (Geomview): "OFF", the counts (vertices, faces, edges: 0, not needed), vertices,
// faces as "3 a b c" with 0-based indices.
// The body shared by OFF and ascii PLY: a line "x y z" per vertex, then "3 a b c" per
// triangle with 0-based indices.
void write_vertex_and_face_lines(TextOut& out, const MeshArrays& m, bool with_attributes) {
  for (std::size_t i = 0; i < m.vertices(); ++i) {
    m.append_vertex(out.text(), i);
    if (with_attributes) m.append_attributes(out.text(), i);
    out.text() += '\n';
    out.maybe_flush();
  }
  for (std::size_t t = 0; t < m.triangles(); ++t) {
    out.text() += "3 ";
    m.append_triangle(out.text(), t, 0);
    out.text() += '\n';
    out.maybe_flush();
  }
  out.flush();
}

void write_off(ByteSink& sink, const MeshArrays& m) {
  TextOut out(sink);
  out.text() = "OFF\n" + std::to_string(m.vertices()) + " " + std::to_string(m.triangles()) + " 0\n";
  write_vertex_and_face_lines(out, m, false);
}

void write_ply(ByteSink& sink, const MeshArrays& m, bool ascii) {
  const std::vector<VertexAttribute> none;
  PlyStreamWriter out(sink, ascii, m.precision, m.vertices(), m.triangles(),
                      m.attribute_count() ? *m.attribute_names : none, m.edges(), m.points());
  for (std::size_t i = 0; i < m.vertices(); ++i)
    out.vertex(Vec3d{m.pos[3 * i], m.pos[3 * i + 1], m.pos[3 * i + 2]},
               m.attribute_count() ? &m.attribute_values[m.attribute_count() * i] : nullptr);
  for (std::size_t t = 0; t < m.triangles(); ++t) out.triangle(&m.tri[3 * t]);
  out.finish();
  write_ply_primitives(sink, m, ascii);
}

// The unit normal of triangle t by the right-hand rule over its corner order; 0 when
// it has no area.
Vec3d facet_normal(const MeshArrays& m, std::size_t t) {
  auto corner = [&](std::size_t k) {
    const double* p = &m.pos[3 * std::size_t(m.tri[3 * t + k])];
    return Vec3d{p[0], p[1], p[2]};
  };
  const Vec3d a = corner(0);
  Vec3d n = cross(corner(1) - a, corner(2) - a);
  double len = length(n);
  if (!(len > 0) || !std::isfinite(len)) return {};
  return n / len;
}

// Binary STL: an 80-byte header (not starting with "solid", which readers take for
// ascii), the triangle count, then per triangle the normal and the three corners as
// float32 and a zero attribute word. STL has no shared vertices: corners are repeated.
void write_stl_binary(ByteSink& sink, const MeshArrays& m, const std::string& path) {
  if (m.triangles() > 0xFFFFFFFFu)
    throw IoError(path + ": " + std::to_string(m.triangles()) +
                  " triangles do not fit in a binary STL (at most 2^32 - 1)");
  unsigned char header[84] = {};
  const char kTitle[] = "binary STL written by oocsimp";
  std::memcpy(header, kTitle, sizeof kTitle - 1);
  std::uint32_t n = std::uint32_t(m.triangles());
  std::memcpy(header + 80, &n, 4);  // little-endian, as the hosts are
  sink.write(header, sizeof header);
  for (std::size_t t = 0; t < m.triangles(); ++t) {
    float rec[12];
    Vec3d nrm = facet_normal(m, t);
    rec[0] = float(nrm.x);
    rec[1] = float(nrm.y);
    rec[2] = float(nrm.z);
    for (int k = 0; k < 3; ++k)
      for (int a = 0; a < 3; ++a) rec[3 + 3 * k + a] = float(m.pos[3 * std::size_t(m.tri[3 * t + k]) + a]);
    sink.write(rec, sizeof rec);
    const unsigned char attribute[2] = {0, 0};
    sink.write(attribute, 2);
  }
}

void write_stl_ascii(ByteSink& sink, const MeshArrays& m) {
  TextOut out(sink);
  out.text() = "solid oocsimp\n";
  for (std::size_t t = 0; t < m.triangles(); ++t) {
    Vec3d nrm = facet_normal(m, t);
    std::string& s = out.text();
    s += "facet normal ";
    append_coord(s, nrm.x, ScalarType::f32);
    s += ' ';
    append_coord(s, nrm.y, ScalarType::f32);
    s += ' ';
    append_coord(s, nrm.z, ScalarType::f32);
    s += "\n outer loop\n";
    for (int k = 0; k < 3; ++k) {
      s += "  vertex ";
      m.append_vertex(s, m.tri[3 * t + std::size_t(k)]);
      s += '\n';
    }
    s += " endloop\nendfacet\n";
    out.maybe_flush();
  }
  out.text() += "endsolid oocsimp\n";
  out.flush();
}

// glTF binary: the arrays as they are, normals and colours found by name.
void write_gltf(ByteSink& sink, const MeshArrays& m) {
  GlbArrays g;
  g.positions = m.pos;
  g.vertex_count = m.vertices();
  g.triangles = m.tri;
  g.triangle_count = m.triangles();
  g.attributes = m.attribute_values;
  g.attribute_width = m.attribute_count();
  texture_pair(m, &g.uv[0], &g.uv[1]);
  const char* normal[3] = {"nx", "ny", "nz"};
  const char* colour[4] = {"red", "green", "blue", "alpha"};
  for (int k = 0; k < 3; ++k) g.normal[k] = m.colour_index(normal[k]);
  for (int k = 0; k < 4; ++k) {
    g.colour[k] = m.colour_index(colour[k]);
    if (g.colour[k] >= 0) g.colour_scale[k] = colour_scale(m.attribute_info(std::size_t(g.colour[k])).type);
  }
  // The materials as OBJ writes them: each triangle's by the same rule, one primitive
  // per material.
  const std::vector<std::pair<std::size_t, std::size_t>> materials = material_columns(m);
  std::vector<std::uint32_t> face_materials;
  if (!materials.empty()) {
    face_materials.resize(m.triangles());
    std::size_t current = kNoMaterial;
    for (std::size_t t = 0; t < m.triangles(); ++t)
      face_materials[t] = std::uint32_t(current = face_material(m, materials, t, current));
    g.face_materials = face_materials.data();
    g.material_names = m.materials->names;
  }
  if (m.materials) g.material_libraries = m.materials->libraries;
  write_glb(sink, g);
}

void write_body(ByteSink& sink, const MeshArrays& m, MeshFormat format, const std::string& path) {
  switch (format) {
    case MeshFormat::glb:
      return write_gltf(sink, m);
    case MeshFormat::obj:
      return write_obj(sink, m);
    case MeshFormat::off:
      return write_off(sink, m);
    case MeshFormat::stl_binary:
      return write_stl_binary(sink, m, path);
    case MeshFormat::stl_ascii:
      return write_stl_ascii(sink, m);
    case MeshFormat::ply_ascii:
      return write_ply(sink, m, true);
    case MeshFormat::ply_binary:
      return write_ply(sink, m, false);
  }
}

}  // namespace

PlyStreamWriter::PlyStreamWriter(ByteSink& sink, bool ascii, ScalarType precision, std::uint64_t vertices,
                                 std::uint64_t triangles, const std::vector<VertexAttribute>& attributes,
                                 std::uint64_t edges, std::uint64_t points, const std::vector<std::string>& comments)
    : sink_(sink),
      ascii_(ascii),
      precision_(precision),
      vertices_(vertices),
      triangles_(triangles),
      attributes_(attributes) {
  const char* type = precision == ScalarType::f32 ? "float" : "double";
  std::string header =
      std::string("ply\nformat ") + (ascii ? "ascii" : "binary_little_endian") + " 1.0\ncomment oocsimp\n";
  for (const std::string& c : comments) header += "comment " + c + "\n";
  header += "element vertex " + std::to_string(vertices) + "\nproperty " + type + " x\nproperty " + type +
            " y\nproperty " + type + " z\n";
  // The attributes under their names and types, after x, y, z.
  for (const VertexAttribute& a : attributes)
    header += std::string("property ") + attribute_type_name(a.type) + " " + a.name + "\n";
  header += "element face " + std::to_string(triangles) + "\nproperty list uchar uint vertex_indices\n";
  if (edges > 0)
    header += "element edge " + std::to_string(edges) +
              "\nproperty int vertex1\nproperty int vertex2\nproperty float thickness\n";
  if (points > 0)
    header += "element point " + std::to_string(points) + "\nproperty int vertex\nproperty float thickness\n";
  header += "end_header\n";
  sink_.write(header);
  record_.resize(precision == ScalarType::f64 ? 24 : 12);
  for (const VertexAttribute& a : attributes) {
    offsets_.push_back(record_.size());
    record_.resize(record_.size() + attribute_type_size(a.type));
  }
}

void PlyStreamWriter::vertex(const Vec3d& p, const double* attributes) {
  ++vertices_written_;
  if (ascii_) {
    append_coord(text_, p.x, precision_);
    text_ += ' ';
    append_coord(text_, p.y, precision_);
    text_ += ' ';
    append_coord(text_, p.z, precision_);
    for (std::size_t k = 0; k < attributes_.size(); ++k) {
      text_ += ' ';
      const AttributeType t = attributes_[k].type;
      if (is_integer_type(t)) {
        char buf[24];
        auto r = std::to_chars(buf, buf + sizeof buf, std::int64_t(attributes[k]));
        text_.append(buf, r.ptr);
      } else {
        append_coord(text_, attributes[k], t == AttributeType::f64 ? ScalarType::f64 : ScalarType::f32);
      }
    }
    text_ += '\n';
    flush_text_past(1 << 16);
    return;
  }
  // x86 and ARM are little-endian: values are stored as they are.
  const AttributeType coordinate = precision_ == ScalarType::f64 ? AttributeType::f64 : AttributeType::f32;
  const std::size_t size = precision_ == ScalarType::f64 ? 8 : 4;
  store_attribute(p.x, coordinate, &record_[0]);
  store_attribute(p.y, coordinate, &record_[size]);
  store_attribute(p.z, coordinate, &record_[2 * size]);
  for (std::size_t k = 0; k < offsets_.size(); ++k)
    store_attribute(attributes[k], attributes_[k].type, &record_[offsets_[k]]);
  sink_.write(record_.data(), record_.size());
}

void PlyStreamWriter::triangle(const std::uint32_t corners[3]) {
  ++triangles_written_;
  if (ascii_) {
    text_ += "3 ";
    append_uint(text_, corners[0]);
    text_ += ' ';
    append_uint(text_, corners[1]);
    text_ += ' ';
    append_uint(text_, corners[2]);
    text_ += '\n';
    flush_text_past(1 << 16);
    return;
  }
  unsigned char rec[13];
  rec[0] = 3;
  std::memcpy(rec + 1, corners, 12);
  sink_.write(rec, 13);
}

void PlyStreamWriter::finish() {
  flush_text_past(0);
  if (vertices_written_ != vertices_ || triangles_written_ != triangles_)
    throw IoError("internal error: a PLY stream wrote " + std::to_string(vertices_written_) + " vertices and " +
                  std::to_string(triangles_written_) + " faces where its header says " + std::to_string(vertices_) +
                  " and " + std::to_string(triangles_));
}

void PlyStreamWriter::flush_text_past(std::size_t bytes) {
  if (text_.size() > bytes || (bytes == 0 && !text_.empty())) {
    sink_.write(text_);
    text_.clear();
  }
}

MeshFormat format_for_path(const std::string& path, bool ascii) {
  const std::string p = without_compression_suffix(path);
  std::string ext = p.size() >= 4 ? p.substr(p.size() - 4) : "";
  for (char& c : ext) c = char(std::tolower(static_cast<unsigned char>(c)));
  if (ext == ".ply") return ascii ? MeshFormat::ply_ascii : MeshFormat::ply_binary;
  if (ext == ".obj") return MeshFormat::obj;
  if (ext == ".stl") return ascii ? MeshFormat::stl_ascii : MeshFormat::stl_binary;
  if (ext == ".off") return MeshFormat::off;
  if (ext == ".glb") return MeshFormat::glb;
  throw UsageError("cannot write \"" + path +
                   "\": the output format comes from the extension, one of .ply, .obj, .stl, .off or .glb, "
                   "optionally followed by .zst or .gz");
}

void write_mesh(const std::string& path, const std::vector<double>& positions,
                const std::vector<std::uint32_t>& triangles, MeshFormat format, ScalarType precision,
                const AttributeValues* attributes, const ThickPrimitives* primitives) {
  OutputFile out(path);
  write_mesh(out, positions, triangles, format, precision, attributes, primitives);
  out.commit();
}

bool format_keeps_primitives(MeshFormat format) {
  return format == MeshFormat::ply_binary || format == MeshFormat::ply_ascii;
}

bool format_keeps_attributes(MeshFormat format, const AttributeValues& attributes) {
  if (attributes.empty()) return true;
  if (format == MeshFormat::ply_binary || format == MeshFormat::ply_ascii) return true;
  if (format != MeshFormat::obj && format != MeshFormat::glb) return false;
  // OBJ keeps the materials as usemtl groups, glTF as a primitive each (format_keeps_materials).
  std::size_t material = 0;
  if (!attributes.materials.names.empty())
    for (const VertexAttribute& a : attributes.attributes) material += is_material_attribute(a.name);
  // OBJ keeps colours ("v x y z r g b"), normals ("vn") and one pair of texture
  // coordinates ("vt"), each whole, and nothing else; glTF the same (COLOR_0 with
  // alpha when there is one, NORMAL, TEXCOORD_0).
  int colours = 0, normals = 0, alpha = 0;
  for (const VertexAttribute& a : attributes.attributes) {
    colours += a.name == "red" || a.name == "green" || a.name == "blue";
    normals += a.name == "nx" || a.name == "ny" || a.name == "nz";
    alpha += format == MeshFormat::glb && a.name == "alpha";
  }
  if (colours != 3) alpha = 0;  // alpha goes with the colours
  const std::size_t texture = texture_coordinate_pair(attributes.attributes) ? 2 : 0;
  return (colours == 0 || colours == 3) && (normals == 0 || normals == 3) &&
         std::size_t(colours + normals + alpha) + texture + material == attributes.attributes.size();
}

bool format_keeps_materials(MeshFormat format) { return format == MeshFormat::obj || format == MeshFormat::glb; }

namespace {

void write_arrays(OutputFile& out, const MeshArrays& m, MeshFormat format) {
  if (m.points() + m.edges() > 0 && m.vertices() > 0x7FFFFFFFu)
    throw IoError(out.path() + ": thick edges and points name vertices as int, and there are more than 2^31");
  ByteSink sink(out.fd(), out.path(), compression_for_path(out.path()));
  write_body(sink, m, format, out.path());
  sink.finish();
}

}  // namespace

void write_mesh(OutputFile& out, const std::vector<double>& positions, const std::vector<std::uint32_t>& triangles,
                MeshFormat format, ScalarType precision, const AttributeValues* attributes,
                const ThickPrimitives* primitives) {
  write_arrays(
      out,
      MeshArrays{positions.data(), positions.size() / 3, triangles.data(), triangles.size() / 3, precision,
                 attributes ? &attributes->attributes : nullptr, attributes ? attributes->values.data() : nullptr,
                 primitives, attributes ? &attributes->materials : nullptr},
      format);
}

void write_mesh(OutputFile& out, const OutputMesh& mesh, MeshFormat format) {
  write_arrays(
      out,
      MeshArrays{mesh.positions.data(), mesh.vertex_count(), mesh.triangles.data(), mesh.triangle_count(),
                 mesh.precision, &mesh.attributes, mesh.attribute_values.data(), &mesh.primitives, &mesh.materials},
      format);
}

}  // namespace oocsimp
