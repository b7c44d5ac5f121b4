#include "hierarchy/hierarchy_file.hpp"

#include <algorithm>
#include <cstring>
#include <stdexcept>
#include <vector>

#include "hierarchy/hierarchy_steps.hpp"
#include "io/attribute_array.hpp"
#include "io/content_hash.hpp"
#include "oocsimp/error.hpp"

namespace oocsimp {

namespace {

constexpr char kMagic[8] = {'o', 'o', 'c', 's', '-', '4', 'k', '\n'};
constexpr std::size_t kHeaderBytes = 64, kHashedHeaderBytes = 56;
constexpr std::size_t kLevelBytes = 32;
constexpr std::size_t kBlockBytes = std::size_t(1) << 20;  // one checksum per block of the body
constexpr std::uint8_t kSwapHead = 0x80;

template <class T>
void put(std::string* out, T value) {
  char bytes[sizeof(T)];
  std::memcpy(bytes, &value, sizeof(T));
  out->append(bytes, sizeof(T));
}

// Reads the bytes up to `end` front to back, naming the byte of any shortfall.
class Reader {
 public:
  Reader(const std::string& bytes, std::size_t at, const std::string& name, std::size_t end = ~std::size_t(0))
      : bytes_(bytes), at_(at), end_(std::min(end, bytes.size())), name_(name) {}
  template <class T>
  T get() {
    T value;
    std::memcpy(&value, take(sizeof(T)), sizeof(T));
    return value;
  }
  /// The next `n` bytes, passed over.
  const unsigned char* take(std::size_t n) {
    if (end_ - at_ < n) fail(at_, end_ < bytes_.size() ? "runs past the end of the body" : "truncated");
    const unsigned char* p = reinterpret_cast<const unsigned char*>(bytes_.data()) + at_;
    at_ += n;
    return p;
  }
  std::size_t at() const { return at_; }
  [[noreturn]] void fail(std::size_t byte, const std::string& what) const {
    throw InputError(name_ + ": byte " + std::to_string(byte) + ": " + what);
  }

 private:
  const std::string& bytes_;
  std::size_t at_, end_;
  const std::string& name_;
};

// Bytes of the attribute section (version 2): the count, each attribute's type, name
// and range, then each vertex's values in the attributes' types.
std::size_t attribute_section_bytes(const AttributeValues& a, std::size_t vertices) {
  std::size_t bytes = 4, per_vertex = 0;
  for (const VertexAttribute& attribute : a.attributes) {
    bytes += 4 + attribute.name.size() + 16;
    per_vertex += attribute_type_size(attribute.type);
  }
  return bytes + vertices * per_vertex;
}

}  // namespace

bool storable_attribute_name(const std::string& name) {
  if (name.empty()) return false;
  return std::all_of(name.begin(), name.end(), storable_name_byte);
}

bool has_hierarchy_magic(const std::string& bytes) {
  return bytes.size() >= sizeof kMagic && std::memcmp(bytes.data(), kMagic, sizeof kMagic) == 0;
}

std::string hierarchy_file_bytes(const MeshHierarchy& h) {
  // The header carries the body's size, so the body is written after it in place.
  const bool f64 = h.precision == ScalarType::f64;
  std::size_t body_bytes = h.levels.size() * 32 + h.positions.size() * (f64 ? 8 : 4) + h.triangles.size() * 4;
  for (const HierarchyRecord& r : h.records) body_bytes += 9 + 4 * std::size_t(r.face_count);
  const std::size_t vertices = h.positions.size() / 3, k = h.attributes.attributes.size();
  if (h.attributes.values.size() != vertices * k)
    throw std::logic_error("hierarchy_file_bytes: attribute values for every vertex");
  body_bytes += attribute_section_bytes(h.attributes, vertices);
  const std::size_t blocks = (body_bytes + kBlockBytes - 1) / kBlockBytes;
  std::string out(kMagic, sizeof kMagic);
  put<std::uint32_t>(&out, kHierarchyFileVersion);
  put<std::uint32_t>(&out, f64 ? 1 : 0);
  put<std::uint64_t>(&out, h.positions.size() / 3);
  put<std::uint64_t>(&out, h.triangles.size() / 3);
  put<std::uint64_t>(&out, h.records.size());
  put<std::uint64_t>(&out, h.levels.size());
  put<std::uint64_t>(&out, body_bytes);
  put<std::uint64_t>(&out, content_hash(out.data(), out.size()));
  const std::size_t body_at = out.size();
  out.reserve(body_at + body_bytes + 8 * blocks);

  for (const HierarchyLevel& level : h.levels) {
    put<std::uint64_t>(&out, level.end_record);
    put<std::uint64_t>(&out, level.triangles);
    put<std::uint64_t>(&out, level.vertices);
    put<float>(&out, level.largest_error);
    put<std::uint32_t>(&out, 0);
  }
  // The arrays through a buffer: appending value by value costs more than the rest.
  std::vector<char> buffer(std::size_t(1) << 16);
  std::size_t held = 0;
  auto add_bytes = [&](const void* bytes, std::size_t n) {
    if (held + n > buffer.size()) {
      out.append(buffer.data(), held);
      held = 0;
    }
    std::memcpy(buffer.data() + held, bytes, n);
    held += n;
  };
  auto add = [&](auto value) { add_bytes(&value, sizeof value); };
  for (double x : h.positions)
    if (f64)
      add(x);
    else
      add(float(x));
  for (std::uint32_t v : h.triangles) add(v);
  for (const HierarchyRecord& r : h.records) {
    add(std::uint8_t(r.swap ? kSwapHead : r.face_count));
    add(r.error);
    add(r.vertex);
    for (int i = 0; i < r.face_count; ++i) add(r.faces[i]);
  }
  add(std::uint32_t(k));
  for (const VertexAttribute& a : h.attributes.attributes) {
    if (a.name.size() > 0xffff)
      throw InputError("a vertex attribute's name of " + std::to_string(a.name.size()) +
                       " bytes: a .4k file holds names of up to 65535");
    add(std::uint8_t(a.type));
    add(std::uint8_t(0));
    add(std::uint16_t(a.name.size()));
    for (const char c : a.name) add(c);
    add(a.min);
    add(a.max);
  }
  for (std::size_t v = 0; v < vertices; ++v)
    for (std::size_t j = 0; j < k; ++j) {
      const AttributeType type = h.attributes.attributes[j].type;
      unsigned char stored[8];
      store_attribute(h.attributes.values[v * k + j], type, stored);
      add_bytes(stored, attribute_type_size(type));
    }
  out.append(buffer.data(), held);
  if (out.size() != body_at + body_bytes) throw std::logic_error("hierarchy_file_bytes: the body's size");
  for (std::size_t at = 0; at < body_bytes; at += kBlockBytes)
    put<std::uint64_t>(&out, content_hash(out.data() + body_at + at, std::min(kBlockBytes, body_bytes - at)));
  return out;
}

namespace {

// The attribute section (version 2), which must end by `body_end`.
void read_attributes(Reader* in, std::uint64_t vertices, std::size_t body_end, AttributeValues* out) {
  const std::size_t count_at = in->at();
  const std::uint32_t k = in->get<std::uint32_t>();
  if (k > 4096) in->fail(count_at, std::to_string(k) + " vertex attributes: more than any mesh has");
  out->attributes.resize(k);
  std::size_t per_vertex = 0;
  for (VertexAttribute& a : out->attributes) {
    const std::size_t at = in->at();
    const std::uint8_t type = in->get<std::uint8_t>();
    if (type > std::uint8_t(AttributeType::f64))
      in->fail(at, "an attribute of no known type (" + std::to_string(type) + ")");
    if (in->get<std::uint8_t>() != 0) in->fail(at + 1, "an attribute's reserved byte is not 0");
    a.type = AttributeType(type);
    const std::uint16_t length = in->get<std::uint16_t>();
    a.name.resize(length);
    for (char& c : a.name) c = in->get<char>();
    // The name goes into the header of every mesh extracted (PLY): it must be one.
    bool repeated = a.name == "x" || a.name == "y" || a.name == "z";
    for (const VertexAttribute* b = out->attributes.data(); b != &a && !repeated; ++b) repeated = b->name == a.name;
    if (!storable_attribute_name(a.name) || repeated)
      in->fail(at + 4, "the attribute name \"" + (storable_attribute_name(a.name) ? a.name : std::string("?")) +
                           "\" is " +
                           (repeated ? "x, y, z or an earlier attribute's" : "empty or holds blanks or control bytes"));
    a.min = in->get<double>();
    a.max = in->get<double>();
    per_vertex += attribute_type_size(a.type);
  }
  // The count must fit what is left before anything is sized by it.
  const std::size_t left = body_end > in->at() ? body_end - in->at() : 0;
  if (per_vertex > 0 && vertices > left / per_vertex)
    in->fail(in->at(), "the attribute values of " + std::to_string(vertices) + " vertices do not fit the body");
  out->values.resize(std::size_t(vertices) * k);
  for (std::size_t v = 0; v < vertices; ++v)
    for (std::size_t j = 0; j < k; ++j)
      out->values[v * k + j] =
          load_value(in->take(attribute_type_size(out->attributes[j].type)), out->attributes[j].type, false);
}

}  // namespace

MeshHierarchy parse_hierarchy_file(const std::string& bytes, const std::string& name) {
  if (!has_hierarchy_magic(bytes))
    throw InputError(name + ": byte 0: not an oocsimp hierarchy (.4k) file: it does not start with \"oocs-4k\"");
  Reader header(bytes, sizeof kMagic, name);
  const std::uint32_t version = header.get<std::uint32_t>();
  if (version < 1 || version > kHierarchyFileVersion)
    header.fail(8, ".4k version " + std::to_string(version) + ", but this oocsimp reads versions 1 to " +
                       std::to_string(kHierarchyFileVersion));
  const std::uint32_t precision = header.get<std::uint32_t>();
  const std::uint64_t vertices = header.get<std::uint64_t>(), triangles = header.get<std::uint64_t>();
  const std::uint64_t records = header.get<std::uint64_t>(), levels = header.get<std::uint64_t>();
  const std::uint64_t body_bytes = header.get<std::uint64_t>();
  const std::uint64_t header_hash = header.get<std::uint64_t>();
  if (content_hash(bytes.data(), kHashedHeaderBytes) != header_hash)
    header.fail(kHashedHeaderBytes, "the header does not match its checksum: the file is damaged");
  if (precision > 1) header.fail(12, "precision " + std::to_string(precision) + " is neither 0 (float) nor 1 (double)");
  const std::uint64_t blocks = (body_bytes + kBlockBytes - 1) / kBlockBytes;
  if (body_bytes > bytes.size() || blocks * 8 > bytes.size() ||
      bytes.size() != kHeaderBytes + body_bytes + blocks * 8) {
    const std::uint64_t expected = kHeaderBytes + body_bytes + blocks * 8;
    header.fail(std::min<std::uint64_t>(bytes.size(), expected),
                bytes.size() < expected
                    ? "truncated: the header says the file has " + std::to_string(expected) + " bytes"
                    : "the file goes on past its end, " + std::to_string(expected) + " bytes");
  }
  for (std::uint64_t b = 0; b < blocks; ++b) {
    const std::size_t at = kHeaderBytes + std::size_t(b) * kBlockBytes;
    const std::size_t size = std::min<std::size_t>(kBlockBytes, std::size_t(body_bytes) - std::size_t(b) * kBlockBytes);
    std::uint64_t stored;
    std::memcpy(&stored, bytes.data() + kHeaderBytes + body_bytes + 8 * b, 8);
    if (content_hash(bytes.data() + at, size) != stored)
      header.fail(at, "damaged: bytes " + std::to_string(at) + " to " + std::to_string(at + size - 1) +
                          " do not match their checksum");
  }

  MeshHierarchy h;
  h.file_version = version;
  h.precision = precision == 1 ? ScalarType::f64 : ScalarType::f32;
  const std::size_t scalar = precision == 1 ? 8 : 4;
  // The counts must fit the body before anything is sized by them.
  if (levels == 0 || levels > body_bytes / kLevelBytes || vertices > body_bytes / (3 * scalar) ||
      triangles > body_bytes / 12 || records > body_bytes / 13)
    header.fail(16, "counts that the file's " + std::to_string(body_bytes) + " bytes of body cannot hold");
  Reader in(bytes, kHeaderBytes, name, kHeaderBytes + std::size_t(body_bytes));
  h.levels.resize(std::size_t(levels));
  for (std::size_t j = 0; j < levels; ++j) {
    const std::size_t at = in.at();
    HierarchyLevel& level = h.levels[j];
    level.end_record = in.get<std::uint64_t>();
    level.triangles = in.get<std::uint64_t>();
    level.vertices = in.get<std::uint64_t>();
    level.largest_error = in.get<float>();
    in.get<std::uint32_t>();
    if (level.end_record > records || (j > 0 && level.end_record < h.levels[j - 1].end_record) ||
        (j == 0 && level.end_record != 0) || (j + 1 == levels && level.end_record != records))
      in.fail(at, "level " + std::to_string(j) + " ends at record " + std::to_string(level.end_record) +
                      ", out of order with the levels around it and the " + std::to_string(records) + " records");
  }
  h.positions.resize(std::size_t(3 * vertices));
  for (double& x : h.positions) x = precision == 1 ? in.get<double>() : double(in.get<float>());
  h.triangles.resize(std::size_t(3 * triangles));
  for (std::size_t i = 0; i < h.triangles.size(); ++i) {
    const std::size_t at = in.at();
    h.triangles[i] = in.get<std::uint32_t>();
    if (h.triangles[i] >= vertices)
      in.fail(at, "triangle " + std::to_string(i / 3) + " names vertex " + std::to_string(h.triangles[i]) + " of " +
                      std::to_string(vertices));
  }
  std::vector<std::size_t> record_at(static_cast<std::size_t>(records));
  h.records.resize(std::size_t(records));
  for (std::size_t r = 0; r < records; ++r) {
    record_at[r] = in.at();
    HierarchyRecord& record = h.records[r];
    const std::uint8_t head = in.get<std::uint8_t>();
    record.swap = head == kSwapHead;
    record.face_count = record.swap ? 2 : head;
    if (!record.swap && (head < 1 || head > 4))
      in.fail(record_at[r], "record " + std::to_string(r) + " is of no known kind (" + std::to_string(head) + ")");
    record.error = in.get<float>();
    record.vertex = in.get<std::uint32_t>();
    for (int i = 0; i < record.face_count; ++i) record.faces[i] = in.get<std::uint32_t>();
  }
  if (version >= 2) read_attributes(&in, vertices, kHeaderBytes + body_bytes, &h.attributes);
  const std::size_t body_end = kHeaderBytes + body_bytes;
  const std::string last = version >= 2 ? "the attributes" : "the records";
  if (in.at() > body_end) in.fail(body_end, last + " run past the body's end");
  if (in.at() < body_end)
    in.fail(in.at(), last + " end " + std::to_string(body_end - in.at()) + " bytes before the body does");
  const std::size_t bad = derive_faces(&h);
  if (bad < h.records.size())
    in.fail(record_at[bad],
            "record " + std::to_string(bad) +
                " replaces faces that do not exist yet, are already replaced, or do not make its shape");
  return h;
}

}  // namespace oocsimp
