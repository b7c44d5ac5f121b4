// oocsimp command line: a thin layer over the library (include/oocsimp/).
//
// Each subcommand is an args struct that CLI11 fills, add_<name>_command declaring its
// options and run_<name> doing the work; main parses, dispatches and maps failures to
// exit codes: 0 ok, 2 usage, 3 bad input, 4 I/O or resource failure.
#include "commands.hpp"

namespace oocsimp_cli {

namespace {

// Levenshtein distance, for "did you mean".
std::size_t edit_distance(const std::string& a, const std::string& b) {
  std::vector<std::size_t> row(b.size() + 1);
  for (std::size_t j = 0; j <= b.size(); ++j) row[j] = j;
  for (std::size_t i = 1; i <= a.size(); ++i) {
    std::size_t diagonal = row[0];
    row[0] = i;
    for (std::size_t j = 1; j <= b.size(); ++j) {
      std::size_t up = row[j];
      row[j] = std::min({row[j] + 1, row[j - 1] + 1, diagonal + (a[i - 1] == b[j - 1] ? 0 : 1)});
      diagonal = up;
    }
  }
  return row[b.size()];
}

// " (did you mean --grid?)" for the first argument that names no flag of `command`
// (or no subcommand of the app) but is within two edits of one; empty otherwise.
std::string suggestion(const CLI::App& app, int argc, char** argv) {
  std::vector<CLI::App*> parsed = app.get_subcommands();
  const CLI::App* command = parsed.empty() ? nullptr : parsed.front();
  std::vector<std::string> names;
  if (command) {
    for (const CLI::Option* o : command->get_options())
      for (const std::string& n : o->get_lnames()) names.push_back("--" + n);
  } else {
    for (const CLI::App* sub : app.get_subcommands([](const CLI::App*) { return true; }))
      names.push_back(sub->get_name());
  }
  for (int i = 1; i < argc; ++i) {
    std::string arg = argv[i];
    arg = arg.substr(0, arg.find('='));
    if (command ? arg.rfind("--", 0) != 0 : arg.rfind("-", 0) == 0) continue;
    if (std::find(names.begin(), names.end(), arg) != names.end()) continue;
    if (!command && i > 1) break;  // only the subcommand's own position
    std::string best;
    std::size_t best_distance = 3;
    for (const std::string& n : names) {
      std::size_t d = edit_distance(arg, n);
      if (d < best_distance) best_distance = d, best = n;
    }
    if (!best.empty()) return " (did you mean " + best + "?)";
  }
  return "";
}

// CLI11's messages may span lines; a usage error is one line.
std::string one_line(std::string text) {
  for (char& c : text)
    if (c == '\n') c = ' ';
  while (!text.empty() && text.back() == ' ') text.pop_back();
  return text;
}

// What each option's value is, for --help: every value is taken as text and checked
// later, which CLI11 would show as TEXT. Every positional argument is a path.
void show_value_types(CLI::App& app) {
  static const std::pair<const char*, const char*> kTypeOfOption[] = {
      {"threads", "INT"},        {"sets", "INT"},           {"max-error", "FLOAT[%]"}, {"target-tris", "INT"},
      {"tris", "INT"},           {"grid", "INT"},           {"lods", "INT"},           {"levels", "INT"},
      {"samples", "INT"},        {"seed", "INT"},           {"level", "INT"},          {"max-depth", "INT"},
      {"height", "INT"},         {"mem", "SIZE"},           {"part", "I/K"},           {"box", "X0,Y0,Z0,X1,Y1,Z1"},
      {"sphere", "X,Y,Z,R"},     {"size", "WxH"},           {"view", "AZ,EL"},         {"attributes", "NAMES"},
      {"tmp", "PATH"},           {"work-dir", "PATH"},      {"output", "PATH"},        {"stats", "PATH"},
      {"lock-vertices", "PATH"}, {"error-colours", "PATH"},
  };
  for (CLI::App* command : app.get_subcommands({}))
    for (CLI::Option* option : command->get_options()) {
      const std::string shown = option->get_type_name();
      if (option->get_type_size() == 0 || shown.empty()) continue;  // a flag
      if (option->get_lnames().empty() && option->get_snames().empty()) {
        option->type_name("PATH");
        continue;
      }
      const std::string name = option->get_lnames().front();
      const char* type = shown.find(':') != std::string::npos ? "NAME" : "FLOAT";  // a choice, or a number
      for (const auto& [n, t] : kTypeOfOption)
        if (name == n) type = t;
      option->type_name(type);
    }
}

}  // namespace

// The exception being handled, reported on stderr as its exit code (called in a catch block).
int report_failure() {
  try {
    throw;
  } catch (const UsageError& e) {
    std::fprintf(stderr, "oocsimp: %s\n", with_flags(e.what()).c_str());
    return kUsage;
  } catch (const InputError& e) {
    std::fprintf(stderr, "oocsimp: %s\n", e.what());
    return kBadInput;
  } catch (const IoError& e) {
    std::fprintf(stderr, "oocsimp: %s\n", with_flags(e.what()).c_str());
    return kIo;
  } catch (const std::bad_alloc&) {
    std::fprintf(stderr, "oocsimp: out of memory\n");
    return kIo;
  } catch (const std::exception& e) {  // Cancelled among them
    std::fprintf(stderr, "oocsimp: %s\n", e.what());
    return kIo;
  }
}

}  // namespace oocsimp_cli

using namespace oocsimp;
using namespace oocsimp_cli;

int main(int argc, char** argv) {
  install_signal_cleanup();
  tune_allocator_for_tiles();
  CLI::App app{"oocsimp: out-of-core simplification of huge triangle meshes"};
  // Before the subcommands: each takes its parent's formatter when it is added.
  app.formatter(std::make_shared<WrappingFormatter>(help_width()));
  app.require_subcommand(1);
  app.set_version_flag("--version", std::string("oocsimp ") + version());
  SimplifyArgs simplify;
  InfoArgs info;
  GenerateArgs generate;
  MeasureArgs measure;
  CurvatureArgs curvature;
  LodSelectArgs lod_select;
  RenderArgs render;
  HierarchyArgs hierarchy;
  ExtractArgs extract;
  MergeArgs merge;
  const std::pair<CLI::App*, std::function<int()>> commands[] = {
      {add_simplify_command(app, simplify), [&] { return run_simplify(simplify); }},
      {add_info_command(app, info), [&] { return run_info(info); }},
      {add_generate_command(app, generate), [&] { return run_generate(generate); }},
      {add_measure_command(app, measure), [&] { return run_measure(measure); }},
      {add_curvature_command(app, curvature), [&] { return run_curvature(curvature); }},
      {add_lod_select_command(app, lod_select), [&] { return run_lod_select(lod_select); }},
      {add_render_command(app, render), [&] { return run_render(render); }},
      {add_hierarchy_command(app, hierarchy), [&] { return run_hierarchy(hierarchy); }},
      {add_extract_command(app, extract), [&] { return run_extract(extract); }},
      {add_merge_command(app, merge), [&] { return run_merge(merge); }},
  };
  show_value_types(app);
  try {
    app.parse(argc, argv);
  } catch (const CLI::CallForHelp& e) {
    return app.exit(e);
  } catch (const CLI::CallForAllHelp& e) {
    return app.exit(e);
  } catch (const CLI::CallForVersion& e) {
    return app.exit(e);
  } catch (const CLI::ParseError& e) {
    std::fprintf(stderr, "oocsimp: %s%s (see oocsimp --help)\n", one_line(e.what()).c_str(),
                 suggestion(app, argc, argv).c_str());
    return kUsage;
  }
  try {
    for (const auto& [command, run] : commands)
      if (*command) return run();
  } catch (...) {
    return report_failure();
  }
  return kUsage;
}
