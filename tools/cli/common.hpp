// What the oocsimp command's subcommands share: exit codes, the flags that stand for
// the library's option fields, number parsing, and the common options (--tmp,
// --threads, --quiet, --mem).
#pragma once

#include <CLI/CLI.hpp>
#include <sys/ioctl.h>
#include <unistd.h>

#include <algorithm>
#include <cctype>
#include <cerrno>
#include <charconv>
#include <chrono>
#include <cinttypes>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <fstream>
#include <functional>
#include <initializer_list>
#include <memory>
#include <new>
#include <sstream>
#include <string>
#include <utility>
#include <vector>

#include "oocsimp/oocsimp.hpp"
#include "oocsimp/generate.hpp"
#include "oocsimp/lod.hpp"
#include "oocsimp/measure.hpp"
#include "oocsimp/progress_reporter.hpp"
#include "oocsimp/render.hpp"
#include "mpi_run.hpp"

namespace oocsimp_cli {

using namespace oocsimp;

enum ExitCode { kOk = 0, kUsage = 2, kBadInput = 3, kIo = 4 };

// --- Option fields shown as flags.

// The library names an option by its field ("options.memory_budget"); the command
// line shows the flag that sets it. The one table of that mapping, for errors and
// warnings alike.
inline constexpr std::pair<const char*, const char*> kFlagOfField[] = {
    {"options.floating.tile_side", "--tile"},
    {"options.floating.keep_temp", "--keep-tmp"},
    {"options.memory_budget", "--mem"},
    {"options.sizing.cell", "--cell"},
    {"options.sizing.grid", "--grid"},
    {"options.sizing.ratio", "--ratio"},
    {"options.attributes", "--attributes"},
    {"options.temp_dir", "--tmp"},
    {"options.target.triangles", "--target-tris"},
    {"options.target.ratio", "--target-ratio"},
    {"options.target.max_error", "--max-error"},
    {"options.target.intermediate_factor", "--intermediate-factor"},
    {"options.thick_edges", "--thick-edges"},
    {"options.lock_boundary", "--lock-boundary"},
    {"options.locked_vertices", "--lock-vertices"},
    {"options.method", "--method"},
    {"options.lods.levels", "--lods"},
    {"options.lods.factor", "--lod-factor"},
    {"options.lods", "--lods"},
    {"options.triangles", "--tris"},
    {"options.samples", "--samples"},
    {"options.radius", "--radius"},
    {"options.curvature.radius", "--radius"},
    {"options.curvature.tolerance", "--curvature-tolerance"},
    {"options.curvature.max_depth", "--max-depth"},
    {"options.curvature.representative", "--rep"},
    {"options.floating.representative", "--rep"},
    {"options.tile_side", "--tile"},
    {"options.at_scale", "--at-scale"},
    {"outputs.replace_input", "--force"},
    {"outputs.stats", "--stats"},
    {"outputs.mesh", "-o"},
    {"query.level", "--level"},
    {"query.triangles", "--tris"},
    {"query.error", "--error"},
    {"query.radius", "--sphere"},
    {"query.box", "--box"},
    {"query.region", "the region"},
    {"query", "extract"},
    {"options.level_ratio", "--level-ratio"},
    {"options.sets_per_level", "--sets"},
};

// A character that continues a name or a path.
inline bool continues_name(char c) {
  return std::isalnum(static_cast<unsigned char>(c)) || c == '_' || c == '-' || c == '/' || c == '.';
}

// Whether text[at, end) stands as a name of its own: not part of a path or of a
// longer field ("options.lods" in "options.lods.levels"). A full stop after it ends
// a sentence.
inline bool stands_alone(const std::string& text, std::size_t at, std::size_t end) {
  if (at > 0 && continues_name(text[at - 1])) return false;
  if (end == text.size() || !continues_name(text[end])) return true;
  return text[end] == '.' && (end + 1 == text.size() || !continues_name(text[end + 1]));
}

// The row of kFlagOfField whose field stands at text[at], or null.
inline const std::pair<const char*, const char*>* field_at(const std::string& text, std::size_t at) {
  for (const auto& row : kFlagOfField) {
    const std::size_t end = at + std::strlen(row.first);
    if (text.compare(at, end - at, row.first) == 0 && stands_alone(text, at, end)) return &row;
  }
  return nullptr;
}

// `text` with each option field it names shown as its flag (advice names fields
// anywhere: "give options.memory_budget 512 MiB or more, or a larger options.sizing.cell").
inline std::string with_flags(const std::string& text) {
  std::string shown;
  for (std::size_t at = 0; at < text.size();) {
    if (const auto* row = field_at(text, at)) {
      shown += row->second;
      at += std::strlen(row->first);
    } else {
      shown += text[at++];
    }
  }
  return shown;
}

// --- Checked option values: every size and count is refused (exit 2, naming the flag
// and the value) rather than replaced by a default. CLI11 reads "-5" into an unsigned
// without complaint, so numbers are taken as text and parsed here.

[[noreturn]] inline void bad_value(const std::string& flag, const std::string& text, const std::string& expected) {
  throw UsageError(flag + " \"" + text + "\": expected " + expected);
}

// A byte count as the user would write it: "1 KiB", "48 MiB", "1000 bytes".
inline std::string byte_size_text(std::uint64_t bytes) {
  if (bytes >= (1u << 20) && bytes % (1u << 20) == 0) return std::to_string(bytes >> 20) + " MiB";
  if (bytes >= 1024 && bytes % 1024 == 0) return std::to_string(bytes >> 10) + " KiB";
  return std::to_string(bytes) + (bytes == 1 ? " byte" : " bytes");
}

inline double positive_number(const std::string& flag, const std::string& text, double max = HUGE_VAL) {
  char* end = nullptr;
  double v = std::strtod(text.c_str(), &end);
  if (text.empty() || *end != '\0' || !std::isfinite(v) || !(v > 0) || v > max) {
    char range[64];
    std::snprintf(range, sizeof range, "a number above 0 and at most %g", max);
    bad_value(flag, text, max == HUGE_VAL ? "a positive finite number" : range);
  }
  return v;
}

// A count: digits, or a number with an exponent or a decimal suffix k, M or G (10^3,
// 10^6, 10^9: "10k", "2.5M", "1e6") that comes to a whole number.
inline std::uint64_t whole_number(const std::string& flag, const std::string& text, std::uint64_t min,
                                  std::uint64_t max) {
  std::uint64_t v = 0;
  auto r = std::from_chars(text.data(), text.data() + text.size(), v);
  bool ok = !text.empty() && text[0] != '-' && r.ec == std::errc() && r.ptr == text.data() + text.size();
  if (!ok && !text.empty() && text[0] != '-') {
    std::string number = text;
    double scale = 1;
    const char last = number.back();
    if (last == 'k' || last == 'K' || last == 'M' || last == 'G') {
      scale = last == 'G' ? 1e9 : last == 'M' ? 1e6 : 1e3;
      number.pop_back();
    }
    char* end = nullptr;
    const double x = std::strtod(number.c_str(), &end) * scale;
    // Below 2^53 every whole number is exact in a double.
    ok = !number.empty() && *end == '\0' && std::isfinite(x) && x >= 0 && x < 9007199254740992.0 && x == std::floor(x);
    if (ok) v = std::uint64_t(x);
  }
  if (!ok || v < min || v > max)
    bad_value(
        flag, text,
        "a whole number from " + std::to_string(min) + " to " + std::to_string(max) + " (digits, or 10k, 2.5M, 1e6)");
  return v;
}

inline constexpr std::uint64_t kMost = ~std::uint64_t(0);
inline constexpr std::uint64_t kMaxThreads = 65536;

// An option taken as text and checked after parsing: whether the user gave it, and what.
struct Given {
  CLI::Option* option = nullptr;
  std::string text;
  bool given() const { return option && option->count() > 0; }
};

inline CLI::Option* add_given(CLI::App* app, const std::string& flag, Given* g, const std::string& help) {
  return g->option = app->add_option(flag, g->text, help);
}

// --- Enum options: their values are spelled by the library's tables (EnumNames).

template <class E>
inline std::vector<std::string> names_of(const EnumNames<E>& names) {
  std::vector<std::string> spelled;
  for (const EnumName<E>& n : names) spelled.push_back(n.name);
  return spelled;
}

// An option taking one of the spellings in `names` into `value`: CLI11 checks the text
// (its help and its error list the spellings, "{cube,sphere}"), the table converts it.
template <class E>
inline CLI::Option* add_enum_option(CLI::App* app, const std::string& flag, E* value, const EnumNames<E>& names,
                                    const std::string& help) {
  return app
      ->add_option_function<std::string>(
          flag, [value, &names](const std::string& text) { value_named(names, text, value); }, help)
      ->check(CLI::IsMember(names_of(names)));
}

// "a (note), b or c (note)": `values` in their order as `names` spells them, each with
// its note when it has one.
template <class E>
inline std::string value_list(const EnumNames<E>& names, std::initializer_list<std::pair<E, const char*>> values) {
  std::string list;
  std::size_t k = 0;
  for (const auto& [value, note] : values) {
    if (k > 0) list += k + 1 == values.size() ? " or " : ", ";
    list += name_of(names, value);
    if (note) list += std::string(" (") + note + ")";
    ++k;
  }
  return list;
}

// --- Options several subcommands take.

inline void add_tmp_option(CLI::App* app, std::string* dir) {
  app->add_option("--tmp", *dir, "Folder for temporary files (default $TMPDIR or /tmp)");
}

inline void add_threads_option(CLI::App* app, Given* threads) {
  add_given(app, "--threads", threads, "Worker threads (default: all cores)");
}

inline unsigned threads_of(const Given& threads) {
  return unsigned(whole_number("--threads", threads.text, 1, kMaxThreads));
}

inline void add_quiet_flag(CLI::App* app, bool* quiet, const std::string& help = "No progress") {
  app->add_flag("--quiet", *quiet, help);
}

// The bytes --mem gives; a bad size, or one below `minimum` (the least a run can hold
// its buffers in), exits 2 naming --mem and what was typed.
inline std::uint64_t memory_budget_of(const Given& mem, std::uint64_t minimum = 1) {
  std::uint64_t bytes = 0;
  try {
    bytes = parse_byte_size(mem.text);
  } catch (const UsageError& e) {
    throw UsageError(std::string("--mem: ") + e.what());
  }
  if (bytes < minimum)
    bad_value("--mem", mem.text,
              "at least " + std::to_string(minimum >> 20) + "M (" + std::to_string(minimum >> 20) + " MiB); it is " +
                  byte_size_text(bytes));
  return bytes;
}

// --- Help

// The columns help is wrapped to: the terminal's width when stdout is one, else 80.
inline std::size_t help_width() {
  constexpr std::size_t kNotTerminal = 80, kNarrowest = 40;
  if (::isatty(STDOUT_FILENO) != 1) return kNotTerminal;
  winsize size{};
  if (::ioctl(STDOUT_FILENO, TIOCGWINSZ, &size) != 0 || size.ws_col == 0) return kNotTerminal;
  return std::max<std::size_t>(size.ws_col, kNarrowest);
}

// `words` filled into lines of at most `width` columns, each after the first starting
// with `indent` spaces; a word longer than a line stands alone on its own.
inline std::string fill_words(const std::string& words, std::size_t first_column, std::size_t indent,
                              std::size_t width) {
  std::string out;
  std::size_t column = first_column;
  std::istringstream in(words);
  bool line_empty = true;
  for (std::string word; in >> word;) {
    if (!line_empty && column + 1 + word.size() > width) {
      out += "\n" + std::string(indent, ' ');
      column = indent;
      line_empty = true;
    }
    if (!line_empty) {
      out += ' ';
      ++column;
    }
    out += word;
    column += word.size();
    line_empty = false;
  }
  return out;
}

// CLI11's help with every line wrapped to the width: an option's or a subcommand's
// description goes on under its own column, a paragraph from the left margin.
class WrappingFormatter : public CLI::Formatter {
 public:
  explicit WrappingFormatter(std::size_t width) : width_(width) {}

  std::string make_help(const CLI::App* app, std::string name, CLI::AppFormatMode mode) const override {
    std::istringstream lines(CLI::Formatter::make_help(app, std::move(name), mode));
    std::string out;
    for (std::string line; std::getline(lines, line);) out += wrapped(line) + "\n";
    return out;
  }

 private:
  std::string wrapped(const std::string& line) const {
    if (line.size() <= width_) return line;
    const std::size_t column = get_column_width();
    // An option's line: its name (or blanks, on a line that goes on from one) in the
    // first column, its description after.
    const bool in_columns = line.compare(0, 2, "  ") == 0 && line.size() > column && line[column - 1] == ' ' &&
                            line[column] != ' ' && column + 20 <= width_;
    if (in_columns) return line.substr(0, column) + fill_words(line.substr(column), column, column, width_);
    const std::size_t indent = line.find_first_not_of(' ');
    if (indent == std::string::npos) return line;
    return line.substr(0, indent) + fill_words(line.substr(indent), indent, indent, width_);
  }

  std::size_t width_;
};

// --- simplify

inline void print_warnings(const std::vector<std::string>& warnings) {
  for (const std::string& w : warnings) std::fprintf(stderr, "oocsimp: warning: %s\n", with_flags(w).c_str());
}

// The last part of a path: level files are named in their description relative to it.

// "open 0.012, bin 0.100, ...": the seconds of each phase.
inline std::string phase_times(const std::vector<PhaseTime>& phases) {
  std::string list;
  for (const PhaseTime& p : phases) {
    char buf[64];
    std::snprintf(buf, sizeof buf, "%s%s %.3f", list.empty() ? "" : ", ", p.name.c_str(), p.seconds);
    list += buf;
  }
  return list;
}

// The floating method's tiles and its spill's parts that exist: on disk, in memory or both.
inline void print_tiles(std::FILE* to, const SimplifyStats& stats) {
  char disk[96] = "", memory[64] = "";
  if (stats.floating.spill_bytes)
    std::snprintf(disk, sizeof disk, ", spill %.1f MiB on disk (%.1f MiB raw)",
                  double(stats.floating.spill_bytes) / 1048576.0, double(stats.floating.spill_raw_bytes) / 1048576.0);
  if (stats.floating.spill_bytes_in_memory)
    std::snprintf(memory, sizeof memory, ", %.1f MiB of spill held in memory",
                  double(stats.floating.spill_bytes_in_memory) / 1048576.0);
  std::fprintf(to, "tiles   %" PRIu64 " tiles%s, %" PRIu64 " rounds%s%s\n", stats.floating.tiles,
               stats.floating.resumed ? " (kept by an earlier run)" : "", stats.floating.rounds, disk, memory);
}

// --- The run summary: input, then the work, then the output, then time and memory,
// each line led by its name in a column of eight.

inline void print_input_line(std::FILE* to, std::uint64_t vertices, std::uint64_t triangles, const char* more = "") {
  std::fprintf(to, "input   %" PRIu64 " vertices, %" PRIu64 " triangles%s\n", vertices, triangles, more);
}

inline void print_memory_line(std::FILE* to, std::uint64_t peak_rss_bytes, std::uint64_t peak_anon_bytes) {
  std::fprintf(to, "memory  peak RSS %.1f MiB, peak anonymous %.1f MiB\n", double(peak_rss_bytes) / 1048576.0,
               double(peak_anon_bytes) / 1048576.0);
}

inline void print_simplify_summary(std::FILE* to, const SimplifyOptions& o, const SimplifyStats& stats) {
  const ClusterMethod method = resolved_method(o);
  const bool collapsed = o.target.given() || method == ClusterMethod::qem;
  print_input_line(to, stats.input_vertices, stats.input_triangles);
  if (method == ClusterMethod::floating) print_tiles(to, stats);
  if (collapsed) {
    // With no clustering before it, the collapse starts from the input itself: no
    // intermediate mesh to count.
    char intermediate[64] = "";
    if (stats.grid_dims[0] != 0)
      std::snprintf(intermediate, sizeof intermediate, "%" PRIu64 " intermediate triangles, ",
                    stats.refine.intermediate_triangles);
    std::fprintf(to, "refine  %s%" PRIu64 " collapses, largest error %.3g (cost %.3g)%s\n", intermediate,
                 stats.refine.collapses, stats.refine.largest_collapse_error, stats.refine.largest_collapse_cost,
                 stats.refine.target_missed ? ", target missed" : "");
  }
  if (stats.refine.passes) {
    std::string counts = std::to_string(stats.input_triangles);
    for (std::uint64_t n : stats.refine.pass_triangles) counts += " -> " + std::to_string(n);
    std::fprintf(to, "passes  %u out-of-core passes of the collapse before the last: %s triangles\n",
                 unsigned(stats.refine.passes), counts.c_str());
  }
  if (stats.refine.phase1_peak_anon_bytes)
    std::fprintf(to, "phases  peak anonymous: phase 1 (%s) %.1f MiB, phase 2 (collapse) %.1f MiB\n",
                 stats.refine.passes ? "out-of-core passes" : "clustering",
                 double(stats.refine.phase1_peak_anon_bytes) / 1048576.0,
                 double(stats.refine.phase2_peak_anon_bytes) / 1048576.0);
  const std::string thick = o.thick_edges ? ", " + std::to_string(stats.output_edges) + " edges, " +
                                                std::to_string(stats.output_points) + " points"
                                          : std::string();
  const double mtri = stats.seconds_total > 0 ? double(stats.input_triangles) / stats.seconds_total / 1e6 : 0;
  // A collapse with no clustering before it has no grid to show.
  char how[160];
  if (stats.grid_dims[0] == 0)
    std::snprintf(how, sizeof how, "%s", collapsed ? "edge collapse" : "as is");
  else
    std::snprintf(how, sizeof how, "%s, grid %ux%ux%u, cell %.6g", method_name(method), stats.grid_dims[0],
                  stats.grid_dims[1], stats.grid_dims[2], stats.cell_size);
  std::fprintf(to,
               "output  %" PRIu64 " vertices, %" PRIu64
               " triangles%s (%s)\n"
               "time    %.3f s (%s): %.2f Mtri/s\n",
               stats.output_vertices, stats.output_triangles, thick.c_str(), how, stats.seconds_total,
               phase_times(stats.phases).c_str(), mtri);
  print_memory_line(to, stats.peak_rss_bytes, stats.peak_anon_bytes);
}

}  // namespace oocsimp_cli
