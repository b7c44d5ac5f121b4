// oocsimp — per-vertex attributes carried from the input to the output: colours,
// normals and any other scalar a vertex has (quality, confidence, intensity, ...).
#pragma once

#include "oocsimp/export.hpp"

#include <cstddef>
#include <cstdint>
#include <string>
#include <vector>

namespace oocsimp {

/// The stored type of an attribute, as PLY names them (char, uchar, short, ushort,
/// int, uint, float, double).
enum class AttributeType : std::uint8_t { i8, u8, i16, u16, i32, u32, f32, f64 };

/// Bytes of one value of `t`.
OOCSIMP_API std::size_t attribute_type_size(AttributeType t);
/// PLY's name of `t` ("uchar", "float", ...).
OOCSIMP_API const char* attribute_type_name(AttributeType t);
/// Whether `t` is an integer type (values are rounded and clamped back to it).
OOCSIMP_API bool is_integer_type(AttributeType t);

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
  /// Carry texture coordinates (u, v, s, t, texture_u, ...) too. The edge collapse
  /// sets it (simplify with ClusterMethod::qem): it keeps their seams closed, the two
  /// sides collapsing together along them. Clustering, which merges vertices across
  /// seams, drops them with a warning.
  bool texture_coordinates = false;
};

/// Whether a vertex property is a texture coordinate (u, v, s, t, texture_u, texture_v,
/// texcoord...): the edge collapse carries those, clustering drops them, since it
/// merges vertices across texture seams.
OOCSIMP_API bool is_texture_coordinate(const std::string& name);

/// Parses --attributes: "all", "none" or "NAME,NAME...". Throws UsageError for an empty
/// name.
OOCSIMP_API AttributeSelection parse_attribute_selection(const std::string& text);

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
};

/// The attributes of a simplified mesh: `values` holds attributes.size() values per
/// output vertex, in the attributes' order; integer types hold whole numbers in range.
/// OBJ's materials: the library files its `mtllib` lines name, as written, and the
/// materials its `usemtl` lines use, in the order of first use; from a glTF file, the
/// names of its primitives' materials in the order of first use ("materialI" for
/// materials[I] without a name) and the library its writer kept (the root's
/// extras.mtllib). A mesh carries them
/// as one float vertex attribute per material, "material_K" for names[K]: 1 on the
/// vertices of that material's faces, 0 elsewhere (a vertex where materials meet is
/// split, one per material, as at a texture seam, and the edge collapse keeps such
/// seams as it keeps texture seams). An output face takes the material whose
/// attribute its three corners sum highest, the first on a tie: the material of its
/// corners when they agree, and after clustering (which averages the attributes by
/// area) the one that covers the most area around them. A face whose corners carry
/// none (the input's faces before its first usemtl) keeps the material of the face
/// written before it.
struct Materials {
  std::vector<std::string> libraries;
  std::vector<std::string> names;
  bool empty() const { return names.empty() && libraries.empty(); }
};

/// "material_K": the vertex attribute of material K (Materials).
OOCSIMP_API std::string material_attribute_name(std::size_t k);
/// Whether `name` is a material's vertex attribute, "material_" and digits.
OOCSIMP_API bool is_material_attribute(const std::string& name);

struct AttributeValues {
  std::vector<VertexAttribute> attributes;
  std::vector<double> values;
  /// The materials the material_K attributes stand for (empty: none).
  Materials materials;
  bool empty() const { return attributes.empty(); }
};

}  // namespace oocsimp
