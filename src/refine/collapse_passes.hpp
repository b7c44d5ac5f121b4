// The collapse in passes (meshoptimizer's order: every edge costed, the cheapest valid
// collapses taken, each vertex in at most one a pass): the first driver of
// collapse_state() on meshes of settings.pass_faces or more.
#pragma once

#include <cstdint>

#include "refine/edge_collapse.hpp"

namespace oocsimp {

class ProgressPhase;

/// Passes over `state` until at most `stop_at` triangles are left, a pass takes too few
/// of the collapses it wanted, or a collapse above settings.max_error comes up. Adds to
/// `stats`; reports the collapses taken to `progress` when given.
void collapse_in_passes(CollapseState& state, const CollapseSettings& settings, std::uint64_t stop_at,
                        CollapseStats* stats, ProgressPhase* progress);

}  // namespace oocsimp
