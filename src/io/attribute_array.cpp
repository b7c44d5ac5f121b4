#include "io/attribute_array.hpp"

#include <tbb/blocked_range.h>
#include <tbb/parallel_reduce.h>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <limits>

#include "io/mapped_file.hpp"
#include "io/position_array.hpp"
#include "oocsimp/error.hpp"

namespace oocsimp {

std::size_t attribute_type_size(AttributeType t) {
  switch (t) {
    case AttributeType::i8:
    case AttributeType::u8:
      return 1;
    case AttributeType::i16:
    case AttributeType::u16:
      return 2;
    case AttributeType::i32:
    case AttributeType::u32:
    case AttributeType::f32:
      return 4;
    case AttributeType::f64:
      return 8;
  }
  return 0;
}

const char* attribute_type_name(AttributeType t) {
  static const char* const names[] = {"char", "uchar", "short", "ushort", "int", "uint", "float", "double"};
  return names[int(t)];
}

namespace {

template <class T>
T load_swapped(const unsigned char* p, bool swap) {
  unsigned char b[sizeof(T)];
  std::memcpy(b, p, sizeof(T));
  if (swap) std::reverse(b, b + sizeof(T));
  T v;
  std::memcpy(&v, b, sizeof(T));
  return v;
}

}  // namespace

double load_value(const unsigned char* p, AttributeType t, bool swap) {
  switch (t) {
    case AttributeType::i8:
      return load_swapped<std::int8_t>(p, false);
    case AttributeType::u8:
      return load_swapped<std::uint8_t>(p, false);
    case AttributeType::i16:
      return load_swapped<std::int16_t>(p, swap);
    case AttributeType::u16:
      return load_swapped<std::uint16_t>(p, swap);
    case AttributeType::i32:
      return load_swapped<std::int32_t>(p, swap);
    case AttributeType::u32:
      return load_swapped<std::uint32_t>(p, swap);
    case AttributeType::f32:
      return load_swapped<float>(p, swap);
    case AttributeType::f64:
      return load_swapped<double>(p, swap);
  }
  return 0;
}

bool is_integer_type(AttributeType t) { return t != AttributeType::f32 && t != AttributeType::f64; }

AttributeSelection parse_attribute_selection(const std::string& text) {
  AttributeSelection s;
  if (text == "all") return s;
  if (text == "none") {
    s.mode = AttributeSelection::Mode::none;
    return s;
  }
  s.mode = AttributeSelection::Mode::named;
  std::size_t at = 0;
  for (;;) {
    std::size_t comma = text.find(',', at);
    std::string name = text.substr(at, comma == std::string::npos ? std::string::npos : comma - at);
    if (name.empty())
      throw UsageError("options.attributes \"" + text + "\": an empty name (expected all, none or NAME,NAME...)");
    if (std::find(s.names.begin(), s.names.end(), name) == s.names.end()) s.names.push_back(name);
    if (comma == std::string::npos) break;
    at = comma + 1;
  }
  return s;
}

bool is_texture_coordinate(const std::string& name) {
  static const char* const names[] = {"u",          "v",         "s",         "t",        "texture_u",
                                      "texture_v",  "texture_s", "texture_t", "texcoord", "texcoord_u",
                                      "texcoord_v", "tex_u",     "tex_v",     "uv",       "st"};
  for (const char* n : names)
    if (name == n) return true;
  return false;
}

namespace {

std::string names_of(const std::vector<AttributeCandidate>& c) {
  std::string s;
  for (const AttributeCandidate& a : c) {
    if (is_texture_coordinate(a.name)) continue;
    s += (s.empty() ? "" : ", ") + a.name;
  }
  return s.empty() ? "none" : s;
}

}  // namespace

std::vector<std::size_t> carried_attributes(const std::vector<AttributeCandidate>& candidates,
                                            const AttributeSelection& selection, const std::string& path,
                                            std::vector<std::string>* notes) {
  std::vector<std::size_t> carried;
  std::string textures;
  for (const AttributeCandidate& a : candidates)
    if (is_texture_coordinate(a.name)) textures += (textures.empty() ? "" : ", ") + a.name;
  if (!textures.empty() && selection.mode != AttributeSelection::Mode::none && notes)
    notes->push_back(path + ": texture coordinates (" + textures +
                     ") are dropped: clustering merges vertices across texture seams");
  switch (selection.mode) {
    case AttributeSelection::Mode::none:
      return carried;
    case AttributeSelection::Mode::all:
      for (std::size_t i = 0; i < candidates.size(); ++i)
        if (!is_texture_coordinate(candidates[i].name)) carried.push_back(i);
      return carried;
    case AttributeSelection::Mode::named:
      for (const std::string& name : selection.names) {
        std::size_t i = 0;
        while (i < candidates.size() && candidates[i].name != name) ++i;
        if (i == candidates.size() || is_texture_coordinate(name))
          throw UsageError("options.attributes: " + path + " has no vertex attribute \"" + name +
                           "\" that can be carried (it has: " + names_of(candidates) + ")");
        carried.push_back(i);
      }
      return carried;
  }
  return carried;
}

void store_attribute(double value, AttributeType type, unsigned char* out) {
  auto put_int = [&](auto tag) {
    using T = decltype(tag);
    double v = std::isnan(value) ? 0.0 : std::nearbyint(value);
    v = std::min(std::max(v, double(std::numeric_limits<T>::min())), double(std::numeric_limits<T>::max()));
    T t = T(v);
    std::memcpy(out, &t, sizeof t);
  };
  switch (type) {
    case AttributeType::i8:
      return put_int(std::int8_t());
    case AttributeType::u8:
      return put_int(std::uint8_t());
    case AttributeType::i16:
      return put_int(std::int16_t());
    case AttributeType::u16:
      return put_int(std::uint16_t());
    case AttributeType::i32:
      return put_int(std::int32_t());
    case AttributeType::u32:
      return put_int(std::uint32_t());
    case AttributeType::f32: {
      float f = float(value);
      std::memcpy(out, &f, sizeof f);
      return;
    }
    case AttributeType::f64:
      std::memcpy(out, &value, sizeof value);
      return;
  }
}

AttributeArrayBuilder::AttributeArrayBuilder(const std::string& temp_dir, const std::string& source_path,
                                             std::vector<VertexAttribute> attributes)
    : attributes_(std::move(attributes)), source_path_(source_path), temp_dir_(temp_dir) {
  for (const VertexAttribute& a : attributes_) {
    offset_.push_back(stride_);
    stride_ += attribute_type_size(a.type);
  }
  record_.resize(stride_);
  if (attributes_.empty()) return;
  file_ = std::make_unique<TempFile>(temp_dir_, "oocsimp-attributes-");
  sink_ = std::make_unique<ByteSink>(file_->fd(), file_->path(), false);
  sink_->on_write_error([this](std::uint64_t on_disk, int err) {
    return temp_dir_ + ": cannot write the temporary attribute array of " + source_path_ + " (" + mib_text(on_disk) +
           " written): " + std::strerror(err);
  });
}

AttributeArrayBuilder::~AttributeArrayBuilder() = default;

void AttributeArrayBuilder::expect(std::uint64_t vertices) {
  if (!attributes_.empty())
    require_free_space(temp_dir_, vertices * stride_, "the temporary attribute array of " + source_path_);
}

void AttributeArrayBuilder::add(const double* values) {
  if (attributes_.empty()) return;
  for (std::size_t k = 0; k < attributes_.size(); ++k)
    store_attribute(values[k], attributes_[k].type, &record_[offset_[k]]);
  sink_->write(record_.data(), stride_);
  ++count_;
}

void AttributeArrayBuilder::finish(MeshInput& out) {
  out.attributes = AttributeArray{};
  if (attributes_.empty()) return;
  sink_->finish();
  sink_.reset();
  file_->close();
  auto map = std::make_unique<MappedFile>(file_->path());
  AttributeArray& a = out.attributes;
  for (std::size_t k = 0; k < attributes_.size(); ++k) a.add(attributes_[k], map->data() + offset_[k], stride_);
  a.count = count_;
  a.swap = false;
  scan_attribute_ranges(a);
  reader_state(out).attribute_map = std::move(map);
  reader_state(out).attribute_file = std::move(file_);
}

void scan_attribute_ranges(AttributeArray& array) {
  const std::size_t n = array.size();
  if (n == 0) return;
  struct Range {
    std::vector<double> lo, hi;
  };
  const double inf = std::numeric_limits<double>::infinity();
  Range init{std::vector<double>(n, inf), std::vector<double>(n, -inf)};
  Range r = tbb::parallel_reduce(
      tbb::blocked_range<std::uint64_t>(0, array.count, 1 << 16), init,
      [&](const tbb::blocked_range<std::uint64_t>& range, Range acc) {
        for (std::uint64_t i = range.begin(); i != range.end(); ++i)
          for (std::size_t k = 0; k < n; ++k) {
            double v = array.get(i, k);
            if (!std::isfinite(v)) continue;
            acc.lo[k] = std::min(acc.lo[k], v);
            acc.hi[k] = std::max(acc.hi[k], v);
          }
        return acc;
      },
      [n](Range a, const Range& b) {
        for (std::size_t k = 0; k < n; ++k) {
          a.lo[k] = std::min(a.lo[k], b.lo[k]);
          a.hi[k] = std::max(a.hi[k], b.hi[k]);
        }
        return a;
      });
  for (std::size_t k = 0; k < n; ++k) {
    bool any = r.lo[k] <= r.hi[k];
    array.attributes[k].min = any ? r.lo[k] : 0;
    array.attributes[k].max = any ? r.hi[k] : 0;
  }
}

}  // namespace oocsimp
