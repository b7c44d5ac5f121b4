// The wall seconds of a driver's stages, as SimplifyStats::phases lists them: one
// clock for the consecutive stages of a run instead of a timestamp per stage, so
// that a stage's name stands where it ends and the phases keep the drivers' order.
#pragma once

#include <iterator>
#include <string>
#include <utility>
#include <vector>

#include "oocsimp/stats.hpp"
#include "runtime/memory_usage.hpp"

namespace oocsimp {

/// Times consecutive stages: each stage runs from the last mark (the construction,
/// the end of the stage before, or restart()) to its end(). The ended stages are held
/// here until move_to() hands them on, so a run that stops half-way reports none.
class PhaseTimer {
 public:
  PhaseTimer() : mark_(now_seconds()) {}

  /// Ends the stage running since the last mark as phase `name`; the next starts now.
  void end(std::string name) {
    const double now = now_seconds();
    ended_.push_back({std::move(name), now - mark_});
    mark_ = now;
  }
  /// Starts the next stage now, leaving the time since the last mark untimed (what
  /// the caller does between stages, e.g. writing a level, is not a phase).
  void restart() { mark_ = now_seconds(); }
  /// Appends the stages ended so far, in order, to `phases`, and forgets them.
  void move_to(std::vector<PhaseTime>* phases) {
    phases->insert(phases->end(), std::make_move_iterator(ended_.begin()), std::make_move_iterator(ended_.end()));
    ended_.clear();
  }

 private:
  double mark_;
  std::vector<PhaseTime> ended_;
};

}  // namespace oocsimp
