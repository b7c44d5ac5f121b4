// What every subcommand shares: help that says what each option takes, progress in
// each phase, the common flags, a summary in one order, and the messages a new user
// meets first.
#include <catch2/catch.hpp>

#include <nlohmann/json.hpp>

#include <algorithm>
#include <cctype>
#include <cstdio>
#include <initializer_list>
#include <map>
#include <set>
#include <sstream>
#include <string>
#include <vector>

#include "test_support.hpp"

using namespace oocsimp_test;

namespace {

std::string q(const std::string& s) { return "'" + s + "'"; }

const char* const kSubcommands[] = {"simplify", "merge",   "hierarchy", "extract",    "info",
                                    "generate", "measure", "curvature", "lod-select", "render"};

// One option as --help shows it: its long flag and the type of its value ("" for a
// flag that takes none).
struct ShownOption {
  std::string flag, type, line;
};

// The options `subcommand --help` lists, and the whole help text.
std::vector<ShownOption> shown_options(const std::string& subcommand, std::string* help = nullptr) {
  const CliResult r = run_cli(subcommand + " --help");
  REQUIRE(r.exit_code == 0);
  if (help) *help = r.out;
  std::vector<ShownOption> options;
  std::istringstream lines(r.out);
  for (std::string line; std::getline(lines, line);) {
    const std::size_t dashes = line.find("--");
    if (line.rfind("  -", 0) != 0 || dashes == std::string::npos) continue;
    // The name and its value's type fill the first 30 columns; past them (or on the
    // next line, when they fill it) comes the description.
    const std::string head = line.size() > 30 && line[29] == ' ' ? line.substr(0, 30) : line;
    std::istringstream words(head.substr(dashes));
    ShownOption o;
    o.line = line;
    words >> o.flag;
    std::string type;
    if (words >> type && !type.empty() && std::isupper(static_cast<unsigned char>(type[0])) && type != "Excludes:" &&
        type != "Needs:" && type.rfind("REQUIRED", 0) != 0)
      o.type = type.substr(0, type.find(':'));  // "NAME:{ball,sphere}": a choice
    if (o.flag != "--help") options.push_back(o);
  }
  return options;
}

// What a subcommand needs besides the option under test to get past its parsing: the
// paths (which do not exist, so the run stops at the input after the options are
// checked) and its required options, less `flag`.
std::string base_args(const std::string& subcommand, const std::string& flag, const ScratchDir& d) {
  const std::string in = q(d.file("missing.ply")), out = q(d.file("out.ply"));
  if (subcommand == "simplify" || subcommand == "hierarchy" || subcommand == "curvature") return in + " -o " + out;
  if (subcommand == "merge") return q(d.file("missing-folder")) + " -o " + out;
  if (subcommand == "extract") {
    const bool query = flag == "--level" || flag == "--tris" || flag == "--error";
    return q(d.file("missing.4k")) + " -o " + out + (query ? "" : " --level 0");
  }
  if (subcommand == "info") return in;
  if (subcommand == "generate") return "-o " + out + (flag == "--tris" ? "" : " --tris 100");
  if (subcommand == "measure") return in + " " + in;
  if (subcommand == "render") return in + " -o " + q(d.file("out.png"));
  std::string args = q(d.file("missing.lods.json"));  // lod-select
  for (const char* required : {"--distance", "--fov", "--height"})
    if (flag != required) args += std::string(" ") + required + " 10";
  return args;
}

// What an option needs beside it to be checked at all (an option of one method needs
// that method, a factor needs what it multiplies).
std::string context_of(const std::string& subcommand, const std::string& flag) {
  if (subcommand != "simplify") return "";
  if (flag == "--lod-factor") return " --lods 2";
  if (flag == "--intermediate-factor") return " --target-tris 100 --method floating";
  if (flag == "--radius" || flag == "--curvature-tolerance" || flag == "--max-depth") return " --method curvature";
  return "";
}

// Whether the run refused `value` as the value of `flag` (`--flag "value": expected ...`).
bool refuses(const CliResult& r, const std::string& flag, const std::string& value) {
  return r.exit_code == 2 && r.err.find(flag + " \"" + value + "\"") != std::string::npos;
}

// Whether `subcommand` with `base` takes one of `values` for `flag`.
bool takes_one_of(const std::string& subcommand, const std::string& base, const std::string& flag,
                  std::initializer_list<const char*> values) {
  for (const char* value : values)
    if (!refuses(run_cli(subcommand + " " + base + " " + flag + " " + value), flag, value)) return true;
  return false;
}

}  // namespace

TEST_CASE("every option's help names the type of value it takes, and the program takes that type", "[cli][help]") {
  ScratchDir d;
  const std::set<std::string> known = {"INT",   "FLOAT", "FLOAT[%]",          "SIZE",   "PATH", "NAME", "I/K", "WxH",
                                       "AZ,EL", "NAMES", "X0,Y0,Z0,X1,Y1,Z1", "X,Y,Z,R"};
  for (const char* sub : kSubcommands) {
    std::string help;
    for (const ShownOption& o : shown_options(sub, &help)) {
      INFO(sub << ": " << o.line);
      if (o.type.empty()) continue;  // a flag
      CHECK(known.count(o.type) == 1);
      const std::string base = base_args(sub, o.flag, d) + context_of(sub, o.flag);
      if (o.type == "INT") {
        // A whole number is taken, a fraction refused naming the flag and the value.
        CHECK(refuses(run_cli(std::string(sub) + " " + base + " " + o.flag + " 2.5"), o.flag, "2.5"));
        CHECK(takes_one_of(sub, base, o.flag, {"5"}));
      } else if (o.type == "FLOAT" || o.type == "FLOAT[%]") {
        // A fraction is taken (one below or above 1, whichever the range has), a word refused.
        CHECK(refuses(run_cli(std::string(sub) + " " + base + " " + o.flag + " many"), o.flag, "many"));
        CHECK(takes_one_of(sub, base, o.flag, {"0.5", "1.5"}));
      } else if (o.type == "SIZE") {
        const CliResult r = run_cli(std::string(sub) + " " + base + " " + o.flag + " lots");
        CHECK((r.exit_code == 2 && r.err.find(o.flag) != std::string::npos));
        CHECK(takes_one_of(sub, base, o.flag, {"64M"}));
      }
    }
    // A positional argument is a path, whatever its name.
    const std::size_t positionals = help.find("Positionals:\n");
    if (positionals != std::string::npos) {
      std::istringstream lines(help.substr(positionals + 13, help.find("\n\n", positionals) - positionals - 13));
      for (std::string line; std::getline(lines, line);) {
        INFO(sub << ": " << line);
        if (line.rfind("  ", 0) == 0 && line[2] != ' ') CHECK(line.find(" PATH") != std::string::npos);
      }
    }
  }
}

TEST_CASE("every option that has a default says it in its help", "[cli][help]") {
  for (const char* sub : kSubcommands)
    for (const ShownOption& o : shown_options(sub)) {
      // A flag is off unless given; a required option has none; -o has none.
      if (o.type.empty() || o.line.find("REQUIRED") != std::string::npos) continue;
      const CliResult r = run_cli(std::string(sub) + " --help");
      // The option's description may go on over several lines: from its line to the next option's.
      const std::size_t at = r.out.find(o.line);
      REQUIRE(at != std::string::npos);
      const std::size_t next = r.out.find("\n  -", at + 1);
      std::string description;  // its words, one blank between each
      std::istringstream words(r.out.substr(at, next == std::string::npos ? std::string::npos : next - at));
      for (std::string word; words >> word;) description += word + " ";
      INFO(sub << ": " << description);
      CHECK((description.find("default") != std::string::npos || description.find("give one of") != std::string::npos));
    }
}

TEST_CASE("help says what a target does, types its values truly and is wrapped to 80 columns", "[cli][help]") {
  std::string help;
  shown_options("simplify", &help);
  // The default with a target is the edge collapse alone.
  CHECK(help.find("clustering to a few times that, then") == std::string::npos);
  CHECK(help.find("by quadric edge collapse") != std::string::npos);
  std::string lod_help;
  shown_options("lod-select", &lod_help);
  CHECK(lod_help.find("lods PATH") != std::string::npos);
  bool sets_int = false;
  for (const ShownOption& o : shown_options("hierarchy")) sets_int |= o.flag == "--sets" && o.type == "INT";
  CHECK(sets_int);
  // Not a terminal: 80 columns, every line of every help.
  std::vector<std::string> helps = {""};
  for (const char* sub : kSubcommands) helps.push_back(sub);
  for (const std::string& sub : helps) {
    const CliResult r = run_cli(sub + " --help");
    REQUIRE(r.exit_code == 0);
    std::istringstream lines(r.out);
    for (std::string line; std::getline(lines, line);) {
      INFO(sub << ": " << line);
      CHECK(line.size() <= 80);
    }
  }
  // Wrapping moves words, it loses none: the --method line's last words are there.
  CHECK(help.find("exactly") != std::string::npos);
}

namespace {

// The phases a batch log names: "oocsimp: NAME started" and "oocsimp: NAME done in".
struct LoggedPhases {
  std::vector<std::string> started, done;
};

LoggedPhases logged_phases(const std::string& err) {
  LoggedPhases p;
  std::istringstream lines(err);
  for (std::string line; std::getline(lines, line);) {
    if (line.rfind("oocsimp: ", 0) != 0) continue;
    const std::string rest = line.substr(9);
    const std::size_t started = rest.find(" started"), done = rest.find(" done in ");
    if (started != std::string::npos && (started + 8 == rest.size() || rest[started + 8] == ':'))
      p.started.push_back(rest.substr(0, started));
    else if (done != std::string::npos)
      p.done.push_back(rest.substr(0, done));
  }
  return p;
}

}  // namespace

TEST_CASE("every phase of every subcommand that works on a mesh is logged as started and done", "[cli][report]") {
  ScratchDir d;
  const std::string s = q(d.file("s.ply")), lods = q(d.file("l.ply"));
  struct Run {
    std::string args;
    std::vector<std::string> phases;  // each must be among the logged ones
  } runs[] = {
      {"generate --tris 20000 -o " + s, {"generate"}},
      {"simplify " + s + " -o " + q(d.file("f.ply")) + " --grid 16", {"read positions", "plan tiles", "write"}},
      {"simplify " + s + " -o " + q(d.file("u.ply")) + " --grid 16 --method uniform", {"read positions", "write"}},
      {"simplify " + s + " -o " + q(d.file("t.ply")) + " --target-tris 1000",
       {"read positions", "load mesh", "face quadrics", "collapse", "write"}},
      {"simplify " + s + " -o " + lods + " --grid 16 --lods 2", {"plan tiles", "regrade tiles", "write"}},
      {"hierarchy " + s + " -o " + q(d.file("h.4k")),
       {"read positions", "load mesh", "manifold", "4-k mesh", "4-k levels", "write"}},
      {"extract " + q(d.file("h.4k")) + " -o " + q(d.file("e.ply")) + " --level 2",
       {"read hierarchy", "extract", "write"}},
      {"info " + s, {"read positions"}},
      {"measure " + s + " " + q(d.file("t.ply")) + " --samples 2000", {"bound B->A", "index samples of B"}},
      {"curvature " + s + " -o " + q(d.file("k.ply")), {"read positions", "curvatures", "write"}},
      {"render " + s + " -o " + q(d.file("r.png")) + " --size 64x48", {"read positions", "render", "write"}},
  };
  for (const Run& run : runs) {
    const CliResult r = run_cli(run.args);  // stderr a file: the batch log's lines
    INFO(run.args << "\n" << r.err);
    REQUIRE(r.exit_code == 0);
    const LoggedPhases p = logged_phases(r.err);
    CHECK_FALSE(p.started.empty());
    // Each phase that starts is done, in the same order.
    CHECK(p.started == p.done);
    for (const std::string& phase : run.phases)
      CHECK(std::find(p.started.begin(), p.started.end(), phase) != p.started.end());
  }
}

TEST_CASE("extract shows its phases on a terminal", "[cli][report]") {
  if (std::system("command -v script >/dev/null 2>&1") != 0) {
    skip_test("script(1) not found: the terminal output is not checked");
    return;
  }
  ScratchDir d;
  REQUIRE(run_cli("generate --quiet --tris 5000 -o " + q(d.file("s.ply"))).exit_code == 0);
  REQUIRE(run_cli("hierarchy --quiet " + q(d.file("s.ply")) + " -o " + q(d.file("h.4k"))).exit_code == 0);
  const std::string args = "extract " + q(d.file("h.4k")) + " -o " + q(d.file("e.ply")) + " --level 1";
  const std::string cmd =
      "script -qfec " + q(std::string(OOCSIMP_CLI) + " " + args) + " /dev/null >" + q(d.file("tty.txt"));
  REQUIRE(std::system(cmd.c_str()) == 0);
  const std::string tty = read_file(d.file("tty.txt"));
  INFO(tty);
  for (const char* phase : {"\033[Kread hierarchy", "\033[Kextract", "\033[Kwrite"})
    CHECK(tty.find(phase) != std::string::npos);
}

TEST_CASE("the summary goes input, work, output, then time and memory", "[cli][report]") {
  ScratchDir d;
  REQUIRE(run_cli("generate --quiet --tris 20000 -o " + q(d.file("s.ply"))).exit_code == 0);
  const auto in_order = [](const std::string& out, std::vector<std::string> labels) {
    std::size_t at = 0;
    for (const std::string& label : labels) {
      const std::size_t found = out.find("\n" + label, at == 0 ? 0 : at);
      const bool first = at == 0 && out.rfind(label, 0) == 0;
      if (!first && found == std::string::npos) return false;
      at = first ? 1 : found + 1;
    }
    return true;
  };
  // A plain qem run: the collapse starts from the input, no intermediate mesh.
  CliResult r = run_cli("simplify --method qem " + q(d.file("s.ply")) + " -o " + q(d.file("q.ply")));
  INFO(r.out);
  REQUIRE(r.exit_code == 0);
  CHECK(r.out.rfind("input ", 0) == 0);
  CHECK(in_order(r.out, {"input ", "refine ", "output ", "time ", "memory "}));
  CHECK(r.out.find("intermediate triangles") == std::string::npos);
  r = run_cli("simplify --method floating --grid 16 " + q(d.file("s.ply")) + " -o " + q(d.file("f.ply")));
  CHECK(in_order(r.out, {"input ", "tiles ", "output ", "time ", "memory "}));
  r = run_cli("hierarchy " + q(d.file("s.ply")) + " -o " + q(d.file("h.4k")));
  INFO(r.out);
  CHECK(in_order(r.out, {"input ", "records ", "output ", "time ", "memory "}));
  r = run_cli("extract " + q(d.file("h.4k")) + " -o " + q(d.file("e.ply")) + " --level 1");
  INFO(r.out);
  CHECK(in_order(r.out, {"input ", "output ", "time ", "memory "}));
  r = run_cli("curvature " + q(d.file("s.ply")) + " -o " + q(d.file("k.ply")));
  INFO(r.out);
  CHECK(in_order(r.out, {"input ", "output ", "time ", "memory "}));
}

TEST_CASE("every subcommand that runs long takes --quiet, which leaves its summary out", "[cli][options]") {
  ScratchDir d;
  const std::string s = q(d.file("s.ply"));
  REQUIRE(run_cli("generate --quiet --tris 5000 -o " + s).exit_code == 0);
  REQUIRE(run_cli("hierarchy --quiet " + s + " -o " + q(d.file("h.4k"))).exit_code == 0);
  for (const std::string& args :
       {"simplify --quiet " + s + " -o " + q(d.file("o.ply")), "hierarchy --quiet " + s + " -o " + q(d.file("h2.4k")),
        "extract --quiet " + q(d.file("h.4k")) + " -o " + q(d.file("e.ply")) + " --level 1",
        "curvature --quiet " + s + " -o " + q(d.file("k.ply")), "render --quiet " + s + " -o " + q(d.file("r.png")),
        "generate --quiet --tris 100 -o " + q(d.file("g.ply"))}) {
    const CliResult r = run_cli(args);
    INFO(args << "\n" << r.out << r.err);
    CHECK(r.exit_code == 0);
    CHECK(r.out.empty());
    CHECK(r.err.empty());
  }
  // info's description is its output: --quiet silences only the progress.
  const CliResult info = run_cli("info --quiet " + s);
  CHECK(info.exit_code == 0);
  CHECK(info.out.find("vertices") != std::string::npos);
  CHECK(info.err.empty());
  // Without --quiet, extract says what it wrote.
  const CliResult extract = run_cli("extract " + q(d.file("h.4k")) + " -o " + q(d.file("e.ply")) + " --level 1");
  CHECK(extract.out.find("output  ") != std::string::npos);
  CHECK(extract.out.find(std::to_string(load_mesh(d.file("e.ply")).triangle_count()) + " triangles") !=
        std::string::npos);
}

TEST_CASE("a --mem below the minimum echoes what was typed", "[cli][options]") {
  ScratchDir d;
  REQUIRE(run_cli("generate --quiet --tris 1000 -o " + q(d.file("s.ply"))).exit_code == 0);
  for (const char* mem : {"1K", "1000", "31M"}) {
    const CliResult r = run_cli("simplify " + q(d.file("s.ply")) + " -o " + q(d.file("o.ply")) + " --mem " + mem);
    INFO(r.err);
    CHECK(r.exit_code == 2);
    CHECK(r.err.find(std::string("--mem \"") + mem + "\"") != std::string::npos);
    CHECK(r.err.find("at least 32M") != std::string::npos);
    CHECK(r.err.find(" 0 MiB") == std::string::npos);
    CHECK(std::count(r.err.begin(), r.err.end(), '\n') == 1);
  }
  const CliResult merge = run_cli("merge " + q(d.path()) + " -o " + q(d.file("o.ply")) + " --mem 1K");
  CHECK(merge.exit_code == 2);
  CHECK(merge.err.find("--mem \"1K\"") != std::string::npos);
  CHECK_FALSE(file_exists(d.file("o.ply")));
}

TEST_CASE("a run whose output is not smaller than its input warns, naming the option to change", "[cli][report]") {
  ScratchDir d;
  REQUIRE(run_cli("generate --quiet --tris 2000 -o " + q(d.file("s.ply"))).exit_code == 0);
  struct Case {
    const char* args;
    const char* option;
  } cases[] = {{"--method uniform --grid 4096", "a smaller --grid"},
               {"--method floating --cell 0.0001", "a larger --cell"},
               {"--max-error 1e-12", "a larger --max-error"}};
  for (const Case& c : cases) {
    const CliResult r = run_cli("simplify --quiet " + q(d.file("s.ply")) + " -o " + q(d.file("o.ply")) + " " + c.args);
    INFO(c.args << ": " << r.err);
    CHECK(r.exit_code == 0);
    CHECK(r.err.find("oocsimp: warning: the output has") != std::string::npos);
    CHECK(r.err.find("nothing was removed") != std::string::npos);
    CHECK(r.err.find(c.option) != std::string::npos);
  }
  // A run that removes triangles says nothing of it.
  const CliResult small =
      run_cli("simplify --quiet " + q(d.file("s.ply")) + " -o " + q(d.file("o.ply")) + " --method uniform --grid 8");
  CHECK(small.exit_code == 0);
  CHECK(small.err.find("nothing was removed") == std::string::npos);
}

TEST_CASE("a --max-error given as a percentage of the diagonal is the length it stands for", "[cli][options]") {
  ScratchDir d;
  REQUIRE(run_cli("generate --quiet --tris 20000 -o " + q(d.file("s.ply"))).exit_code == 0);
  const CliResult info = run_cli("info --json " + q(d.file("s.ply")));
  REQUIRE(info.exit_code == 0);
  const nlohmann::json js = nlohmann::json::parse(info.out);
  const double diagonal = js.at("diagonal").get<double>();
  REQUIRE(diagonal > 0);
  char length[40];
  std::snprintf(length, sizeof length, "%.17g", 0.5 / 100 * diagonal);
  REQUIRE(
      run_cli("simplify --quiet " + q(d.file("s.ply")) + " -o " + q(d.file("p.ply")) + " --max-error 0.5%").exit_code ==
      0);
  REQUIRE(run_cli("simplify --quiet " + q(d.file("s.ply")) + " -o " + q(d.file("a.ply")) + " --max-error " + length)
              .exit_code == 0);
  CHECK(read_file(d.file("p.ply")) == read_file(d.file("a.ply")));
  CHECK(load_mesh(d.file("p.ply")).triangle_count() < 20000);
  for (const char* bad : {"0%", "101%", "x%", "%"}) {
    const CliResult r =
        run_cli("simplify --quiet " + q(d.file("s.ply")) + " -o " + q(d.file("b.ply")) + " --max-error " + bad);
    INFO(bad << ": " << r.err);
    CHECK(r.exit_code == 2);
    CHECK(r.err.find(std::string("--max-error \"") + bad + "\"") != std::string::npos);
  }
}

TEST_CASE("info --json describes a mesh and a hierarchy, errors with their units", "[cli][report]") {
  ScratchDir d;
  REQUIRE(run_cli("generate --quiet --tris 3000 --attributes -o " + q(d.file("s.ply"))).exit_code == 0);
  CliResult r = run_cli("info --json " + q(d.file("s.ply")));
  REQUIRE(r.exit_code == 0);
  nlohmann::json js = nlohmann::json::parse(r.out);
  const LoadedMesh m = load_mesh(d.file("s.ply"));
  CHECK(js.at("vertices").get<std::uint64_t>() == m.vertex_count());
  CHECK(js.at("faces").get<std::uint64_t>() == m.triangle_count());
  CHECK(js.at("file").get<std::string>() == d.file("s.ply"));
  CHECK(js.at("attributes").size() == 6);  // red, green, blue, nx, ny, nz
  CHECK(js.at("bounds").at("min").size() == 3);
  REQUIRE(run_cli("hierarchy --quiet " + q(d.file("s.ply")) + " -o " + q(d.file("h.4k"))).exit_code == 0);
  r = run_cli("info --json " + q(d.file("h.4k")));
  REQUIRE(r.exit_code == 0);
  js = nlohmann::json::parse(r.out);
  CHECK(js.at("levels").size() > 1);
  CHECK(js.at("error_units").get<std::string>().find("model units^4") != std::string::npos);
  // The text forms say the units too.
  CHECK(run_cli("info " + q(d.file("h.4k"))).out.find("model units^4") != std::string::npos);
  CHECK(run_cli("hierarchy " + q(d.file("s.ply")) + " -o " + q(d.file("h2.4k"))).out.find("model units^4") !=
        std::string::npos);
}

TEST_CASE("a .gz output is gzip, reads back as the same mesh, and is only there after a run that worked",
          "[cli][output]") {
  ScratchDir d;
  REQUIRE(run_cli("generate --quiet --tris 20000 -o " + q(d.file("s.ply"))).exit_code == 0);
  REQUIRE(run_cli("generate --quiet --tris 20000 -o " + q(d.file("s.ply.gz"))).exit_code == 0);
  CHECK(load_mesh(d.file("s.ply.gz")).positions == load_mesh(d.file("s.ply")).positions);
  for (const char* out : {"o.ply", "o.ply.gz", "o.obj.gz", "o.stl.gz"}) {
    const CliResult r = run_cli("simplify --quiet " + q(d.file("s.ply")) + " -o " + q(d.file(out)) + " --grid 16");
    INFO(out << ": " << r.err);
    REQUIRE(r.exit_code == 0);
  }
  const std::string gz = read_file(d.file("o.ply.gz"));
  REQUIRE(gz.size() > 2);
  CHECK((static_cast<unsigned char>(gz[0]) == 0x1f && static_cast<unsigned char>(gz[1]) == 0x8b));
  const LoadedMesh plain = load_mesh(d.file("o.ply")), packed = load_mesh(d.file("o.ply.gz"));
  CHECK(packed.positions == plain.positions);
  CHECK(packed.triangles == plain.triangles);
  CHECK(load_mesh(d.file("o.obj.gz")).triangle_count() == plain.triangle_count());
  CHECK(load_mesh(d.file("o.stl.gz")).triangle_count() == plain.triangle_count());
  // A run that fails leaves no .gz behind, nor a temporary one.
  write_file(d.file("bad.ply"), "ply\nformat binary_little_endian 1.0\nelement vertex 3\nproperty float x\n");
  const std::vector<std::string> before = d.entries();
  const CliResult bad = run_cli("simplify --quiet " + q(d.file("bad.ply")) + " -o " + q(d.file("x.ply.gz")));
  CHECK(bad.exit_code == 3);
  CHECK(d.entries() == before);
}

namespace {

// The common flags each subcommand takes: --quiet where it works on a mesh, --threads
// where its work is parallel, --stats where a script reads the figures of a run that
// writes a file, --json where the report is itself the output.
struct CommonFlags {
  const char* subcommand;
  bool quiet, threads, stats, json;
};
const CommonFlags kCommonFlags[] = {
    {"simplify", true, true, true, false},     {"merge", true, true, true, false},
    {"hierarchy", true, true, true, false},    {"extract", true, false, true, false},
    {"info", true, false, false, true},        {"generate", true, false, false, false},
    {"measure", true, true, false, true},      {"curvature", true, true, true, false},
    {"lod-select", false, false, false, true}, {"render", true, false, false, false},
};

}  // namespace

TEST_CASE("every subcommand takes the common flags its work calls for", "[cli][options]") {
  std::set<std::string> listed;
  for (const CommonFlags& c : kCommonFlags) {
    listed.insert(c.subcommand);
    std::set<std::string> flags;
    for (const ShownOption& o : shown_options(c.subcommand)) flags.insert(o.flag);
    INFO(c.subcommand);
    CHECK(flags.count("--quiet") == std::size_t(c.quiet));
    CHECK(flags.count("--threads") == std::size_t(c.threads));
    CHECK(flags.count("--stats") == std::size_t(c.stats));
    CHECK(flags.count("--json") == std::size_t(c.json));
  }
  // The table covers every subcommand the program has.
  CHECK(listed == std::set<std::string>(std::begin(kSubcommands), std::end(kSubcommands)));
}

TEST_CASE("hierarchy, extract and curvature write --stats as simplify does", "[cli][report]") {
  ScratchDir d;
  const std::string s = d.file("s.ply");
  REQUIRE(run_cli("generate --quiet --tris 6000 -o " + q(s)).exit_code == 0);
  const LoadedMesh input = load_mesh(s);
  std::string version = run_cli("--version").out;  // "oocsimp X.Y.Z\n"
  version = version.substr(8, version.find_last_not_of("\n") - 7);
  struct Run {
    std::string subcommand, in, out, args;
  } runs[] = {
      {"simplify", s, d.file("o.ply"), "--target-tris 1000"},
      {"hierarchy", s, d.file("h.4k"), ""},
      {"extract", d.file("h.4k"), d.file("e.ply"), "--level 2"},
      {"curvature", s, d.file("k.ply"), ""},
  };
  for (const Run& run : runs) {
    const std::string stats = d.file(run.subcommand + ".json");
    const CliResult r =
        run_cli(run.subcommand + " " + q(run.in) + " -o " + q(run.out) + " --stats " + q(stats) + " " + run.args);
    INFO(run.subcommand << ": " << r.err);
    REQUIRE(r.exit_code == 0);
    const nlohmann::json js = nlohmann::json::parse(read_file(stats));
    CHECK(js.at("version").get<std::string>() == version);
    CHECK(js.at("paths").at("input").get<std::string>() == run.in);
    CHECK(js.at("paths").at("output").get<std::string>() == run.out);
    CHECK(js.at("paths").at("stats").get<std::string>() == stats);
    CHECK(js.at("options").is_object());
    // The input is the generated mesh (for extract: the hierarchy's finest level, the same mesh).
    CHECK(js.at("input").at("triangles").get<std::uint64_t>() == input.triangle_count());
    CHECK(js.at("input").at("vertices").get<std::uint64_t>() == input.vertex_count());
    if (run.subcommand != "hierarchy") {
      const LoadedMesh out = load_mesh(run.out);
      CHECK(js.at("output").at("triangles").get<std::uint64_t>() == out.triangle_count());
      CHECK(js.at("output").at("vertices").get<std::uint64_t>() == out.vertex_count());
    } else {
      CHECK(js.at("output").at("bytes").get<std::uint64_t>() == read_file(run.out).size());
    }
    CHECK(js.at("warnings").is_array());
    CHECK(js.at("seconds").at("total").get<double>() >= 0);
    CHECK(js.at("memory").at("peak_rss_bytes").get<std::uint64_t>() > 0);
  }
  // extract's level 2 is coarser than the input, and simplify met its target.
  CHECK(load_mesh(d.file("e.ply")).triangle_count() < input.triangle_count());
  CHECK(load_mesh(d.file("o.ply")).triangle_count() == 1000);
}

TEST_CASE("a --stats of - puts the JSON on stdout and the summary on stderr, and a stats file may not be the input",
          "[cli][report]") {
  ScratchDir d;
  const std::string s = d.file("s.ply");
  REQUIRE(run_cli("generate --quiet --tris 3000 -o " + q(s)).exit_code == 0);
  REQUIRE(run_cli("hierarchy --quiet " + q(s) + " -o " + q(d.file("h.4k"))).exit_code == 0);
  const std::string in_bytes = read_file(s);
  for (const std::string& args : {"hierarchy " + q(s) + " -o " + q(d.file("h2.4k")),
                                  "extract " + q(d.file("h.4k")) + " -o " + q(d.file("e.ply")) + " --level 1",
                                  "curvature " + q(s) + " -o " + q(d.file("k.ply"))}) {
    CliResult r = run_cli(args + " --stats -");
    INFO(args << "\n" << r.out << r.err);
    REQUIRE(r.exit_code == 0);
    CHECK(nlohmann::json::parse(r.out).at("input").at("triangles").get<std::uint64_t>() > 0);
    CHECK(r.err.find("input ") != std::string::npos);
    CHECK(r.err.find("memory ") != std::string::npos);
    // --quiet leaves the summary out, not the stats.
    r = run_cli(args + " --quiet --stats -");
    CHECK(nlohmann::json::parse(r.out).is_object());
    CHECK(r.err.empty());
    // A stats file that is the input is refused before anything is written.
    const std::string first = args.substr(args.find(' ') + 1, args.find(' ', args.find(' ') + 1) - args.find(' ') - 1);
    r = run_cli(args + " --stats " + first);
    CHECK(r.exit_code == 2);
    CHECK(r.err.find("--stats") != std::string::npos);
  }
  CHECK(read_file(s) == in_bytes);
  // extract with the mesh on stdout cannot put the stats there too.
  const CliResult both = run_cli("extract " + q(d.file("h.4k")) + " -o - --level 1 --stats -");
  CHECK(both.exit_code == 2);
}

TEST_CASE("hierarchy and curvature give the same files for any --threads", "[cli][options]") {
  ScratchDir d;
  const std::string s = q(d.file("s.ply"));
  REQUIRE(run_cli("generate --quiet --tris 8000 -o " + s).exit_code == 0);
  for (const char* threads : {"1", "2"}) {
    const std::string t = threads;
    REQUIRE(run_cli("hierarchy --quiet " + s + " -o " + q(d.file("h" + t + ".4k")) + " --threads " + t).exit_code == 0);
    REQUIRE(run_cli("curvature --quiet " + s + " -o " + q(d.file("k" + t + ".ply")) + " --threads " + t).exit_code ==
            0);
  }
  CHECK(read_file(d.file("h1.4k")) == read_file(d.file("h2.4k")));
  CHECK(read_file(d.file("k1.ply")) == read_file(d.file("k2.ply")));
}
