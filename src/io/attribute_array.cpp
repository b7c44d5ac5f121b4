#include "io/attribute_array.hpp"

#include <tbb/blocked_range.h>
#include <tbb/parallel_reduce.h>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <limits>
#include <type_traits>

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

double load_value(const unsigned char* p, AttributeType t, bool swap) {
  return with_stored_type(t, [&](auto zero) { return double(load_stored<decltype(zero)>(p, swap)); });
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
      throw UsageError("options.attributes",
                       "options.attributes \"" + text + "\": an empty name (expected all, none or NAME,NAME...)");
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

std::string material_attribute_name(std::size_t k) { return "material_" + std::to_string(k); }

bool is_material_attribute(const std::string& name) {
  constexpr std::size_t kPrefix = 9;  // "material_"
  if (name.size() <= kPrefix || name.compare(0, kPrefix, "material_") != 0) return false;
  return std::all_of(name.begin() + kPrefix, name.end(), [](char c) { return c >= '0' && c <= '9'; });
}

bool carries_texture_coordinates(const std::vector<VertexAttribute>& attributes) {
  // Material attributes have seams as texture coordinates do, where faces of two
  // materials meet: the edge collapse keeps both kinds closed.
  for (const VertexAttribute& a : attributes)
    if (is_texture_coordinate(a.name) || is_material_attribute(a.name)) return true;
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
  const auto dropped = [&](const std::string& name) {
    return !selection.texture_coordinates && is_texture_coordinate(name);
  };
  for (const AttributeCandidate& a : candidates)
    if (dropped(a.name)) textures += (textures.empty() ? "" : ", ") + a.name;
  if (!textures.empty() && selection.mode != AttributeSelection::Mode::none && notes)
    notes->push_back(path + ": texture coordinates (" + textures +
                     ") are dropped: clustering merges vertices across texture seams");
  switch (selection.mode) {
    case AttributeSelection::Mode::none:
      return carried;
    case AttributeSelection::Mode::all:
      for (std::size_t i = 0; i < candidates.size(); ++i)
        if (!dropped(candidates[i].name)) carried.push_back(i);
      return carried;
    case AttributeSelection::Mode::named:
      for (const std::string& name : selection.names) {
        std::size_t i = 0;
        while (i < candidates.size() && candidates[i].name != name) ++i;
        if (i == candidates.size() || dropped(name))
          throw UsageError("options.attributes", "options.attributes: " + path + " has no vertex attribute \"" + name +
                                                     "\" that can be carried (it has: " + names_of(candidates) + ")");
        carried.push_back(i);
      }
      return carried;
  }
  return carried;
}

void store_attribute(double value, AttributeType type, unsigned char* out) {
  with_stored_type(type, [&](auto tag) {
    using T = decltype(tag);
    T t;
    if constexpr (std::is_floating_point_v<T>) {
      t = T(value);
    } else {  // rounded and clamped into the type's range; NaN as 0
      double v = std::isnan(value) ? 0.0 : std::nearbyint(value);
      v = std::min(std::max(v, double(std::numeric_limits<T>::min())), double(std::numeric_limits<T>::max()));
      t = T(v);
    }
    std::memcpy(out, &t, sizeof t);
  });
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
  // An empty file maps to no address: no vertex, no value to point at.
  for (std::size_t k = 0; k < attributes_.size(); ++k)
    a.add(attributes_[k], map->data() ? map->data() + offset_[k] : nullptr, stride_);
  a.count = count_;
  a.swap = false;
  scan_attribute_ranges(a);
  reader_state(out).attribute_map = std::move(map);
  reader_state(out).attribute_file = std::move(file_);
}

AttributeRanges::AttributeRanges(std::size_t attributes)
    : lo(attributes, std::numeric_limits<double>::infinity()),
      hi(attributes, -std::numeric_limits<double>::infinity()) {}

void AttributeRanges::widen(const AttributeArray& array, std::uint64_t begin, std::uint64_t end) {
  if (begin == end) return;
  // An attribute at a time, decoded by a loop of its own type; integers compared as
  // they are stored (every one is finite, and converts exactly).
  for (std::size_t k = 0; k < lo.size(); ++k)
    with_stored_type(array.attributes[k].type, [&](auto zero) {
      using T = decltype(zero);
      const unsigned char* base = array.base[k];
      const std::size_t stride = array.stride[k];
      if constexpr (std::is_integral_v<T>) {
        // Four lanes, whose comparisons do not wait on each other.
        T least[4], most[4];
        for (int l = 0; l < 4; ++l) least[l] = most[l] = load_stored<T>(base + begin * stride, array.swap);
        std::uint64_t i = begin;
        for (; i + 4 <= end; i += 4)
          for (int l = 0; l < 4; ++l) {
            const T v = load_stored<T>(base + (i + std::uint64_t(l)) * stride, array.swap);
            least[l] = std::min(least[l], v);
            most[l] = std::max(most[l], v);
          }
        for (; i != end; ++i) {
          const T v = load_stored<T>(base + i * stride, array.swap);
          least[0] = std::min(least[0], v);
          most[0] = std::max(most[0], v);
        }
        lo[k] = std::min(lo[k], double(std::min({least[0], least[1], least[2], least[3]})));
        hi[k] = std::max(hi[k], double(std::max({most[0], most[1], most[2], most[3]})));
      } else {
        double least = lo[k], most = hi[k];
        for (std::uint64_t i = begin; i != end; ++i) {
          const double v = double(load_stored<T>(base + i * stride, array.swap));
          if (!std::isfinite(v)) continue;
          least = std::min(least, v);
          most = std::max(most, v);
        }
        lo[k] = least;
        hi[k] = most;
      }
    });
}

void AttributeRanges::merge(const AttributeRanges& later) {
  for (std::size_t k = 0; k < lo.size(); ++k) {
    lo[k] = std::min(lo[k], later.lo[k]);
    hi[k] = std::max(hi[k], later.hi[k]);
  }
}

void AttributeRanges::store(AttributeArray& array) const {
  for (std::size_t k = 0; k < lo.size(); ++k) {
    const bool any = lo[k] <= hi[k];
    array.attributes[k].min = any ? lo[k] : 0;
    array.attributes[k].max = any ? hi[k] : 0;
  }
}

void scan_attribute_ranges(AttributeArray& array) {
  if (array.empty()) return;
  const AttributeRanges r = tbb::parallel_reduce(
      tbb::blocked_range<std::uint64_t>(0, array.count, 1 << 16), AttributeRanges(array.size()),
      [&](const tbb::blocked_range<std::uint64_t>& range, AttributeRanges acc) {
        acc.widen(array, range.begin(), range.end());
        return acc;
      },
      [](AttributeRanges a, const AttributeRanges& b) {
        a.merge(b);
        return a;
      });
  r.store(array);
}

}  // namespace oocsimp
