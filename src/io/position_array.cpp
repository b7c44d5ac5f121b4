#include "io/position_array.hpp"

#include <tbb/blocked_range.h>
#include <tbb/parallel_reduce.h>
#include <unistd.h>

#include <cmath>
#include <cstring>
#include <sstream>

#include "common/vec3_math.hpp"
#include "io/attribute_array.hpp"
#include "oocsimp/error.hpp"

namespace oocsimp {

double Box3d::diagonal() const {
  if (empty()) return 0;
  return distance(max, min);
}

void Box3d::add(const Vec3d& p) {
  min = oocsimp::min(min, p);
  max = oocsimp::max(max, p);
}

void Box3d::add(const Box3d& b) {
  if (b.empty()) return;
  add(b.min);
  add(b.max);
}

PositionArrayBuilder::PositionArrayBuilder(const std::string& temp_dir, const std::string& source_path)
    : source_path_(source_path), temp_dir_(temp_dir) {
  open_file();
}

PositionArrayBuilder::~PositionArrayBuilder() = default;

void PositionArrayBuilder::open_file() {
  file_ = std::make_unique<TempFile>(temp_dir_, "oocsimp-positions-");
  sink_ = std::make_unique<ByteSink>(file_->fd(), file_->path(), false);
  sink_->on_write_error([this](std::uint64_t on_disk, int err) {
    std::string need =
        expected_vertices_ ? ", of about " + mib_text(expected_vertices_ * record_bytes()) + " needed" : "";
    return temp_dir_ + ": cannot write the temporary position array of " + source_path_ + " (" + mib_text(on_disk) +
           " written" + need + "): " + std::strerror(err);
  });
}

void PositionArrayBuilder::expect(std::uint64_t vertices) {
  expected_vertices_ = vertices;
  require_free_space(temp_dir_, vertices * record_bytes(), "the temporary position array of " + source_path_);
}

Vec3d PositionArrayBuilder::widen(const float* f) { return {double(f[0]), double(f[1]), double(f[2])}; }

void PositionArrayBuilder::beyond_float_range(double x, double y, double z, const std::string& where) const {
  // The value is a number, just not one the declared float holds: converting would
  // invent an infinity, so this is bad input rather than a vertex to skip.
  std::ostringstream msg;
  msg << source_path_ << ": " << where << ": vertex " << count_ << " (" << x << ", " << y << ", " << z
      << ") is beyond the float range of its declared type";
  throw InputError(msg.str());
}

void PositionArrayBuilder::declare(ScalarType type) {
  if (type == ScalarType::f32)
    round_to_float_ = true;
  else
    store_as_double();
}

void PositionArrayBuilder::store_as_double() {
  if (is_double_) return;
  is_double_ = true;
  if (expected_vertices_) expect(expected_vertices_);
  // The floats so far, widened (exactly) into a new file; the old one goes with its owner.
  sink_->finish();
  sink_.reset();
  file_->close();
  std::unique_ptr<TempFile> floats = std::move(file_);
  open_file();
  if (count_ == 0) return;
  MappedFile map(floats->path());
  for (std::uint64_t i = 0; i < count_; ++i) {
    float f[3];
    std::memcpy(f, map.data() + 12 * i, sizeof f);
    double d[3] = {f[0], f[1], f[2]};
    sink_->write(d, sizeof d);
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
  if (is_double_) {
    out.positions.type = ScalarType::f64;
    out.positions.stride = 3 * sizeof(double);
    out.positions.offset[1] = sizeof(double);
    out.positions.offset[2] = 2 * sizeof(double);
  }
  out.info.double_precision = is_double_;
  out.info.bounds = bounds_;
  out.info.non_finite_vertices = non_finite_;
  out.info.first_non_finite_vertex = first_non_finite_;
  out.info.first_non_finite_position = first_non_finite_position_;
  reader_state(out).position_map = std::move(map);
  reader_state(out).position_file = std::move(file_);
}

// The first non-finite vertex in index order is described, so the report does not
// depend on the thread count. Attributes stored next to the positions are scanned in
// the same pass, a block at a time while its records are in cache: a second pass
// over a mapped file larger than the cache would read it all again.
void scan_positions(MeshInput& out) {
  struct Scan {
    Box3d box;
    std::uint64_t non_finite = 0;
    std::uint64_t first_non_finite = ~std::uint64_t(0);
    AttributeRanges attributes;
  };
  const PositionArray& pa = out.positions;
  const AttributeArray& aa = out.attributes;
  Scan s = tbb::parallel_reduce(
      tbb::blocked_range<std::uint64_t>(0, pa.count, 1 << 16),
      Scan{{}, 0, ~std::uint64_t(0), AttributeRanges(aa.size())},
      [&](const tbb::blocked_range<std::uint64_t>& r, Scan acc) {
        constexpr std::uint64_t kBlock = 1024;  // records that stay in cache for the attributes
        for (std::uint64_t begin = r.begin(); begin < r.end(); begin += kBlock) {
          const std::uint64_t end = std::min(r.end(), begin + kBlock);
          for (std::uint64_t i = begin; i != end; ++i) {
            Vec3d p = pa.get(i);
            if (!is_finite(p)) {
              ++acc.non_finite;
              acc.first_non_finite = std::min(acc.first_non_finite, i);
              continue;
            }
            acc.box.add(p);
          }
          if (!aa.empty()) acc.attributes.widen(aa, begin, end);
        }
        return acc;
      },
      [](Scan a, const Scan& b) {
        a.box.add(b.box);
        a.non_finite += b.non_finite;
        a.first_non_finite = std::min(a.first_non_finite, b.first_non_finite);
        a.attributes.merge(b.attributes);
        return a;
      });
  out.info.bounds = s.box;
  out.info.non_finite_vertices = s.non_finite;
  if (s.non_finite > 0) out.info.first_non_finite_vertex = s.first_non_finite;
  if (!aa.empty()) s.attributes.store(out.attributes);
}

}  // namespace oocsimp
