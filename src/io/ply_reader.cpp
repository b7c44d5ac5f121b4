// PLY reader: ascii, binary_little_endian and binary_big_endian (Turk's format).
//
// Positions: a binary, uncompressed file whose vertex records have a fixed size and
// hold x, y, z as float or double is read in place through mmap; anything else is
// converted to a temporary position array of the declared type. Faces are streamed
// record by record and fanned; other elements are skipped.

#include <cmath>
#include <cstdio>
#include <cstring>
#include <memory>
#include <string>
#include <vector>

#include "io/attribute_array.hpp"
#include "io/position_array.hpp"
#include "io/face_range.hpp"
#include "io/readers.hpp"
#include "io/text_scan.hpp"
#include "io/error_text.hpp"
#include "oocsimp/error.hpp"

namespace oocsimp {

namespace {

enum class PlyType : std::uint8_t { i8, u8, i16, u16, i32, u32, f32, f64 };
enum class PlyFormat { ascii, binary_le, binary_be };

// PlyType lists the types in AttributeType's order: one table of sizes and names.
std::size_t type_size(PlyType t) { return attribute_type_size(AttributeType(int(t))); }

bool parse_type(std::string_view s, PlyType* t) {
  static const struct {
    const char* name;
    PlyType type;
  } names[] = {{"char", PlyType::i8},   {"int8", PlyType::i8},     {"uchar", PlyType::u8},   {"uint8", PlyType::u8},
               {"short", PlyType::i16}, {"int16", PlyType::i16},   {"ushort", PlyType::u16}, {"uint16", PlyType::u16},
               {"int", PlyType::i32},   {"int32", PlyType::i32},   {"uint", PlyType::u32},   {"uint32", PlyType::u32},
               {"float", PlyType::f32}, {"float32", PlyType::f32}, {"double", PlyType::f64}, {"float64", PlyType::f64}};
  for (const auto& n : names)
    if (s == n.name) {
      *t = n.type;
      return true;
    }
  return false;
}

const char* type_name(PlyType t) { return attribute_type_name(AttributeType(int(t))); }

bool is_integer(PlyType t) { return t != PlyType::f32 && t != PlyType::f64; }

struct PlyProperty {
  std::string name;
  PlyType type = PlyType::f32;  // item type for lists
  bool is_list = false;
  PlyType count_type = PlyType::u8;
};

struct PlyElement {
  std::string name;
  std::uint64_t count = 0;
  std::vector<PlyProperty> props;
  bool fixed_size() const {
    for (const auto& p : props)
      if (p.is_list) return false;
    return true;
  }
  std::size_t record_size() const {  // fixed-size elements only
    std::size_t s = 0;
    for (const auto& p : props) s += type_size(p.type);
    return s;
  }
  int find(std::string_view n) const {
    for (std::size_t i = 0; i < props.size(); ++i)
      if (props[i].name == n) return int(i);
    return -1;
  }
};

struct PlyHeader {
  PlyFormat format = PlyFormat::ascii;
  std::vector<PlyElement> elements;
  std::vector<std::string> comments;
  std::uint64_t header_bytes = 0;
  int vertex = -1, face = -1;  // element indices
  int xyz[3] = {-1, -1, -1};   // property indices in the vertex element
  int indices = -1;            // list property index in the face element
};

// Loads one binary scalar, byte-swapping when needed.
template <class T>
T load(const unsigned char* p, bool swap) {
  T v;
  if (!swap || sizeof(T) == 1) {
    std::memcpy(&v, p, sizeof(T));
  } else {
    unsigned char b[sizeof(T)];
    for (std::size_t i = 0; i < sizeof(T); ++i) b[i] = p[sizeof(T) - 1 - i];
    std::memcpy(&v, b, sizeof(T));
  }
  return v;
}

double load_double(const unsigned char* p, PlyType t, bool swap) { return load_value(p, AttributeType(int(t)), swap); }

// Integer types only (checked when the header is read).
std::int64_t load_int(const unsigned char* p, PlyType t, bool swap) {
  switch (t) {
    case PlyType::i8:
      return load<std::int8_t>(p, swap);
    case PlyType::u8:
      return load<std::uint8_t>(p, swap);
    case PlyType::i16:
      return load<std::int16_t>(p, swap);
    case PlyType::u16:
      return load<std::uint16_t>(p, swap);
    case PlyType::i32:
      return load<std::int32_t>(p, swap);
    case PlyType::u32:
      return load<std::uint32_t>(p, swap);
    default:
      return 0;
  }
}

[[noreturn]] void header_error(const ByteSource& src, const std::string& what) {
  throw InputError(at_line(src.path(), src.line_number(), what));
}

// Reads a header line; the header as a whole is bounded (PLY headers are a few hundred
// bytes), and so checked while each line grows.
bool next_header_line(ByteSource& src, std::string_view* line) {
  constexpr std::uint64_t kMaxHeaderBytes = ByteSource::kMaxHeaderLine;
  constexpr const char* kTooLong = "PLY header longer than 1 MiB (missing end_header?)";
  if (src.offset() >= kMaxHeaderBytes) throw InputError(at_line(src.path(), src.line_number() + 1, kTooLong));
  return src.next_line(line, std::size_t(kMaxHeaderBytes - src.offset()), kTooLong);
}

PlyHeader read_header(ByteSource& src) {
  PlyHeader h;
  std::string_view line;
  if (!next_header_line(src, &line) || line != "ply") header_error(src, "not a PLY file (first line must be \"ply\")");
  bool have_format = false;
  for (;;) {
    if (!next_header_line(src, &line)) header_error(src, "end of file inside the header (missing end_header)");
    TokenScanner t(line);
    std::string_view kw = t.next();
    if (kw.empty()) continue;
    if (kw == "comment" || kw == "obj_info") {
      h.comments.emplace_back(line);
    } else if (kw == "format") {
      if (have_format) header_error(src, "second format line");
      std::string_view f = t.next(), v = t.next();
      if (f == "ascii")
        h.format = PlyFormat::ascii;
      else if (f == "binary_little_endian")
        h.format = PlyFormat::binary_le;
      else if (f == "binary_big_endian")
        h.format = PlyFormat::binary_be;
      else
        header_error(src, "unknown PLY format " + quoted(f));
      if (v != "1.0" && v != "1") header_error(src, "unsupported PLY version " + quoted(v) + " (expected 1.0)");
      have_format = true;
    } else if (kw == "element") {
      PlyElement e;
      e.name = std::string(t.next());
      if (e.name.empty() || !parse_uint(t.next(), &e.count) || !t.at_end())
        header_error(src, "malformed element line (expected \"element NAME COUNT\")");
      for (const PlyElement& before : h.elements)
        if (before.name == e.name) header_error(src, "element " + quoted(e.name) + " declared twice");
      h.elements.push_back(std::move(e));
    } else if (kw == "property") {
      if (h.elements.empty()) header_error(src, "property before any element");
      PlyProperty p;
      std::string_view ty = t.next();
      if (ty == "list") {
        p.is_list = true;
        std::string_view ct = t.next(), it = t.next();
        if (!parse_type(ct, &p.count_type)) header_error(src, "unknown list count type " + quoted(ct));
        if (!is_integer(p.count_type)) header_error(src, "list count type must be an integer type");
        if (!parse_type(it, &p.type)) header_error(src, "unknown list item type " + quoted(it));
      } else if (!parse_type(ty, &p.type)) {
        header_error(src, "unknown property type " + quoted(ty));
      }
      p.name = std::string(t.next());
      if (p.name.empty() || !t.at_end()) header_error(src, "malformed property line");
      PlyElement& e = h.elements.back();
      if (e.find(p.name) >= 0)
        header_error(src, "property " + quoted(p.name) + " declared twice in element " + quoted(e.name));
      e.props.push_back(std::move(p));
    } else if (kw == "end_header") {
      break;
    } else {
      header_error(src, "unknown header keyword " + quoted(kw));
    }
  }
  if (!have_format) header_error(src, "header has no format line");
  h.header_bytes = src.offset();

  for (std::size_t i = 0; i < h.elements.size(); ++i) {
    if (h.elements[i].name == "vertex" && h.vertex < 0) h.vertex = int(i);
    if (h.elements[i].name == "face" && h.face < 0) h.face = int(i);
  }
  if (h.vertex < 0) throw InputError(src.path() + ": PLY header declares no vertex element");
  const PlyElement& v = h.elements[h.vertex];
  const char* axes[3] = {"x", "y", "z"};
  for (int k = 0; k < 3; ++k) {
    h.xyz[k] = v.find(axes[k]);
    if (h.xyz[k] < 0 || v.props[h.xyz[k]].is_list)
      throw InputError(src.path() + ": PLY vertex element has no scalar property \"" + axes[k] + "\"");
  }
  if (h.face >= 0) {
    const PlyElement& f = h.elements[h.face];
    h.indices = f.find("vertex_indices");
    if (h.indices < 0) h.indices = f.find("vertex_index");
    if (h.indices < 0 || !f.props[h.indices].is_list)
      throw InputError(src.path() + ": PLY face element has no vertex_indices list");
    if (!is_integer(f.props[h.indices].type))
      throw InputError(src.path() + ": PLY face indices must have an integer type");
  }
  return h;
}

// Reads the records of one element from a ByteSource, binary or ascii. Positions in
// errors are byte offsets (binary) or line numbers (ascii).
class ElementReader {
 public:
  ElementReader(ByteSource& src, const PlyHeader& h) : src_(src), h_(h), swap_(h.format == PlyFormat::binary_be) {}

  // Skips a whole element.
  void skip(const PlyElement& e) {
    if (h_.format != PlyFormat::ascii && e.fixed_size()) {
      std::uint64_t bytes = e.count * e.record_size();
      if (e.record_size() != 0 && bytes / e.record_size() != e.count)
        throw InputError(at_byte(src_.path(), src_.offset(), "element " + quoted(e.name) + " count overflows"));
      src_.skip(bytes, ("element " + quoted(e.name)).c_str());
      return;
    }
    for (std::uint64_t i = 0; i < e.count; ++i) read_record(e, -1, nullptr, nullptr);
  }

  // Reads one record; scalar values of properties listed in `want` (-1 terminated
  // list of property indices, or null) go to `values`; the items of list property
  // `list_prop` go to `list`.
  void read_record(const PlyElement& e, int list_prop, std::vector<std::uint64_t>* list, double* values,
                   const int* want = nullptr, int nwant = 0) {
    record_start_ = h_.format == PlyFormat::ascii ? src_.line_number() + 1 : src_.offset();
    if (h_.format == PlyFormat::ascii)
      read_ascii(e, list_prop, list, values, want, nwant);
    else
      read_binary(e, list_prop, list, values, want, nwant);
  }

  [[noreturn]] void fail(const std::string& what) const {
    if (h_.format == PlyFormat::ascii) throw InputError(at_line(src_.path(), record_start_, what));
    throw InputError(at_byte(src_.path(), record_start_, what));
  }
  /// Where the last record read starts: "line N" (ascii) or "byte N".
  std::string record_position() const {
    return (h_.format == PlyFormat::ascii ? "line " : "byte ") + std::to_string(record_start_);
  }

 private:
  const unsigned char* need(std::size_t n, const PlyElement& e) {
    const unsigned char* p = src_.peek(n);
    if (!p) fail("unexpected end of file in element " + quoted(e.name) + " (truncated body?)");
    return p;
  }

  void check_index(std::int64_t v, PlyType t) {
    if (v < 0) fail("negative vertex index " + std::to_string(v));
    (void)t;
  }

  void read_binary(const PlyElement& e, int list_prop, std::vector<std::uint64_t>* list, double* values,
                   const int* want, int nwant) {
    for (int pi = 0; pi < int(e.props.size()); ++pi) {
      const PlyProperty& p = e.props[pi];
      if (!p.is_list) {
        std::size_t sz = type_size(p.type);
        const unsigned char* b = need(sz, e);
        for (int w = 0; w < nwant; ++w)
          if (want[w] == pi) values[w] = load_double(b, p.type, swap_);
        src_.consume(sz);
        continue;
      }
      std::size_t csz = type_size(p.count_type);
      std::int64_t count = load_int(need(csz, e), p.count_type, swap_);
      src_.consume(csz);
      if (count < 0) fail("negative list count " + std::to_string(count));
      if (std::uint64_t(count) > kMaxPolygonCorners)
        fail("list count " + std::to_string(count) + " is implausibly large");
      std::size_t isz = type_size(p.type);
      if (pi == list_prop) {
        list->clear();
        for (std::int64_t k = 0; k < count; ++k) {
          std::int64_t v = load_int(need(isz, e), p.type, swap_);
          src_.consume(isz);
          check_index(v, p.type);
          list->push_back(std::uint64_t(v));
        }
      } else {
        src_.skip(std::uint64_t(count) * isz, "list items");
      }
    }
  }

  void read_ascii(const PlyElement& e, int list_prop, std::vector<std::uint64_t>* list, double* values, const int* want,
                  int nwant) {
    std::string_view line;
    do {
      if (!src_.next_line(&line)) fail("unexpected end of file in element " + quoted(e.name));
      record_start_ = src_.line_number();
    } while (TokenScanner(line).at_end());  // tolerate blank lines
    TokenScanner t(line);
    for (int pi = 0; pi < int(e.props.size()); ++pi) {
      const PlyProperty& p = e.props[pi];
      if (!p.is_list) {
        std::string_view tok = t.next();
        if (tok.empty()) fail("too few values in " + quoted(e.name) + " record (missing " + quoted(p.name) + ")");
        bool wanted = false;
        for (int w = 0; w < nwant; ++w)
          if (want[w] == pi) {
            wanted = true;
            if (!parse_double(tok, &values[w])) fail("malformed number " + quoted(tok) + " for " + quoted(p.name));
          }
        if (!wanted) {
          double dummy;
          if (!parse_double(tok, &dummy)) fail("malformed number " + quoted(tok) + " for " + quoted(p.name));
        }
        continue;
      }
      std::int64_t count;
      std::string_view tok = t.next();
      if (!parse_int(tok, &count)) fail("malformed list count " + quoted(tok));
      if (count < 0) fail("negative list count " + std::to_string(count));
      if (std::uint64_t(count) > kMaxPolygonCorners)
        fail("list count " + std::to_string(count) + " is implausibly large");
      if (pi == list_prop) list->clear();
      for (std::int64_t k = 0; k < count; ++k) {
        tok = t.next();
        if (tok.empty()) fail("list has fewer items than its count " + std::to_string(count));
        if (pi == list_prop) {
          std::int64_t v;
          if (!parse_int(tok, &v)) fail("malformed vertex index " + quoted(tok));
          check_index(v, p.type);
          list->push_back(std::uint64_t(v));
        }
      }
    }
    if (!t.at_end()) fail("extra values at the end of a " + quoted(e.name) + " record");
  }

  ByteSource& src_;
  const PlyHeader& h_;
  bool swap_;
  std::uint64_t record_start_ = 0;
};

// Once the elements before `next` have been read: the elements that follow must be
// complete, and nothing may follow them. Lines of blanks after an ascii body are
// tolerated (editors add a final newline); in binary, any byte is trailing data.
void check_no_trailing_data(ByteSource& src, const PlyHeader& h);

void check_nothing_follows(ByteSource& src, ElementReader& reader, const PlyHeader& h, std::size_t next) {
  for (std::size_t i = next; i < h.elements.size(); ++i) reader.skip(h.elements[i]);
  check_no_trailing_data(src, h);
}

// Nothing but blank lines (ascii) or nothing at all (binary) after the last element.
void check_no_trailing_data(ByteSource& src, const PlyHeader& h) {
  if (h.format == PlyFormat::ascii) {
    std::string_view line;
    while (src.next_line(&line))
      if (!TokenScanner(line).at_end())
        throw InputError(at_line(src.path(), src.line_number(), "trailing data after the last element"));
  } else if (!src.at_end()) {
    throw InputError(at_byte(src.path(), src.offset(), "trailing data after the last element"));
  }
}

// Whether the faces have the common binary layout, "property list uchar int|uint
// vertex_indices" alone: a triangle is then a record of FixedFaceTable::kStride bytes.
bool fixed_triangle_layout(const PlyHeader& h) {
  if (h.format == PlyFormat::ascii || h.face < 0) return false;
  const PlyElement& f = h.elements[h.face];
  const PlyProperty& p = f.props[h.indices];
  return f.props.size() == 1 && p.count_type == PlyType::u8 && (p.type == PlyType::i32 || p.type == PlyType::u32);
}

// Streams the face element's polygons as fanned triangles.
class PlyTriangleStream : public TriangleStream {
 public:
  PlyTriangleStream(std::shared_ptr<const PlyHeader> h, std::shared_ptr<InputFile> file, std::uint64_t vertex_count)
      : h_(std::move(h)), src_(std::move(file)), reader_(src_, *h_), vertex_count_(vertex_count) {
    if (h_->format == PlyFormat::ascii) {
      // Read the header as lines, so that error line numbers count from the file's start.
      std::string_view line;
      while (src_.offset() < h_->header_bytes && next_header_line(src_, &line)) {
      }
    } else {
      src_.skip(h_->header_bytes, "header");
    }
    // Without faces the stream only reads what follows the vertices (edges, points).
    const int first = h_->face >= 0 ? h_->face : h_->vertex + 1;
    for (int i = 0; i < first; ++i) reader_.skip(h_->elements[i]);
    if (h_->face < 0) return;
    remaining_ = h_->elements[h_->face].count;
    // The common binary layout gets a direct path for its triangles.
    fast_ = fixed_triangle_layout(*h_);
    fast_signed_ = h_->elements[h_->face].props[h_->indices].type == PlyType::i32;
  }

  std::size_t read(std::uint64_t* out, std::size_t max) override {
    if (h_->face < 0) {
      if (!finished_) finish();
      return 0;
    }
    const PlyElement& face = h_->elements[h_->face];
    const bool swap = h_->format == PlyFormat::binary_be;
    std::size_t n = 0;
    while (n < max) {
      if (fan_.pending()) {
        n += fan_.emit(out + 3 * n, max - n);
        continue;
      }
      if (fast_) {
        const unsigned char* rec;
        while (n < max && remaining_ > 0 && (rec = src_.peek(FixedFaceTable::kStride)) != nullptr && rec[0] == 3) {
          std::uint32_t v[3];
          fixed_face_indices(rec, swap, v);
          for (int k = 0; k < 3; ++k) {
            if (v[k] >= vertex_count_)
              throw InputError(
                  at_byte(src_.path(), src_.offset(), fixed_face_index_problem(v[k], fast_signed_, vertex_count_)));
            out[3 * n + k] = v[k];
          }
          src_.consume(FixedFaceTable::kStride);
          --remaining_;
          ++n;
        }
        if (n == max) break;
      }
      if (remaining_ == 0) {
        if (!finished_) finish();
        break;
      }
      reader_.read_record(face, h_->indices, &fan_.polygon(), nullptr);
      --remaining_;
      auto& poly = fan_.polygon();
      for (std::uint64_t v : poly)
        if (v >= vertex_count_)
          reader_.fail("vertex index " + std::to_string(v) + " out of range (" + std::to_string(vertex_count_) +
                       " vertices)");
      if (poly.size() < 3) {
        ++skipped_;
        poly.clear();
      }
      fan_.start();
    }
    return n;
  }
  std::uint64_t bytes_consumed() const override { return src_.raw_consumed(); }
  SkippedFaces skipped() const override { return {skipped_, 0, 0}; }
  void set_primitive_sink(PrimitiveSink sink) override { primitives_.set_sink(std::move(sink)); }

 private:
  // After the faces: the thick edges and points to the sink, the rest skipped, and
  // nothing after the last element.
  void finish() {
    finished_ = true;
    const int first = h_->face >= 0 ? h_->face + 1 : h_->vertex + 1;
    for (std::size_t i = std::size_t(first); i < h_->elements.size(); ++i)
      if (!(primitives_.wanted() && read_primitives(h_->elements[i]))) reader_.skip(h_->elements[i]);
    primitives_.flush();
    check_no_trailing_data(src_, *h_);
  }

  // Element "edge" (vertex1, vertex2, optional thickness) or "point" (vertex,
  // optional thickness) to the sink; false for any other element.
  bool read_primitives(const PlyElement& e) {
    const bool edge = e.name == "edge";
    if (!edge && e.name != "point") return false;
    int want[3] = {e.find(edge ? "vertex1" : "vertex"), edge ? e.find("vertex2") : 0, e.find("thickness")};
    for (int k = 0; k < 3; ++k)
      if (want[k] >= 0 && e.props[std::size_t(want[k])].is_list) want[k] = -1;
    if (want[0] < 0 || want[1] < 0) return false;  // not an element of ours: skipped
    double values[3] = {0, 0, 0};
    for (std::uint64_t i = 0; i < e.count; ++i) {
      reader_.read_record(e, -1, nullptr, values, want, 3);
      const std::uint64_t a = vertex_index(values[0]), b = edge ? vertex_index(values[1]) : a;
      const double t = want[2] >= 0 && std::isfinite(values[2]) && values[2] > 0 ? values[2] : 0.0;
      primitives_.add(a, b, float(t));
    }
    return true;
  }

  std::uint64_t vertex_index(double v) const {
    if (!(v >= 0 && v < double(vertex_count_) && v == std::floor(v)))
      reader_.fail("vertex index " + format_value(v) + " out of range (" + std::to_string(vertex_count_) +
                   " vertices)");
    return std::uint64_t(v);
  }
  static std::string format_value(double v) {
    char buf[32];
    std::snprintf(buf, sizeof buf, "%.17g", v);
    return buf;
  }

  std::shared_ptr<const PlyHeader> h_;
  bool fast_ = false, fast_signed_ = false;
  ByteSource src_;
  ElementReader reader_;
  std::uint64_t vertex_count_;
  std::uint64_t remaining_ = 0;
  std::uint64_t skipped_ = 0;
  bool finished_ = false;
  FanTriangulator fan_;
  PrimitiveBatch primitives_;
};

class EmptyTriangleStream : public TriangleStream {
 public:
  std::size_t read(std::uint64_t*, std::size_t) override { return 0; }
  std::uint64_t bytes_consumed() const override { return 0; }
};

// The bounds of the mapped positions, and where the first non-finite one is.
void scan_mapped_positions(MeshInput& out, std::uint64_t vertex_offset) {
  scan_positions(out);
  if (out.info.non_finite_vertices > 0)
    out.info.first_non_finite_position =
        "byte " + std::to_string(vertex_offset + out.info.first_non_finite_vertex * out.positions.stride);
}

std::string describe(const PlyElement& e) {
  std::string s = e.name + " " + std::to_string(e.count) + " (";
  for (std::size_t i = 0; i < e.props.size(); ++i) {
    const PlyProperty& p = e.props[i];
    if (i) s += ", ";
    s += p.name + " ";
    if (p.is_list) s += std::string("list ") + type_name(p.count_type) + " ";
    s += type_name(p.type);
  }
  return s + ")";
}

// The vertex element's scalar properties other than x, y, z, with their indices, and
// what the input has that no attribute can carry (list properties of vertices,
// properties of faces besides the index list).
struct VertexCandidates {
  std::vector<AttributeCandidate> candidates;
  std::vector<int> property;  // index in the vertex element, per candidate
};

VertexCandidates vertex_candidates(const PlyHeader& h, const std::string& path, std::vector<std::string>* notes) {
  VertexCandidates c;
  const PlyElement& v = h.elements[h.vertex];
  std::string lists;
  for (int pi = 0; pi < int(v.props.size()); ++pi) {
    if (pi == h.xyz[0] || pi == h.xyz[1] || pi == h.xyz[2]) continue;
    const PlyProperty& p = v.props[pi];
    if (p.is_list) {
      lists += (lists.empty() ? "" : ", ") + p.name;
      continue;
    }
    c.candidates.push_back({p.name, AttributeType(int(p.type))});  // PlyType and AttributeType list the same types
    c.property.push_back(pi);
  }
  if (!lists.empty()) notes->push_back(path + ": vertex list properties (" + lists + ") are not carried");
  if (h.face >= 0) {
    const PlyElement& f = h.elements[h.face];
    std::string others;
    for (int pi = 0; pi < int(f.props.size()); ++pi)
      if (pi != h.indices) others += (others.empty() ? "" : ", ") + f.props[pi].name;
    if (!others.empty())
      notes->push_back(path + ": face properties (" + others +
                       ") are not carried: clustering keeps a triangle only where three clusters meet, per vertex");
  }
  return c;
}

// The faces as a FixedFaceTable, when they are the last element, the common binary
// layout alone and exactly fill the file from `after_vertices` on (elements between
// the vertices and the faces of fixed size): then, once every record is checked to
// hold a triangle, the records are the whole stream. Empty otherwise.
FixedFaceTable fixed_face_table(const PlyHeader& h, std::uint64_t after_vertices, const MappedFile& file) {
  FixedFaceTable table;
  if (h.face < 0 || std::size_t(h.face) + 1 != h.elements.size() || h.face < h.vertex) return table;
  std::uint64_t offset = after_vertices;
  for (int i = h.vertex + 1; i < h.face; ++i) {
    const PlyElement& e = h.elements[i];
    if (!e.fixed_size() ||
        (e.record_size() != 0 && e.count > (file.size() - std::min(offset, file.size())) / e.record_size()))
      return table;
    offset += e.count * e.record_size();
  }
  const PlyElement& f = h.elements[h.face];
  if (!fixed_triangle_layout(h) || offset > file.size() ||
      (file.size() - offset) / FixedFaceTable::kStride != f.count ||
      (file.size() - offset) % FixedFaceTable::kStride != 0)
    return table;
  table.base = file.data() + offset;
  table.count = f.count;
  table.file_offset = offset;
  table.swap = h.format == PlyFormat::binary_be;
  table.signed_index = f.props[h.indices].type == PlyType::i32;
  return table;
}

}  // namespace

void open_ply(ByteSource& src, const OpenOptions& options, ProgressPhase& progress, MeshInput& out) {
  auto h = std::make_shared<PlyHeader>(read_header(src));
  static const char* fmt_names[] = {"ascii", "binary_little_endian", "binary_big_endian"};
  out.info.format = std::string("ply ") + fmt_names[int(h->format)];
  for (const auto& e : h->elements) out.info.elements.push_back(describe(e));
  out.info.comments = h->comments;
  const PlyElement& v = h->elements[h->vertex];
  out.info.vertex_count = v.count;
  out.info.face_count = h->face >= 0 ? h->elements[h->face].count : 0;
  for (const PlyElement& e : h->elements) {
    if (e.name == "edge") out.info.edge_count = e.count;
    if (e.name == "point") out.info.point_count = e.count;
  }

  // Where the vertex element starts, if every element before it has a fixed size.
  bool binary = h->format != PlyFormat::ascii;
  std::uint64_t vertex_offset = h->header_bytes;
  bool offset_known = binary;
  for (int i = 0; i < h->vertex && offset_known; ++i) {
    const PlyElement& e = h->elements[i];
    if (!e.fixed_size()) {
      offset_known = false;
    } else {
      std::uint64_t rs = e.record_size();
      if (rs != 0 && e.count > (~std::uint64_t(0) - vertex_offset) / rs)
        throw InputError(at_byte(src.path(), vertex_offset, "element " + quoted(e.name) + " count overflows"));
      vertex_offset += e.count * rs;
    }
  }
  PlyType xt = v.props[h->xyz[0]].type;
  bool same_float_type =
      (xt == PlyType::f32 || xt == PlyType::f64) && v.props[h->xyz[1]].type == xt && v.props[h->xyz[2]].type == xt;
  std::size_t next_element = 0;  // the first element that src has not read yet
  const VertexCandidates offered = vertex_candidates(*h, src.path(), &out.info.not_carried);
  const std::vector<std::size_t> carried =
      carried_attributes(offered.candidates, options.attributes, src.path(), &out.info.not_carried);
  std::vector<VertexAttribute> carried_attrs;
  std::vector<int> want(h->xyz, h->xyz + 3);  // x, y, z, then the carried properties
  for (std::size_t i : carried) {
    carried_attrs.push_back({offered.candidates[i].name, offered.candidates[i].type, 0, 0});
    want.push_back(offered.property[i]);
  }
  if (offset_known && src.content_size_known() && v.fixed_size() && same_float_type) {
    std::size_t rs = v.record_size();
    // Compared by division: vertex_offset + count * rs may wrap around 2^64.
    if (vertex_offset > src.file_size() || v.count > (src.file_size() - vertex_offset) / rs)
      throw InputError(at_byte(src.path(), src.file_size(),
                               "file ends inside the vertex element (header declares " + std::to_string(v.count) +
                                   " vertices of " + std::to_string(rs) + " bytes from byte " +
                                   std::to_string(vertex_offset) + ")"));
    reader_state(out).position_map = std::make_unique<MappedFile>(src.input()->fd(), src.file_size(), src.path());
    PositionArray& pa = out.positions;
    pa.base = reader_state(out).position_map->data() + vertex_offset;
    pa.count = v.count;
    pa.stride = rs;
    pa.type = xt == PlyType::f32 ? ScalarType::f32 : ScalarType::f64;
    pa.swap = h->format == PlyFormat::binary_be;
    for (int k = 0; k < 3; ++k) {
      std::size_t off = 0;
      for (int pi = 0; pi < h->xyz[k]; ++pi) off += type_size(v.props[pi].type);
      pa.offset[k] = off;
    }
    out.info.positions_in_place = true;
    if (!carried_attrs.empty()) {
      AttributeArray& aa = out.attributes;
      aa.count = v.count;
      aa.swap = pa.swap;
      for (std::size_t k = 0; k < carried.size(); ++k) {
        std::size_t off = 0;
        for (int pi = 0; pi < want[3 + k]; ++pi) off += type_size(v.props[pi].type);
        aa.add(carried_attrs[k], pa.base + off, rs);
      }
    }
    scan_mapped_positions(out, vertex_offset);  // and the attributes' ranges
    out.fixed_faces = fixed_face_table(*h, vertex_offset + v.count * rs, *reader_state(out).position_map);
  } else {
    ElementReader reader(src, *h);
    for (int i = 0; i < h->vertex; ++i) reader.skip(h->elements[i]);
    PositionArrayBuilder builder(options.temp_dir, src.path());
    AttributeArrayBuilder attribute_builder(options.temp_dir, src.path(), carried_attrs);
    if (same_float_type)
      builder.declare(xt == PlyType::f32 ? ScalarType::f32 : ScalarType::f64);
    else if (xt == PlyType::f64 || v.props[h->xyz[1]].type == PlyType::f64 || v.props[h->xyz[2]].type == PlyType::f64)
      builder.declare(ScalarType::f64);
    if (src.content_size_known()) {
      // A record takes at least this many bytes, so the file's size bounds the vertex
      // count: a header claiming 10^12 vertices on a small file is a truncated file
      // (InputError below), not a request for terabytes of temporary space.
      std::uint64_t min_record = 0;
      for (const PlyProperty& p : v.props)
        min_record += binary ? type_size(p.is_list ? p.count_type : p.type) : 2;  // ascii: a digit and a blank
      builder.expect(std::min(v.count, src.file_size() / std::max<std::uint64_t>(min_record, 1)));
      attribute_builder.expect(std::min(v.count, src.file_size() / std::max<std::uint64_t>(min_record, 1)));
    }
    std::vector<double> values(want.size());
    for (std::uint64_t i = 0; i < v.count; ++i) {
      reader.read_record(v, -1, nullptr, values.data(), want.data(), int(want.size()));
      builder.add(values[0], values[1], values[2], [&] { return reader.record_position(); });
      attribute_builder.add(values.data() + 3);
      if ((i & 0xFFFF) == 0) progress.set(src.raw_consumed());
    }
    builder.finish(out);
    attribute_builder.finish(out);
    next_element = std::size_t(h->vertex) + 1;
  }

  std::uint64_t vcount = v.count;
  if (h->face < 0) {
    // A stream that reads nothing may never reach the end, so the end is checked here.
    ElementReader reader(src, *h);
    check_nothing_follows(src, reader, *h, next_element);
  }
  if (h->face >= 0 || out.info.edge_count > 0 || out.info.point_count > 0) {
    std::shared_ptr<InputFile> file = src.input();
    reader_state(out).make_triangles = [h, file, vcount]() -> std::unique_ptr<TriangleStream> {
      return std::make_unique<PlyTriangleStream>(h, file, vcount);
    };
  } else {
    reader_state(out).make_triangles = []() -> std::unique_ptr<TriangleStream> {
      return std::make_unique<EmptyTriangleStream>();
    };
  }
}

}  // namespace oocsimp
