// The library as other programs use it: one progress-and-cancel callback
// for every long call, cancellation that leaves nothing behind, error messages that
// name option fields (the CLI turns them into its flags), options nested per method.
#include <catch2/catch.hpp>

#include <cmath>
#include <atomic>
#include <cstring>
#include <map>
#include <mutex>
#include <string>
#include <tuple>
#include <utility>
#include <vector>

#include "oocsimp/generate.hpp"
#include "oocsimp/measure.hpp"
#include "oocsimp/oocsimp.hpp"
#include "test_support.hpp"

using namespace oocsimp;
using namespace oocsimp_test;

namespace {

// Records every call of a ProgressCallback and checks, as they come, that no two
// calls overlap and that each phase's reports lie between its begin and its end.
struct ProgressLog {
  struct Phase {
    std::string name;
    std::string unit;
    std::uint64_t total = 0;
    std::uint64_t last_done = 0;
    int advances = 0;
    bool ended = false;
  };
  std::vector<Phase> phases;
  std::atomic<int> inside{0};
  bool overlapped = false, unmatched = false, beyond_total = false;
  std::string cancel_in;  // cancel at the first advance of this phase ("" = never)
  bool cancel_at_begin = false;

  ProgressCallback callback() {
    return [this](const Progress& p) {
      if (inside.fetch_add(1) != 0) overlapped = true;
      bool go_on = true;
      switch (p.event) {
        case Progress::Event::begin:
          phases.push_back({p.phase, p.unit, p.total, 0, 0, false});
          if (cancel_at_begin && cancel_in == p.phase) go_on = false;
          break;
        case Progress::Event::advance:
          if (phases.empty() || phases.back().ended || phases.back().name != p.phase) {
            unmatched = true;
          } else {
            Phase& ph = phases.back();
            ++ph.advances;
            ph.last_done = p.done;
            if (p.total > 0 && p.done > p.total) beyond_total = true;
          }
          if (!cancel_at_begin && cancel_in == p.phase) go_on = false;
          break;
        case Progress::Event::end:
          if (phases.empty() || phases.back().ended || phases.back().name != p.phase)
            unmatched = true;
          else
            phases.back().ended = true;
          break;
      }
      inside.fetch_sub(1);
      return go_on;
    };
  }
  std::vector<std::string> names() const {
    std::vector<std::string> n;
    for (const Phase& p : phases) n.push_back(p.name);
    return n;
  }
  const Phase* find(const std::string& name) const {
    for (const Phase& p : phases)
      if (p.name == name) return &p;
    return nullptr;
  }
};

std::string sphere(const ScratchDir& d, std::uint64_t triangles) {
  GenerateOptions g;
  g.triangles = triangles;
  std::string path = d.file("sphere.ply");
  generate_mesh(path, g);
  return path;
}

SimplifyOptions small_run(ClusterMethod method, const ScratchDir& tmp) {
  SimplifyOptions o;
  o.method = method;
  o.sizing.grid = 32;
  o.threads = 2;
  o.temp_dir = tmp.path();
  return o;
}

}  // namespace

TEST_CASE("one callback hears every phase of a run, balanced and one call at a time", "[api][progress]") {
  ScratchDir d, tmp;
  const std::string in = sphere(d, 200000);
  for (ClusterMethod method : cluster_methods()) {
    INFO(method_name(method));
    ProgressLog log;
    SimplifyOptions o = small_run(method, tmp);
    o.floating.tile_side = 0.3;  // several tiles
    if (method == ClusterMethod::qem) o.sizing = CellSizing(), o.target.triangles = 20000;
    o.progress = log.callback();
    simplify_file(in, d.file("out.ply"), o, nullptr);
    CHECK_FALSE(log.overlapped);
    CHECK_FALSE(log.unmatched);
    CHECK_FALSE(log.beyond_total);
    for (const ProgressLog::Phase& p : log.phases) {
      INFO(p.name);
      CHECK(p.ended);
    }
    const std::vector<std::string> names = log.names();
    REQUIRE(names.size() >= 3);
    CHECK(names.front() == "read positions");
    CHECK(names.back() == "write");
    // Each method's phases, and one of them counted (its total known from the start,
    // in its unit).
    std::vector<std::string> expected = {"load mesh", "collapse"};
    std::string counted_phase = "collapse", unit = "tri";
    if (method == ClusterMethod::floating)
      expected = {"bin tiles", "grade tiles", "rounds", "cluster tiles", "stitch", "assemble"},
      counted_phase = "grade tiles", unit = "tile";
    if (method == ClusterMethod::uniform)
      expected = {"cell means", "cell quadrics", "solve"}, counted_phase = "cell means", unit = "vtx";
    if (method == ClusterMethod::curvature)
      expected = {"curvature cells", "curvature parts", "cell means", "cell quadrics", "solve"},
      counted_phase = "curvature cells", unit = "vtx";
    for (const std::string& e : expected) CHECK(log.find(e) != nullptr);
    const ProgressLog::Phase* counted = log.find(counted_phase);
    REQUIRE(counted);
    CHECK(counted->total > 0);
    CHECK(counted->unit == unit);
  }
}

TEST_CASE("the curvature estimate reports its survey then its binning in tiles then its estimate", "[api][progress]") {
  ScratchDir d, tmp;
  const std::string in = sphere(d, 20000);
  for (const double tile_side : {0.0, 0.5}) {
    INFO("tile side " << tile_side);
    ProgressLog log;
    CurvatureOptions o;
    o.tile_side = tile_side;
    o.temp_dir = tmp.path();
    o.progress = log.callback();
    CurvatureStats st;
    curvature_file(in, d.file("k.ply"), o, &st);
    CHECK_FALSE(log.overlapped);
    CHECK_FALSE(log.unmatched);
    CHECK_FALSE(log.beyond_total);
    std::vector<std::string> expected = {"read positions", "survey", "curvatures", "write"};
    if (tile_side > 0) expected = {"read positions", "survey", "bin tiles", "curvatures", "write"};
    CHECK(log.names() == expected);
    const ProgressLog::Phase* curvatures = log.find("curvatures");
    REQUIRE(curvatures);
    CHECK(curvatures->total == st.vertices);
    CHECK(curvatures->unit == "vtx");
    CHECK(st.vertices > 10000);
  }
}

TEST_CASE("a callback that returns false cancels the run and leaves no file behind", "[api][progress]") {
  ScratchDir d, tmp;
  const std::string in = sphere(d, 200000);
  struct Case {
    ClusterMethod method;
    const char* phase;
    bool at_begin;
  };
  const Case cases[] = {
      {ClusterMethod::floating, "read positions", true}, {ClusterMethod::floating, "bin tiles", false},
      {ClusterMethod::floating, "grade tiles", true},    {ClusterMethod::floating, "cluster tiles", true},
      {ClusterMethod::floating, "assemble", true},       {ClusterMethod::uniform, "cell quadrics", true},
      {ClusterMethod::uniform, "solve", true},
  };
  for (const Case& c : cases) {
    INFO(method_name(c.method) << " " << c.phase << (c.at_begin ? " at its begin" : " at its first report"));
    ProgressLog log;
    log.cancel_in = c.phase;
    log.cancel_at_begin = c.at_begin;
    SimplifyOptions o = small_run(c.method, tmp);
    o.floating.tile_side = 0.3;
    o.progress = log.callback();
    const std::string out = d.file("cancelled.ply");
    CHECK_THROWS_AS(simplify_file(in, out, o, nullptr), Cancelled);
    CHECK_FALSE(file_exists(out));
    CHECK(tmp.entries().empty());
    CHECK(d.entries() == std::vector<std::string>{"sphere.ply"});
    CHECK(log.phases.back().name == c.phase);
    // Nothing is heard after the cancel but the ends of the phases it unwinds.
    CHECK_FALSE(log.unmatched);
  }
}

TEST_CASE("the in-memory entry point reports and cancels through the same callback", "[api][progress]") {
  std::vector<float> xyz;
  std::vector<std::uint32_t> tri;
  const int n = 100;
  for (int j = 0; j <= n; ++j)
    for (int i = 0; i <= n; ++i) xyz.insert(xyz.end(), {float(i) / n, float(j) / n, 0.0f});
  for (std::uint32_t j = 0; j < n; ++j)
    for (std::uint32_t i = 0; i < n; ++i) {
      std::uint32_t a = j * (n + 1) + i, b = a + 1, c = a + n + 1, e = c + 1;
      tri.insert(tri.end(), {a, b, e, a, e, c});
    }
  MeshView v;
  v.positions = xyz.data();
  v.vertex_count = xyz.size() / 3;
  v.indices = tri.data();
  v.triangle_count = tri.size() / 3;
  ScratchDir tmp;
  SimplifyOptions o = small_run(ClusterMethod::floating, tmp);
  ProgressLog log;
  o.progress = log.callback();
  SimplifyStats stats;
  SimplifiedMesh m = simplify_mesh(v, o, &stats);
  CHECK(!m.triangles.empty());
  CHECK(log.find("grade tiles") != nullptr);
  CHECK(stats.peak_anon_bytes > 0);  // sampled by the library, not by a progress display
  // The run's time, at least the sum of its phases'.
  double phases = 0;
  for (const auto& phase : stats.phases) phases += phase.seconds;
  CHECK(stats.seconds_total > 0);
  CHECK(stats.seconds_total >= phases);
  ProgressLog stop;
  stop.cancel_in = "grade tiles";
  stop.cancel_at_begin = true;
  o.progress = stop.callback();
  CHECK_THROWS_AS(simplify_mesh(v, o), Cancelled);
  CHECK(tmp.entries().empty());
}

TEST_CASE("generate and measure take the same callback and cancel without output", "[api][progress]") {
  ScratchDir d;
  ProgressLog log;
  GenerateOptions g;
  g.triangles = 3000000;  // past 2^20 faces: counted reports
  g.progress = log.callback();
  generate_mesh(d.file("g.ply"), g);
  REQUIRE(log.find("generate"));
  CHECK(log.find("generate")->unit == std::string("tri"));
  CHECK(log.find("generate")->ended);

  ProgressLog stop;
  stop.cancel_in = "generate";
  g.progress = stop.callback();
  CHECK_THROWS_AS(generate_mesh(d.file("never.ply"), g), Cancelled);
  CHECK_FALSE(file_exists(d.file("never.ply")));

  GenerateOptions small;
  small.triangles = 20000;
  generate_mesh(d.file("s.ply"), small);
  MeasureOptions m;
  m.samples = 20000;
  m.temp_dir = d.path();
  ProgressLog heard;
  m.progress = heard.callback();
  DistanceReport r = measure_surface_distance(d.file("s.ply"), d.file("s.ply"), m);
  CHECK(r.symmetric.max <= 1e-6 * r.a_diagonal);  // the same surface
  CHECK(heard.find("open A"));
  CHECK(heard.find("distance A->B"));
  CHECK_FALSE(heard.overlapped);
  ProgressLog cancel;
  cancel.cancel_in = "distance A->B";
  cancel.cancel_at_begin = true;
  m.progress = cancel.callback();
  CHECK_THROWS_AS(measure_surface_distance(d.file("s.ply"), d.file("s.ply"), m), Cancelled);
}

TEST_CASE("library errors name option fields, the CLI shows its flags instead", "[api][errors]") {
  ScratchDir d, tmp;
  const std::string in = sphere(d, 20000);
  auto message = [&](const SimplifyOptions& o) {
    try {
      simplify_file(in, d.file("o.ply"), o, nullptr);
    } catch (const UsageError& e) {
      return std::string(e.what());
    }
    return std::string("no error");
  };
  SimplifyOptions both = small_run(ClusterMethod::floating, tmp);
  both.sizing.ratio = 0.5;
  const std::string two = message(both);
  CHECK(two.find("options.sizing.grid") != std::string::npos);
  CHECK(two.find("--") == std::string::npos);
  SimplifyOptions tiny = small_run(ClusterMethod::uniform, tmp);
  tiny.memory_budget = 1 << 20;
  const std::string mem = message(tiny);
  CHECK(mem.find("options.memory_budget 1 MiB") != std::string::npos);
  CHECK(mem.find("--") == std::string::npos);
  SimplifyOptions named = small_run(ClusterMethod::uniform, tmp);
  named.attributes = parse_attribute_selection("nosuch");
  const std::string attr = message(named);
  CHECK(attr.find("options.attributes: ") != std::string::npos);
  CHECK(attr.find("--") == std::string::npos);

  CliResult cli = run_cli("simplify --quiet --mem 1M '" + in + "' -o '" + d.file("o.ply") + "'");
  CHECK(cli.exit_code == 2);
  CHECK(cli.err.find("--mem \"1M\"") != std::string::npos);
  CHECK(cli.err.find("options.") == std::string::npos);
  cli = run_cli("simplify --quiet --attributes nosuch '" + in + "' -o '" + d.file("o.ply") + "'");
  CHECK(cli.exit_code == 2);
  CHECK(cli.err.find("--attributes: ") != std::string::npos);
  CHECK(cli.err.find("options.") == std::string::npos);
}

TEST_CASE("a file simplified into memory is the mesh simplify_file writes, level by level too", "[api]") {
  ScratchDir d, tmp;
  const std::string in = sphere(d, 50000);
  for (ClusterMethod method : cluster_methods()) {
    INFO(method_name(method));
    SimplifyOptions o = small_run(method, tmp);
    if (method == ClusterMethod::qem) o.sizing = CellSizing(), o.target.triangles = 5000;
    simplify_file(in, d.file("file.ply"), o, nullptr);
    SimplifyStats st;
    const SimplifiedMesh m = simplify_file_to_mesh(in, o, &st);
    CHECK(st.output_triangles == m.triangles.size() / 3);
    write_mesh(d.file("memory.ply"), m.positions, m.triangles, MeshFormat::ply_binary, m.precision, &m.attributes);
    CHECK(read_file(d.file("memory.ply")) == read_file(d.file("file.ply")));
  }
  SimplifyOptions o = small_run(ClusterMethod::floating, tmp);
  LodOptions lods;
  lods.levels = 2;
  OutputOptions outputs;
  outputs.mesh = d.file("lod.ply");
  simplify_lods_file(in, outputs, o, lods, nullptr);
  std::uint32_t heard = 0;
  simplify_file_to_lods(in, o, lods, [&](std::uint32_t level, SimplifiedMesh& m, const SimplifyStats&) {
    CHECK(level == heard++);
    const std::string path = d.file("memory.lod" + std::to_string(level) + ".ply");
    write_mesh(path, m.positions, m.triangles, MeshFormat::ply_binary, m.precision, &m.attributes);
    CHECK(read_file(path) == read_file(lod_level_path(outputs.mesh, level)));
  });
  CHECK(heard == 2);
}

TEST_CASE("a usage error about one option carries its field, which its message starts with", "[api][errors]") {
  ScratchDir d, tmp;
  const std::string in = sphere(d, 20000);
  auto error = [&](const SimplifyOptions& o) {
    try {
      simplify_file(in, d.file("o.ply"), o, nullptr);
    } catch (const UsageError& e) {
      return std::make_pair(e.option(), std::string(e.what()));
    }
    return std::make_pair(std::string("no error"), std::string());
  };
  SimplifyOptions tiny = small_run(ClusterMethod::uniform, tmp);
  tiny.memory_budget = 1 << 20;
  auto [option, what] = error(tiny);
  CHECK(option == "options.memory_budget");
  CHECK(what.rfind("options.memory_budget 1 MiB", 0) == 0);
  SimplifyOptions named = small_run(ClusterMethod::uniform, tmp);
  named.attributes = parse_attribute_selection("nosuch");
  std::tie(option, what) = error(named);
  CHECK(option == "options.attributes");
  CHECK(what.rfind("options.attributes: ", 0) == 0);
  // About two options at once: no one field.
  SimplifyOptions both = small_run(ClusterMethod::floating, tmp);
  both.sizing.ratio = 0.5;
  std::tie(option, what) = error(both);
  CHECK(option.empty());
  CHECK(what.rfind("give at most one of options.sizing.cell", 0) == 0);
  CHECK(UsageError("plain").option().empty());
}

TEST_CASE("each option value is spelled once, in the tables the *_name functions read", "[api]") {
  auto check = [](const auto& names, auto name, auto default_value) {
    REQUIRE_FALSE(names.empty());
    CHECK(names.front().value == default_value);  // the default first
    for (const auto& n : names) {
      CHECK(std::string(name(n.value)) == n.name);
      auto back = names.back().value;
      CHECK(value_named(names, n.name, &back));
      CHECK(back == n.value);
    }
  };
  const SimplifyOptions o;
  check(cluster_method_names(), method_name, o.method);
  check(cell_shape_names(), cell_shape_name, o.floating.cell_shape);
  check(assign_rule_names(), assign_name, o.floating.assign);
  check(representative_rule_names(), representative_name, o.floating.representative);
  check(spill_compression_names(), spill_compression_name, o.floating.spill_compression);
  check(refine_method_names(), refine_name, o.target.refine);
  check(precision_names(), precision_name, o.precision);
  check(
      synthetic_shape_names(), [](SyntheticShape s) { return name_of(synthetic_shape_names(), s); },
      GenerateOptions().shape);
  std::vector<ClusterMethod> methods;
  for (const auto& n : cluster_method_names())
    if (n.value != ClusterMethod::automatic) methods.push_back(n.value);
  CHECK(methods == cluster_methods());  // every method but the default's choice between them
  CHECK(cluster_method_names().front().value == ClusterMethod::automatic);
  ClusterMethod m = ClusterMethod::floating;
  CHECK_FALSE(value_named(cluster_method_names(), "Uniform", &m));
  CHECK(m == ClusterMethod::floating);
  CHECK(std::string(precision_name(Precision::float64)) == "double");
}

TEST_CASE("describe_mesh gives what info prints: counts, carried attributes, thick edges and points", "[api]") {
  ScratchDir d;
  write_file(d.file("l.obj"), "v 0 0 0\nv 1 0 0\nv 0 1 0\nv 1 1 0\nf 1 2 3\nl 1 4 3\np 2\n");
  const MeshSummary lines = describe_mesh(d.file("l.obj"), d.path());
  CHECK(lines.info.format == "obj");
  CHECK(lines.info.vertex_count == 4);
  CHECK(lines.info.face_count == 1);
  CHECK(lines.edges.count == 2);  // a polyline of three vertices is two edges
  CHECK(lines.points.count == 1);
  CHECK(lines.edges.most == 0);  // OBJ gives no thickness
  CHECK(lines.attributes.empty());
  GenerateOptions g;
  g.triangles = 2000;
  g.attributes = true;
  generate_mesh(d.file("coloured.ply"), g);
  const MeshSummary coloured = describe_mesh(d.file("coloured.ply"));
  CHECK(coloured.info.face_count > 0);
  CHECK(coloured.edges.count == 0);
  CHECK(coloured.points.count == 0);
  std::vector<std::string> names;
  for (const VertexAttribute& a : coloured.attributes) names.push_back(a.name);
  CHECK(names == std::vector<std::string>{"red", "green", "blue", "nx", "ny", "nz"});
}

TEST_CASE("MeshView::vertex_lock keeps the marked vertices where they are", "[api][locks]") {
  // A 40 x 40 grid on a wave; every 50th vertex marked.
  const std::uint32_t n = 40;
  std::vector<double> xyz;
  std::vector<std::uint32_t> tri;
  for (std::uint32_t j = 0; j <= n; ++j)
    for (std::uint32_t i = 0; i <= n; ++i)
      xyz.insert(xyz.end(), {double(i) / n, double(j) / n, 0.1 * std::sin(6.0 * i / n) * std::cos(5.0 * j / n)});
  for (std::uint32_t j = 0; j < n; ++j)
    for (std::uint32_t i = 0; i < n; ++i) {
      const std::uint32_t a = j * (n + 1) + i, b = a + 1, c = a + n + 1, e = c + 1;
      tri.insert(tri.end(), {a, b, e, a, e, c});
    }
  std::vector<std::uint8_t> lock(xyz.size() / 3, 0);
  for (std::size_t v = 3; v < lock.size(); v += 50) lock[v] = 1;
  MeshView view;
  view.positions = xyz.data();
  view.position_type = ScalarType::f64;
  view.vertex_count = xyz.size() / 3;
  view.indices = tri.data();
  view.triangle_count = tri.size() / 3;
  view.vertex_lock = lock.data();
  SimplifyOptions o;
  o.target.triangles = 300;
  const SimplifiedMesh m = simplify_mesh(view, o);
  CHECK(m.triangles.size() == 3 * 300);
  for (std::size_t v = 0; v < lock.size(); ++v) {
    if (!lock[v]) continue;
    bool found = false;
    for (std::size_t w = 0; w < m.positions.size() / 3 && !found; ++w) {
      double d = 0;
      for (int k = 0; k < 3; ++k)
        d = std::max(d, std::fabs(m.positions[3 * w + std::size_t(k)] - xyz[3 * v + std::size_t(k)]));
      found = d == 0;  // to the last bit, though the collapse works relative to the box's corner
    }
    CAPTURE(v);
    CHECK(found);
  }
  // Clustering makes each marked vertex a cluster of its own, where it is.
  o.target = TargetOptions();
  o.method = ClusterMethod::floating;
  o.sizing.grid = 8;
  SimplifyStats st;
  const SimplifiedMesh clustered = simplify_mesh(view, o, &st);
  std::size_t kept = 0, marked = 0, left_out = 0;
  // One all of whose neighbours fall in one other cell makes no triangle: it is
  // counted in a warning.
  for (const std::string& w : st.warnings)
    if (w.find(" locked vertices are left out") != std::string::npos) left_out = std::stoul(w);
  for (std::size_t v = 0; v < lock.size(); ++v) {
    if (!lock[v]) continue;
    ++marked;
    for (std::size_t w = 0; w < clustered.positions.size() / 3; ++w)
      if (clustered.positions[3 * w] == xyz[3 * v] && clustered.positions[3 * w + 1] == xyz[3 * v + 1] &&
          clustered.positions[3 * w + 2] == xyz[3 * v + 2]) {
        ++kept;
        break;
      }
  }
  CHECK(kept + left_out == marked);
  CHECK(left_out <= 2);
}

TEST_CASE("extract_file and curvature_file take their output as named fields, and refuse simplify_file's others",
          "[api]") {
  ScratchDir d, tmp;
  const std::string in = sphere(d, 20000);
  const auto starts_with = [](const std::string& path, const std::string& head) {
    return read_file(path).compare(0, head.size(), head) == 0;
  };
  CurvatureOptions c;
  c.temp_dir = tmp.path();
  OutputOptions out;
  out.mesh = d.file("k.ply");
  out.ascii = true;
  curvature_file(in, out, c);
  CHECK(starts_with(out.mesh, "ply\nformat ascii 1.0\n"));
  curvature_file(in, d.file("kb.ply"), c);  // the path alone: binary
  CHECK(starts_with(d.file("kb.ply"), "ply\nformat binary_little_endian 1.0\n"));

  HierarchyOptions h;
  h.temp_dir = tmp.path();
  build_hierarchy_file(in, d.file("s.4k"), h);
  HierarchyQuery q;
  q.triangles = 1000;
  out.mesh = d.file("e.ply");
  extract_file(d.file("s.4k"), out, q);
  CHECK(starts_with(out.mesh, "ply\nformat ascii 1.0\n"));

  // Fields only simplify_file honours are refused, naming the field, before any file is made.
  OutputOptions normals = out, stats = out, replace = out;
  normals.normals = true;
  stats.stats = d.file("s.json");
  replace.replace_input = true;
  for (const OutputOptions* o : {&normals, &stats, &replace}) {
    CHECK_THROWS_AS(curvature_file(in, *o, c), UsageError);
    CHECK_THROWS_AS(extract_file(d.file("s.4k"), *o, q), UsageError);
  }
  CHECK_THROWS_WITH(curvature_file(in, normals, c), Catch::Contains("outputs.normals"));
  CHECK_THROWS_WITH(extract_file(d.file("s.4k"), stats, q), Catch::Contains("outputs.stats"));
  CHECK_FALSE(file_exists(d.file("s.json")));
}
