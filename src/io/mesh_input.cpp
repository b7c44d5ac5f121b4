#include <cstdlib>
#include <cstring>

#include "io/position_array.hpp"
#include "io/readers.hpp"
#include "oocsimp/error.hpp"

namespace oocsimp {

MeshInput::MeshInput() : impl(std::make_unique<Impl>()) {}
MeshInput::MeshInput(MeshInput&&) noexcept = default;
MeshInput& MeshInput::operator=(MeshInput&&) noexcept = default;
MeshInput::~MeshInput() {
  triangles.reset();  // streams first: they may refer to the mappings
}

void MeshInput::restart_triangles() { triangles = impl->make_triangles(); }

std::string default_temp_dir() {
  const char* t = std::getenv("TMPDIR");
  return t && *t ? std::string(t) : std::string("/tmp");
}

namespace {

bool ends_with(const std::string& s, const char* suffix) {
  std::size_t n = std::strlen(suffix);
  if (s.size() < n) return false;
  for (std::size_t i = 0; i < n; ++i)
    if (std::tolower(static_cast<unsigned char>(s[s.size() - n + i])) != suffix[i]) return false;
  return true;
}

}  // namespace

MeshInput open_mesh_input(const std::string& path, const OpenOptions& options_in) {
  OpenOptions options = options_in;
  if (options.temp_dir.empty()) options.temp_dir = default_temp_dir();
  MeshInput out;
  out.info.path = path;
  ByteSource src(path);
  out.info.compressed = src.compressed();
  out.file_size = src.file_size();
  std::string name = path;
  if (ends_with(name, ".zst")) name.resize(name.size() - 4);

  // The content decides; the extension only separates OBJ from STL when the first
  // bytes do not.
  const unsigned char* head = src.peek(4);
  if (head && std::memcmp(head, "ply", 3) == 0 && (head[3] == '\n' || head[3] == '\r')) {
    open_ply(src, options, out);
  } else if (ends_with(name, ".stl")) {
    open_stl(src, options, out);
  } else if (ends_with(name, ".obj")) {
    open_obj(src, options, out);
  } else if (ends_with(name, ".ply")) {
    throw InputError(at_byte(path, 0, "not a PLY file (it does not start with \"ply\")"));
  } else {
    const unsigned char* p = src.peek(5);
    if (p && std::memcmp(p, "solid", 5) == 0) open_stl(src, options, out);
    else throw InputError(path + ": unknown mesh format (expected .ply, .obj or .stl, optionally .zst)");
  }
  out.restart_triangles();
  return out;
}

}  // namespace oocsimp
