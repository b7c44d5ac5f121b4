// Low & Tan 1997 §4: the level of detail for a viewing distance, from OUT.lods.json.
// The JSON is read through nlohmann::json (Debian's nlohmann-json3-dev): a well-kept
// parser beats a hand-written one on hostile files.
#include <nlohmann/json.hpp>

#include <cmath>
#include <fstream>
#include <sstream>

#include "common/math_constants.hpp"
#include "io/temp_file.hpp"
#include "oocsimp/error.hpp"
#include "oocsimp/lod.hpp"

namespace oocsimp {

namespace {

[[noreturn]] void bad(const std::string& path, const std::string& what) { throw InputError(path + ": " + what); }

std::uint64_t count(const nlohmann::json& level, const char* key, const std::string& path, std::size_t i) {
  if (!level.contains(key)) return 0;
  const nlohmann::json& v = level[key];
  if (!v.is_number_unsigned()) bad(path, "levels[" + std::to_string(i) + "]." + key + " is not a whole number");
  return v.get<std::uint64_t>();
}

}  // namespace

std::vector<LodLevel> read_lod_levels(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in) throw IoError(path + ": cannot be read");
  std::stringstream text;
  text << in.rdbuf();
  nlohmann::json doc;
  try {
    doc = nlohmann::json::parse(text.str());
  } catch (const nlohmann::json::parse_error& e) {
    bad(path, "not JSON at byte " + std::to_string(e.byte));
  }
  if (!doc.is_object() || !doc.contains("levels") || !doc["levels"].is_array())
    bad(path, "no \"levels\" array (a simplify --lods description is expected)");
  std::vector<LodLevel> levels;
  for (std::size_t i = 0; i < doc["levels"].size(); ++i) {
    const nlohmann::json& l = doc["levels"][i];
    const std::string at = "levels[" + std::to_string(i) + "]";
    if (!l.is_object()) bad(path, at + " is not an object");
    if (!l.contains("file") || !l["file"].is_string()) bad(path, at + ".file is missing or not a string");
    if (!l.contains("cell") || !l["cell"].is_number() || !(l["cell"].get<double>() > 0) ||
        !std::isfinite(l["cell"].get<double>()))
      bad(path, at + ".cell is missing or not a positive number");
    LodLevel level;
    level.file = l["file"].get<std::string>();
    level.cell = l["cell"].get<double>();
    level.vertices = count(l, "vertices", path, i);
    level.triangles = count(l, "triangles", path, i);
    level.edges = count(l, "edges", path, i);
    level.points = count(l, "points", path, i);
    if (!levels.empty() && !(level.cell > levels.back().cell))
      bad(path, at + ".cell is not coarser than the level before it");
    levels.push_back(level);
  }
  if (levels.empty()) bad(path, "\"levels\" is empty");
  return levels;
}

std::string lod_levels_json(const std::vector<LodLevel>& levels) {
  nlohmann::ordered_json doc;
  doc["levels"] = nlohmann::ordered_json::array();
  for (const LodLevel& l : levels) {
    nlohmann::ordered_json j;
    j["file"] = l.file;
    j["cell"] = l.cell;
    j["vertices"] = l.vertices;
    j["triangles"] = l.triangles;
    j["edges"] = l.edges;
    j["points"] = l.points;
    j["seconds"] = l.seconds;
    nlohmann::ordered_json phases = nlohmann::ordered_json::object();
    for (const auto& [name, seconds] : l.phases) phases[name] = seconds;
    j["phases"] = phases;
    if (l.rms >= 0) j["rms"] = l.rms;
    if (l.hausdorff >= 0) j["hausdorff"] = l.hausdorff;
    doc["levels"].push_back(j);
  }
  return doc.dump(2) + "\n";
}

void write_lod_levels(const std::string& path, const std::vector<LodLevel>& levels) {
  OutputFile out(path);
  out.write_all(lod_levels_json(levels));
  out.commit();
}

double pixel_size_at(double distance, double fov_degrees, double height_pixels) {
  if (!(distance > 0) || !std::isfinite(distance)) throw UsageError("the distance must be a positive number");
  if (!(fov_degrees > 0 && fov_degrees < 180))
    throw UsageError("the field of view must be above 0 and below 180 degrees");
  if (!(height_pixels >= 1) || !std::isfinite(height_pixels)) throw UsageError("the height must be at least 1 pixel");
  return 2 * distance * std::tan(fov_degrees * kPi / 360) / height_pixels;
}

std::string lod_choice_json(const std::vector<LodLevel>& levels, const LodChoice& c, double pixel, double factor) {
  const LodLevel& l = levels.at(c.level);
  nlohmann::ordered_json j;
  j["level"] = c.level;
  j["file"] = l.file;
  j["cell"] = l.cell;
  j["pixel_size"] = pixel;
  j["factor"] = factor;
  j["thick_line_pixels_per_unit"] = 1 / pixel;
  j["finest_too_coarse"] = c.finest_too_coarse;
  return j.dump();
}

LodChoice choose_lod(const std::vector<LodLevel>& levels, double pixel, double factor) {
  if (!(factor >= 1) || !std::isfinite(factor)) throw UsageError("the factor must be a number of at least 1");
  LodChoice c;
  const double largest = factor * pixel;
  c.finest_too_coarse = levels.empty() || levels.front().cell > largest;
  for (std::size_t i = 0; i < levels.size(); ++i)
    if (levels[i].cell <= largest) c.level = i;  // the cells grow with the level
  return c;
}

}  // namespace oocsimp
