// Distributed runs: one part of a run per process or machine, and the merge of the
// parts into the run's output (docs/cluster.md).
#pragma once

#include "oocsimp/export.hpp"

#include <cstdint>
#include <string>

#include "oocsimp/options.hpp"
#include "oocsimp/stats.hpp"

namespace oocsimp {

/// One part of a run spread over processes or machines.
struct PartOptions {
  std::uint32_t index = 0;  ///< this part, below count
  std::uint32_t count = 1;  ///< the parts of the run, each given the same input and options
  std::string work_dir;     ///< where the part's file goes; the folder merge_parts reads
  /// Parts that run at once (MPI ranks) may exchange what they decide while they run;
  /// floating cells then split their grading and border sweeps between the parts
  /// instead of each part running them whole. Empty for parts that run apart (job
  /// arrays).
  PartExchange exchange = nullptr;
  /// With `exchange`, a part's messages to each part (MPI's all-to-all), for what
  /// one part has and another needs (floating cells: the triangles each rank reads
  /// for the others' tiles). Optional: without it they go through `exchange`, each
  /// part then receiving every message.
  PartDelivery deliver = nullptr;
};

/// Throws UsageError naming the option when `options` ask for what a distributed run
/// cannot do yet: thick edges, locks.
OOCSIMP_API void check_distributed_options(const SimplifyOptions& options);

/// Part part.index of part.count of the run simplify_file(input_path, ..., options)
/// would make: the share of its work the part owns, left in
/// part.work_dir/part-I-of-K.oocpart (renamed into place when complete, so a failed
/// part leaves nothing) for merge_parts. Every part reads the whole input from a
/// shared path. Four runs spread for now (UsageError otherwise): options.method
/// uniform without a target, whose chunks the parts sum; a target with the edge
/// collapse (options.method qem, or automatic with a target), whose first out-of-core
/// pass the parts share; options.method floating, whose parts each accumulate their
/// own tiles (grading and sweeping only those with part.exchange); and
/// options.method curvature, whose parts each estimate the curvatures of their share
/// of the vertices (the merge builds the clusters). A target after one of those
/// clustering methods spreads its phase 1 (its first attempt) the same way; the
/// collapse runs in the merge. Fills the input counts of `stats` when given.
OOCSIMP_API void simplify_part(const std::string& input_path, const SimplifyOptions& options, const PartOptions& part,
                               SimplifyStats* stats = nullptr);

/// Finishes a distributed run from the part files in `work_dir`: writes `outputs` as
/// simplify_file would with the parts' input and options, the same bytes for any
/// part count and threads. From `options` only the memory budget, threads, temporary
/// folder and progress apply. Throws InputError (exit 3) naming a missing, damaged or
/// stale part (another input or other options), or an input changed since.
OOCSIMP_API void merge_parts(const std::string& work_dir, const OutputOptions& outputs, const SimplifyOptions& options,
                             SimplifyStats* stats = nullptr);

}  // namespace oocsimp
