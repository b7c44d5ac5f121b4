// Building the mapped attribute arrays behind a MeshInput, and choosing which of an
// input's vertex properties are carried, so that colours, normals and scalars reach
// the output.
#pragma once

#include <algorithm>
#include <cstdint>
#include <cstring>
#include <memory>
#include <string>
#include <vector>

#include "io/byte_sink.hpp"
#include "oocsimp/attributes.hpp"
#include "io/mesh_input.hpp"
#include "io/temp_file.hpp"

namespace oocsimp {

/// One value of type `t` at `p` (byte-swapped when `swap`) as a double: the one
/// decoder of stored scalars, for attributes and the PLY reader alike.
double load_value(const unsigned char* p, AttributeType t, bool swap);

/// Value k of vertex i of `array` (unchecked) as a double.
inline double attribute_value(const AttributeArray& array, std::uint64_t i, std::size_t k) {
  return load_value(array.base[k] + i * array.stride[k], array.attributes[k].type, array.swap);
}

/// A vertex property an input offers, before the selection.
struct AttributeCandidate {
  std::string name;
  AttributeType type = AttributeType::f32;
};

/// Materials past this many are not carried (OBJ's usemtl groups, glTF's primitives'
/// materials): each is an attribute of every vertex.
constexpr std::size_t kMostMaterials = 64;

/// Whether any of `attributes` is a texture coordinate.
bool carries_texture_coordinates(const std::vector<VertexAttribute>& attributes);

/// The positions in `candidates` of the attributes a run carries, in the order the
/// output writes them: every candidate but texture coordinates for Mode::all, the
/// named ones in their order for Mode::named, none for Mode::none. Texture coordinates
/// and (for a selection) the candidates left out are described in `notes`, one line
/// each naming `path`. Throws UsageError naming `path` and what it has when a named
/// attribute is not among the candidates, or names a texture coordinate.
std::vector<std::size_t> carried_attributes(const std::vector<AttributeCandidate>& candidates,
                                            const AttributeSelection& selection, const std::string& path,
                                            std::vector<std::string>* notes);

/// Streams converted attribute values into a temporary file under `temp_dir`, packed
/// in their stored types (native byte order), tracking each attribute's range; finish()
/// maps the file into MeshInput::attributes. Integer attributes are rounded and clamped
/// into their type's range.
class AttributeArrayBuilder {
 public:
  AttributeArrayBuilder(const std::string& temp_dir, const std::string& source_path,
                        std::vector<VertexAttribute> attributes);
  ~AttributeArrayBuilder();
  bool empty() const { return attributes_.empty(); }
  /// Throws IoError up front when the temp folder lacks the room for `vertices`.
  void expect(std::uint64_t vertices);
  /// Appends one vertex's values, attributes().size() of them.
  void add(const double* values);
  /// Flushes, maps the file and stores the view and the ranges in `out`.
  void finish(MeshInput& out);

 private:
  std::vector<VertexAttribute> attributes_;
  std::vector<std::size_t> offset_;
  std::size_t stride_ = 0;
  std::vector<unsigned char> record_;
  std::unique_ptr<TempFile> file_;
  std::unique_ptr<ByteSink> sink_;
  std::string source_path_, temp_dir_;
  std::uint64_t count_ = 0;
};

/// One value stored as T at `p`, byte-swapped when `swap`.
template <class T>
inline T load_stored(const unsigned char* p, bool swap) {
  unsigned char b[sizeof(T)];
  std::memcpy(b, p, sizeof(T));
  if (sizeof(T) > 1 && swap) std::reverse(b, b + sizeof(T));
  T v;
  std::memcpy(&v, b, sizeof(T));
  return v;
}

/// Calls f(T()) with the C++ type of `t`: loops over many values of one attribute
/// dispatch once and decode inline, instead of a switch per value (load_value).
template <class F>
inline decltype(auto) with_stored_type(AttributeType t, F&& f) {
  switch (t) {
    case AttributeType::i8:
      return f(std::int8_t());
    case AttributeType::u8:
      return f(std::uint8_t());
    case AttributeType::i16:
      return f(std::int16_t());
    case AttributeType::u16:
      return f(std::uint16_t());
    case AttributeType::i32:
      return f(std::int32_t());
    case AttributeType::u32:
      return f(std::uint32_t());
    case AttributeType::f32:
      return f(float());
    case AttributeType::f64:
      break;
  }
  return f(double());
}

/// The least and greatest finite value of each attribute of an array, gathered a
/// block of vertices at a time (so that a scan of the positions can take them in the
/// same pass over the records).
struct AttributeRanges {
  std::vector<double> lo, hi;
  explicit AttributeRanges(std::size_t attributes = 0);
  /// Takes in vertices [begin, end) of `array`.
  void widen(const AttributeArray& array, std::uint64_t begin, std::uint64_t end);
  /// Takes in the ranges of vertices that come after these.
  void merge(const AttributeRanges& later);
  /// Stores them as the attributes' min and max; 0, 0 for one without a finite value.
  void store(AttributeArray& array) const;
};

/// Fills attributes[k].min and max from the finite values of the mapped `array`
/// (in parallel); an attribute without a finite value gets 0, 0.
void scan_attribute_ranges(AttributeArray& array);

/// Stores `value` as `type` at `out` (native byte order): integers rounded to nearest
/// and clamped to the type's range, NaN as 0.
void store_attribute(double value, AttributeType type, unsigned char* out);

}  // namespace oocsimp
