// oocsimp — writing small (in-memory) meshes.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

namespace oocsimp {

class OutputFile;

enum class MeshFormat { ply_binary, ply_ascii, obj };

/// The format implied by a path: ".obj" (optionally ".obj.zst") gives OBJ, anything
/// else PLY; `ascii` selects ascii PLY. Compression is implied by a ".zst" suffix.
MeshFormat format_for_path(const std::string& path, bool ascii);

/// Writes a triangle mesh given as flat arrays: `positions` holds 3 floats per vertex,
/// `triangles` 3 vertex indices per face. PLY is written with float x,y,z and a
/// "uchar uint vertex_indices" list; a ".zst" suffix compresses the stream.
/// The destination is an OutputFile: a regular file is written under a temporary name
/// in its folder and renamed into place only when complete (on any failure it is
/// untouched and the temporary file removed); a device, FIFO or "-" is streamed into.
/// Throws IoError.
void write_mesh(const std::string& path, const std::vector<float>& positions,
                const std::vector<std::uint32_t>& triangles, MeshFormat format);

/// The same into an OutputFile opened earlier; the caller commits it.
void write_mesh(OutputFile& out, const std::vector<float>& positions, const std::vector<std::uint32_t>& triangles,
                MeshFormat format);

}  // namespace oocsimp
