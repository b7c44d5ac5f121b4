// The JSON that --stats of hierarchy, extract and curvature write, in the shape
// simplify's has, and the JSON helpers info --json shares (stats_file.hpp).
#include "stats_file.hpp"

#include <filesystem>
#include <system_error>

namespace oocsimp_cli {

namespace {

// Whether two paths name one file: the same text, or both there and the same inode.
bool same_path(const std::string& a, const std::string& b) {
  if (a == b) return true;
  std::error_code ec;
  return std::filesystem::equivalent(a, b, ec) && !ec;
}

// Seconds to the microsecond, as simplify's --stats writes them.
std::string json_seconds(double v) {
  char text[32];
  std::snprintf(text, sizeof text, "%.6f", v);
  return text;
}

}  // namespace

void add_stats_option(CLI::App* cmd, std::string* path) {
  cmd->add_option("--stats", *path, "Write statistics as JSON to this file (- for stdout; default: none written)");
}

// Refused before the run (exit 2), as simplify refuses them: a stats file that is the
// input or the output, and both on stdout.
void check_stats_path(const std::string& stats, const std::string& input, const std::string& output) {
  if (stats.empty()) return;
  if (stats == "-" && output == "-") throw UsageError("-o - and --stats - cannot both write to stdout");
  if (stats != "-" && same_path(stats, input)) throw UsageError("--stats " + stats + " is the input " + input);
  if (stats != "-" && same_path(stats, output)) throw UsageError("--stats " + stats + " is the output " + output);
}

// `fields` ("\"name\": value" each) as one JSON object, written after the run worked:
// to stdout for "-", else through a temporary file renamed into place, so a failed
// write leaves no half file.
void write_stats(const std::string& path, const std::vector<std::string>& fields) {
  std::string js = "{\n";
  for (std::size_t k = 0; k < fields.size(); ++k) js += "  " + fields[k] + (k + 1 < fields.size() ? ",\n" : "\n");
  js += "}\n";
  if (path == "-") {
    std::fputs(js.c_str(), stdout);
    std::fflush(stdout);
    return;
  }
  const std::string temp = path + ".tmp" + std::to_string(::getpid());
  {
    std::ofstream out(temp, std::ios::binary | std::ios::trunc);
    out << js;
    out.close();
    if (!out) {
      std::remove(temp.c_str());
      throw IoError(path + ": cannot write the statistics");
    }
  }
  if (std::rename(temp.c_str(), path.c_str()) != 0) {
    std::remove(temp.c_str());
    throw IoError(path + ": cannot write the statistics: " + std::strerror(errno));
  }
}

std::string json_field(const char* name, const std::string& value) { return json_string(name) + ": " + value; }

std::string json_count(std::uint64_t n) { return std::to_string(n); }

// A mesh's size as the stats' "input" and "output" give it.
std::string counts_json(std::uint64_t vertices, std::uint64_t triangles) {
  return "{\"vertices\": " + json_count(vertices) + ", \"triangles\": " + json_count(triangles) + "}";
}

// The shortest text that reads back as `v`, as simplify's --stats writes numbers; null
// where JSON has no number.
std::string json_shortest(double v) {
  if (!std::isfinite(v)) return "null";
  char text[32];
  const auto end = std::to_chars(text, text + sizeof text, v).ptr;
  return std::string(text, end);
}

std::string json_bool(bool b) { return b ? "true" : "false"; }

std::vector<std::string> stats_head(const std::string& input, const std::string& output, const std::string& stats) {
  return {json_field("version", json_string(version())),
          json_field("paths", "{\"input\": " + json_string(input) + ", \"output\": " + json_string(output) +
                                  ", \"stats\": " + json_string(stats) + "}")};
}

std::vector<std::string> stats_tail(const std::vector<std::string>& warnings, double seconds,
                                    std::uint64_t peak_rss_bytes, std::uint64_t peak_anon_bytes) {
  return {json_field("warnings", json_strings(warnings)),
          json_field("seconds", "{\"total\": " + json_seconds(seconds) + "}"),
          json_field("memory", "{\"peak_rss_bytes\": " + json_count(peak_rss_bytes) +
                                   ", \"peak_anon_bytes\": " + json_count(peak_anon_bytes) + "}")};
}

std::vector<std::string> joined(std::vector<std::string> a, const std::vector<std::string>& b) {
  a.insert(a.end(), b.begin(), b.end());
  return a;
}

// A string as a JSON string: quoted, with quotes, backslashes and control bytes escaped.
std::string json_string(const std::string& text) {
  std::string out = "\"";
  for (const char c : text) {
    if (c == '"' || c == '\\') {
      out += '\\';
      out += c;
    } else if (static_cast<unsigned char>(c) < 0x20) {
      char escaped[8];
      std::snprintf(escaped, sizeof escaped, "\\u%04x", unsigned(static_cast<unsigned char>(c)));
      out += escaped;
    } else {
      out += c;
    }
  }
  return out + "\"";
}

// A number as JSON has it: 17 significant digits, and null where JSON has no number.
std::string json_number(double v) {
  if (!std::isfinite(v)) return "null";
  char text[32];
  std::snprintf(text, sizeof text, "%.17g", v);
  return text;
}

std::string json_strings(const std::vector<std::string>& list) {
  std::string out = "[";
  for (std::size_t k = 0; k < list.size(); ++k) out += (k ? ", " : "") + json_string(list[k]);
  return out + "]";
}

}  // namespace oocsimp_cli
