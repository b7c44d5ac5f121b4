// Welding as an external sort of (position, index) records, in three stages:
//  1. Runs. The positions are read in index order, a run of R vertices at a time (R
//     from the budget). A run's records are sorted; of each group of equal positions
//     only the first (smallest index) goes to the runs file, and the others are
//     redirected to it. The run's redirections are appended to the remap file, which
//     holds one entry per original vertex: itself, or an earlier vertex at the same
//     position.
//  2. Merge. The runs are merged by (position, index) through a heap; a record whose
//     position equals the one before is redirected to it. When there are more runs
//     than the heap may hold, groups of them are merged into longer runs first (their
//     first occurrences only), and again, until one merge remains.
//  3. Numbering. In index order, a vertex that points to itself is a first occurrence:
//     it takes the next new id and its position is appended to the new position
//     array; any other vertex takes the new id of the vertex it points to, which is
//     smaller and so already numbered (chains left by stages 1 and 2 resolve so).
// A run holds R vertices whatever their positions, so a million copies of one point
// cost no more memory than a million distinct points (hash buckets would put them all
// in one bucket). The remap file is mapped; the heap holds one run or one merge's
// heads, bounded by the budget.
#include "io/vertex_weld.hpp"

#include <tbb/parallel_sort.h>

#include <algorithm>
#include <cstring>
#include <memory>
#include <vector>

#include "io/attribute_array.hpp"
#include "io/byte_sink.hpp"
#include "io/mapped_file.hpp"
#include "io/position_array.hpp"
#include "io/temp_file.hpp"

namespace oocsimp {

namespace {

// The bits of a stored coordinate, float (uint32) or double (uint64).
template <class Word>
struct FloatBits;
template <>
struct FloatBits<std::uint32_t> {
  static constexpr std::uint32_t sign = 0x80000000u, exponent = 0x7f800000u;
  static std::uint32_t swap(std::uint32_t w) { return __builtin_bswap32(w); }
};
template <>
struct FloatBits<std::uint64_t> {
  static constexpr std::uint64_t sign = 0x8000000000000000ull, exponent = 0x7ff0000000000000ull;
  static std::uint64_t swap(std::uint64_t w) { return __builtin_bswap64(w); }
};

// An array of vertex indices in mapped or heap memory, 4 bytes an entry when every
// index fits in 32 bits, else 8.
class IndexArray {
 public:
  IndexArray(unsigned char* base, unsigned width) : base_(base), width_(width) {}
  std::uint64_t get(std::uint64_t i) const {
    if (width_ == 4) {
      std::uint32_t v;
      std::memcpy(&v, base_ + 4 * i, 4);
      return v;
    }
    std::uint64_t v;
    std::memcpy(&v, base_ + 8 * i, 8);
    return v;
  }
  void set(std::uint64_t i, std::uint64_t v) {
    if (width_ == 4) {
      std::uint32_t u = std::uint32_t(v);
      std::memcpy(base_ + 4 * i, &u, 4);
    } else {
      std::memcpy(base_ + 8 * i, &v, 8);
    }
  }

 private:
  unsigned char* base_;
  unsigned width_;
};

// The new index of every original vertex, in a mapped temporary file that lives as
// long as the input's triangle streams.
struct WeldMap {
  std::unique_ptr<TempFile> file;
  std::unique_ptr<MappedFile> map;
  unsigned width = 8;
  IndexArray indices() const { return IndexArray(map->writable_data(), width); }
};

// Yields the inner stream's triangles with welded indices.
class WeldedTriangleStream : public TriangleStream {
 public:
  WeldedTriangleStream(std::unique_ptr<TriangleStream> inner, std::shared_ptr<const WeldMap> weld)
      : inner_(std::move(inner)), weld_(std::move(weld)), indices_(weld_->indices()) {}
  std::size_t read(std::uint64_t* out, std::size_t max_triangles) override {
    std::size_t n = inner_->read(out, max_triangles);
    for (std::size_t k = 0; k < 3 * n; ++k) out[k] = indices_.get(out[k]);
    return n;
  }
  std::uint64_t bytes_consumed() const override { return inner_->bytes_consumed(); }
  SkippedFaces skipped() const override { return inner_->skipped(); }
  // Edges and points name the welded vertices too.
  void set_primitive_sink(PrimitiveSink sink) override {
    inner_->set_primitive_sink([this, sink = std::move(sink)](const LinePrimitive* p, std::size_t n) {
      welded_.assign(p, p + n);
      for (LinePrimitive& l : welded_) {
        l.a = indices_.get(l.a);
        l.b = indices_.get(l.b);
      }
      sink(welded_.data(), welded_.size());
    });
  }

 private:
  std::unique_ptr<TriangleStream> inner_;
  std::vector<LinePrimitive> welded_;
  std::shared_ptr<const WeldMap> weld_;
  IndexArray indices_;
};

// A vertex's position as the sort key, and its original index (in two halves, so a
// record of float positions takes 20 bytes, not 24).
template <class Word>
struct WeldRecord {
  Word key[3];
  std::uint32_t index_lo, index_hi;

  std::uint64_t index() const { return std::uint64_t(index_hi) << 32 | index_lo; }
  bool same_position(const WeldRecord& o) const {
    return key[0] == o.key[0] && key[1] == o.key[1] && key[2] == o.key[2];
  }
  bool operator<(const WeldRecord& o) const {
    for (int k = 0; k < 3; ++k)
      if (key[k] != o.key[k]) return key[k] < o.key[k];
    return index() < o.index();
  }
};

template <class Word>
class Welder {
 public:
  using Record = WeldRecord<Word>;

  Welder(MeshInput& input, const std::string& temp_dir, std::uint64_t budget, bool wide_map)
      : input_(input),
        positions_(input.positions),
        n_(input.positions.count),
        temp_dir_(temp_dir),
        width_(wide_map || n_ > (std::uint64_t(1) << 32) ? 8 : 4) {
    // Half the budget for a run (its records and its slice of the remap), the rest
    // for the I/O buffers; a merge's heads take as much.
    const std::uint64_t half = std::max<std::uint64_t>(budget / 2, 1);
    run_vertices_ = std::max<std::uint64_t>(64, half / (sizeof(Record) + width_));
    fan_in_ = std::max<std::size_t>(2, std::size_t(half / (sizeof(Head) + 2 * sizeof(std::uint64_t))));
  }

  void run() {
    // Only the map's size is certain: the runs and the new positions shrink with every
    // duplicate, so they are not estimated (a failed write names the folder and file).
    require_free_space(temp_dir_, n_ * width_, "the vertex map for welding the vertices of " + input_.info.path);
    auto weld = std::make_shared<WeldMap>();
    weld->width = width_;
    weld->file = write_runs();
    weld->map = std::make_unique<MappedFile>(weld->file->path(), MapAccess::read_write);
    merge_runs(weld->indices());
    number_vertices(weld->indices());
    auto inner = std::move(reader_state(input_).make_triangles);
    std::shared_ptr<const WeldMap> shared = std::move(weld);
    reader_state(input_).make_triangles = [inner, shared]() -> std::unique_ptr<TriangleStream> {
      return std::make_unique<WeldedTriangleStream>(inner(), shared);
    };
  }

 private:
  struct Run {
    std::uint64_t first, count;  // in records of the runs file
  };
  struct Head {
    Record record;
    std::uint32_t run;
  };

  std::unique_ptr<ByteSink> sink_for(const TempFile& file, const char* what) const {
    auto sink = std::make_unique<ByteSink>(file.fd(), file.path(), false);
    std::string dir = temp_dir_, source = input_.info.path;
    sink->on_write_error([dir, source, what](std::uint64_t on_disk, int err) {
      return dir + ": cannot write the " + what + " for welding the vertices of " + source + " (" + mib_text(on_disk) +
             " written): " + std::strerror(err);
    });
    return sink;
  }

  Word word(std::uint64_t i, int k) const {
    Word w;
    std::memcpy(&w, positions_.base + i * positions_.stride + positions_.offset[k], sizeof w);
    return positions_.swap ? FloatBits<Word>::swap(w) : w;
  }

  // False for a vertex with a NaN or infinite coordinate: it is never welded.
  bool make_record(std::uint64_t i, Record* r) const {
    for (int k = 0; k < 3; ++k) {
      Word w = word(i, k);
      if ((w & FloatBits<Word>::exponent) == FloatBits<Word>::exponent) return false;
      r->key[k] = w == FloatBits<Word>::sign ? Word(0) : w;  // -0 welds with +0
    }
    r->index_lo = std::uint32_t(i);
    r->index_hi = std::uint32_t(i >> 32);
    return true;
  }

  // Stage 1: writes the sorted runs (first occurrences within each) to runs_file_ and
  // returns the remap file, each vertex pointing to itself or an earlier one.
  std::unique_ptr<TempFile> write_runs() {
    auto remap_file = std::make_unique<TempFile>(temp_dir_, "oocsimp-weld-map-");
    auto remap_sink = sink_for(*remap_file, "vertex map");
    runs_file_ = std::make_unique<TempFile>(temp_dir_, "oocsimp-weld-runs-");
    auto runs_sink = sink_for(*runs_file_, "sorted runs");
    std::vector<Record> records;
    records.reserve(std::size_t(std::min(run_vertices_, n_)));
    std::vector<unsigned char> slice(std::size_t(std::min(run_vertices_, n_) * width_));
    std::uint64_t written = 0;
    for (std::uint64_t start = 0; start < n_; start += run_vertices_) {
      const std::uint64_t end = std::min(n_, start + run_vertices_);
      IndexArray local(slice.data(), width_);  // entries start..end-1
      records.clear();
      for (std::uint64_t i = start; i < end; ++i) {
        local.set(i - start, i);
        Record r;
        if (make_record(i, &r)) records.push_back(r);
      }
      tbb::parallel_sort(records.begin(), records.end());  // (position, index) is unique: one order
      std::uint64_t kept = 0;
      std::size_t first = 0;
      for (std::size_t k = 0; k < records.size(); ++k) {
        if (k > 0 && records[k].same_position(records[first])) {
          local.set(records[k].index() - start, records[first].index());
        } else {
          first = k;
          runs_sink->write(&records[k], sizeof(Record));
          ++kept;
        }
      }
      if (kept > 0) runs_.push_back({written, kept});
      written += kept;
      remap_sink->write(slice.data(), std::size_t((end - start) * width_));
    }
    runs_sink->finish();
    runs_file_->close();
    remap_sink->finish();
    remap_file->close();
    return remap_file;
  }

  // Stage 2: merges the runs until one merge covers them all.
  void merge_runs(IndexArray remap) {
    while (runs_.size() > 1) {
      const bool last = runs_.size() <= fan_in_;
      MappedFile in(runs_file_->path());
      std::unique_ptr<TempFile> next_file;
      std::unique_ptr<ByteSink> next_sink;
      std::vector<Run> next_runs;
      if (!last) {
        next_file = std::make_unique<TempFile>(temp_dir_, "oocsimp-weld-runs-");
        next_sink = sink_for(*next_file, "sorted runs");
      }
      std::uint64_t written = 0;
      for (std::size_t g = 0; g < runs_.size(); g += fan_in_) {
        std::size_t count = std::min(fan_in_, runs_.size() - g);
        std::uint64_t kept = merge_group(in.data(), &runs_[g], count, remap, next_sink.get());
        next_runs.push_back({written, kept});
        written += kept;
      }
      if (last) break;
      next_sink->finish();
      next_file->close();
      runs_file_ = std::move(next_file);
      runs_ = std::move(next_runs);
    }
    runs_file_.reset();
  }

  // Merges `count` runs of the mapped runs file `data`, redirecting each record to the
  // first one at its position; returns how many first occurrences there were, written
  // to `out` when given.
  std::uint64_t merge_group(const unsigned char* data, const Run* runs, std::size_t count, IndexArray remap,
                            ByteSink* out) {
    std::vector<std::uint64_t> next(count), end(count);
    auto load = [&](std::uint32_t r) {
      Record rec;
      std::memcpy(&rec, data + next[r] * sizeof(Record), sizeof rec);
      ++next[r];
      return rec;
    };
    auto later = [](const Head& a, const Head& b) { return b.record < a.record; };  // smallest on top
    std::vector<Head> heap;
    heap.reserve(count);
    for (std::uint32_t r = 0; r < count; ++r) {
      next[r] = runs[r].first;
      end[r] = runs[r].first + runs[r].count;
      heap.push_back({load(r), r});
    }
    std::make_heap(heap.begin(), heap.end(), later);
    Record previous{};
    std::uint64_t kept = 0;
    while (!heap.empty()) {
      std::pop_heap(heap.begin(), heap.end(), later);
      const Head head = heap.back();
      heap.pop_back();
      if (kept > 0 && head.record.same_position(previous)) {
        remap.set(head.record.index(), previous.index());
      } else {
        previous = head.record;
        ++kept;
        if (out) out->write(&head.record, sizeof(Record));
      }
      if (next[head.run] < end[head.run]) {
        heap.push_back({load(head.run), head.run});
        std::push_heap(heap.begin(), heap.end(), later);
      }
    }
    return kept;
  }

  // Stage 3: numbers the first occurrences in index order, turns the remap into new
  // ids, and replaces the input's positions by the first occurrences'.
  void number_vertices(IndexArray remap) {
    auto file = std::make_unique<TempFile>(temp_dir_, "oocsimp-positions-");
    auto sink = sink_for(*file, "welded position array");
    // A welded vertex keeps the attributes of its first occurrence.
    const AttributeArray& attrs = input_.attributes;
    std::unique_ptr<AttributeArrayBuilder> attribute_builder;
    if (!attrs.empty())
      attribute_builder = std::make_unique<AttributeArrayBuilder>(temp_dir_, input_.info.path, attrs.attributes);
    std::vector<double> values(attrs.size());
    std::uint64_t next = 0;
    for (std::uint64_t i = 0; i < n_; ++i) {
      const std::uint64_t to = remap.get(i);
      if (to == i) {
        remap.set(i, next++);
        const Word w[3] = {word(i, 0), word(i, 1), word(i, 2)};
        sink->write(w, sizeof w);
        if (attribute_builder) {
          for (std::size_t k = 0; k < attrs.size(); ++k) values[k] = attribute_value(attrs, i, k);
          attribute_builder->add(values.data());
        }
      } else {
        remap.set(i, remap.get(to));
      }
    }
    sink->finish();
    file->close();
    // Non-finite vertices are never welded, so the first of them stays the first, now
    // under its new number (where it is in the file stays as the reader said).
    if (input_.info.non_finite_vertices > 0)
      input_.info.first_non_finite_vertex = remap.get(input_.info.first_non_finite_vertex);
    auto map = std::make_unique<MappedFile>(file->path());
    PositionArray welded = input_.positions;  // same scalar type, native byte order, packed
    welded.base = map->data();
    welded.count = next;
    welded.stride = 3 * sizeof(Word);
    for (int k = 0; k < 3; ++k) welded.offset[k] = k * sizeof(Word);
    welded.swap = false;
    input_.positions = welded;
    reader_state(input_).position_map = std::move(map);
    reader_state(input_).position_file = std::move(file);
    input_.info.positions_in_place = false;
    if (attribute_builder) attribute_builder->finish(input_);  // replaces the array (and its file) it read
    input_.info.unwelded_vertex_count = n_;
    input_.info.vertex_count = next;
  }

  MeshInput& input_;
  const PositionArray positions_;  // as read; stays mapped until stage 3 replaces it
  const std::uint64_t n_;
  const std::string temp_dir_;
  const unsigned width_;
  std::uint64_t run_vertices_ = 0;
  std::size_t fan_in_ = 2;
  std::unique_ptr<TempFile> runs_file_;
  std::vector<Run> runs_;
};

}  // namespace

void weld_vertices(MeshInput& input, const std::string& temp_dir, std::uint64_t memory_budget, bool wide_map) {
  if (input.positions.type == ScalarType::f32)
    Welder<std::uint32_t>(input, temp_dir, memory_budget, wide_map).run();
  else
    Welder<std::uint64_t>(input, temp_dir, memory_budget, wide_map).run();
}

}  // namespace oocsimp
