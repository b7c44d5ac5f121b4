// The faces around each vertex of an indexed triangle mesh, as one array in vertex
// order (a compressed adjacency): what a pass over each vertex's fan reads.
#pragma once

#include <cstddef>
#include <cstdint>
#include <vector>

namespace oocsimp {

struct VertexFaces {
  std::vector<std::uint32_t> start;  // per vertex, then one past the last
  std::vector<std::uint32_t> faces;  // the faces of vertex v: faces[start[v], start[v + 1])

  /// `triangles` holds 3 corners per face, each below `vertices`.
  VertexFaces(std::size_t vertices, const std::vector<std::uint32_t>& triangles) : start(vertices + 1, 0) {
    for (std::uint32_t v : triangles) ++start[std::size_t(v) + 1];
    for (std::size_t v = 0; v < vertices; ++v) start[v + 1] += start[v];
    faces.resize(triangles.size());
    std::vector<std::uint32_t> fill(start.begin(), start.end() - 1);
    for (std::size_t i = 0; i < triangles.size(); ++i) faces[fill[triangles[i]]++] = std::uint32_t(i / 3);
  }
};

}  // namespace oocsimp
