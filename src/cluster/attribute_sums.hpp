// What a cluster accumulates of its vertices' attributes so that the output keeps
// them, shared by both methods: in vcglib's terms the cell policy for colours, normals
// and scalars.
//
// An output vertex gets the area-weighted mean of its cluster's values: a vertex
// weighs a third of the area of its incident triangles, the same weight its quadric
// carries. Per cluster the sums are, in this order (width() of them):
//   [0] the weight W = sum w_v           [1] the vertex count N
//   [2 + k] sum w_v a'_vk                [2 + n + k] sum a'_vk
// where a'_vk is attribute k scaled into [0, 1] by the input's range, so that the
// floating method's fixed-point sums (partition-independent, like its quadric sums)
// keep their precision and cannot overflow whatever the attribute's units. A cluster
// whose triangles have no area (W = 0) takes the plain mean. Colours are averaged in
// the space they are stored in (no gamma decoding), as MeshLab and Open3D do. The
// uniform method keeps sums of its own (UniformAttributeSums) and shares finish_means.
#pragma once

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <limits>
#include <string>
#include <vector>

#include "io/attribute_array.hpp"
#include "oocsimp/attributes.hpp"

namespace oocsimp {

class AttributeLayout {
 public:
  AttributeLayout() = default;
  explicit AttributeLayout(const AttributeArray& array) : attributes_(array.attributes) {
    for (const VertexAttribute& a : attributes_) {
      const double range = a.max - a.min;
      inv_range_.push_back(range > 0 ? 1.0 / range : 0.0);
      min_.push_back(a.min);
    }
    normal_[0] = find("nx");
    normal_[1] = find("ny");
    normal_[2] = find("nz");
  }

  std::size_t count() const { return attributes_.size(); }
  bool empty() const { return attributes_.empty(); }
  /// Sums per cluster.
  std::size_t width() const { return 2 + 2 * count(); }
  const std::vector<VertexAttribute>& attributes() const { return attributes_; }

  /// Attribute k of vertex i scaled into [0, 1]; 0 for a constant attribute and for a
  /// value that is not finite (it counts as the attribute's minimum).
  double scaled(const AttributeArray& array, std::uint64_t i, std::size_t k) const {
    const double v = (attribute_value(array, i, k) - min_[k]) * inv_range_[k];
    if (v >= 0 && v <= 1) return v;  // every finite value: the range is the input's
    return v > 1 && v <= std::numeric_limits<double>::max() ? 1.0 : 0.0;  // rounding; NaN and infinities
  }

  /// Adds vertex i of `array` with weight `w` to a cluster's sums (width() of them),
  /// through add(sum, term): double sums for uniform (added in a fixed order),
  /// fixed-point ones for floating cells.
  template <class Sum, class Add>
  void add_vertex(Sum* sums, const AttributeArray& array, std::uint64_t i, double w, Add add) const {
    const std::size_t n = count();
    add(sums[0], w);
    add(sums[1], 1.0);
    for (std::size_t k = 0; k < n; ++k) {
      const double a = scaled(array, i, k);
      add(sums[2 + k], w * a);
      add(sums[2 + n + k], a);
    }
  }

  /// A cluster's output values (count() of them) from its merged sums: the weighted
  /// mean (the plain one where W = 0) in the attribute's units; integer types rounded
  /// to nearest within the input's range; nx, ny, nz renormalised to unit length.
  void finish(const double* sums, double* out) const {
    const std::size_t n = count();
    const double w = sums[0], members = sums[1];
    for (std::size_t k = 0; k < n; ++k)
      out[k] = w > 0 ? sums[2 + k] / w : members > 0 ? sums[2 + n + k] / members : 0.0;
    finish_means(out);
  }

  /// The output values (count() of them) in place from the cluster's means scaled into
  /// [0, 1] (clamped to it): in the attribute's units, integer types rounded to nearest
  /// within the input's range, nx, ny, nz renormalised.
  void finish_means(double* out) const {
    const std::size_t n = count();
    for (std::size_t k = 0; k < n; ++k) {
      const double mean = std::min(std::max(out[k], 0.0), 1.0);
      const VertexAttribute& a = attributes_[k];
      out[k] = a.min + mean * (a.max - a.min);
    }
    settle(out);
  }

  /// Values (count() of them) made what the attributes' types hold: integer types
  /// rounded to nearest within the input's range, nx, ny, nz renormalised to unit
  /// length. For values a collapse interpolated as well as for cluster means.
  void settle(double* out) const {
    for (std::size_t k = 0; k < count(); ++k) {
      const VertexAttribute& a = attributes_[k];
      if (is_integer_type(a.type)) out[k] = std::min(std::max(std::nearbyint(out[k]), a.min), a.max);
    }
    if (normal_[0] >= 0 && normal_[1] >= 0 && normal_[2] >= 0) {
      double& x = out[normal_[0]];
      double& y = out[normal_[1]];
      double& z = out[normal_[2]];
      const double len = std::sqrt(x * x + y * y + z * z);
      if (len > 0 && !is_integer_type(attributes_[std::size_t(normal_[0])].type)) {
        x /= len;
        y /= len;
        z /= len;
      }
    }
  }

 private:
  int find(const char* name) const {
    for (std::size_t k = 0; k < attributes_.size(); ++k)
      if (attributes_[k].name == name) return int(k);
    return -1;
  }

  std::vector<VertexAttribute> attributes_;
  std::vector<double> min_, inv_range_;  // flat copies for the per-corner loop
  int normal_[3] = {-1, -1, -1};
};

}  // namespace oocsimp
