#include "cluster/kept_tiles.hpp"

#include <sys/stat.h>

#include <cinttypes>
#include <cstdio>
#include <cstdlib>
#include <sstream>

#include "oocsimp/error.hpp"

namespace oocsimp {

namespace {

constexpr const char* kMagic = "oocsimp-kept-tiles";
constexpr unsigned kVersion = 3;  // 3: input identity and checksums of every file

std::string hex(std::uint64_t v) {
  char buf[17];
  std::snprintf(buf, sizeof buf, "%016" PRIx64, v);
  return buf;
}

}  // namespace

bool regular_file_identity(const std::string& path, FileIdentity* id) {
  struct stat st;
  if (::stat(path.c_str(), &st) != 0 || !S_ISREG(st.st_mode)) return false;
  id->device = std::uint64_t(st.st_dev);
  id->inode = std::uint64_t(st.st_ino);
  id->size = std::uint64_t(st.st_size);
  id->mtime_ns = std::int64_t(st.st_mtim.tv_sec) * 1000000000 + st.st_mtim.tv_nsec;
  id->ctime_ns = std::int64_t(st.st_ctim.tv_sec) * 1000000000 + st.st_ctim.tv_nsec;
  return true;
}

std::string format_kept_manifest(const KeptManifest& m) {
  std::ostringstream o;
  o << kMagic << " " << kVersion << "\n";
  o << "input " << m.input.device << " " << m.input.inode << " " << m.input.size << " " << m.input.mtime_ns << " "
    << m.input.ctime_ns << " " << m.input_digest.size << " " << hex(m.input_digest.hash) << "\n";
  o << "tiles " << m.tiles_digest.size << " " << hex(m.tiles_digest.hash) << "\n";
  o << "vertices " << m.vertices_digest.size << " " << hex(m.vertices_digest.hash) << "\n";
  char line[256];
  std::snprintf(line, sizeof line, "binning %a %" PRIu64 " %" PRIu64 " %" PRIu64 " %" PRIu64 " %zu\n", m.tile_side,
                m.triangles, m.skipped.short_faces, m.skipped.non_finite, m.skipped.repeated_index, m.tiles.size());
  o << line;
  for (const KeptTile& t : m.tiles)
    o << t.coord.x << " " << t.coord.y << " " << t.coord.z << " " << t.triangles.last_block << " "
      << t.triangles.records << " " << t.vertices.last_block << " " << t.vertices.records << "\n";
  std::string body = o.str();
  return body + "end " + hex(content_hash(body.data(), body.size())) + "\n";
}

bool parse_kept_manifest(const std::string& text, KeptManifest* m) {
  // The last line checks the rest; without it nothing below is trusted.
  std::size_t end = text.rfind("end ");
  if (end == std::string::npos || (end > 0 && text[end - 1] != '\n') || text.size() != end + 4 + 16 + 1 ||
      text.back() != '\n' || text.compare(end + 4, 16, hex(content_hash(text.data(), end))) != 0)
    return false;
  std::istringstream in(text.substr(0, end));
  std::string word, input_hash, tiles_hash, vertices_hash, side;
  unsigned version = 0;
  std::size_t count = 0;
  if (!(in >> word) || word != kMagic || !(in >> version) || version != kVersion) return false;
  if (!(in >> word) || word != "input" ||
      !(in >> m->input.device >> m->input.inode >> m->input.size >> m->input.mtime_ns >> m->input.ctime_ns >>
        m->input_digest.size >> input_hash))
    return false;
  if (!(in >> word) || word != "tiles" || !(in >> m->tiles_digest.size >> tiles_hash)) return false;
  if (!(in >> word) || word != "vertices" || !(in >> m->vertices_digest.size >> vertices_hash)) return false;
  if (!(in >> word) || word != "binning" ||
      !(in >> side >> m->triangles >> m->skipped.short_faces >> m->skipped.non_finite >> m->skipped.repeated_index >>
        count))
    return false;
  auto parse_hex = [](const std::string& s, std::uint64_t* v) {
    char* e = nullptr;
    *v = std::strtoull(s.c_str(), &e, 16);
    return s.size() == 16 && e == s.c_str() + s.size();
  };
  char* side_end = nullptr;
  m->tile_side = std::strtod(side.c_str(), &side_end);
  if (!parse_hex(input_hash, &m->input_digest.hash) || !parse_hex(tiles_hash, &m->tiles_digest.hash) ||
      !parse_hex(vertices_hash, &m->vertices_digest.hash) || side_end != side.c_str() + side.size() ||
      !(m->tile_side > 0))
    return false;
  // Each tile line takes more than 7 bytes: a count beyond that is damage, not a
  // reason to reserve memory.
  if (count > text.size() / 7) return false;
  m->tiles.resize(count);
  for (KeptTile& t : m->tiles)
    if (!(in >> t.coord.x >> t.coord.y >> t.coord.z >> t.triangles.last_block >> t.triangles.records >>
          t.vertices.last_block >> t.vertices.records))
      return false;
  return !(in >> word);  // nothing after the last tile
}

BackgroundDigest::BackgroundDigest(const std::string& path)
    : thread_([this, path] {
        try {
          digest_ = file_digest(path, &stop_);
        } catch (const std::exception& e) {
          error_ = e.what();
        }
      }) {}

BackgroundDigest::~BackgroundDigest() {
  stop_ = true;
  if (thread_.joinable()) thread_.join();
}

bool BackgroundDigest::get(FileDigest* digest, std::string* error) {
  if (thread_.joinable()) thread_.join();
  *digest = digest_;
  *error = error_;
  return error_.empty();
}

}  // namespace oocsimp
