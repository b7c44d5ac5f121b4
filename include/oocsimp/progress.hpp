// oocsimp — progress of a long run, and how a caller cancels it.
#pragma once

#include <cstdint>
#include <functional>

namespace oocsimp {

/// One report of a run's progress: a phase began, counted some work, or ended.
struct Progress {
  enum class Event : std::uint8_t { begin, advance, end };
  Event event = Event::advance;
  const char* phase = "";  ///< e.g. "read positions", "bin tiles", "cell quadrics", "write"
  const char* unit = "";   ///< what done and total count: "B" (input bytes), "tri", "tile", "vtx", ...
  std::uint64_t done = 0;
  std::uint64_t total = 0;  ///< 0 while unknown (phases without a count report only begin and end)
  /// What the phase says of itself beside its counts, "" for most: a pass of the
  /// out-of-core collapse tells the triangles it starts from, and at its end
  /// "IN -> OUT triangles".
  const char* detail = "";
};

/// The one progress-and-cancel callback of the library (SimplifyOptions::progress,
/// OpenOptions::progress, MeasureOptions::progress, GenerateOptions::progress). It is
/// called at each phase's begin and end and at most every 50 ms in between, from any of
/// the run's threads but never two at a time. Returning false cancels the run: it stops
/// at its next report with oocsimp::Cancelled, its temporary files deleted and no output
/// written. An empty callback costs nothing.
using ProgressCallback = std::function<bool(const Progress&)>;

}  // namespace oocsimp
