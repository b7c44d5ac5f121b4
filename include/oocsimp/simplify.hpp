// The core of the facade: simplifying a file or a mesh in memory, to one mesh or to
// levels of detail (docs/library.md). oocsimp/oocsimp.hpp gathers this and the rest.
#pragma once

#include "oocsimp/export.hpp"

#include <cstdint>
#include <functional>
#include <string>
#include <vector>

#include "oocsimp/mesh.hpp"
#include "oocsimp/options.hpp"
#include "oocsimp/stats.hpp"

namespace oocsimp {

/// Opens `input_path`, simplifies it and writes `outputs` (see OutputFile: regular files
/// through a temporary name and a rename, devices, FIFOs and stdout streamed). Before any
/// work it refuses (UsageError) an unwritable extension and destinations that are the
/// input (unless replace_input) or each other, and opens every destination; the stats
/// are committed before the mesh, so a failure leaves the mesh as it was. Fills `stats`
/// when given.
OOCSIMP_API void simplify_file(const std::string& input_path, const OutputOptions& outputs,
                               const SimplifyOptions& options, SimplifyStats* stats);
/// The same with only a mesh output; a PLY or STL is written binary (the overload
/// above names an ascii one in OutputOptions::ascii).
OOCSIMP_API void simplify_file(const std::string& input_path, const std::string& output_path,
                               const SimplifyOptions& options, SimplifyStats* stats = nullptr);

/// simplify_lods on the file at `input_path`, level k written to
/// lod_level_path(outputs.mesh, k) (outputs.normals and outputs.ascii apply; not
/// stdout, and outputs.stats is refused: the levels' figures are the caller's to
/// describe). Every level file is opened before the work and renamed into place only
/// when all levels are written. Fills `stats` with one entry per level.
OOCSIMP_API void simplify_lods_file(const std::string& input_path, const OutputOptions& outputs,
                                    const SimplifyOptions& options, const LodOptions& lods,
                                    std::vector<SimplifyStats>* stats);

/// Simplifies a mesh in memory: the mesh is read in place (with options.attributes), then simplified as a file would
/// be. With a budget the spills fit in (the default, a quarter of memory, for any mesh that fits in memory), no file is
/// written, and options.temp_dir is not touched. The result equals the one simplify_file gives for the same mesh stored
/// in a file.
OOCSIMP_API SimplifiedMesh simplify_mesh(const MeshView& mesh, const SimplifyOptions& options,
                                         SimplifyStats* stats = nullptr);

/// Simplifies the file at `input_path` into memory: what simplify_file writes, as a
/// SimplifiedMesh (input opened as simplify_file opens it; no normals added).
OOCSIMP_API SimplifiedMesh simplify_file_to_mesh(const std::string& input_path, const SimplifyOptions& options,
                                                 SimplifyStats* stats = nullptr);

/// Hears each level when it is done: its number, its mesh (which the sink may move
/// from) and its stats.
using LodSink = std::function<void(std::uint32_t level, SimplifiedMesh& mesh, const SimplifyStats& stats)>;

/// simplify_lods_file into memory: each level of the file at `input_path`, finest
/// first, handed to `sink` when it is done (the levels simplify_lods_file writes).
/// With a target, the levels that go on from level 0's collapse are all done before
/// level 0 is handed on.
OOCSIMP_API void simplify_file_to_lods(const std::string& input_path, const SimplifyOptions& options,
                                       const LodOptions& lods, const LodSink& sink);

}  // namespace oocsimp
