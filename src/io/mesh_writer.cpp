#include "oocsimp/mesh_writer.hpp"

#include <charconv>
#include <cstring>

#include "io/byte_sink.hpp"
#include "oocsimp/error.hpp"
#include "oocsimp/temp_file.hpp"

namespace oocsimp {

namespace {

// Shortest text that reads back as the same float.
void append_float(std::string& s, float v) {
  char buf[32];
  auto r = std::to_chars(buf, buf + sizeof buf, v);
  s.append(buf, r.ptr);
}

void append_uint(std::string& s, std::uint64_t v) {
  char buf[24];
  auto r = std::to_chars(buf, buf + sizeof buf, v);
  s.append(buf, r.ptr);
}

void write_body(ByteSink& sink, const std::vector<float>& pos, const std::vector<std::uint32_t>& tri, MeshFormat format) {
  std::size_t nv = pos.size() / 3, nf = tri.size() / 3;
  std::string text;
  auto flush_text = [&](bool force) {
    if (force || text.size() > (1 << 16)) {
      sink.write(text);
      text.clear();
    }
  };
  if (format == MeshFormat::obj) {
    text = "# oocsimp\n";
    for (std::size_t i = 0; i < nv; ++i) {
      text += "v ";
      append_float(text, pos[3 * i]);
      text += ' ';
      append_float(text, pos[3 * i + 1]);
      text += ' ';
      append_float(text, pos[3 * i + 2]);
      text += '\n';
      flush_text(false);
    }
    for (std::size_t i = 0; i < nf; ++i) {
      text += "f ";
      append_uint(text, tri[3 * i] + std::uint64_t(1));
      text += ' ';
      append_uint(text, tri[3 * i + 1] + std::uint64_t(1));
      text += ' ';
      append_uint(text, tri[3 * i + 2] + std::uint64_t(1));
      text += '\n';
      flush_text(false);
    }
    flush_text(true);
    return;
  }
  bool ascii = format == MeshFormat::ply_ascii;
  text = std::string("ply\nformat ") + (ascii ? "ascii" : "binary_little_endian") +
         " 1.0\ncomment oocsimp\nelement vertex " + std::to_string(nv) +
         "\nproperty float x\nproperty float y\nproperty float z\nelement face " + std::to_string(nf) +
         "\nproperty list uchar uint vertex_indices\nend_header\n";
  sink.write(text);
  text.clear();
  if (!ascii) {
    static_assert(sizeof(float) == 4, "float must be 32-bit");
    // x86 and ARM are little-endian: the arrays are written as they are.
    if (!pos.empty()) sink.write(pos.data(), pos.size() * sizeof(float));  // data() may be null when empty
    for (std::size_t i = 0; i < nf; ++i) {
      unsigned char rec[13];
      rec[0] = 3;
      std::memcpy(rec + 1, &tri[3 * i], 12);
      sink.write(rec, 13);
    }
    return;
  }
  for (std::size_t i = 0; i < nv; ++i) {
    append_float(text, pos[3 * i]);
    text += ' ';
    append_float(text, pos[3 * i + 1]);
    text += ' ';
    append_float(text, pos[3 * i + 2]);
    text += '\n';
    flush_text(false);
  }
  for (std::size_t i = 0; i < nf; ++i) {
    text += "3 ";
    append_uint(text, tri[3 * i]);
    text += ' ';
    append_uint(text, tri[3 * i + 1]);
    text += ' ';
    append_uint(text, tri[3 * i + 2]);
    text += '\n';
    flush_text(false);
  }
  flush_text(true);
}

}  // namespace

MeshFormat format_for_path(const std::string& path, bool ascii) {
  std::string p = path;
  if (has_zst_suffix(p)) p.resize(p.size() - 4);
  if (p.size() >= 4) {
    std::string ext = p.substr(p.size() - 4);
    for (char& c : ext) c = char(std::tolower(static_cast<unsigned char>(c)));
    if (ext == ".obj") return MeshFormat::obj;
  }
  return ascii ? MeshFormat::ply_ascii : MeshFormat::ply_binary;
}

void write_mesh(const std::string& path, const std::vector<float>& positions,
                const std::vector<std::uint32_t>& triangles, MeshFormat format) {
  OutputFile out(path);
  write_mesh(out, positions, triangles, format);
  out.commit();
}

void write_mesh(OutputFile& out, const std::vector<float>& positions, const std::vector<std::uint32_t>& triangles,
                MeshFormat format) {
  ByteSink sink(out.fd(), out.path(), has_zst_suffix(out.path()));
  write_body(sink, positions, triangles, format);
  sink.finish();
}

}  // namespace oocsimp
