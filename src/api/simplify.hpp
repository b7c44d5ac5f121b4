// The facade's entry points on an opened input (MeshInput), for the facade's own
// functions, the tests and the tools that work on a MeshInput directly.
#pragma once

#include <functional>

#include "cluster/quadric.hpp"
#include "grid/grid_choice.hpp"
#include "grid/grid_spec.hpp"
#include "io/mesh_input.hpp"
#include "methods/run_plan.hpp"
#include "oocsimp/formats.hpp"
#include "oocsimp/names.hpp"
#include "oocsimp/parts.hpp"
#include "oocsimp/simplify.hpp"

namespace oocsimp {

/// The run `options` ask for on `input`, checked and settled (methods/run_plan.hpp):
/// throws UsageError naming the option for a value the run cannot take, InputError
/// for an input coordinate beyond the float range.
RunPlan plan_run(const MeshInput& input, const SimplifyOptions& options);

/// Clusters `input` by `options.method`: floating cells (the default; Low & Tan,
/// see docs/design.md: cells centred on the heaviest vertices,
/// quadric representatives kept in their cell, tiles of the grid spilled to
/// `options.temp_dir` and sized from `options.memory_budget`) or a uniform grid
/// (OoCS: per cell the area-weighted plane quadrics of every triangle with a corner
/// in it and the mean of its vertices; the representative minimises the quadric
/// around that mean and stays in its cell). Either way a triangle survives when its
/// corners fall in three different clusters, each unordered triple once with the
/// orientation of its first occurrence in file order, and the result is
/// byte-identical for any thread count (and, for floating cells, any tiling).
/// With a target, `quadrics` (when given) receives the output vertices' quadrics
/// where the run ends in the edge collapse (simplify_to_target); else it stays empty.
SimplifiedMesh simplify(MeshInput& input, const SimplifyOptions& options, SimplifyStats* stats,
                        std::vector<Quadric>* quadrics = nullptr);

/// For the facade's functions that write one mesh (extract_file, curvature_file):
/// refuses (UsageError, naming the field and `function`) the fields of `outputs` only
/// simplify_file honours: stats, normals and replace_input.
void refuse_simplify_only_outputs(const OutputOptions& outputs, const char* function);

/// simplify() at K levels, finest first. Level 0 is what simplify() gives for
/// `options`; level k clusters at cell C F^k (C the cell of level 0), and equals
/// simplify() with options.sizing.cell = C F^k. Floating cells bin and grade the
/// input once for all levels (binning and grading do not depend on the cell; the
/// tiles fit the coarsest); the uniform grid, which neither bins nor grades, reads
/// the input twice per level. With a target (triangles or ratio, not max_error),
/// level k aims at the target halved k times, the edge collapse of level 0 going on
/// to each coarser level (its SimplifyStats::lod_cell an equivalent cell). Throws
/// UsageError for a bad `lods`, `qem` without a target, options.target.max_error,
/// or a triangle target that the levels halve below 4.
void simplify_lods(MeshInput& input, const SimplifyOptions& options, const LodOptions& lods, const LodSink& sink);

/// The precision `options` ask for on `input` (resolves Precision::automatic).
ScalarType output_precision(const MeshInput& input, Precision precision);

/// Opens a mesh in memory as a MeshInput for simplify() (no file, no copy: the views
/// point into the caller's arrays), with the attributes `selection` names (as
/// --attributes does). Throws UsageError for null arrays with non-zero counts, or a
/// selection naming an attribute the view lacks; an index out of range is an
/// InputError when the triangles are read.
MeshInput open_mesh_view(const MeshView& mesh, const AttributeSelection& selection = {});

}  // namespace oocsimp
