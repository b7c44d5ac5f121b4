#include "test_support.hpp"
#include "oocsimp/oocsimp.hpp"

#include <dirent.h>
#include <stdlib.h>
#include <sys/stat.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <set>
#include <map>
#include <cstdio>
#include <fstream>
#include <iostream>
#include <sstream>
#include <stdexcept>

#include "io/byte_sink.hpp"

namespace oocsimp_test {

void skip_test(const std::string& reason) { std::cout << "SKIPPED: " << reason << std::endl; }

ScratchDir::ScratchDir() {
  std::string base = oocsimp::default_temp_dir() + "/oocsimp-test-XXXXXX";
  std::vector<char> buf(base.begin(), base.end());
  buf.push_back('\0');
  if (!mkdtemp(buf.data())) throw std::runtime_error("mkdtemp failed");
  path_ = buf.data();
}

ScratchDir::~ScratchDir() {
  std::string cmd = "rm -rf '" + path_ + "'";
  if (std::system(cmd.c_str()) != 0) std::fprintf(stderr, "could not remove %s\n", path_.c_str());
}

std::vector<std::string> ScratchDir::entries() const {
  std::vector<std::string> names;
  if (DIR* d = opendir(path_.c_str())) {
    while (dirent* e = readdir(d)) {
      std::string n = e->d_name;
      if (n != "." && n != "..") names.push_back(n);
    }
    closedir(d);
  }
  std::sort(names.begin(), names.end());
  return names;
}

void write_file(const std::string& path, const std::string& bytes) {
  std::ofstream f(path, std::ios::binary | std::ios::trunc);
  f.write(bytes.data(), std::streamsize(bytes.size()));
  if (!f) throw std::runtime_error("cannot write " + path);
}

std::string read_file(const std::string& path) {
  std::ifstream f(path, std::ios::binary);
  std::ostringstream s;
  s << f.rdbuf();
  return s.str();
}

void write_zstd_file(const std::string& path, const std::string& bytes) {
  FILE* f = std::fopen(path.c_str(), "wb");
  if (!f) throw std::runtime_error("cannot write " + path);
  {
    oocsimp::ByteSink sink(fileno(f), path, true);
    sink.write(bytes.data(), bytes.size());
    sink.finish();
  }
  std::fclose(f);
}

bool file_exists(const std::string& path) {
  struct stat st;
  return ::stat(path.c_str(), &st) == 0;
}

LoadedMesh load_mesh(const std::string& path, const std::string& temp_dir) {
  oocsimp::OpenOptions o;
  o.temp_dir = temp_dir;
  oocsimp::MeshInput in = oocsimp::open_mesh_input(path, o);
  LoadedMesh m;
  m.info = in.info;
  for (std::uint64_t i = 0; i < in.positions.count; ++i) {
    oocsimp::Vec3d p = in.positions.get(i);
    m.positions.insert(m.positions.end(), {p.x, p.y, p.z});
  }
  in.triangles->set_primitive_sink([&](const oocsimp::LinePrimitive* p, std::size_t n) {
    for (std::size_t k = 0; k < n; ++k) (p[k].a == p[k].b ? m.points : m.edges).push_back(p[k]);
  });
  std::vector<std::uint64_t> buf(3 * 1000);
  while (std::size_t n = in.triangles->read(buf.data(), 1000))
    m.triangles.insert(m.triangles.end(), buf.begin(), buf.begin() + 3 * n);
  m.skipped = in.triangles->skipped();
  m.skipped_faces = m.skipped.short_faces;
  return m;
}

CliResult run_cli(const std::string& args, const std::string& setup) {
  ScratchDir d;
  std::string cmd =
      std::string(OOCSIMP_CLI) + " " + args + " >'" + d.file("out") + "' 2>'" + d.file("err") + "' </dev/null";
  if (!setup.empty()) cmd = setup + " && exec " + cmd;
  int status = std::system(cmd.c_str());
  CliResult r;
  r.exit_code = WIFEXITED(status) ? WEXITSTATUS(status) : 128 + WTERMSIG(status);
  r.out = read_file(d.file("out"));
  r.err = read_file(d.file("err"));
  return r;
}

void write_binary_ply(const std::string& path, const std::vector<float>& v, const std::vector<std::uint32_t>& t) {
  std::string s = "ply\nformat binary_little_endian 1.0\nelement vertex " + std::to_string(v.size() / 3) +
                  "\nproperty float x\nproperty float y\nproperty float z\nelement face " +
                  std::to_string(t.size() / 3) + "\nproperty list uchar int vertex_indices\nend_header\n";
  for (float f : v) put_le(s, f);
  for (std::size_t i = 0; i < t.size(); i += 3) {
    s.push_back(3);
    for (int k = 0; k < 3; ++k) put_le(s, std::int32_t(t[i + k]));
  }
  write_file(path, s);
}

void write_binary_stl(const std::string& path, const std::vector<float>& v, const std::vector<std::uint32_t>& t) {
  std::string s = "binary STL written by a test";
  s.resize(80, ' ');
  put_le(s, std::uint32_t(t.size() / 3));
  for (std::size_t i = 0; i < t.size(); i += 3) {
    for (int k = 0; k < 3; ++k) put_le(s, 0.0f);  // normal
    for (int c = 0; c < 3; ++c)
      for (int k = 0; k < 3; ++k) put_le(s, v[3 * std::size_t(t[i + std::size_t(c)]) + std::size_t(k)]);
    put_le(s, std::uint16_t(0));  // attribute byte count
  }
  write_file(path, s);
}

void write_ascii_stl(const std::string& path, const std::vector<float>& v, const std::vector<std::uint32_t>& t) {
  std::string s = "solid test\n";
  char line[128];
  for (std::size_t i = 0; i < t.size(); i += 3) {
    s += "  facet normal 0 0 0\n    outer loop\n";
    for (int c = 0; c < 3; ++c) {
      const float* p = &v[3 * std::size_t(t[i + std::size_t(c)])];
      std::snprintf(line, sizeof line, "      vertex %.9g %.9g %.9g\n", double(p[0]), double(p[1]), double(p[2]));
      s += line;
    }
    s += "    endloop\n  endfacet\n";
  }
  write_file(path, s + "endsolid test\n");
}

void write_plane_ply(const std::string& path, int n, double a, double b, double c) {
  std::vector<float> v;
  std::vector<std::uint32_t> t;
  for (int j = 0; j <= n; ++j)
    for (int i = 0; i <= n; ++i) {
      double x = double(i) / n, y = double(j) / n;
      v.insert(v.end(), {float(x), float(y), float(a * x + b * y + c)});
    }
  for (int j = 0; j < n; ++j)
    for (int i = 0; i < n; ++i) {
      std::uint32_t v00 = std::uint32_t(j * (n + 1) + i), v10 = v00 + 1, v01 = v00 + std::uint32_t(n + 1),
                    v11 = v01 + 1;
      t.insert(t.end(), {v00, v10, v11, v00, v11, v01});
    }
  write_binary_ply(path, v, t);
}

void write_cube_ply(const std::string& path, int n) {
  // Six faces, each an (n+1)^2 grid of its own vertices (duplicated along the edges,
  // as in many scanned and exported files); normals point outwards.
  static const int faces[6][4] = {{0, 1, 1, 2},  {0, -1, 2, 1}, {1, 1, 2, 0},
                                  {1, -1, 0, 2}, {2, 1, 0, 1},  {2, -1, 1, 0}};
  std::vector<float> v;
  std::vector<std::uint32_t> t;
  for (const auto& f : faces) {
    std::uint32_t base = std::uint32_t(v.size() / 3);
    for (int j = 0; j <= n; ++j)
      for (int i = 0; i <= n; ++i) {
        float q[3];
        q[f[0]] = f[1] > 0 ? 1.0f : 0.0f;
        q[f[2]] = float(double(i) / n);
        q[f[3]] = float(double(j) / n);
        v.insert(v.end(), {q[0], q[1], q[2]});
      }
    for (int j = 0; j < n; ++j)
      for (int i = 0; i < n; ++i) {
        std::uint32_t v00 = base + std::uint32_t(j * (n + 1) + i), v10 = v00 + 1, v01 = v00 + std::uint32_t(n + 1),
                      v11 = v01 + 1;
        // For the negative faces the tangents were swapped, so this winding is outward too.
        t.insert(t.end(), {v00, v10, v11, v00, v11, v01});
      }
  }
  write_binary_ply(path, v, t);
}

Topology topology(const std::vector<double>& p, const std::vector<std::uint32_t>& t) {
  Topology out;
  out.faces = t.size() / 3;
  std::set<std::pair<std::uint32_t, std::uint32_t>> directed;
  std::set<std::uint32_t> used;
  for (std::size_t f = 0; f < t.size(); f += 3) {
    for (int k = 0; k < 3; ++k) {
      used.insert(t[f + std::size_t(k)]);
      if (!directed.insert({t[f + std::size_t(k)], t[f + std::size_t((k + 1) % 3)]}).second) out.manifold = false;
    }
    const double* a = &p[3 * t[f]];
    const double* b = &p[3 * t[f + 1]];
    const double* c = &p[3 * t[f + 2]];
    const double u[3] = {b[0] - a[0], b[1] - a[1], b[2] - a[2]}, w[3] = {c[0] - a[0], c[1] - a[1], c[2] - a[2]};
    const double n[3] = {u[1] * w[2] - u[2] * w[1], u[2] * w[0] - u[0] * w[2], u[0] * w[1] - u[1] * w[0]};
    if (!(n[0] * n[0] + n[1] * n[1] + n[2] * n[2] > 0)) ++out.zero_area;
  }
  out.vertices = used.size();
  std::map<std::uint32_t, std::uint32_t> boundary_next;
  for (const auto& [a, b] : directed) {
    if (!directed.count({b, a})) {
      ++out.boundary_edges;
      ++out.edges;
      if (!boundary_next.insert({a, b}).second) out.manifold = false;  // two outlines through a
    } else if (a < b) {
      ++out.edges;
    }
  }
  std::set<std::uint32_t> seen;
  for (const auto& [start, next] : boundary_next) {
    if (seen.count(start)) continue;
    ++out.boundary_loops;
    for (std::uint32_t v = start; !seen.count(v);) {
      seen.insert(v);
      const auto it = boundary_next.find(v);
      if (it == boundary_next.end()) {
        out.manifold = false;
        break;
      }
      v = it->second;
    }
  }
  return out;
}

}  // namespace oocsimp_test
