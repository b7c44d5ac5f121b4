// Object File Format (Geomview's OFF, as the writer writes it and MeshLab, CGAL and
// Open3D exchange it): a keyword line ("OFF", with the prefixes C, N, ST for vertex
// colours, normals and texture coordinates), the counts "vertices faces edges", the
// vertices a line each, then the faces as "n i0 i1 ... [colour]". '#' starts a
// comment anywhere. Polygons are fanned into triangles.
//
// Two streaming passes, as for OBJ: the first converts the vertex lines to a position
// array, the second (the triangle stream) skips them again and reads the faces. The
// values after a vertex's x y z (normals, colours, texture coordinates) are not
// carried; a note says so.
#include <memory>
#include <string>
#include <utility>

#include "io/attribute_array.hpp"
#include "io/error_text.hpp"
#include "io/position_array.hpp"
#include "io/readers.hpp"
#include "io/text_scan.hpp"
#include "oocsimp/error.hpp"

namespace oocsimp {

namespace {

// The next line that holds anything besides blanks and a comment, without the comment;
// false at the end of the content.
bool next_data_line(ByteSource& src, std::string_view* line) {
  while (src.next_line(line)) {
    std::string_view l = *line;
    const std::size_t hash = l.find('#');
    if (hash != std::string_view::npos) l = l.substr(0, hash);
    std::size_t i = 0;
    while (i < l.size() && TokenScanner::is_space(l[i])) ++i;
    if (i < l.size()) {
      *line = l.substr(i);
      return true;
    }
  }
  return false;
}

// What the keyword line says: the prefixes of "[ST][C][N][4][n]OFF".
struct OffHeader {
  bool colours = false, normals = false, texture = false;
  std::uint64_t vertices = 0, faces = 0;
};

[[noreturn]] void fail(const ByteSource& src, const std::string& what) {
  throw InputError(at_line(src.path(), src.line_number(), what));
}

// Reads the keyword and the counts; on return the next data line is the first vertex.
OffHeader read_header(ByteSource& src) {
  std::string_view line;
  if (!next_data_line(src, &line)) throw InputError(at_byte(src.path(), 0, "empty file (no OFF keyword)"));
  TokenScanner t(line);
  std::string_view keyword = t.next();
  OffHeader h;
  std::string_view k = keyword;
  if (k.substr(0, 2) == "ST") h.texture = true, k.remove_prefix(2);
  if (k.substr(0, 1) == "C") h.colours = true, k.remove_prefix(1);
  if (k.substr(0, 1) == "N") h.normals = true, k.remove_prefix(1);
  if (k.substr(0, 1) == "4" || k.substr(0, 1) == "n")
    fail(src, quoted(keyword) + ": only three-dimensional OFF is read (no 4OFF or nOFF)");
  if (k != "OFF") fail(src, "not an OFF file (it does not start with \"OFF\"; found " + quoted(keyword) + ")");
  std::string_view rest = t.next();
  if (rest == "BINARY") fail(src, "binary OFF is not read; convert it to text OFF, PLY or OBJ");
  // The counts follow on the keyword line or on the next data line.
  if (rest.empty()) {
    if (!next_data_line(src, &line)) fail(src, "no vertex and face counts after the OFF keyword");
    t = TokenScanner(line);
    rest = t.next();
  }
  std::string_view faces = t.next();
  if (!parse_uint(rest, &h.vertices) || !parse_uint(faces, &h.faces))
    fail(src, "expected the counts \"vertices faces edges\", found " + quoted(rest) + " " + quoted(faces));
  return h;
}

class OffTriangleStream : public TriangleStream {
 public:
  OffTriangleStream(std::shared_ptr<InputFile> file, std::uint64_t vertex_count, std::uint64_t face_count)
      : src_(std::move(file)), vertex_count_(vertex_count), face_count_(face_count) {
    read_header(src_);
    std::string_view line;
    for (std::uint64_t v = 0; v < vertex_count_; ++v) next_data_line(src_, &line);  // checked by the first pass
  }

  std::size_t read(std::uint64_t* out, std::size_t max) override {
    std::size_t n = 0;
    std::string_view line;
    while (n < max) {
      if (fan_.pending()) {
        n += fan_.emit(out + 3 * n, max - n);
        continue;
      }
      if (read_ == face_count_) break;
      if (!next_data_line(src_, &line))
        fail(src_,
             "the file ends after " + std::to_string(read_) + " of its " + std::to_string(face_count_) + " faces");
      parse_face(line);
      ++read_;
      fan_.start();
    }
    return n;
  }
  std::uint64_t bytes_consumed() const override { return src_.raw_consumed(); }
  SkippedFaces skipped() const override { return {skipped_, 0, 0}; }

 private:
  void parse_face(std::string_view line) {
    TokenScanner t(line);
    const std::string_view count_text = t.next();
    std::uint64_t corners = 0;
    if (!parse_uint(count_text, &corners)) fail(src_, "malformed corner count " + quoted(count_text));
    if (corners > kMaxPolygonCorners) fail(src_, "polygon with more than 2^20 corners");
    auto& poly = fan_.polygon();
    poly.clear();
    for (std::uint64_t c = 0; c < corners; ++c) {
      const std::string_view tok = t.next();
      std::uint64_t v = 0;
      if (tok.empty())
        fail(src_, "a face of " + std::to_string(corners) + " corners lists " + std::to_string(c) + " indices");
      if (!parse_uint(tok, &v)) fail(src_, "malformed vertex index " + quoted(tok));
      if (v >= vertex_count_)
        fail(src_,
             "vertex index " + std::to_string(v) + " is not below the vertex count " + std::to_string(vertex_count_));
      poly.push_back(v);
    }
    if (poly.size() < 3) {  // a point or an edge: no triangle
      ++skipped_;
      poly.clear();
    }
  }

  ByteSource src_;
  std::uint64_t vertex_count_, face_count_;
  std::uint64_t read_ = 0, skipped_ = 0;
  FanTriangulator fan_;
};

}  // namespace

void open_off(ByteSource& src, const OpenOptions& options, ProgressPhase& progress, MeshInput& out) {
  const OffHeader h = read_header(src);
  out.info.format = "off";
  PositionArrayBuilder builder(options.temp_dir, src.path());
  std::string_view line;
  for (std::uint64_t v = 0; v < h.vertices; ++v) {
    if (!next_data_line(src, &line))
      fail(src, "the file ends after " + std::to_string(v) + " of its " + std::to_string(h.vertices) + " vertices");
    TokenScanner t(line);
    double c[3];
    bool fits_float = true;
    for (int k = 0; k < 3; ++k) {
      const std::string_view tok = t.next();
      if (!parse_double(tok, &c[k]))
        fail(src, tok.empty() ? "vertex with fewer than 3 coordinates" : "malformed vertex coordinate " + quoted(tok));
      fits_float = fits_float && decimal_fits_float(tok, c[k]);
    }
    builder.add(
        c[0], c[1], c[2], [&] { return "line " + std::to_string(src.line_number()); }, fits_float);
    if ((v & 0xFFFF) == 0) progress.set(src.raw_consumed());
  }
  // No vertex attribute is carried: a selection that names one cannot be met.
  carried_attributes({}, options.attributes, src.path(), nullptr);
  std::string extras;
  for (const auto& [given, name] :
       {std::pair<bool, const char*>{h.normals, "normals"}, {h.colours, "colours"}, {h.texture, "texture coordinates"}})
    if (given) extras += (extras.empty() ? "" : ", ") + std::string(name);
  if (!extras.empty() && options.attributes.mode != AttributeSelection::Mode::none)
    out.info.not_carried.push_back(src.path() + ": OFF vertex " + extras + " are not carried");
  out.info.vertex_count = builder.count();
  out.info.face_count = h.faces;
  out.info.elements = {"vertices " + std::to_string(h.vertices), "faces " + std::to_string(h.faces)};
  builder.finish(out);
  std::shared_ptr<InputFile> file = src.input();
  const std::uint64_t vertices = h.vertices, faces = h.faces;
  reader_state(out).make_triangles = [file, vertices, faces]() -> std::unique_ptr<TriangleStream> {
    return std::make_unique<OffTriangleStream>(file, vertices, faces);
  };
}

}  // namespace oocsimp
