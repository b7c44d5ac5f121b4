// Wavefront OBJ reader: `v` and `f` lines, and `l` and `p` lines for a PrimitiveSink;
// everything else is ignored.
//
// Two streaming passes: the first converts `v` lines to a temporary position array
// (and counts `f` lines), the second streams the faces. An index refers to the
// vertices defined so far (negative ones count back from the latest), as in the
// format's definition, so forward references are rejected.
//
// OBJ gives texture coordinates (`vt`) and normals (`vn`) to face corners, not to
// vertices, and materials (`usemtl`) to faces. When they are carried, a corner pass
// between the two reads them onto vertices:
// - a position whose corners name several texture coordinates (a texture seam), or
//   whose faces have several materials, is split, one vertex per pair, so that the
//   seam stays sharp (CornerVertices); a material becomes a vertex attribute
//   material_K, 1 on its faces' vertices (Materials in oocsimp/attributes.hpp);
// - the normals of a position's corners are averaged: splitting at every hard edge
//   would cut the surface open there, and the simplifier would treat each cut as a
//   border.
#include <cmath>
#include <cstring>
#include <map>
#include <memory>
#include <string>
#include <utility>

#include "io/attribute_array.hpp"
#include "io/large_array.hpp"
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

// A corner's texture coordinate: its `vt` index, or kNoTexture when it names none.
constexpr std::uint64_t kNoTexture = ~std::uint64_t(0);
// A corner's material: 0 for none (before the first usemtl), K + 1 for material K.
// It takes the top bits of a corner's key, the texture coordinate the rest.
constexpr int kMaterialShift = 40;
constexpr std::uint64_t kTextureKeyMask = (std::uint64_t(1) << kMaterialShift) - 1;

// The rest of `line` after `keyword` and blanks when the line is that statement
// ("usemtl wood"), trailing blanks removed; false otherwise.
bool statement(std::string_view line, std::string_view keyword, std::string_view* rest) {
  if (line.size() < keyword.size() || line.substr(0, keyword.size()) != keyword) return false;
  if (line.size() > keyword.size() && !TokenScanner::is_space(line[keyword.size()])) return false;
  std::string_view r = line.substr(keyword.size());
  while (!r.empty() && TokenScanner::is_space(r.front())) r.remove_prefix(1);
  while (!r.empty() && (TokenScanner::is_space(r.back()) || r.back() == '\r')) r.remove_suffix(1);
  *rest = r;
  return true;
}

using MaterialIndex = std::map<std::string, std::uint32_t, std::less<>>;

// The material a usemtl line switches to (K + 1), 0 for a name not carried.
std::uint64_t material_of_line(const MaterialIndex& index, std::string_view name) {
  const auto found = index.find(name);
  return found == index.end() ? 0 : found->second + 1;
}

// The vertices that a file's corners make of its positions and texture coordinates:
// one per (position, texture coordinate) pair they name. Position p keeps index p for
// the first pair its corners name; every further pair becomes a new vertex after the
// file's own, in the order corners first name them, so the numbering depends only on
// the file. The pairs of one position form a chain (the first in first_, the rest in
// more_), held in LargeArrays, so the index stays out of the heap for any file.
class CornerVertices {
 public:
  CornerVertices(std::uint64_t positions, const ArrayPlace& place) : positions_(positions), more_(place, "obj-seams") {
    first_.assign_zeroed(positions, place, "obj-corners");
  }

  // The vertex of the corner at position p with texture coordinate t and material m
  // (0 or K + 1), made if new.
  std::uint64_t add(std::uint64_t p, std::uint64_t t, std::uint64_t m = 0) {
    const std::uint64_t key = key_of(t, m);
    Link* link = &first_[p];
    if (link->texture == 0) {
      link->texture = key;
      return p;
    }
    std::uint64_t vertex = p;
    int walked = 1;
    for (;;) {
      if (link->texture == key) return vertex;
      if (link->next == 0) break;
      vertex = positions_ + link->next - 1;
      link = &more_[link->next - 1];
      ++walked;
    }
    if (walked >= kLongestChain) {
      // A position with many texture coordinates (a pole of a UV sphere, or a file
      // made to be slow): the rest are looked up by pair, not walked.
      const auto found = crowded_.find({p, key});
      if (found != crowded_.end()) return found->second;
      more_.push_back({key, 0, p});
      const std::uint64_t made = positions_ + more_.size() - 1;
      crowded_.emplace(std::make_pair(p, key), made);
      return made;
    }
    more_.push_back({key, 0, p});
    // more_ may have moved: find the end of the chain again by the vertex found last.
    Link& last = vertex == p ? first_[p] : more_[vertex - positions_];
    last.next = more_.size();
    return positions_ + more_.size() - 1;
  }

  // The vertex of a corner that add() has seen.
  std::uint64_t find(std::uint64_t p, std::uint64_t t, std::uint64_t m = 0) const {
    const std::uint64_t key = key_of(t, m);
    const Link* link = &first_[p];
    std::uint64_t vertex = p;
    while (link->texture != key && link->next != 0) {
      vertex = positions_ + link->next - 1;
      link = &more_[link->next - 1];
    }
    if (link->texture == key) return vertex;
    const auto found = crowded_.find({p, key});
    return found != crowded_.end() ? found->second : p;  // every pair was added: found
  }

  std::uint64_t vertex_count() const { return positions_ + more_.size(); }
  std::uint64_t position_of(std::uint64_t vertex) const {
    return vertex < positions_ ? vertex : more_[vertex - positions_].position;
  }
  // The texture coordinate of a vertex: kNoTexture also for a position no corner names.
  std::uint64_t texture_of(std::uint64_t vertex) const {
    const std::uint64_t key = key_at(vertex) & kTextureKeyMask;
    return key < 2 ? kNoTexture : key - 2;
  }
  // The material of a vertex: 0 for none, K + 1 for material K.
  std::uint64_t material_of(std::uint64_t vertex) const { return key_at(vertex) >> kMaterialShift; }

 private:
  std::uint64_t key_at(std::uint64_t vertex) const {
    return vertex < positions_ ? first_[vertex].texture : more_[vertex - positions_].texture;
  }
  // 0 marks a position no corner has named yet, 1 a corner without a texture
  // coordinate; the material goes above (read_corners checks that t fits below it).
  static std::uint64_t key_of(std::uint64_t t, std::uint64_t m) {
    return (t == kNoTexture ? 1 : t + 2) | m << kMaterialShift;
  }
  struct Link {
    std::uint64_t texture;   // key_of(the texture coordinate, the material)
    std::uint64_t next;      // the chain's next pair: its place in more_ + 1, 0: the end
    std::uint64_t position;  // in more_: the position split
  };
  // Pairs past this many at one position go to crowded_.
  static constexpr int kLongestChain = 16;
  std::uint64_t positions_;
  LargeArray<Link> first_;
  AppendArray<Link> more_;
  std::map<std::pair<std::uint64_t, std::uint64_t>, std::uint64_t> crowded_;  // (position, key) -> vertex
};

// How many `v`, `vt` and `vn` lines came so far: what a face's indices may refer to.
struct DefinedSoFar {
  std::uint64_t positions = 0, textures = 0, normals = 0;
};

// The 0-based element of OBJ index text `text` (of corner token `tok`) among `defined`
// elements of kind `what`: 1-based, or negative counting back from the latest.
// `fail` throws the message.
template <class Fail>
std::uint64_t obj_index(std::string_view text, std::string_view tok, std::uint64_t defined, const char* what,
                        Fail&& fail) {
  std::int64_t idx;
  if (!parse_int(text, &idx)) fail(std::string("malformed ") + what + " index " + quoted(tok));
  std::int64_t abs = 0;
  if (idx > 0)
    abs = idx - 1;
  else if (idx < 0)
    abs = std::int64_t(defined) + idx;
  else
    fail(std::string(what) + " index 0 (OBJ indices start at 1)");
  if (abs < 0 || std::uint64_t(abs) >= defined)
    fail(std::string(what) + " index " + std::to_string(idx) + " refers to a " + what + " not defined yet (" +
         std::to_string(defined) + " so far)");
  return std::uint64_t(abs);
}

// A face corner "v", "v/vt", "v//vn" or "v/vt/vn" split into its three index texts
// (empty where absent).
struct CornerText {
  std::string_view position, texture, normal;
};
inline CornerText split_corner(std::string_view tok) {
  CornerText c;
  const std::size_t a = tok.find('/');
  c.position = tok.substr(0, a);
  if (a == std::string_view::npos) return c;
  const std::size_t b = tok.find('/', a + 1);
  c.texture = tok.substr(a + 1, b == std::string_view::npos ? std::string_view::npos : b - a - 1);
  if (b != std::string_view::npos) c.normal = tok.substr(b + 1);
  return c;
}

class ObjTriangleStream : public TriangleStream {
 public:
  // `corners`: the vertices of split texture and material seams, or null when faces
  // name positions; `textures`: whether texture coordinates split them; `materials`:
  // the carried materials, or null.
  ObjTriangleStream(std::shared_ptr<InputFile> file, std::shared_ptr<const CornerVertices> corners, bool textures,
                    std::shared_ptr<const MaterialIndex> materials)
      : src_(std::move(file)), corners_(std::move(corners)), textures_(textures), materials_(std::move(materials)) {}

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
      std::string_view rest;
      if (materials_ && statement(line, "usemtl", &rest)) {
        material_ = material_of_line(*materials_, rest);
      } else if (is_keyword(line, 'v')) {
        ++defined_.positions;
      } else if (line.size() > 2 && line[0] == 'v' && line[1] == 't' && TokenScanner::is_space(line[2])) {
        ++defined_.textures;
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
      const std::uint64_t v = position_index(split_corner(tok).position, tok);
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
      const CornerText corner = split_corner(tok);
      std::uint64_t v = position_index(corner.position, tok);
      if (corners_) {
        const auto failed = [&](const std::string& what) { fail(what); };
        const std::uint64_t texture =
            !textures_ || corner.texture.empty()
                ? kNoTexture
                : obj_index(corner.texture, tok, defined_.textures, "texture coordinate", failed);
        v = corners_->find(v, texture, material_);
      }
      if (poly.size() >= kMaxPolygonCorners) fail("polygon with more than 2^20 corners");
      poly.push_back(v);
    }
    if (poly.size() < 3) {
      ++skipped_;
      poly.clear();
    }
  }

  std::uint64_t position_index(std::string_view text, std::string_view tok) const {
    return obj_index(text, tok, defined_.positions, "vertex", [&](const std::string& what) { fail(what); });
  }

  ByteSource src_;
  std::shared_ptr<const CornerVertices> corners_;
  bool textures_;
  std::shared_ptr<const MaterialIndex> materials_;
  std::uint64_t material_ = 0;  // of the faces from here: 0 or K + 1
  PrimitiveBatch primitives_;
  DefinedSoFar defined_;
  std::uint64_t skipped_ = 0;
  FanTriangulator fan_;
};

}  // namespace

namespace {

// Where each carried attribute of an OBJ vertex comes from: a colour channel of its
// `v` line, a value of its corners' `vt`, or a component of their averaged `vn`.
enum class ObjSource { colour, texture, normal, material };
struct ObjAttribute {
  ObjSource source;
  int component;
};

// What the first pass keeps of a file's per-vertex and per-corner values, as floats.
struct ObjValues {
  explicit ObjValues(const ArrayPlace& place)
      : colours(place, "obj-colours"), textures(place, "obj-texcoords"), normals(place, "obj-normals") {}
  AppendArray<float> colours;   // r, g, b per `v` line (once the first has them)
  AppendArray<float> textures;  // u, v per `vt` line
  AppendArray<float> normals;   // x, y, z per `vn` line
};

// Reads up to `count` numbers of the rest of an OBJ line into `out` (0 where absent).
void read_floats(TokenScanner& t, float* out, int count, const ByteSource& src) {
  for (int k = 0; k < count; ++k) {
    std::string_view tok = t.next();
    double v = 0;
    if (!tok.empty() && !parse_double(tok, &v))
      throw InputError(at_line(src.path(), src.line_number(), "malformed value " + quoted(tok)));
    out[k] = float(v);
  }
}

// The corner pass: every face corner's texture coordinate (when `textures`) and
// material (when `materials`) onto the vertex it makes (`corners`, when either is
// carried) and its normal into its position's sum (`normal_sums`, when carried).
void read_corners(const std::shared_ptr<InputFile>& file, const ObjValues& values, CornerVertices* corners,
                  bool textures, const MaterialIndex* materials, LargeArray<float>* normal_sums) {
  ByteSource src(file);
  DefinedSoFar defined;
  const auto fail = [&](const std::string& what) { throw InputError(at_line(src.path(), src.line_number(), what)); };
  std::string_view line, rest;
  std::uint64_t material = 0;
  while (src.next_line(&line)) {
    line = trim_front(line);
    if (materials && statement(line, "usemtl", &rest)) {
      material = material_of_line(*materials, rest);
    } else if (is_keyword(line, 'v')) {
      ++defined.positions;
    } else if (line.size() > 2 && line[0] == 'v' && TokenScanner::is_space(line[2])) {
      defined.textures += line[1] == 't';
      defined.normals += line[1] == 'n';
    } else if (is_keyword(line, 'f')) {
      TokenScanner t(line.substr(1));
      for (std::string_view tok = t.next(); !tok.empty(); tok = t.next()) {
        const CornerText corner = split_corner(tok);
        const std::uint64_t p = obj_index(corner.position, tok, defined.positions, "vertex", fail);
        if (corners) {
          const std::uint64_t t = !textures || corner.texture.empty()
                                      ? kNoTexture
                                      : obj_index(corner.texture, tok, defined.textures, "texture coordinate", fail);
          if (material != 0 && t != kNoTexture && t + 2 > kTextureKeyMask)
            fail("more than 2^40 texture coordinates with materials");
          corners->add(p, t, material);
        }
        if (normal_sums && !corner.normal.empty()) {
          const std::uint64_t n = obj_index(corner.normal, tok, defined.normals, "normal", fail);
          for (std::size_t k = 0; k < 3; ++k) (*normal_sums)[3 * p + k] += values.normals[3 * n + k];
        }
      }
    }
  }
}

// Rewrites `positions` (the file's `v` lines) with the vertices a split adds after
// them, each at its position, into `out`.
void add_split_positions(MeshInput& positions, const CornerVertices& corners, const std::string& temp_dir,
                         const std::string& path, MeshInput& out) {
  PositionArrayBuilder builder(temp_dir, path);
  builder.declare(positions.info.double_precision ? ScalarType::f64 : ScalarType::f32);
  // The builder counts the non-finite vertices as the split numbers them (a `v` line
  // used with several attributes is several vertices); the first is placed by its line
  // where it is the file's first, else by its `v` line's number.
  for (std::uint64_t i = 0; i < corners.vertex_count(); ++i) {
    const std::uint64_t source = corners.position_of(i);
    const Vec3d p = positions.positions.get(source);
    builder.add(p.x, p.y, p.z, [&] {
      return source == positions.info.first_non_finite_vertex ? positions.info.first_non_finite_position
                                                              : "the file's vertex " + std::to_string(source);
    });
  }
  builder.finish(out);
}

}  // namespace

void open_obj(ByteSource& src, const OpenOptions& options, ProgressPhase& progress, MeshInput& out) {
  out.info.format = "obj";
  PositionArrayBuilder builder(options.temp_dir, src.path());
  const ArrayPlace place = ArrayPlace::within(options.memory_budget, options.temp_dir);
  const bool any_attributes = options.attributes.mode != AttributeSelection::Mode::none;
  // "v x y z r g b" (MeshLab, CloudCompare and most scanners' exporters): colours, when
  // the first vertex has them.
  ObjValues values(place);
  bool coloured = false;
  std::uint64_t faces = 0, uncoloured = 0, line_elements = 0, point_elements = 0;
  // A file with lines but no OBJ statement (text, or binary named .obj) is refused
  // rather than read as an empty mesh; the first foreign line is named. 1000 foreign
  // lines before any statement end the reading there, so a large foreign file is not
  // read to its end.
  bool any_statement = false;
  auto material_index = std::make_shared<MaterialIndex>();
  std::string_view rest;
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
      if (builder.count() == 0 && extra == 3) coloured = any_attributes;
      if (coloured) {
        if (extra < 3) {
          ++uncoloured;
          c[3] = c[4] = c[5] = 0;
        }
        for (int k = 3; k < 6; ++k) values.colours.push_back(float(c[k]));
      }
      builder.add(
          c[0], c[1], c[2], [&] { return "line " + std::to_string(src.line_number()); }, fits_float);
    } else if (is_keyword(line, 'f')) {
      ++faces;
    } else if (statement(line, "mtllib", &rest)) {
      if (!rest.empty()) out.info.materials.libraries.emplace_back(rest);
    } else if (statement(line, "usemtl", &rest)) {
      if (material_index->find(rest) == material_index->end()) {
        material_index->emplace(std::string(rest), std::uint32_t(out.info.materials.names.size()));
        out.info.materials.names.emplace_back(rest);
      }
    } else if (is_keyword(line, 'l')) {
      ++line_elements;
    } else if (is_keyword(line, 'p')) {
      ++point_elements;
    } else if (any_attributes && line.size() > 2 && line[0] == 'v' && TokenScanner::is_space(line[2]) &&
               (line[1] == 't' || line[1] == 'n')) {
      // "vt u [v [w]]" and "vn x y z".
      TokenScanner t(line.substr(2));
      float f[3];
      const int count = line[1] == 't' ? 2 : 3;
      read_floats(t, f, count, src);
      AppendArray<float>& to = line[1] == 't' ? values.textures : values.normals;
      for (int k = 0; k < count; ++k) to.push_back(f[k]);
    }
    if ((src.line_number() & 0xFFFF) == 0) progress.set(src.raw_consumed());
  }
  if (!any_statement && foreign_line > 0) refuse("no line");
  // Nothing at all (no byte, or comments and names only): no mesh, not an empty one.
  if (builder.count() == 0 && faces == 0 && line_elements == 0 && point_elements == 0)
    throw InputError(at_line(src.path(), src.line_number(), "no vertices or faces found"));

  // The attributes offered, and which of them are carried.
  std::vector<AttributeCandidate> offered;
  std::vector<ObjAttribute> sources;
  const auto offer = [&](const char* name, ObjSource source, int component) {
    offered.push_back({name, AttributeType::f32});
    sources.push_back({source, component});
  };
  if (coloured) {
    offer("red", ObjSource::colour, 0);
    offer("green", ObjSource::colour, 1);
    offer("blue", ObjSource::colour, 2);
  }
  if (!values.textures.empty()) {
    offer("u", ObjSource::texture, 0);
    offer("v", ObjSource::texture, 1);
  }
  if (!values.normals.empty()) {
    offer("nx", ObjSource::normal, 0);
    offer("ny", ObjSource::normal, 1);
    offer("nz", ObjSource::normal, 2);
  }
  const std::size_t material_count = out.info.materials.names.size();
  std::vector<std::string> material_names;  // offer() keeps the pointer
  if (any_attributes && material_count > kMostMaterials) {
    out.info.not_carried.push_back(src.path() + ": " + std::to_string(material_count) +
                                   " materials (usemtl), more than the " + std::to_string(kMostMaterials) +
                                   " carried; the faces' materials are dropped");
  } else {
    for (std::size_t k = 0; k < material_count; ++k) material_names.push_back(material_attribute_name(k));
    for (std::size_t k = 0; k < material_count; ++k) offer(material_names[k].c_str(), ObjSource::material, int(k));
  }
  const std::vector<std::size_t> carried =
      carried_attributes(offered, options.attributes, src.path(), &out.info.not_carried);
  bool carry_textures = false, carry_normals = false, carry_materials = false;
  for (std::size_t i : carried) {
    carry_textures = carry_textures || sources[i].source == ObjSource::texture;
    carry_normals = carry_normals || sources[i].source == ObjSource::normal;
    carry_materials = carry_materials || sources[i].source == ObjSource::material;
  }
  if (!carry_materials) material_index.reset();
  if (uncoloured > 0)
    out.info.not_carried.push_back(src.path() + ": " + std::to_string(uncoloured) +
                                   " vertices have no colour (the first vertex has one); they count as black");

  const std::uint64_t positions = builder.count();
  std::shared_ptr<CornerVertices> corners;
  LargeArray<float> normal_sums;
  if (carry_textures || carry_materials) corners = std::make_shared<CornerVertices>(positions, place);
  if (carry_normals) normal_sums.assign_zeroed(3 * positions, place, "obj-normal-sums");
  if (corners || carry_normals)
    read_corners(src.input(), values, corners.get(), carry_textures, material_index.get(),
                 carry_normals ? &normal_sums : nullptr);
  const std::uint64_t vertices = corners ? corners->vertex_count() : positions;

  out.info.vertex_count = vertices;
  out.info.face_count = faces;
  out.info.edge_count = line_elements;
  out.info.point_count = point_elements;
  out.info.elements = {"v " + std::to_string(positions), "f " + std::to_string(faces)};
  if (line_elements > 0) out.info.elements.push_back("l " + std::to_string(line_elements));
  if (point_elements > 0) out.info.elements.push_back("p " + std::to_string(point_elements));
  if (vertices > positions)
    out.info.elements.push_back(std::string(carry_materials ? "texture and material seams: " : "texture seams: ") +
                                std::to_string(vertices - positions) + " vertices split");
  if (vertices > positions) {
    MeshInput file_positions;
    builder.finish(file_positions);
    add_split_positions(file_positions, *corners, options.temp_dir, src.path(), out);
  } else {
    builder.finish(out);
  }

  std::vector<VertexAttribute> attrs;
  for (std::size_t i : carried) attrs.push_back({offered[i].name, offered[i].type, 0, 0});
  AttributeArrayBuilder attributes(options.temp_dir, src.path(), attrs);
  std::vector<double> record(carried.size());
  for (std::uint64_t i = 0; !attrs.empty() && i < vertices; ++i) {
    const std::uint64_t p = corners ? corners->position_of(i) : i;
    const std::uint64_t texture = corners ? corners->texture_of(i) : kNoTexture;
    float normal[3] = {0, 0, 0};
    if (carry_normals) {
      for (std::size_t k = 0; k < 3; ++k) normal[k] = normal_sums[3 * p + k];
      const double l =
          std::sqrt(double(normal[0]) * normal[0] + double(normal[1]) * normal[1] + double(normal[2]) * normal[2]);
      for (float& c : normal) c = l > 0 ? float(c / l) : 0.0f;
    }
    for (std::size_t k = 0; k < carried.size(); ++k) {
      const ObjAttribute& a = sources[carried[k]];
      switch (a.source) {
        case ObjSource::colour:
          record[k] = values.colours[3 * p + std::size_t(a.component)];
          break;
        case ObjSource::texture:
          record[k] = texture == kNoTexture ? 0.0 : values.textures[2 * texture + std::size_t(a.component)];
          break;
        case ObjSource::normal:
          record[k] = normal[a.component];
          break;
        case ObjSource::material:
          record[k] = corners->material_of(i) == std::uint64_t(a.component) + 1 ? 1.0 : 0.0;
          break;
      }
    }
    attributes.add(record.data());
  }
  attributes.finish(out);
  std::shared_ptr<InputFile> file = src.input();
  std::shared_ptr<const CornerVertices> split = vertices > positions ? corners : nullptr;
  std::shared_ptr<const MaterialIndex> materials = split ? material_index : nullptr;
  reader_state(out).make_triangles = [file, split, carry_textures, materials]() -> std::unique_ptr<TriangleStream> {
    return std::make_unique<ObjTriangleStream>(file, split, carry_textures, materials);
  };
  if (!carry_materials) out.info.materials.names.clear();
}

}  // namespace oocsimp
