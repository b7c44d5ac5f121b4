// oocsimp — per-vertex attributes carried from the input to the output: colours,
// normals and any other scalar a vertex has (quality, confidence, intensity, ...).
#pragma once

#include <cstddef>
#include <cstdint>
#include <cstring>
#include <string>
#include <vector>

namespace oocsimp {

/// The stored type of an attribute, as PLY names them (char, uchar, short, ushort,
/// int, uint, float, double).
enum class AttributeType : std::uint8_t { i8, u8, i16, u16, i32, u32, f32, f64 };

/// Bytes of one value of `t`.
std::size_t attribute_type_size(AttributeType t);
/// PLY's name of `t` ("uchar", "float", ...).
const char* attribute_type_name(AttributeType t);
/// Whether `t` is an integer type (values are rounded and clamped back to it).
bool is_integer_type(AttributeType t);

/// One per-vertex scalar property.
struct VertexAttribute {
  std::string name;                         ///< as the input names it ("red", "nx", "quality")
  AttributeType type = AttributeType::f32;  ///< as the input stores it; the output writes the same
  /// The range of the input's finite values: the clusterers sum values scaled into
  /// [0, 1] by it, so that fixed-point sums neither overflow nor lose precision.
  double min = 0, max = 0;
};

/// Which of the input's vertex attributes a run carries (--attributes).
struct AttributeSelection {
  enum class Mode { all, none, named };
  Mode mode = Mode::all;
  std::vector<std::string> names;  ///< for Mode::named, in the order the output writes them
};

/// Parses --attributes: "all", "none" or "NAME,NAME...". Throws UsageError for an empty
/// name.
AttributeSelection parse_attribute_selection(const std::string& text);

/// Read-only view of the carried attributes of every vertex, in mapped (or the
/// caller's) memory: value k of vertex i is at base[k] + i*stride[k], stored as
/// attributes[k].type, byte-swapped when `swap`. Empty when nothing is carried.
struct AttributeArray {
  std::vector<VertexAttribute> attributes;
  std::vector<const unsigned char*> base;  ///< per attribute: its value of vertex 0
  std::vector<std::size_t> stride;         ///< per attribute: bytes from one vertex's value to the next
  std::uint64_t count = 0;
  bool swap = false;

  bool empty() const { return attributes.empty(); }
  std::size_t size() const { return attributes.size(); }
  /// Adds attribute `a` whose values start at `first` and are `step` bytes apart.
  void add(const VertexAttribute& a, const void* first, std::size_t step) {
    attributes.push_back(a);
    base.push_back(static_cast<const unsigned char*>(first));
    stride.push_back(step);
  }
  /// Value k of vertex i (unchecked) as a double.
  inline double get(std::uint64_t i, std::size_t k) const;
};

/// The attributes of a simplified mesh: `values` holds attributes.size() values per
/// output vertex, in the attributes' order; integer types hold whole numbers in range.
struct AttributeValues {
  std::vector<VertexAttribute> attributes;
  std::vector<double> values;
  bool empty() const { return attributes.empty(); }
};

namespace detail {
template <class T>
T load_attribute(const unsigned char* p, bool swap) {
  unsigned char b[sizeof(T)];
  std::memcpy(b, p, sizeof(T));
  if (swap)
    for (std::size_t i = 0; i < sizeof(T) / 2; ++i) {
      unsigned char c = b[i];
      b[i] = b[sizeof(T) - 1 - i];
      b[sizeof(T) - 1 - i] = c;
    }
  T v;
  std::memcpy(&v, b, sizeof(T));
  return v;
}
}  // namespace detail

inline double AttributeArray::get(std::uint64_t i, std::size_t k) const {
  const unsigned char* p = base[k] + i * stride[k];
  switch (attributes[k].type) {
    case AttributeType::i8:
      return detail::load_attribute<std::int8_t>(p, false);
    case AttributeType::u8:
      return detail::load_attribute<std::uint8_t>(p, false);
    case AttributeType::i16:
      return detail::load_attribute<std::int16_t>(p, swap);
    case AttributeType::u16:
      return detail::load_attribute<std::uint16_t>(p, swap);
    case AttributeType::i32:
      return detail::load_attribute<std::int32_t>(p, swap);
    case AttributeType::u32:
      return detail::load_attribute<std::uint32_t>(p, swap);
    case AttributeType::f32:
      return detail::load_attribute<float>(p, swap);
    case AttributeType::f64:
      return detail::load_attribute<double>(p, swap);
  }
  return 0;
}

}  // namespace oocsimp
