#include "cluster/kept_tiles.hpp"

#include <limits.h>
#include <stdlib.h>
#include <sys/stat.h>
#include <unistd.h>

#include <cinttypes>
#include <cstdio>
#include <cstdlib>
#include <sstream>

#include "cluster/vertex_grading.hpp"
#include "oocsimp/error.hpp"
#include "io/temp_file.hpp"

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

KeptTileStore::KeptTileStore(const MeshInput& input, std::string temp_dir, std::vector<std::string>* warnings)
    : input_(input), temp_dir_(std::move(temp_dir)), warnings_(warnings) {}

KeptTileStore::~KeptTileStore() = default;

std::string KeptTileStore::kept_path(const char* ext) const {
  char real[PATH_MAX];
  std::string id = ::realpath(input_.info.path.c_str(), real) ? std::string(real) : input_.info.path;
  if (input_.info.unwelded_vertex_count) id += "|welded";
  char key[17];
  std::snprintf(key, sizeof key, "%016llx", (unsigned long long)content_hash(id.data(), id.size()));
  return temp_dir_ + "/oocsimp-kept-" + key + "." + ext;
}

void KeptTileStore::warn(const std::string& text) {
  if (warnings_) warnings_->push_back(text);
}

bool KeptTileStore::start() {
  if (!regular_file_identity(input_.info.path, &kept_input_)) {
    warn(input_.info.path + ": options.floating.keep_temp needs a regular file as input; nothing is kept");
    return false;
  }
  input_digest_ = std::make_unique<BackgroundDigest>(input_.info.path);
  return true;
}

void KeptTileStore::keep(BinnedTiles& tiles, StreamSpill& graded) {
  FileDigest input_digest;
  std::string error;
  FileIdentity after;
  if (!input_digest_->get(&input_digest, &error) || !regular_file_identity(input_.info.path, &after) ||
      after != kept_input_ || input_digest.size != kept_input_.size) {
    warn(error.empty() ? input_.info.path + ": changed during the run; its tiles are not kept" : error);
    return;
  }
  // The old manifest goes first: a crash below must not leave it describing new files.
  ::unlink(kept_path("manifest").c_str());
  tiles.triangles->keep_as(kept_path("tiles"));
  graded.keep_as(kept_path("vertices"));
  KeptManifest m;
  m.input = kept_input_;
  m.input_digest = input_digest;
  m.tiles_digest = file_digest(kept_path("tiles"));
  m.vertices_digest = file_digest(kept_path("vertices"));
  m.tile_side = tiles.grid.side;
  m.triangles = tiles.triangle_count;
  m.skipped = tiles.skipped;  // a resumed run does not read the stream
  for (std::uint32_t t = 0; t < tiles.count(); ++t)
    m.tiles.push_back({tiles.grid.coord(t), tiles.triangles->chain(t), graded.chain(t)});
  write_file_atomically(kept_path("manifest"), format_kept_manifest(m));
}

// Why kept tiles cannot be used, as a warning; empty when they can. `m` is the
// parsed manifest, `now` the input's identity.
std::string KeptTileStore::fault(const KeptManifest& m, const FileIdentity& now) const {
  const std::string& in = input_.info.path;
  if (now != m.input) return in + ": changed since its tiles were kept (inode, size or times differ); binning again";
  const std::pair<const char*, const FileDigest*> kept[2] = {{"tiles", &m.tiles_digest},
                                                             {"vertices", &m.vertices_digest}};
  for (const auto& [ext, digest] : kept) {
    struct stat st;
    std::string path = kept_path(ext);
    if (::stat(path.c_str(), &st) != 0) return path + ": kept file missing; binning again";
    if (std::uint64_t(st.st_size) != digest->size)
      return path + ": kept file of " + std::to_string(st.st_size) + " bytes, " + std::to_string(digest->size) +
             " expected (truncated?); binning again";
  }
  try {
    if (file_digest(in) != m.input_digest)
      return in + ": content differs from the input whose tiles were kept (checksum); binning again";
    for (const auto& [ext, digest] : kept)
      if (file_digest(kept_path(ext)) != *digest)
        return kept_path(ext) + ": kept file damaged (checksum differs); binning again";
  } catch (const IoError& e) {
    return std::string(e.what()) + "; binning again";
  }
  return "";
}

bool KeptTileStore::resume(double min_side, BinnedTiles* tiles, std::unique_ptr<StreamSpill>* graded) {
  FileIdentity now;
  if (!regular_file_identity(input_.info.path, &now)) return false;  // start() says why
  std::string text;
  if (!read_manifest(&text)) {
    struct stat st;
    for (const char* ext : {"tiles", "vertices"})
      if (::stat(kept_path(ext).c_str(), &st) == 0) {
        warn(kept_path("manifest") + ": missing beside kept tiles; binning again");
        break;
      }
    return false;
  }
  KeptManifest m;
  if (!parse_kept_manifest(text, &m)) {
    warn(kept_path("manifest") + ": damaged manifest of kept tiles; binning again");
    return false;
  }
  if (m.tile_side < min_side) return false;  // the options, not the files: no warning
  std::string why = fault(m, now);
  if (!why.empty()) {
    warn(why);
    return false;
  }
  std::vector<StreamSpill::Chain> tri_chains, vtx_chains;
  for (const KeptTile& t : m.tiles) {
    tri_chains.push_back(t.triangles);
    vtx_chains.push_back(t.vertices);
  }
  BinnedTiles r;
  r.triangles = StreamSpill::open_kept(kept_path("tiles"), sizeof(TriangleRecord), tri_chains);
  *graded = StreamSpill::open_kept(kept_path("vertices"), sizeof(GradedVertex), vtx_chains);
  r.grid.side = m.tile_side;
  r.triangle_count = m.triangles;
  r.skipped = m.skipped;
  for (const KeptTile& t : m.tiles) r.grid.add(t.coord);
  *tiles = std::move(r);
  return true;
}

// The manifest's text; false when there is none. A file beyond any plausible
// manifest (a line per tile) is read as far as that and then fails its checksum.
bool KeptTileStore::read_manifest(std::string* text) const {
  FILE* f = std::fopen(kept_path("manifest").c_str(), "rb");
  if (!f) return false;
  char buf[65536];
  for (std::size_t n; (n = std::fread(buf, 1, sizeof buf, f)) > 0 && text->size() < (std::size_t(1) << 30);)
    text->append(buf, n);
  std::fclose(f);
  return true;
}

}  // namespace oocsimp
