#include "parts/distributed_run.hpp"

#include <dirent.h>

#include <algorithm>
#include <cstdio>
#include <cstdlib>
#include <map>
#include <sstream>

#include "cluster/uniform_cells.hpp"
#include "oocsimp/error.hpp"

namespace oocsimp {

std::string part_options_text(const RunPlan& plan) {
  std::string attributes;
  switch (plan.attributes.mode) {
    case AttributeSelection::Mode::all:
      attributes = "all";
      break;
    case AttributeSelection::Mode::none:
      attributes = "none";
      break;
    case AttributeSelection::Mode::named:
      for (const std::string& n : plan.attributes.names) attributes += (attributes.empty() ? "" : ",") + n;
      break;
  }
  const TargetOptions& t = plan.target;
  const CurvatureClusterOptions& c = plan.curvature;
  return std::string("method ") + method_name(plan.method) + " target " + std::to_string(t.triangles) + " ratio " +
         part_hex_double(t.ratio) + " max_error " + part_hex_double(t.max_error) + " weld " +
         std::to_string(int(plan.weld)) + " precision " + std::to_string(int(plan.precision)) + " attributes " +
         attributes + " cells " + std::to_string(int(plan.floating.cell_shape)) + " " +
         std::to_string(int(plan.floating.assign)) + " " + std::to_string(int(plan.floating.representative)) +
         " curvature " + part_hex_double(c.radius) + " " + std::to_string(int(c.sphere_neighbourhood)) + " " +
         part_hex_double(c.tolerance) + " " + std::to_string(c.max_depth) + " " +
         std::to_string(int(c.representative)) + " refine " + std::to_string(int(t.refine)) + " " +
         part_hex_double(t.intermediate_factor);
}

bool read_part_options(const std::string& text, SimplifyOptions* options) {
  std::istringstream s(text);
  std::string method_key, method, target_key, ratio_key, ratio, error_key, error, weld_key, precision_key,
      attributes_key, attributes, cells_key, curvature_key, radius, tolerance, refine_key, factor;
  std::uint64_t target = 0;
  int weld = -1, precision = -1, shape = -1, assign = -1, representative = -1, sphere = -1, depth = -1,
      curvature_representative = -1, refine = -1;
  s >> method_key >> method >> target_key >> target >> ratio_key >> ratio >> error_key >> error >> weld_key >> weld >>
      precision_key >> precision >> attributes_key >> attributes >> cells_key >> shape >> assign >> representative >>
      curvature_key >> radius >> sphere >> tolerance >> depth >> curvature_representative >> refine_key >> refine >>
      factor;
  if (s.fail() || method_key != "method" ||
      (method != "uniform" && method != "qem" && method != "floating" && method != "curvature") ||
      curvature_key != "curvature" || refine_key != "refine" || refine < 0 || refine > int(RefineMethod::none) ||
      sphere < 0 || sphere > 1 || depth < 0 || curvature_representative < 0 ||
      curvature_representative > int(RepresentativeRule::vertex) || cells_key != "cells" || shape < 0 ||
      shape > int(CellShape::sphere) || assign < 0 || assign > int(AssignRule::heaviest) || representative < 0 ||
      representative > int(RepresentativeRule::vertex) || target_key != "target" || ratio_key != "ratio" ||
      error_key != "max_error" || weld_key != "weld" || weld < 0 || weld > 1 || precision_key != "precision" ||
      precision < 0 || precision > int(Precision::float64) || attributes_key != "attributes")
    return false;
  options->method = method == "qem"         ? ClusterMethod::qem
                    : method == "floating"  ? ClusterMethod::floating
                    : method == "curvature" ? ClusterMethod::curvature
                                            : ClusterMethod::uniform;
  options->curvature.radius = std::strtod(radius.c_str(), nullptr);
  options->curvature.sphere_neighbourhood = sphere == 1;
  options->curvature.tolerance = std::strtod(tolerance.c_str(), nullptr);
  options->curvature.max_depth = std::uint32_t(depth);
  options->curvature.representative = RepresentativeRule(curvature_representative);
  options->target.refine = RefineMethod(refine);
  options->target.intermediate_factor = std::strtod(factor.c_str(), nullptr);
  options->floating.cell_shape = CellShape(shape);
  options->floating.assign = AssignRule(assign);
  options->floating.representative = RepresentativeRule(representative);
  options->target.triangles = target;
  options->target.ratio = std::strtod(ratio.c_str(), nullptr);
  options->target.max_error = std::strtod(error.c_str(), nullptr);
  options->weld = weld == 1;
  options->precision = Precision(precision);
  options->attributes = parse_attribute_selection(attributes);
  return true;
}

void run_uniform_part(MeshInput& input, const RunPlan& plan, const PartManifest& manifest, const std::string& dir,
                      SimplifyStats* stats) {
  PartWriter writer(dir, manifest);
  UniformCells cells(manifest.grid, input.attributes);
  ChunkPart part;
  part.part = manifest.part;
  part.parts = manifest.parts;
  std::uint64_t triangles = 0;
  part.vertices = [&](std::uint64_t chunk, const VertexChunkSums& sums) { writer.vertices(chunk, sums); };
  part.faces = [&](std::uint64_t chunk, const FaceChunkSums& sums) {
    triangles += sums.triangles;
    writer.faces(chunk, sums);
  };
  const auto [vertex_chunks, face_chunks] = cells.sum_part(input, part, plan.progress);
  writer.commit(vertex_chunks, face_chunks, input.triangles->skipped());
  if (stats) {
    stats->input_triangles = triangles;  // the part's own
    stats->skipped = input.triangles->skipped();
  }
}

void run_qem_part(MeshInput& input, const RunPlan& plan, const PartManifest& manifest, const std::string& dir,
                  SimplifyStats* stats) {
  PartWriter writer(dir, manifest);
  FirstPassPlan first_pass;
  const bool spread = simplify_to_target_part(
      input, plan, manifest.part, manifest.parts, [&](const TileOutput& tile) { writer.tile(tile); }, &first_pass);
  if (spread) writer.plan(first_pass);
  writer.commit(0, 0, first_pass.skipped);
  if (stats) {
    // A run with no pass to spread reads the input's count from its header.
    stats->input_triangles = spread ? first_pass.input_triangles : input.info.face_count;
    stats->skipped = first_pass.skipped;
    stats->refine.collapses = first_pass.collapses;  // the part's own
  }
}

void run_floating_part(MeshInput& input, const RunPlan& plan, const PartManifest& manifest, const PartChannel& channel,
                       const std::string& dir, SimplifyStats* stats) {
  PartWriter writer(dir, manifest);
  FloatingPartPlan tiling;
  const AttributeLayout layout(input.attributes);
  cluster_floating_part(
      input, plan, manifest.grid, manifest.part, manifest.parts, channel,
      [&](ShareKind kind, const void* records, std::size_t count) {
        writer.shares(kind, records, count * share_record_bytes(kind, layout));
      },
      &tiling, stats);
  writer.floating_plan(tiling);
  writer.commit(0, 0, tiling.skipped);
}

void run_curvature_part(MeshInput& input, const RunPlan& plan, const PartManifest& manifest, const std::string& dir,
                        SimplifyStats* stats) {
  PartWriter writer(dir, manifest);
  constexpr std::size_t kRunValues = 1 << 16;  // values per record
  std::vector<VertexCurvatureValue> run;
  run.reserve(kRunValues);
  const CurvaturePartPlan estimate = estimate_curvature_part(
      input, plan, manifest.part, manifest.parts,
      [&](const std::uint64_t* vertices, const float* k1, const float* k2, std::size_t n) {
        for (std::size_t i = 0; i < n; ++i) {
          run.push_back({std::uint32_t(vertices[i]), k1[i], k2[i]});
          if (run.size() == kRunValues) {
            writer.curvatures(run);
            run.clear();
          }
        }
      },
      stats);
  if (!run.empty()) writer.curvatures(run);
  writer.curvature_plan(estimate);
  writer.commit(0, 0, input.triangles->skipped());
  if (stats) {
    stats->input_triangles = estimate.triangles;
    stats->skipped = input.triangles->skipped();
  }
}

void run_clustering_part(MeshInput& input, const RunPlan& plan, PartManifest manifest, const PartChannel& channel,
                         const std::string& dir, SimplifyStats* stats) {
  if (plan.target.given()) {
    if (!target_clustering_grid(input, plan, &manifest.grid)) {
      manifest.grid = GridSpec();
      manifest.grid.cell = 0;  // nothing clustered: the merge runs the target whole
      PartWriter(dir, manifest).commit(0, 0, SkippedFaces());
      if (stats) stats->input_triangles = input.info.face_count;
      return;
    }
    input.restart_triangles();
  }
  switch (plan.method) {
    case ClusterMethod::floating:
      run_floating_part(input, plan, manifest, channel, dir, stats);
      break;
    case ClusterMethod::curvature:
      run_curvature_part(input, plan, manifest, dir, stats);
      break;
    default:
      run_uniform_part(input, plan, manifest, dir, stats);
  }
}

namespace {

// The part files of `dir` by part count, then part number.
std::map<std::uint32_t, std::map<std::uint32_t, std::string>> list_part_files(const std::string& dir) {
  std::map<std::uint32_t, std::map<std::uint32_t, std::string>> found;
  DIR* d = ::opendir(dir.c_str());
  if (!d) throw InputError(dir + ": cannot open the work folder");
  while (const dirent* e = ::readdir(d)) {
    unsigned part = 0, parts = 0;
    char tail[16] = "";
    if (std::sscanf(e->d_name, "part-%u-of-%u.%15s", &part, &parts, tail) == 3 && std::string(tail) == "oocpart" &&
        e->d_name == part_file_name(part, parts))
      found[parts][part] = dir + "/" + e->d_name;
  }
  ::closedir(d);
  return found;
}

// What differs between two manifests of one run, or "" when nothing does.
std::string manifest_difference(const PartManifest& a, const PartManifest& b) {
  if (a.input != b.input) return "its input is " + b.input + ", not " + a.input;
  if (a.key != b.key) return "its input " + b.input + " was another file or another version of it";
  if (a.options != b.options) return "its options are \"" + b.options + "\", not \"" + a.options + "\"";
  const GridSpec &g = a.grid, &h = b.grid;
  if (g.origin.x != h.origin.x || g.origin.y != h.origin.y || g.origin.z != h.origin.z || g.cell != h.cell ||
      g.dims[0] != h.dims[0] || g.dims[1] != h.dims[1] || g.dims[2] != h.dims[2])
    return "it chose another grid (other sizing options, or, with a target, another --mem)";
  return "";
}

}  // namespace

PartSet::PartSet(const std::string& dir) : dir_(dir) {
  const auto found = list_part_files(dir);
  if (found.empty())
    throw InputError(dir +
                     ": no part files (part-I-of-K.oocpart): run oocsimp simplify IN -o OUT --part I/K "
                     "--work-dir " +
                     dir + " for each part first");
  if (found.size() > 1) {
    const auto& a = *found.begin();
    const auto& b = *std::next(found.begin());
    throw InputError(dir + ": part files of runs in " + std::to_string(a.first) + " and " + std::to_string(b.first) +
                     " parts (" + a.second.begin()->second + ", " + b.second.begin()->second +
                     "): remove the stale ones");
  }
  const std::uint32_t count = found.begin()->first;
  const auto& files = found.begin()->second;
  for (std::uint32_t i = 0; i < count; ++i) {
    const auto it = files.find(i);
    if (it == files.end())
      throw InputError(dir + "/" + part_file_name(i, count) + ": part " + std::to_string(i) + " of " +
                       std::to_string(count) + " is missing: run it (--part " + std::to_string(i) + "/" +
                       std::to_string(count) + "), then merge again");
    parts_.push_back(std::make_unique<PartReader>(it->second));
    const PartManifest& m = parts_.back()->manifest();
    if (m.part != i || m.parts != count)
      throw InputError(it->second + ": byte 12: it says it is part " + std::to_string(m.part) + " of " +
                       std::to_string(m.parts));
    if (m.build != part_file_build())
      throw InputError(it->second + ": stale: it was written by another build (" + m.build + "), not this one (" +
                       part_file_build() + "): run the part again with the merge's oocsimp");
    const std::string difference = i == 0 ? "" : manifest_difference(parts_[0]->manifest(), m);
    if (!difference.empty())
      throw InputError(it->second + ": stale: " + difference + " (as " + parts_[0]->path() +
                       " says): run the part again, then merge");
    if (parts_.back()->vertex_chunks() != parts_[0]->vertex_chunks() ||
        parts_.back()->face_chunks() != parts_[0]->face_chunks())
      throw InputError(it->second + ": stale: it read another number of chunks than " + parts_[0]->path());
  }
  const PartManifest& m = manifest();
  if (input_key(m.input) != m.key)
    throw InputError(m.input + ": the input changed since the parts read it: run them again, then merge");
}

bool PartSet::has_first_pass() const {
  for (const std::unique_ptr<PartReader>& part : parts_)
    if (part->has_plan() != parts_[0]->has_plan())
      throw InputError(part->path() + ": stale: it " + (part->has_plan() ? "holds" : "holds no") +
                       " first pass of the collapse, where " + parts_[0]->path() +
                       (part->has_plan() ? " holds none" : " does") + ": run the part again, then merge");
  return parts_[0]->has_plan();
}

FirstPassParts PartSet::first_pass(std::size_t attributes) const {
  FirstPassParts out;
  FirstPassPlan& sum = out.plan;
  for (const std::unique_ptr<PartReader>& part : parts_) {
    const FirstPassPlan p = part->plan();
    if (&part == &parts_[0]) {
      sum = p;
      continue;
    }
    if (p.input_triangles != sum.input_triangles || p.tiles != sum.tiles || p.side != sum.side ||
        p.threshold != sum.threshold || p.skipped.total() != sum.skipped.total())
      throw InputError(part->path() + ": stale: its first pass was planned otherwise than " + parts_[0]->path() +
                       "'s (another build?): run the part again, then merge");
    sum.collapses += p.collapses;
    sum.largest_cost = std::max(sum.largest_cost, p.largest_cost);
    sum.largest_error = std::max(sum.largest_error, p.largest_error);
  }
  out.tiles = [this, attributes](const TileOutputSink& sink) {
    for (const std::unique_ptr<PartReader>& part : parts_) part->tiles(attributes, sink);
  };
  return out;
}

bool PartSet::has_floating() const {
  for (const std::unique_ptr<PartReader>& part : parts_)
    if (!part->has_floating_plan())
      throw InputError(part->path() +
                       ": stale: it holds no cluster shares of floating cells: run the part again, "
                       "then merge");
  return true;
}

FloatingPartPlan PartSet::floating_plan() const {
  has_floating();
  const FloatingPartPlan plan = parts_[0]->floating_plan();
  for (const std::unique_ptr<PartReader>& part : parts_) {
    const FloatingPartPlan p = part->floating_plan();
    if (p.tile_side != plan.tile_side || p.tiles != plan.tiles || p.triangles != plan.triangles ||
        p.vertices != plan.vertices || p.skipped.total() != plan.skipped.total())
      throw InputError(part->path() + ": stale: it tiled the input otherwise than " + parts_[0]->path() +
                       " (another --mem?): give every part the same --mem, run it again, then merge");
  }
  return plan;
}

ClusterShareSource PartSet::floating_shares(const AttributeLayout& layout) const {
  return [this, layout](const ClusterShareSink& sink) {
    for (const std::unique_ptr<PartReader>& part : parts_) part->shares(sink, layout);
  };
}

CurvaturePartPlan PartSet::curvature_plan() const {
  CurvaturePartPlan sum;
  for (const std::unique_ptr<PartReader>& part : parts_) {
    if (!part->has_curvature_plan())
      throw InputError(part->path() + ": stale: it holds no curvature values: run the part again, then merge");
    const CurvaturePartPlan p = part->curvature_plan();
    if (&part == &parts_[0]) {
      sum = p;
      continue;
    }
    if (p.vertices != sum.vertices || p.triangles != sum.triangles || p.radius != sum.radius ||
        p.estimated != sum.estimated)
      throw InputError(part->path() + ": stale: its curvature estimate was planned otherwise than " +
                       parts_[0]->path() + "'s: run the part again, then merge");
    sum.invariant += p.invariant;
    sum.fitted += p.fitted;
  }
  if (sum.invariant + sum.fitted > sum.vertices)
    throw InputError(parts_.back()->path() + ": stale: the parts estimated more vertices than the input has");
  return sum;
}

CurvatureFill PartSet::curvatures(std::uint64_t vertices) const {
  return [this, vertices](float* k) {
    const CurvaturePartPlan plan = curvature_plan();
    if (plan.vertices != vertices)
      throw InputError(parts_[0]->path() + ": stale: its curvature values are of " + std::to_string(plan.vertices) +
                       " vertices; the input has " + std::to_string(vertices) + ": run the parts again, then merge");
    CurvatureStats st;
    st.vertices = plan.vertices;
    st.triangles = plan.triangles;
    st.radius = plan.radius;
    st.invariant = plan.invariant;
    st.fitted = plan.fitted;
    st.none = plan.vertices - plan.invariant - plan.fitted;
    for (const std::unique_ptr<PartReader>& part : parts_) part->curvatures(plan.vertices, k);
    return st;
  };
}

MergedPhaseOne PartSet::clustering(MeshInput& input, const RunPlan& plan) const {
  return [this, &input, plan](const GridSpec& grid, SimplifyStats* stats, std::vector<Quadric>* quadrics) {
    switch (plan.method) {
      case ClusterMethod::floating:
        return merge_floating_shares(input, plan, grid, floating_plan(),
                                     floating_shares(AttributeLayout(input.attributes)), stats, quadrics);
      case ClusterMethod::curvature:
        curvature_plan();  // a stale part is named before any work
        return merge_curvature_parts(input, plan, grid, curvatures(input.positions.count), stats, quadrics);
      default:
        return merge_uniform_chunks(input, plan, grid, chunks(), stats, quadrics);
    }
  };
}

UniformChunkSource PartSet::chunks() const {
  UniformChunkSource s;
  s.vertex_chunks = parts_[0]->vertex_chunks();
  s.face_chunks = parts_[0]->face_chunks();
  s.skipped = parts_[0]->skipped();
  const std::uint64_t count = parts_.size();
  s.vertices = [this, count](std::uint64_t j, VertexChunkSums* out) { parts_[j % count]->vertices(j, out); };
  s.faces = [this, count](std::uint64_t j, FaceChunkSums* out) { parts_[j % count]->faces(j, out); };
  return s;
}

}  // namespace oocsimp
