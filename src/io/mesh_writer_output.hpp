// Writing a mesh into an OutputFile the caller opened before the run (simplify_file
// opens every destination first, so a missing folder fails before the work).
#pragma once

#include "io/temp_file.hpp"
#include "oocsimp/oocsimp.hpp"

namespace oocsimp {

/// write_mesh into an OutputFile opened earlier; the caller commits it.
void write_mesh(OutputFile& out, const std::vector<double>& positions, const std::vector<std::uint32_t>& triangles,
                MeshFormat format, ScalarType precision = ScalarType::f32, const AttributeValues* attributes = nullptr,
                const ThickPrimitives* primitives = nullptr);

}  // namespace oocsimp
