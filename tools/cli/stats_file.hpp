// --stats of hierarchy, extract and curvature, in the shape simplify's has: version,
// paths, options, input, the work, output, warnings, seconds and memory; and the JSON
// pieces info --json shares.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "common.hpp"

namespace oocsimp_cli {

void add_stats_option(CLI::App* cmd, std::string* path);
/// Refused before the run (exit 2), as simplify refuses them: a stats file that is the
/// input or the output, and both on stdout.
void check_stats_path(const std::string& stats, const std::string& input, const std::string& output);
/// `fields` ("\"name\": value" each) as one JSON object, written after the run worked:
/// to stdout for "-", else through a temporary file renamed into place.
void write_stats(const std::string& path, const std::vector<std::string>& fields);

std::string json_field(const char* name, const std::string& value);
std::string json_count(std::uint64_t n);
/// A mesh's size as the stats' "input" and "output" give it.
std::string counts_json(std::uint64_t vertices, std::uint64_t triangles);
/// The shortest text that reads back as `v`; null where JSON has no number.
std::string json_shortest(double v);
std::string json_bool(bool b);
/// A string as a JSON string: quoted, with quotes, backslashes and control bytes escaped.
std::string json_string(const std::string& text);
/// A number as JSON has it: 17 significant digits, and null where JSON has no number.
std::string json_number(double v);
std::string json_strings(const std::vector<std::string>& list);

/// The fields every stats file starts with (version and paths) and ends with
/// (warnings, seconds and memory).
std::vector<std::string> stats_head(const std::string& input, const std::string& output, const std::string& stats);
std::vector<std::string> stats_tail(const std::vector<std::string>& warnings, double seconds,
                                    std::uint64_t peak_rss_bytes, std::uint64_t peak_anon_bytes);
std::vector<std::string> joined(std::vector<std::string> a, const std::vector<std::string>& b);

}  // namespace oocsimp_cli
