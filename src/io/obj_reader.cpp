// Wavefront OBJ reader: `v` and `f` lines, and `l` and `p` lines for a PrimitiveSink;
// everything else is ignored.
//
// Two streaming passes: the first converts `v` lines to a temporary position array
// (and counts `f` lines), the second streams the faces. An index refers to the
// vertices defined so far (negative ones count back from the latest), as in the
// format's definition, so forward references are rejected.
#include <memory>
#include <string>
#include <utility>

#include "io/attribute_array.hpp"
#include "io/position_array.hpp"
#include "io/readers.hpp"
#include "io/text_scan.hpp"
#include "io/error_text.hpp"
#include "oocsimp/error.hpp"

namespace oocsimp {

namespace {

bool is_keyword(std::string_view line, char c) {
  return line.size() >= 2 && line[0] == c && TokenScanner::is_space(line[1]);
}

// Whether `word` opens a statement of the OBJ format (its specification's keywords,
// free-form geometry included): a file none of whose lines does is not OBJ.
bool is_obj_statement(std::string_view word) {
  static const char* const kStatements[] = {
      "v",          "vt",        "vn",     "vp",     "f",     "l",        "p",        "o",    "g",      "s",
      "mg",         "usemtl",    "mtllib", "cstype", "deg",   "bmat",     "step",     "curv", "curv2",  "surf",
      "parm",       "trim",      "hole",   "scrv",   "sp",    "end",      "con",      "lod",  "maplib", "usemap",
      "shadow_obj", "trace_obj", "ctech",  "stech",  "bevel", "c_interp", "d_interp", "call", "csh"};
  for (const char* k : kStatements)
    if (word == k) return true;
  return false;
}

// Lines may start with blanks; returns the line from its first non-blank character.
std::string_view trim_front(std::string_view line) {
  std::size_t i = 0;
  while (i < line.size() && TokenScanner::is_space(line[i])) ++i;
  return line.substr(i);
}

class ObjTriangleStream : public TriangleStream {
 public:
  ObjTriangleStream(std::shared_ptr<InputFile> file, std::uint64_t vertex_count)
      : src_(std::move(file)), vertex_count_(vertex_count) {}

  std::size_t read(std::uint64_t* out, std::size_t max) override {
    std::size_t n = 0;
    std::string_view line;
    while (n < max) {
      if (fan_.pending()) {
        n += fan_.emit(out + 3 * n, max - n);
        continue;
      }
      if (!src_.next_line(&line)) {
        primitives_.flush();
        break;
      }
      line = trim_front(line);
      if (is_keyword(line, 'v')) {
        ++defined_;
      } else if (is_keyword(line, 'f')) {
        parse_face(line);
        fan_.start();
      } else if (primitives_.wanted() && (is_keyword(line, 'l') || is_keyword(line, 'p'))) {
        parse_primitives(line);
      }
    }
    return n;
  }
  std::uint64_t bytes_consumed() const override { return src_.raw_consumed(); }
  SkippedFaces skipped() const override { return {skipped_, 0, 0}; }
  void set_primitive_sink(PrimitiveSink sink) override { primitives_.set_sink(std::move(sink)); }

 private:
  // "l a b c ...": the edges of the polyline (a, b), (b, c), ...; "p a b ...": a point
  // at each. OBJ gives no thickness.
  void parse_primitives(std::string_view line) {
    const bool points = line[0] == 'p';
    TokenScanner t(line.substr(1));
    std::uint64_t previous = 0;
    bool first = true;
    for (std::string_view tok = t.next(); !tok.empty(); tok = t.next()) {
      const std::uint64_t v = index_of(tok.substr(0, tok.find('/')), tok);
      if (points)
        primitives_.add(v, v, 0);
      else if (!first)
        primitives_.add(previous, v, 0);
      previous = v;
      first = false;
    }
  }

  [[noreturn]] void fail(const std::string& what) const {
    throw InputError(at_line(src_.path(), src_.line_number(), what));
  }

  void parse_face(std::string_view line) {
    TokenScanner t(line.substr(1));
    auto& poly = fan_.polygon();
    poly.clear();
    for (std::string_view tok = t.next(); !tok.empty(); tok = t.next()) {
      // v, v/vt, v//vn, v/vt/vn: the position index is the part before the first '/'.
      const std::uint64_t v = index_of(tok.substr(0, tok.find('/')), tok);
      if (poly.size() >= kMaxPolygonCorners) fail("polygon with more than 2^20 corners");
      poly.push_back(v);
    }
    if (poly.size() < 3) {
      ++skipped_;
      poly.clear();
    }
    (void)vertex_count_;
  }

  // The 0-based vertex of index text `vtok` (of token `tok`): 1-based, or negative
  // counting back from the latest vertex.
  std::uint64_t index_of(std::string_view vtok, std::string_view tok) const {
    std::int64_t idx;
    if (!parse_int(vtok, &idx)) fail("malformed vertex index " + quoted(tok));
    std::int64_t abs = 0;
    if (idx > 0)
      abs = idx - 1;
    else if (idx < 0)
      abs = std::int64_t(defined_) + idx;
    else
      fail("vertex index 0 (OBJ indices start at 1)");
    if (abs < 0 || std::uint64_t(abs) >= defined_)
      fail("vertex index " + std::to_string(idx) + " refers to a vertex not defined yet (" + std::to_string(defined_) +
           " so far)");
    return std::uint64_t(abs);
  }

  ByteSource src_;
  PrimitiveBatch primitives_;
  std::uint64_t vertex_count_;
  std::uint64_t defined_ = 0;
  std::uint64_t skipped_ = 0;
  FanTriangulator fan_;
};

}  // namespace

void open_obj(ByteSource& src, const OpenOptions& options, ProgressPhase& progress, MeshInput& out) {
  out.info.format = "obj";
  PositionArrayBuilder builder(options.temp_dir, src.path());
  // "v x y z r g b" (MeshLab, CloudCompare and most scanners' exporters): colours, when
  // the first vertex has them; which of them are carried is decided there too.
  std::unique_ptr<AttributeArrayBuilder> colours;
  std::vector<std::size_t> carried;
  std::uint64_t faces = 0, texture_lines = 0, normal_lines = 0, uncoloured = 0, line_elements = 0, point_elements = 0;
  // A file with lines but no OBJ statement (text, or binary named .obj) is refused
  // rather than read as an empty mesh; the first foreign line is named. 1000 foreign
  // lines before any statement end the reading there, so a large foreign file is not
  // read to its end.
  bool any_statement = false;
  std::uint64_t foreign_line = 0, foreign_lines = 0;
  std::string foreign_word;
  const auto refuse = [&](const char* scope) {
    throw InputError(at_line(src.path(), foreign_line,
                             std::string("not an OBJ file: ") + scope +
                                 " opens an OBJ statement (this one opens with " + quoted(foreign_word) + ")"));
  };
  std::string_view line;
  while (src.next_line(&line)) {
    line = trim_front(line);
    if (!any_statement && !line.empty() && line[0] != '#') {
      std::string_view word = TokenScanner(line).next();
      if (is_obj_statement(word)) {
        any_statement = true;
      } else {
        if (foreign_line == 0) {
          foreign_line = src.line_number();
          foreign_word = std::string(word.substr(0, 16));
        }
        if (++foreign_lines == 1000) refuse("none of the first 1000 lines");
      }
    }
    if (is_keyword(line, 'v')) {
      // "v x y z [w]" or "v x y z r g b": the first three values are the position.
      TokenScanner t(line.substr(1));
      double c[6];
      bool fits_float = true;
      for (int k = 0; k < 3; ++k) {
        std::string_view tok = t.next();
        if (!parse_double(tok, &c[k]))
          throw InputError(at_line(
              src.path(), src.line_number(),
              tok.empty() ? "vertex with fewer than 3 coordinates" : "malformed vertex coordinate " + quoted(tok)));
        fits_float = fits_float && decimal_fits_float(tok, c[k]);
      }
      int extra = 0;
      for (std::string_view tok = t.next(); !tok.empty() && extra < 3; tok = t.next()) {
        if (!parse_double(tok, &c[3 + extra]))
          throw InputError(at_line(src.path(), src.line_number(), "malformed vertex value " + quoted(tok)));
        ++extra;
      }
      if (builder.count() == 0 && extra == 3) {
        const std::vector<AttributeCandidate> offered = {
            {"red", AttributeType::f32}, {"green", AttributeType::f32}, {"blue", AttributeType::f32}};
        carried = carried_attributes(offered, options.attributes, src.path(), &out.info.not_carried);
        std::vector<VertexAttribute> attrs;
        for (std::size_t i : carried) attrs.push_back({offered[i].name, offered[i].type, 0, 0});
        colours = std::make_unique<AttributeArrayBuilder>(options.temp_dir, src.path(), attrs);
      }
      if (colours) {
        if (extra < 3) {
          ++uncoloured;
          c[3] = c[4] = c[5] = 0;
        }
        double values[3];
        for (std::size_t k = 0; k < carried.size(); ++k) values[k] = c[3 + carried[k]];
        colours->add(values);
      }
      builder.add(
          c[0], c[1], c[2], [&] { return "line " + std::to_string(src.line_number()); }, fits_float);
    } else if (is_keyword(line, 'f')) {
      ++faces;
    } else if (is_keyword(line, 'l')) {
      ++line_elements;
    } else if (is_keyword(line, 'p')) {
      ++point_elements;
    } else if (line.size() > 2 && line[0] == 'v' && TokenScanner::is_space(line[2])) {
      texture_lines += line[1] == 't';
      normal_lines += line[1] == 'n';
    }
    if ((src.line_number() & 0xFFFF) == 0) progress.set(src.raw_consumed());
  }
  if (!any_statement && foreign_line > 0) refuse("no line");
  // Nothing at all (no byte, or comments and names only): no mesh, not an empty one.
  if (builder.count() == 0 && faces == 0 && line_elements == 0 && point_elements == 0)
    throw InputError(at_line(src.path(), src.line_number(), "no vertices or faces found"));
  // No colours (or no vertices): a selection that names an attribute cannot be met.
  if (!colours) carried_attributes({}, options.attributes, src.path(), nullptr);
  if (texture_lines > 0 && options.attributes.mode != AttributeSelection::Mode::none)
    out.info.not_carried.push_back(src.path() + ": texture coordinates (" + std::to_string(texture_lines) +
                                   " vt lines) are dropped: clustering merges vertices across texture seams");
  if (normal_lines > 0 && options.attributes.mode != AttributeSelection::Mode::none)
    out.info.not_carried.push_back(src.path() + ": normals (" + std::to_string(normal_lines) +
                                   " vn lines) belong to face corners in OBJ and are not carried");
  if (uncoloured > 0)
    out.info.not_carried.push_back(src.path() + ": " + std::to_string(uncoloured) +
                                   " vertices have no colour (the first vertex has one); they count as black");
  out.info.vertex_count = builder.count();
  out.info.face_count = faces;
  out.info.edge_count = line_elements;
  out.info.point_count = point_elements;
  out.info.elements = {"v " + std::to_string(builder.count()), "f " + std::to_string(faces)};
  if (line_elements > 0) out.info.elements.push_back("l " + std::to_string(line_elements));
  if (point_elements > 0) out.info.elements.push_back("p " + std::to_string(point_elements));
  builder.finish(out);
  if (colours) colours->finish(out);
  std::shared_ptr<InputFile> file = src.input();
  std::uint64_t vcount = out.info.vertex_count;
  reader_state(out).make_triangles = [file, vcount]() -> std::unique_ptr<TriangleStream> {
    return std::make_unique<ObjTriangleStream>(file, vcount);
  };
}

}  // namespace oocsimp
