#include "parts/part_file.hpp"

#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

#include <cerrno>
#include <cinttypes>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <sstream>
#include <type_traits>

#include "io/content_hash.hpp"
#include "io/error_text.hpp"
#include "oocsimp/error.hpp"

namespace oocsimp {

namespace {

constexpr char kMagic[8] = {'O', 'O', 'C', 'S', 'P', 'A', 'R', 'T'};
constexpr std::uint32_t kVersion = 4;
constexpr std::size_t kHeaderBytes = 8 + 4 + 4 + 4 + 8;  // magic, version, part, parts, manifest bytes
// A record: its kind (1 byte), the chunk (8) and the payload bytes (8), then the payload.
enum RecordKind : std::uint8_t {
  kEnd = 0,
  kVertices = 1,
  kFaces = 2,
  kTile = 3,
  kPlan = 4,
  kShares = 5,
  kFloatingPlan = 6,
  kCurvatures = 7,
  kCurvaturePlan = 8
};
constexpr std::uint64_t kSampleBytes = 1 << 20;
static_assert(std::is_trivially_copyable<PassFace>::value && std::is_trivially_copyable<PassVertex>::value &&
                  std::is_trivially_copyable<FirstPassPlan>::value &&
                  std::is_trivially_copyable<FloatingPartPlan>::value &&
                  std::is_trivially_copyable<VertexCurvatureValue>::value &&
                  std::is_trivially_copyable<CurvaturePartPlan>::value,
              "a tile's records are written as they are in memory");

std::string manifest_text(const PartManifest& m) {
  std::ostringstream s;
  s << "input " << m.input << "\n";
  s << "input_size " << m.key.size << "\n";
  s << "input_mtime_ns " << m.key.mtime_ns << "\n";
  s << "input_sample " << m.key.sample << "\n";
  s << "options " << m.options << "\n";
  s << "build " << part_file_build() << "\n";
  s << "grid " << part_hex_double(m.grid.origin.x) << ' ' << part_hex_double(m.grid.origin.y) << ' '
    << part_hex_double(m.grid.origin.z) << ' ' << part_hex_double(m.grid.cell) << ' ' << m.grid.dims[0] << ' '
    << m.grid.dims[1] << ' ' << m.grid.dims[2] << "\n";
  return s.str();
}

// The manifest from its text; false when a line is missing or malformed.
bool parse_manifest(const std::string& text, PartManifest* m) {
  std::istringstream lines(text);
  std::string line;
  int found = 0;
  while (std::getline(lines, line)) {
    const std::size_t space = line.find(' ');
    if (space == std::string::npos) return false;
    const std::string key = line.substr(0, space), value = line.substr(space + 1);
    std::istringstream v(value);
    if (key == "input") {
      m->input = value;
    } else if (key == "input_size") {
      v >> m->key.size;
    } else if (key == "input_mtime_ns") {
      v >> m->key.mtime_ns;
    } else if (key == "input_sample") {
      v >> m->key.sample;
    } else if (key == "options") {
      m->options = value;
    } else if (key == "build") {
      m->build = value;
    } else if (key == "grid") {
      std::string x, y, z, c;
      v >> x >> y >> z >> c >> m->grid.dims[0] >> m->grid.dims[1] >> m->grid.dims[2];
      m->grid.origin = {std::strtod(x.c_str(), nullptr), std::strtod(y.c_str(), nullptr),
                        std::strtod(z.c_str(), nullptr)};
      m->grid.cell = std::strtod(c.c_str(), nullptr);
    } else {
      return false;
    }
    if (v.fail()) return false;
    ++found;
  }
  return found == 7;
}

// Resized, then copied: vector::insert of a few bytes draws a false
// -Wstringop-overflow from GCC 12 in position-independent code.
template <class T>
void append(std::vector<unsigned char>* out, const T& value) {
  const std::size_t at = out->size();
  out->resize(at + sizeof(T));
  std::memcpy(out->data() + at, &value, sizeof(T));
}

template <class T>
void append_array(std::vector<unsigned char>* out, const std::vector<T>& values) {
  append(out, std::uint64_t(values.size()));
  const auto* p = reinterpret_cast<const unsigned char*>(values.data());
  out->insert(out->end(), p, p + values.size() * sizeof(T));
}

}  // namespace

InputKey input_key(const std::string& path) {
  const int fd = ::open(path.c_str(), O_RDONLY | O_CLOEXEC);
  if (fd < 0) throw IoError(system_error_text(path, "cannot open", errno));
  struct stat st;
  if (::fstat(fd, &st) != 0) {
    const int e = errno;
    ::close(fd);
    throw IoError(system_error_text(path, "cannot stat", e));
  }
  InputKey key;
  key.size = std::uint64_t(st.st_size);
  key.mtime_ns = std::int64_t(st.st_mtim.tv_sec) * 1000000000 + st.st_mtim.tv_nsec;
  ContentHash hash;
  std::vector<unsigned char> buffer(std::size_t(std::min(key.size, kSampleBytes)));
  const std::uint64_t offsets[2] = {0, key.size - buffer.size()};
  for (std::uint64_t at : offsets) {
    std::size_t done = 0;
    while (done < buffer.size()) {
      const ssize_t r = ::pread(fd, buffer.data() + done, buffer.size() - done, off_t(at + done));
      if (r < 0 && errno == EINTR) continue;
      if (r <= 0) {
        const int e = r < 0 ? errno : EIO;
        ::close(fd);
        throw IoError(system_error_text(path, "cannot read", e));
      }
      done += std::size_t(r);
    }
    hash.add(buffer.data(), buffer.size());
  }
  ::close(fd);
  key.sample = hash.digest();
  return key;
}

#ifndef OOCSIMP_VERSION
#error "OOCSIMP_VERSION comes from the CMake project version"
#endif

std::string part_hex_double(double v) {
  char buf[64];
  std::snprintf(buf, sizeof buf, "%a", v);
  return buf;
}

std::string part_file_build() {
  return std::string("oocsimp ") + OOCSIMP_VERSION + " records " + std::to_string(sizeof(VertexSum)) + " " +
         std::to_string(sizeof(Quadric)) + " " + std::to_string(sizeof(PassFace)) + " " +
         std::to_string(sizeof(PassVertex)) + " " + std::to_string(sizeof(FirstPassPlan));
}

std::string part_file_name(std::uint32_t part, std::uint32_t parts) {
  return "part-" + std::to_string(part) + "-of-" + std::to_string(parts) + ".oocpart";
}

PartWriter::PartWriter(const std::string& dir, const PartManifest& manifest)
    : dir_(dir), path_(dir + "/" + part_file_name(manifest.part, manifest.parts)), file_(dir, ".oocpart") {
  const std::string text = manifest_text(manifest);
  put(kMagic, sizeof kMagic);
  std::vector<unsigned char> head;
  append(&head, kVersion);
  append(&head, manifest.part);
  append(&head, manifest.parts);
  append(&head, std::uint64_t(text.size()));
  put(head.data(), head.size());
  put(text.data(), text.size());
}

void PartWriter::vertices(std::uint64_t chunk, const VertexChunkSums& sums) {
  std::vector<unsigned char> payload;
  append(&payload, std::uint64_t(sums.keys.size()));
  const auto* k = reinterpret_cast<const unsigned char*>(sums.keys.data());
  payload.insert(payload.end(), k, k + sums.keys.size() * sizeof(std::uint64_t));
  const auto* v = reinterpret_cast<const unsigned char*>(sums.sums.data());
  payload.insert(payload.end(), v, v + sums.sums.size() * sizeof(VertexSum));
  put_record(kVertices, chunk, payload);
}

void PartWriter::faces(std::uint64_t chunk, const FaceChunkSums& sums) {
  std::vector<unsigned char> payload;
  append(&payload, sums.triangles);
  append(&payload, std::uint64_t(sums.keys.size()));
  const auto* k = reinterpret_cast<const unsigned char*>(sums.keys.data());
  payload.insert(payload.end(), k, k + sums.keys.size() * sizeof(std::uint64_t));
  const auto* q = reinterpret_cast<const unsigned char*>(sums.quadrics.data());
  payload.insert(payload.end(), q, q + sums.quadrics.size() * sizeof(Quadric));
  append_array(&payload, sums.kept);
  append_array(&payload, sums.attribute_sums);
  put_record(kFaces, chunk, payload);
}

void PartWriter::tile(const TileOutput& tile) {
  std::vector<unsigned char> payload;
  append_array(&payload, tile.faces);
  append_array(&payload, tile.owned);
  append_array(&payload, tile.attributes);
  put_record(kTile, tiles_++, payload);
}

void PartWriter::plan(const FirstPassPlan& plan) {
  std::vector<unsigned char> payload;
  append(&payload, plan);
  put_record(kPlan, 0, payload);
}

void PartWriter::shares(ShareKind kind, const void* records, std::size_t bytes) {
  put_record(kShares, std::uint64_t(kind), records, bytes);
}

void PartWriter::floating_plan(const FloatingPartPlan& plan) { put_record(kFloatingPlan, 0, &plan, sizeof plan); }

void PartWriter::curvatures(const std::vector<VertexCurvatureValue>& values) {
  put_record(kCurvatures, curvature_runs_++, values.data(), values.size() * sizeof(VertexCurvatureValue));
}

void PartWriter::curvature_plan(const CurvaturePartPlan& plan) { put_record(kCurvaturePlan, 0, &plan, sizeof plan); }

void PartWriter::put_record(std::uint8_t kind, std::uint64_t chunk, const std::vector<unsigned char>& payload) {
  put_record(kind, chunk, payload.data(), payload.size());
}

void PartWriter::put_record(std::uint8_t kind, std::uint64_t chunk, const void* payload, std::size_t bytes) {
  std::vector<unsigned char> head;
  append(&head, kind);
  append(&head, chunk);
  append(&head, std::uint64_t(bytes));
  put(head.data(), head.size());
  put(payload, bytes);
}

void PartWriter::put(const void* data, std::size_t bytes) {
  const auto* p = static_cast<const unsigned char*>(data);
  buffer_.insert(buffer_.end(), p, p + bytes);
  if (buffer_.size() >= (1u << 20)) flush();
}

void PartWriter::flush() {
  std::size_t done = 0;
  while (done < buffer_.size()) {
    const ssize_t w = ::pwrite(file_.fd(), buffer_.data() + done, buffer_.size() - done, off_t(written_ + done));
    if (w < 0 && errno == EINTR) continue;
    if (w < 0) throw IoError(system_error_text(dir_, "cannot write the part file in", errno));
    done += std::size_t(w);
  }
  written_ += buffer_.size();
  buffer_.clear();
}

void PartWriter::commit(std::uint64_t vertex_chunks, std::uint64_t face_chunks, const SkippedFaces& skipped) {
  std::vector<unsigned char> end;
  append(&end, std::uint8_t(kEnd));
  append(&end, vertex_chunks);
  append(&end, face_chunks);
  append(&end, skipped.short_faces);
  append(&end, skipped.non_finite);
  append(&end, skipped.repeated_index);
  put(end.data(), end.size());
  flush();
  const std::uint64_t checksum = file_digest(file_.path()).hash;
  put(&checksum, sizeof checksum);
  flush();
  if (::fsync(file_.fd()) != 0) throw IoError(system_error_text(file_.path(), "cannot sync", errno));
  file_.commit(path_);
}

namespace {

// Reads fields from a mapped part file, refusing one that would run past its end.
class PartCursor {
 public:
  PartCursor(const std::string& path, const unsigned char* data, std::uint64_t end, std::uint64_t at)
      : path_(path), data_(data), end_(end), at_(at) {}
  template <class T>
  T get() {
    need(sizeof(T));
    T v;
    std::memcpy(&v, data_ + at_, sizeof(T));
    at_ += sizeof(T);
    return v;
  }
  template <class T>
  void array(std::uint64_t n, std::vector<T>* out) {
    if (n > (end_ - at_) / sizeof(T)) fail("an array of " + std::to_string(n) + " values runs past the end");
    out->resize(std::size_t(n));
    if (n) std::memcpy(static_cast<void*>(out->data()), data_ + at_, std::size_t(n) * sizeof(T));
    at_ += n * sizeof(T);
  }
  void skip(std::uint64_t bytes) {
    need(bytes);
    at_ += bytes;
  }
  std::uint64_t at() const { return at_; }
  [[noreturn]] void fail(const std::string& what) const {
    throw InputError(path_ + ": byte " + std::to_string(at_) + ": " + what);
  }

 private:
  void need(std::uint64_t bytes) const {
    if (bytes > end_ - at_) fail("the part file ends early (truncated?)");
  }
  const std::string& path_;
  const unsigned char* data_;
  std::uint64_t end_, at_;
};

}  // namespace

PartReader::PartReader(const std::string& path) : path_(path) {
  map_ = std::make_unique<MappedFile>(path);
  const unsigned char* data = map_->data();
  const std::uint64_t size = map_->size();
  if (size < sizeof kMagic || std::memcmp(data, kMagic, sizeof kMagic) != 0)
    throw InputError(path + ": byte 0: not an oocsimp part file");
  PartCursor head(path, data, size, sizeof kMagic);
  const auto version = head.get<std::uint32_t>();
  if (version != kVersion)
    throw InputError(path + ": byte 8: part file version " + std::to_string(version) + "; this oocsimp reads version " +
                     std::to_string(kVersion));
  if (size < kHeaderBytes + 8)
    throw InputError(path + ": byte " + std::to_string(size) + ": the part file is truncated");
  std::uint64_t stored;
  std::memcpy(&stored, data + size - 8, 8);
  if (content_hash(data, std::size_t(size - 8)) != stored)
    throw InputError(path + ": byte " + std::to_string(size - 8) +
                     ": checksum mismatch: the part file is damaged or truncated; run the part again");
  const std::uint64_t end = size - 8;
  PartCursor c(path, data, end, 12);
  manifest_.part = c.get<std::uint32_t>();
  manifest_.parts = c.get<std::uint32_t>();
  const auto text_bytes = c.get<std::uint64_t>();
  const std::uint64_t text_at = c.at();
  c.skip(text_bytes);
  if (manifest_.parts == 0 || manifest_.part >= manifest_.parts ||
      !parse_manifest(std::string(reinterpret_cast<const char*>(data + text_at), std::size_t(text_bytes)), &manifest_))
    throw InputError(path + ": byte " + std::to_string(text_at) + ": the part's manifest is malformed");
  for (;;) {
    const std::uint64_t record = c.at();
    const auto kind = c.get<std::uint8_t>();
    if (kind == kEnd) {
      vertex_chunks_ = c.get<std::uint64_t>();
      face_chunks_ = c.get<std::uint64_t>();
      skipped_.short_faces = c.get<std::uint64_t>();
      skipped_.non_finite = c.get<std::uint64_t>();
      skipped_.repeated_index = c.get<std::uint64_t>();
      break;
    }
    const auto chunk = c.get<std::uint64_t>();
    const auto bytes = c.get<std::uint64_t>();
    if (kind == kShares || kind == kFloatingPlan) {
      if (kind == kShares ? (chunk < std::uint64_t(ShareKind::partial) || chunk > std::uint64_t(ShareKind::attribute))
                          : (floating_plan_at_ != 0 || chunk != 0 || bytes != sizeof(FloatingPartPlan)))
        throw InputError(path + ": byte " + std::to_string(record) + ": an unexpected record");
      if (kind == kShares)
        share_at_.push_back({c.at(), bytes, ShareKind(chunk)});
      else
        floating_plan_at_ = c.at();
      c.skip(bytes);
      continue;
    }
    if (kind == kCurvatures || kind == kCurvaturePlan) {
      if (kind == kCurvatures ? (chunk != curvature_at_.size() || bytes % sizeof(VertexCurvatureValue) != 0)
                              : (curvature_plan_at_ != 0 || chunk != 0 || bytes != sizeof(CurvaturePartPlan)))
        throw InputError(path + ": byte " + std::to_string(record) + ": an unexpected record");
      if (kind == kCurvatures)
        curvature_at_.push_back({c.at(), bytes});
      else
        curvature_plan_at_ = c.at();
      c.skip(bytes);
      continue;
    }
    if (kind == kTile || kind == kPlan) {
      if (kind == kTile ? chunk != tile_at_.size() : (plan_at_ != 0 || chunk != 0 || bytes != sizeof(FirstPassPlan)))
        throw InputError(path + ": byte " + std::to_string(record) + ": an unexpected record");
      if (kind == kTile)
        tile_at_.push_back({c.at(), bytes});
      else
        plan_at_ = c.at();
      c.skip(bytes);
      continue;
    }
    std::vector<std::uint64_t>& at = kind == kVertices ? vertex_at_ : face_at_;
    if ((kind != kVertices && kind != kFaces) || chunk != manifest_.part + at.size() * manifest_.parts)
      throw InputError(path + ": byte " + std::to_string(record) + ": an unexpected record");
    at.push_back(c.at());
    c.skip(bytes);
  }
  const auto owned = [&](std::uint64_t chunks) {
    return chunks > manifest_.part ? (chunks - manifest_.part + manifest_.parts - 1) / manifest_.parts : 0;
  };
  if (c.at() != end || vertex_at_.size() != owned(vertex_chunks_) || face_at_.size() != owned(face_chunks_))
    throw InputError(path + ": byte " + std::to_string(c.at()) + ": the part's chunks do not match its end record");
}

bool PartReader::has_vertices(std::uint64_t chunk) const {
  return chunk % manifest_.parts == manifest_.part && chunk / manifest_.parts < vertex_at_.size();
}

bool PartReader::has_faces(std::uint64_t chunk) const {
  return chunk % manifest_.parts == manifest_.part && chunk / manifest_.parts < face_at_.size();
}

void PartReader::vertices(std::uint64_t chunk, VertexChunkSums* out) const {
  PartCursor c(path_, map_->data(), map_->size() - 8, vertex_at_[std::size_t(chunk / manifest_.parts)]);
  const auto n = c.get<std::uint64_t>();
  c.array(n, &out->keys);
  c.array(n, &out->sums);
}

void PartReader::faces(std::uint64_t chunk, FaceChunkSums* out) const {
  PartCursor c(path_, map_->data(), map_->size() - 8, face_at_[std::size_t(chunk / manifest_.parts)]);
  out->triangles = c.get<std::uint64_t>();
  const auto n = c.get<std::uint64_t>();
  c.array(n, &out->keys);
  c.array(n, &out->quadrics);
  c.array(c.get<std::uint64_t>(), &out->kept);
  c.array(c.get<std::uint64_t>(), &out->attribute_sums);
}

FirstPassPlan PartReader::plan() const {
  PartCursor c(path_, map_->data(), map_->size() - 8, plan_at_);
  const FirstPassPlan plan = c.get<FirstPassPlan>();
  if (!(plan.side > 0 && std::isfinite(plan.side)) || !(plan.threshold >= 0 && std::isfinite(plan.threshold)) ||
      plan.tiles == 0)
    c.fail("the first pass's plan is malformed");
  return plan;
}

void PartReader::tiles(std::size_t attributes, const TileOutputSink& sink) const {
  TileOutput tile;
  auto finite = [](const Vec3d& p) { return std::isfinite(p.x) && std::isfinite(p.y) && std::isfinite(p.z); };
  for (const RecordPlace& r : tile_at_) {
    PartCursor c(path_, map_->data(), r.at + r.bytes, r.at);
    c.array(c.get<std::uint64_t>(), &tile.faces);
    c.array(c.get<std::uint64_t>(), &tile.owned);
    c.array(c.get<std::uint64_t>(), &tile.attributes);
    if (c.at() != r.at + r.bytes || tile.attributes.size() != tile.owned.size() * attributes)
      c.fail("a collapsed tile's record does not hold what it says (another build of oocsimp?)");
    for (const PassFace& f : tile.faces)
      if (!finite(f.p[0]) || !finite(f.p[1]) || !finite(f.p[2])) c.fail("a collapsed tile holds a position not finite");
    for (const PassVertex& v : tile.owned)
      if (!finite(v.position)) c.fail("a collapsed tile holds a position not finite");
    sink(tile);
  }
}

FloatingPartPlan PartReader::floating_plan() const {
  PartCursor c(path_, map_->data(), map_->size() - 8, floating_plan_at_);
  const FloatingPartPlan plan = c.get<FloatingPartPlan>();
  if (!(plan.tile_side > 0 && std::isfinite(plan.tile_side)) || plan.tiles == 0)
    c.fail("the floating run's plan is malformed");
  return plan;
}

void PartReader::shares(const ClusterShareSink& sink, const AttributeLayout& layout) const {
  for (const ShareRecord& r : share_at_) {
    const std::size_t bytes = share_record_bytes(r.kind, layout);
    if (bytes == 0 || r.bytes % bytes != 0) {
      PartCursor c(path_, map_->data(), map_->size() - 8, r.at);
      c.fail("a cluster share's record does not hold whole shares (another build of oocsimp?)");
    }
    sink(r.kind, map_->data() + r.at, std::size_t(r.bytes / bytes));
  }
}

CurvaturePartPlan PartReader::curvature_plan() const {
  PartCursor c(path_, map_->data(), map_->size() - 8, curvature_plan_at_);
  const CurvaturePartPlan plan = c.get<CurvaturePartPlan>();
  if (plan.estimated > 1 || plan.invariant + plan.fitted > plan.vertices ||
      (plan.estimated && !(plan.radius >= 0 && std::isfinite(plan.radius))))
    c.fail("the curvature run's plan is malformed");
  return plan;
}

void PartReader::curvatures(std::uint64_t vertices, float* k) const {
  for (const RecordPlace& r : curvature_at_) {
    const unsigned char* at = map_->data() + r.at;
    for (std::uint64_t i = 0; i < r.bytes / sizeof(VertexCurvatureValue); ++i) {
      VertexCurvatureValue v;
      std::memcpy(&v, at + i * sizeof v, sizeof v);
      if (v.vertex >= vertices) {
        PartCursor c(path_, map_->data(), map_->size() - 8, r.at + i * sizeof v);
        c.fail("a curvature value of vertex " + std::to_string(v.vertex) + ", past the input's " +
               std::to_string(vertices) + " vertices");
      }
      k[2 * std::uint64_t(v.vertex)] = v.k1;
      k[2 * std::uint64_t(v.vertex) + 1] = v.k2;
    }
  }
}

}  // namespace oocsimp
