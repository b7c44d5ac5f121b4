#include "io/position_array.hpp"

#include <unistd.h>

#include <cmath>
#include <cstring>
#include <sstream>

#include "oocsimp/error.hpp"

namespace oocsimp {

double Box3d::diagonal() const {
  if (empty()) return 0;
  double dx = max.x - min.x, dy = max.y - min.y, dz = max.z - min.z;
  return std::sqrt(dx * dx + dy * dy + dz * dz);
}

void Box3d::add(const Vec3d& p) {
  min.x = std::min(min.x, p.x);
  min.y = std::min(min.y, p.y);
  min.z = std::min(min.z, p.z);
  max.x = std::max(max.x, p.x);
  max.y = std::max(max.y, p.y);
  max.z = std::max(max.z, p.z);
}

void Box3d::add(const Box3d& b) {
  if (b.empty()) return;
  add(b.min);
  add(b.max);
}

PositionArrayBuilder::PositionArrayBuilder(const std::string& temp_dir, const std::string& source_path)
    : file_(std::make_unique<TempFile>(temp_dir, "oocsimp-positions-")),
      sink_(std::make_unique<ByteSink>(file_->fd(), file_->path(), false)),
      source_path_(source_path),
      temp_dir_(temp_dir) {
  sink_->on_write_error([this](std::uint64_t on_disk, int err) {
    std::string need = expected_bytes_ ? ", of about " + mib_text(expected_bytes_) + " needed" : "";
    return temp_dir_ + ": cannot write the temporary position array of " + source_path_ + " (" + mib_text(on_disk) +
           " written" + need + "): " + std::strerror(err);
  });
}

void PositionArrayBuilder::expect(std::uint64_t vertices) {
  expected_bytes_ = vertices * 3 * sizeof(float);
  require_free_space(temp_dir_, expected_bytes_, "the temporary position array of " + source_path_);
}

PositionArrayBuilder::~PositionArrayBuilder() = default;

Vec3d PositionArrayBuilder::widen(const float* f) { return {double(f[0]), double(f[1]), double(f[2])}; }

void PositionArrayBuilder::not_finite_as_float(double x, double y, double z, const std::string& where) {
  if (std::isfinite(x) && std::isfinite(y) && std::isfinite(z)) {
    // The value is a number, just not one a float holds: converting would invent an
    // infinity, so this is bad input rather than a vertex to skip.
    std::ostringstream msg;
    msg << source_path_ << ": " << where << ": vertex " << count_ << " (" << x << ", " << y << ", " << z
        << ") is beyond the float range";
    throw InputError(msg.str());
  }
  if (non_finite_++ == 0) {
    first_non_finite_ = count_;
    first_non_finite_position_ = where;
  }
}

void PositionArrayBuilder::finish(MeshInput& out) {
  sink_->finish();
  sink_.reset();
  file_->close();
  auto map = std::make_unique<MappedFile>(file_->path());
  out.positions = PositionArray{};
  out.positions.base = map->data();
  out.positions.count = count_;
  out.info.bounds = bounds_;
  out.info.non_finite_vertices = non_finite_;
  out.info.first_non_finite_vertex = first_non_finite_;
  out.info.first_non_finite_position = first_non_finite_position_;
  out.impl->position_map = std::move(map);
  out.impl->position_file = std::move(file_);
}

}  // namespace oocsimp
