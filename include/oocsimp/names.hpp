// The options' defaults and their values' names as the command line spells them, the
// version, and a run's reports (its JSON stats, the input it skipped).
#pragma once

#include "oocsimp/export.hpp"

#include <cstdint>
#include <string>
#include <vector>

#include "oocsimp/enum_names.hpp"
#include "oocsimp/options.hpp"
#include "oocsimp/stats.hpp"

namespace oocsimp {

/// A quarter of physical memory: the default working-set budget.
OOCSIMP_API std::uint64_t default_memory_budget();

/// The least memory budget a simplify run takes (32 MiB): below it a run cannot hold
/// its I/O buffers, one tile's spill buffers and the pipeline's chunks, whatever the
/// input.
OOCSIMP_API std::uint64_t minimum_memory_budget();

/// Parses a byte size with an optional binary suffix: "256M", "2G", "512k", "1048576".
/// Throws UsageError.
OOCSIMP_API std::uint64_t parse_byte_size(const std::string& text);

/// The default temporary directory: $TMPDIR if set and non-empty, else /tmp.
OOCSIMP_API std::string default_temp_dir();

/// A run as a JSON object: the version, the paths, the method and every option, counts,
/// seconds per phase, peak memory and input Mtri/s.
OOCSIMP_API std::string stats_to_json(const SimplifyStats& stats, const std::string& input_path,
                                      const OutputOptions& outputs, const SimplifyOptions& options);

/// The oocsimp version (the CMake project version).
OOCSIMP_API const char* version();

/// Every clustering method, the default first.
OOCSIMP_API std::vector<ClusterMethod> cluster_methods();

/// Option values as the command line spells them ("floating", "cube", "nearest", ...).
OOCSIMP_API const char* method_name(ClusterMethod m);
OOCSIMP_API const char* cell_shape_name(CellShape s);
OOCSIMP_API const char* assign_name(AssignRule a);
OOCSIMP_API const char* representative_name(RepresentativeRule r);
OOCSIMP_API const char* spill_compression_name(SpillCompression c);
OOCSIMP_API const char* refine_name(RefineMethod r);
OOCSIMP_API const char* precision_name(Precision p);

/// The tables those names come from, one per enum, each in the order the command line
/// lists the values (the default first).
OOCSIMP_API const EnumNames<ClusterMethod>& cluster_method_names();
OOCSIMP_API const EnumNames<CellShape>& cell_shape_names();
OOCSIMP_API const EnumNames<AssignRule>& assign_rule_names();
OOCSIMP_API const EnumNames<RepresentativeRule>& representative_rule_names();
OOCSIMP_API const EnumNames<SpillCompression>& spill_compression_names();
OOCSIMP_API const EnumNames<RefineMethod>& refine_method_names();
OOCSIMP_API const EnumNames<Precision>& precision_names();

/// One line (no newline) naming `input_path` and every count of skipped faces and
/// ignored vertices in `stats`, with the first non-finite vertex; empty when the input
/// lost nothing.
OOCSIMP_API std::string skipped_input_summary(const std::string& input_path, const SimplifyStats& stats);

}  // namespace oocsimp
