// oocsimp — error types.
//
// Every failure leaves the library as an exception of one of three kinds (or
// Cancelled, when the caller's progress callback asked to stop); the CLI maps each
// kind to an exit code (usage 2, bad input 3, I/O or resources 4). Messages are one
// line and name the file and the position (byte offset or line). An option at fault is
// named by its field, as the caller set it: "options.memory_budget",
// "options.sizing.grid", "options.floating.tile_side", "options.temp_dir" (the CLI
// shows its own flags in their place); a UsageError about one option also carries its
// field (UsageError::option()).
#pragma once

#include "oocsimp/export.hpp"

#include <stdexcept>
#include <string>
#include <utility>

namespace oocsimp {

/// Inconsistent or impossible options (exit code 2).
class OOCSIMP_API UsageError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
  /// An error about one option: `message` starts with its field, `option`
  /// ("options.memory_budget 256 MiB cannot hold ..."), so that a program can show the
  /// option its own way (the CLI shows the flag that sets it).
  UsageError(std::string option, const std::string& message)
      : std::runtime_error(message), option_(std::move(option)) {}
  /// The field the message starts with; empty when the error is about no one option.
  const std::string& option() const { return option_; }

 private:
  std::string option_;
};

/// The input file is malformed: truncated, wrong counts, bad indices, a malformed
/// number (exit code 3). NaN or infinite coordinates are not errors: such vertices are
/// counted and ignored (see MeshInfo::non_finite_vertices). The message starts with "FILE: byte N:" or "FILE: line N:".
class OOCSIMP_API InputError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

/// Reading, writing, mapping or allocating failed for a reason outside the input's
/// content: missing file, full disk, permissions, memory (exit code 4).
class OOCSIMP_API IoError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

/// The caller's ProgressCallback returned false: the run stopped, deleting its
/// temporary files and writing no output.
class OOCSIMP_API Cancelled : public std::runtime_error {
 public:
  Cancelled() : std::runtime_error("cancelled") {}
};

}  // namespace oocsimp
