// Helpers shared by the tests: scratch folders, file writing, whole-mesh reading
// (small test meshes only) and running the CLI.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "io/mesh_input.hpp"

// Whether this is an AddressSanitizer build (tests whose memory figures ASan distorts
// skip there): GCC defines __SANITIZE_ADDRESS__, clang says it through __has_feature.
#if defined(__SANITIZE_ADDRESS__)
#define OOCSIMP_TEST_UNDER_ASAN 1
#elif defined(__has_feature)
#if __has_feature(address_sanitizer)
#define OOCSIMP_TEST_UNDER_ASAN 1
#endif
#endif
#ifndef OOCSIMP_TEST_UNDER_ASAN
#define OOCSIMP_TEST_UNDER_ASAN 0
#endif

namespace oocsimp_test {

/// Marks the running test as skipped where the environment lacks what it needs
/// (Catch2 v2 has no SKIP): prints a line "SKIPPED: <reason>" to stdout, which
/// tests/CMakeLists.txt makes ctest report as "Skipped" and list among the tests that
/// did not run. The caller returns right after. ctest's skip pattern wins over a
/// failure, so a test skips before it has checked anything.
void skip_test(const std::string& reason);

/// A fresh folder under $TMPDIR (or /tmp), removed with its content on destruction.
class ScratchDir {
 public:
  ScratchDir();
  ~ScratchDir();
  const std::string& path() const { return path_; }
  /// path() + "/" + name
  std::string file(const std::string& name) const { return path_ + "/" + name; }
  /// Names of the entries in the folder (not . and ..), sorted.
  std::vector<std::string> entries() const;

 private:
  std::string path_;
};

/// Writes `bytes` to `path` (overwrites).
void write_file(const std::string& path, const std::string& bytes);
/// Reads a whole (small) file.
std::string read_file(const std::string& path);
/// Writes `bytes` zstd-compressed to `path`.
void write_zstd_file(const std::string& path, const std::string& bytes);
bool file_exists(const std::string& path);

/// A whole mesh read through open_mesh_input: 3 doubles per vertex, 3 indices per
/// triangle (polygons fanned).
struct LoadedMesh {
  std::vector<double> positions;
  std::vector<std::uint64_t> triangles;
  oocsimp::MeshInfo info;
  oocsimp::SkippedFaces skipped;
  std::uint64_t skipped_faces = 0;                    ///< skipped.short_faces
  std::vector<oocsimp::LinePrimitive> edges, points;  ///< thick edges and points (a == b)
  std::size_t vertex_count() const { return positions.size() / 3; }
  std::size_t triangle_count() const { return triangles.size() / 3; }
};
LoadedMesh load_mesh(const std::string& path, const std::string& temp_dir = "");

/// Little-endian / big-endian byte appenders for building binary files.
template <class T>
void put_le(std::string& s, T v) {
  const unsigned char* p = reinterpret_cast<const unsigned char*>(&v);
  for (std::size_t i = 0; i < sizeof(T); ++i) s.push_back(char(p[i]));
}
template <class T>
void put_be(std::string& s, T v) {
  const unsigned char* p = reinterpret_cast<const unsigned char*>(&v);
  for (std::size_t i = sizeof(T); i-- > 0;) s.push_back(char(p[i]));
}

/// Result of running the oocsimp binary.
struct CliResult {
  int exit_code = -1;
  std::string out;  ///< stdout
  std::string err;  ///< stderr
};
/// Runs the built oocsimp CLI with `args` (a shell-quoted argument string), after the
/// shell commands `setup` (e.g. "ulimit -f 100") when given.
CliResult run_cli(const std::string& args, const std::string& setup = "");

/// Writes binary little-endian PLY: 3 floats per vertex, 3 indices per triangle.
void write_binary_ply(const std::string& path, const std::vector<float>& positions,
                      const std::vector<std::uint32_t>& triangles);

/// Writes the triangles of an indexed mesh (3 floats per vertex, 3 indices per
/// triangle) as STL, every corner spelled out and the normals zero; ascii prints 9
/// significant digits, which read back as the same floats.
void write_binary_stl(const std::string& path, const std::vector<float>& positions,
                      const std::vector<std::uint32_t>& triangles);
void write_ascii_stl(const std::string& path, const std::vector<float>& positions,
                     const std::vector<std::uint32_t>& triangles);

/// Writes a finely tessellated triangle mesh as binary PLY: an n x n grid on the
/// unit square in the plane z = a*x + b*y + c (plane()), or the surface of the
/// cube [0,1]^3 with n x n quads per side (cube()).
void write_plane_ply(const std::string& path, int n, double a, double b, double c);
void write_cube_ply(const std::string& path, int n);

/// What a mesh's faces say of its surface, counted from the faces alone (every
/// vertex the faces use, every edge once).
struct Topology {
  bool manifold = true;  ///< every directed edge once; every vertex one fan
  std::size_t vertices = 0, edges = 0, faces = 0, boundary_edges = 0, boundary_loops = 0;
  std::size_t zero_area = 0;
  long euler() const { return long(vertices) - long(edges) + long(faces); }
};
/// The topology of the faces `t` (3 corners each) over positions `p` (3 per vertex).
Topology topology(const std::vector<double>& p, const std::vector<std::uint32_t>& t);

}  // namespace oocsimp_test
