// The software rasteriser behind `oocsimp render`: an orthographic camera framing the
// model's projected outline, a depth buffer, triangles streamed from the file and drawn in file
// order (so ties in depth go to the earlier triangle, the same for every run).
#include <algorithm>
#include <cmath>
#include <string>
#include <vector>

#include "common/math_constants.hpp"
#include "common/vec3_math.hpp"
#include "io/attribute_array.hpp"
#include "oocsimp/error.hpp"
#include "render/legend.hpp"
#include "render/rasterizer.hpp"
#include "runtime/progress_phase.hpp"

namespace oocsimp {

namespace {

constexpr double kFraming = 1.05;  // the image's extent over the outline's, along the side it fills
// A surface faces one way when its area-weighted normals sum to at least this share of
// its area (a closed surface's sum to 0, a plane's to 1).
constexpr double kFacingShare = 0.1;
// A closed surface's base: faces whose centroid lies within this share of the box's
// extent from one of its sides and whose normal is within 25 degrees of that side's
// outward direction. The base decides when it holds at least kBaseShare of the area
// and kBaseMargin times the base of any other axis: the scans' bases pass both by a
// wide margin and a sphere's sides fail the second (docs/cli.md, render, has the
// shares measured).
constexpr double kBaseDepth = 0.02, kBaseCosine = 0.9063, kBaseShare = 0.005, kBaseMargin = 2.0;

// The view: screen axes `right` and `up` and the direction `towards` the camera, all
// unit, and the model point at the image's centre.
struct Camera {
  Vec3d right, up, towards, centre;
  double pixel = 1;               // model units per pixel
  double half_w = 0, half_h = 0;  // the image's half size in pixels

  // The axes only; frame() places the model.
  explicit Camera(const RenderOptions& o) {
    const double az = o.azimuth_degrees * kPi / 180, el = o.elevation_degrees * kPi / 180;
    // The up axis U and the two across it, A (azimuth 0) and B, with A x B = U.
    const Vec3d x{1, 0, 0}, y{0, 1, 0}, z{0, 0, 1};
    const Vec3d U = o.up == UpAxis::z ? z : o.up == UpAxis::y ? y : x;
    const Vec3d A = o.up == UpAxis::z ? x : o.up == UpAxis::y ? z : y;
    const Vec3d B = cross(U, A);
    const Vec3d across = A * std::cos(az) + B * std::sin(az);
    towards = across * std::cos(el) + U * std::sin(el);
    // U is up on the screen, unless the camera looks along it: then away from the camera's azimuth.
    const Vec3d world_up = std::fabs(dot(towards, U)) > 0.999 ? across * -1.0 : U;
    right = cross(world_up, towards);
    right = right / length(right);
    up = cross(towards, right);
    half_w = 0.5 * o.width;
    half_h = 0.5 * o.height;
  }

  // Centres the outline `outline` (screen coordinates right, up relative to the box's
  // centre, the projection of everything drawn) in the first `width` pixels of the
  // image's width and scales it to fill that or the height, whichever it meets first,
  // less the margin. A bounding sphere would leave the sides of a long or flat model
  // empty. An outline of no extent (a point, a segment seen end on) falls back to the
  // box's diagonal across the shorter side.
  void frame(const Box3d& box, const Box3d& outline, double width, double height) {
    const Vec3d box_centre = box.empty() ? Vec3d{} : (box.min + box.max) * 0.5;
    const double diameter = box.empty() ? 0 : length(box.max - box.min);
    centre = box_centre;
    half_w = 0.5 * width;
    pixel = 0;
    if (!outline.empty()) {
      centre =
          box_centre + right * (0.5 * (outline.min.x + outline.max.x)) + up * (0.5 * (outline.min.y + outline.max.y));
      pixel = kFraming * std::max((outline.max.x - outline.min.x) / width, (outline.max.y - outline.min.y) / height);
    }
    if (!(pixel > 0) || !std::isfinite(pixel)) pixel = diameter > 0 ? kFraming * diameter / std::min(width, height) : 1;
  }

  // Screen coordinates of p relative to `origin`: x right, y up, z towards the camera.
  Vec3d screen(const Vec3d& p, const Vec3d& origin) const {
    const Vec3d d = p - origin;
    return {dot(d, right), dot(d, up), dot(d, towards)};
  }

  // Pixel coordinates (x right, y down, pixel centres at .5) and depth (larger: nearer).
  Vec3d project(const Vec3d& p) const {
    const Vec3d d = p - centre;
    return {half_w + dot(d, right) / pixel, half_h - dot(d, up) / pixel, dot(d, towards)};
  }
};

// The outline of everything render_mesh draws, in the camera's screen coordinates
// relative to the box's centre (x, y; z unused): every finite vertex (one pass over the
// positions), and with thick edges the widths of the lines and discs, which reach past
// their vertices (one more pass over the stream, for their thicknesses).
Box3d projected_outline(MeshInput& input, const Camera& camera, bool thick_edges) {
  const Box3d& box = input.info.bounds;
  Box3d outline;
  if (box.empty()) return outline;
  const Vec3d origin = (box.min + box.max) * 0.5;
  for (std::uint64_t i = 0; i < input.positions.count; ++i) {
    const Vec3d p = input.positions.get(i);
    if (!is_finite(p)) continue;
    const Vec3d s = camera.screen(p, origin);
    outline.add(Vec3d{s.x, s.y, 0});
  }
  if (!thick_edges) return outline;
  const auto reach = [&](std::uint64_t v, double radius) {
    const Vec3d p = input.positions.get(v);
    if (!is_finite(p) || !(radius > 0) || !std::isfinite(radius)) return;
    const Vec3d s = camera.screen(p, origin);
    outline.add(Vec3d{s.x - radius, s.y - radius, 0});
    outline.add(Vec3d{s.x + radius, s.y + radius, 0});
  };
  input.restart_triangles();
  input.triangles->set_primitive_sink([&](const LinePrimitive* p, std::size_t n) {
    for (std::size_t k = 0; k < n; ++k) {
      reach(p[k].a, 0.5 * double(p[k].thickness));
      reach(p[k].b, 0.5 * double(p[k].thickness));
    }
  });
  constexpr std::size_t kChunk = 65536;
  std::vector<std::uint64_t> chunk(3 * kChunk);
  while (input.triangles->read(chunk.data(), kChunk) > 0) {
  }
  input.triangles->set_primitive_sink(nullptr);
  input.restart_triangles();
  return outline;
}

// The smooth-shading normals: the input's nx, ny, nz attributes, when it has them.
struct VertexNormals {
  int index[3] = {-1, -1, -1};
  bool present() const { return index[0] >= 0 && index[1] >= 0 && index[2] >= 0; }
  explicit VertexNormals(const AttributeArray& a) {
    const char* names[3] = {"nx", "ny", "nz"};
    for (std::size_t i = 0; i < a.size(); ++i)
      for (int k = 0; k < 3; ++k)
        if (a.attributes[i].name == names[k]) index[k] = int(i);
  }
  Vec3d get(const AttributeArray& a, std::uint64_t v) const {
    return {attribute_value(a, v, std::size_t(index[0])), attribute_value(a, v, std::size_t(index[1])),
            attribute_value(a, v, std::size_t(index[2]))};
  }
};

// The vertex colours red, green, blue of a mesh coloured by its error: integer values
// as they are (0 to 255), real ones scaled from [0, 1].
struct VertexColours {
  int index[3] = {-1, -1, -1};
  double scale[3] = {1, 1, 1};
  bool present() const { return index[0] >= 0 && index[1] >= 0 && index[2] >= 0; }
  explicit VertexColours(const AttributeArray& a) {
    const char* names[3] = {"red", "green", "blue"};
    for (std::size_t i = 0; i < a.size(); ++i)
      for (int k = 0; k < 3; ++k)
        if (a.attributes[i].name == names[k]) {
          index[k] = int(i);
          scale[k] = is_integer_type(a.attributes[i].type) ? 1.0 : 255.0;
        }
  }
  void get(const AttributeArray& a, std::uint64_t v, float out[3]) const {
    for (int k = 0; k < 3; ++k)
      out[k] = float(std::clamp(attribute_value(a, v, std::size_t(index[k])) * scale[k], 0.0, 255.0));
  }
};

class Rasterizer {
 public:
  // With `coloured`, each pixel keeps the colour its triangle interpolates from its
  // corners' colours, instead of the one surface colour.
  Rasterizer(const RenderOptions& o, bool coloured)
      : o_(o),
        depth_(std::size_t(o.width) * o.height, -HUGE_VAL),
        shade_(std::size_t(o.width) * o.height, -1.0f),
        colour_(coloured ? 3 * std::size_t(o.width) * o.height : 0, 0.0f) {}

  // Draws the triangle with pixel-space corners s[3]; `light` gives the shading
  // (|cos| of the normal against the view) at each corner; `colour` (3 per corner, 0
  // to 255) the colours of a coloured rasteriser.
  void draw(const Vec3d s[3], const double light[3], const float* colour = nullptr) {
    const double area = (s[1].x - s[0].x) * (s[2].y - s[0].y) - (s[2].x - s[0].x) * (s[1].y - s[0].y);
    if (!(std::fabs(area) > 0)) return;  // degenerate, or not finite
    const double w = o_.width, h = o_.height;
    const double lo_x = std::max(0.0, std::floor(std::min({s[0].x, s[1].x, s[2].x}) - 0.5));
    const double hi_x = std::min(w - 1, std::ceil(std::max({s[0].x, s[1].x, s[2].x}) - 0.5));
    const double lo_y = std::max(0.0, std::floor(std::min({s[0].y, s[1].y, s[2].y}) - 0.5));
    const double hi_y = std::min(h - 1, std::ceil(std::max({s[0].y, s[1].y, s[2].y}) - 0.5));
    if (!(lo_x <= hi_x && lo_y <= hi_y)) return;  // off the image
    const double sign = area > 0 ? 1 : -1;
    for (std::uint32_t y = std::uint32_t(lo_y); y <= std::uint32_t(hi_y); ++y) {
      const double py = y + 0.5;
      for (std::uint32_t x = std::uint32_t(lo_x); x <= std::uint32_t(hi_x); ++x) {
        const double px = x + 0.5;
        // Barycentric weights by edge functions; a pixel centre on an edge belongs to
        // the triangle on the edge's left or top (the top-left rule), so that two
        // triangles sharing an edge cover each pixel once.
        double b[3];
        bool inside = true;
        for (int k = 0; k < 3 && inside; ++k) {
          const Vec3d& p = s[(k + 1) % 3];
          const Vec3d& q = s[(k + 2) % 3];
          const double e = sign * ((q.x - p.x) * (py - p.y) - (q.y - p.y) * (px - p.x));
          const double dx = sign * (q.x - p.x), dy = sign * (q.y - p.y);
          const bool top_left = (dy < 0) || (dy == 0 && dx > 0);
          inside = e > 0 || (e == 0 && top_left);
          b[k] = e;
        }
        if (!inside) continue;
        const double total = b[0] + b[1] + b[2];
        const double z = (b[0] * s[0].z + b[1] * s[1].z + b[2] * s[2].z) / total;
        const std::size_t at = std::size_t(y) * o_.width + x;
        if (!(z > depth_[at])) continue;
        depth_[at] = z;
        shade_[at] = float((b[0] * light[0] + b[1] * light[1] + b[2] * light[2]) / total);
        if (colour && !colour_.empty())
          for (int k = 0; k < 3; ++k)
            colour_[3 * at + std::size_t(k)] =
                float((b[0] * colour[k] + b[1] * colour[3 + k] + b[2] * colour[6 + k]) / total);
      }
    }
  }

  // Draws the capsule of half width `half` pixels around the segment s0 s1 (pixel
  // space, depth in z): a cylinder of radius `radius` (model units) seen from the side,
  // lit by `light` (the dynamic normal's cosine) times that of the turn across its
  // width. With s0 = s1 it is a sphere's disc, lit by its own normals.
  void draw_capsule(const Vec3d& s0, const Vec3d& s1, double half, double radius, double light) {
    if (!is_finite(s0) || !is_finite(s1) || !std::isfinite(half) || !std::isfinite(radius)) return;
    const double w = o_.width, h = o_.height;
    const double lo_x = std::max(0.0, std::floor(std::min(s0.x, s1.x) - half - 0.5));
    const double hi_x = std::min(w - 1, std::ceil(std::max(s0.x, s1.x) + half - 0.5));
    const double lo_y = std::max(0.0, std::floor(std::min(s0.y, s1.y) - half - 0.5));
    const double hi_y = std::min(h - 1, std::ceil(std::max(s0.y, s1.y) + half - 0.5));
    if (!(lo_x <= hi_x && lo_y <= hi_y)) return;  // off the image
    const double dx = s1.x - s0.x, dy = s1.y - s0.y, len2 = dx * dx + dy * dy;
    for (std::uint32_t y = std::uint32_t(lo_y); y <= std::uint32_t(hi_y); ++y)
      for (std::uint32_t x = std::uint32_t(lo_x); x <= std::uint32_t(hi_x); ++x) {
        const double px = x + 0.5 - s0.x, py = y + 0.5 - s0.y;
        const double t = len2 > 0 ? std::clamp((px * dx + py * dy) / len2, 0.0, 1.0) : 0.0;
        const double ex = px - t * dx, ey = py - t * dy;
        const double off2 = (ex * ex + ey * ey) / (half * half);
        if (off2 > 1) continue;
        const double across = std::sqrt(1 - off2);  // cos of the turn away from the view
        const double z = s0.z + t * (s1.z - s0.z) + radius * across;
        const std::size_t at = std::size_t(y) * o_.width + x;
        if (!(z > depth_[at])) continue;
        depth_[at] = z;
        shade_[at] = float(light * across);
      }
  }

  Image image(std::uint64_t* covered) const {
    Image out;
    out.width = o_.width;
    out.height = o_.height;
    out.rgb.resize(std::size_t(o_.width) * o_.height * 3);
    *covered = 0;
    for (std::size_t i = 0; i < shade_.size(); ++i) {
      const std::uint32_t c = shade_[i] < 0 ? o_.background : o_.surface;
      const double f = shade_[i] < 0 ? 1.0 : 0.2 + 0.8 * std::clamp(double(shade_[i]), 0.0, 1.0);
      // Colours keep more of their own light, so that the ramp still reads on faces
      // turned away.
      const bool coloured = !colour_.empty() && shade_[i] >= 0;
      const double g = 0.5 + 0.5 * std::clamp(double(shade_[i]), 0.0, 1.0);
      *covered += shade_[i] >= 0;
      for (int k = 0; k < 3; ++k) {
        const double channel =
            coloured ? double(colour_[3 * i + std::size_t(k)]) * g : double((c >> (16 - 8 * k)) & 0xFF) * f;
        out.rgb[3 * i + std::size_t(k)] = std::uint8_t(std::lround(std::clamp(channel, 0.0, 255.0)));
      }
    }
    return out;
  }

 private:
  const RenderOptions& o_;
  std::vector<double> depth_;
  std::vector<float> shade_;   // -1: background
  std::vector<float> colour_;  // 3 per pixel, when coloured
};

void check_size(const RenderOptions& o) {
  constexpr std::uint32_t kLargest = 16384;
  if (o.width < 1 || o.height < 1 || o.width > kLargest || o.height > kLargest)
    throw UsageError("options.width",
                     "options.width and options.height must be 1 to " + std::to_string(kLargest) + " pixels");
  if (!std::isfinite(o.azimuth_degrees) || !std::isfinite(o.elevation_degrees))
    throw UsageError("options.azimuth_degrees", "options.azimuth_degrees and options.elevation_degrees must be finite");
}

}  // namespace

UpAxis choose_up_axis(MeshInput& input) {
  const Box3d& box = input.info.bounds;
  // Without a sign from the surface: glTF's frame is y-up (glTF 2.0 §3.4), the rest z.
  const UpAxis fallback = input.info.format == "glb" ? UpAxis::y : UpAxis::z;
  if (box.empty()) return fallback;
  // Twice the area-weighted normal, summed; twice the area; and twice the area of each
  // of the box's six sides' base: faces near the side, facing out through it.
  Vec3d facing{};
  double area = 0, base[3][2] = {{0, 0}, {0, 0}, {0, 0}};
  const double lo[3] = {box.min.x, box.min.y, box.min.z}, hi[3] = {box.max.x, box.max.y, box.max.z};
  constexpr std::size_t kChunk = 65536;
  std::vector<std::uint64_t> chunk(3 * kChunk);
  input.restart_triangles();
  while (std::size_t n = input.triangles->read(chunk.data(), kChunk))
    for (std::size_t t = 0; t < n; ++t) {
      const Vec3d p[3] = {input.positions.get(chunk[3 * t]), input.positions.get(chunk[3 * t + 1]),
                          input.positions.get(chunk[3 * t + 2])};
      const Vec3d normal = cross(p[1] - p[0], p[2] - p[0]);
      const double twice_area = length(normal);
      if (!is_finite(normal) || !(twice_area > 0)) continue;
      facing += normal;
      area += twice_area;
      const Vec3d centroid = (p[0] + p[1] + p[2]) / 3.0;
      const double c[3] = {centroid.x, centroid.y, centroid.z}, u[3] = {normal.x, normal.y, normal.z};
      for (int k = 0; k < 3; ++k) {
        const double near = kBaseDepth * (hi[k] - lo[k]), cosine = u[k] / twice_area;
        if (c[k] - lo[k] <= near && -cosine >= kBaseCosine) base[k][0] += twice_area;
        if (hi[k] - c[k] <= near && cosine >= kBaseCosine) base[k][1] += twice_area;
      }
    }
  input.restart_triangles();
  if (!(area > 0)) return fallback;
  const UpAxis axes[3] = {UpAxis::x, UpAxis::y, UpAxis::z};
  // The axis with the most of `score`, when it has `margin` times any other's; else the
  // fallback.
  const auto clear_winner = [&](const double* score, double margin) {
    int best = 2;
    for (int k : {1, 0})
      if (score[k] > score[best]) best = k;
    for (int k = 0; k < 3; ++k)
      if (k != best && !(score[best] >= margin * score[k])) return fallback;
    return axes[best];
  };
  // An open surface facing one way: up where it faces up along an axis (a terrain, a
  // scan open at its base, whose missing underside leaves the sum pointing up). One
  // facing down an axis is no terrain (a facade seen from the back, a ceiling): the
  // fallback, and not the base rule, whose sides a thin sheet fills.
  if (length(facing) >= kFacingShare * area) {
    const double f[3] = {facing.x, facing.y, facing.z};
    int along = 2;
    for (int k : {1, 0})
      if (std::fabs(f[k]) > std::fabs(f[along])) along = k;
    return f[along] > 0 ? axes[along] : fallback;
  }
  // A closed (or balanced) surface: the axis of its base, a figure's soles or a scan's
  // flat underside, when it stands out.
  const double b[3] = {std::max(base[0][0], base[0][1]), std::max(base[1][0], base[1][1]),
                       std::max(base[2][0], base[2][1])};
  if (std::max({b[0], b[1], b[2]}) < kBaseShare * area) return fallback;
  return clear_winner(b, kBaseMargin);
}

Image render_mesh(MeshInput& input, const RenderOptions& options, RenderStats* stats) {
  check_size(options);
  RenderStats local;
  RenderStats& st = stats ? *stats : local;
  RenderOptions view = options;
  if (view.up == UpAxis::automatic) {
    ProgressPhase phase(options.progress, "choose up axis", 0, "B");
    view.up = choose_up_axis(input);
  }
  st.up = view.up;
  // A mesh coloured by its error (measure --error-colours) is drawn in its colours,
  // with the ramp's legend in a strip at the right that the model leaves free.
  const ErrorRamp ramp = find_error_ramp(input.info.comments);
  const VertexColours colours(input.attributes);
  const bool error_map = ramp.found && colours.present();
  const std::uint32_t legend = error_map ? legend_width(options.width, options.height, ramp) : 0;
  Camera camera(view);
  camera.frame(input.info.bounds, projected_outline(input, camera, options.thick_edges), double(options.width - legend),
               double(options.height));
  st.pixel_size = camera.pixel;
  Rasterizer raster(options, error_map);
  const VertexNormals normals(input.attributes);
  const bool smooth = options.shading == Shading::smooth && normals.present();
  ProgressPhase phase(options.progress, "render", input.file_size, "B");
  input.restart_triangles();
  input.triangles->set_primitive_sink([&](const LinePrimitive* p, std::size_t n) {
    for (std::size_t k = 0; k < n; ++k) {
      const Vec3d a = input.positions.get(p[k].a), b = input.positions.get(p[k].b);
      // Half the width in pixels, at least half a pixel; the radius in model units.
      const double radius = options.thick_edges ? 0.5 * double(p[k].thickness) : 0.0;
      const double half = std::max(0.5, radius / camera.pixel);
      if (p[k].a == p[k].b) {
        ++st.points;
        raster.draw_capsule(camera.project(a), camera.project(a), half, radius, 1.0);
        continue;
      }
      ++st.edges;
      // Low & Tan's dynamic normal lies in the plane of the edge and the view, across
      // the edge: with the camera at infinity, its cosine to the view is
      // |towards x e| / |e|, the sine of the angle between the edge and the view.
      const Vec3d e = b - a;
      const double len = length(e);
      const double light = len > 0 ? length(cross(camera.towards, e)) / len : 1.0;
      raster.draw_capsule(camera.project(a), camera.project(b), half, radius, light);
    }
  });
  constexpr std::size_t kChunk = 65536;
  std::vector<std::uint64_t> chunk(3 * kChunk);
  while (std::size_t n = input.triangles->read(chunk.data(), kChunk)) {
    for (std::size_t t = 0; t < n; ++t) {
      Vec3d p[3], s[3];
      for (int k = 0; k < 3; ++k) {
        p[k] = input.positions.get(chunk[3 * t + std::size_t(k)]);
        s[k] = camera.project(p[k]);
      }
      double light[3];
      float colour[9];
      if (error_map)
        for (int k = 0; k < 3; ++k) colours.get(input.attributes, chunk[3 * t + std::size_t(k)], colour + 3 * k);
      if (smooth) {
        for (int k = 0; k < 3; ++k) {
          const Vec3d nv = normals.get(input.attributes, chunk[3 * t + std::size_t(k)]);
          const double l = length(nv);
          light[k] = l > 0 ? std::fabs(dot(nv, camera.towards)) / l : 0;
        }
      } else {
        const Vec3d nf = cross(p[1] - p[0], p[2] - p[0]);
        const double l = length(nf);
        light[0] = light[1] = light[2] = l > 0 ? std::fabs(dot(nf, camera.towards)) / l : 0;
      }
      raster.draw(s, light, error_map ? colour : nullptr);
    }
    st.triangles += n;
    phase.set(input.triangles->bytes_consumed());
  }
  Image image = raster.image(&st.covered_pixels);
  if (legend > 0) {
    draw_error_legend(&image, ramp);
    st.legend = true;
  }
  return image;
}

const EnumNames<UpAxis>& up_axis_names() {
  static const EnumNames<UpAxis> names = {
      {UpAxis::automatic, "auto"}, {UpAxis::z, "z"}, {UpAxis::y, "y"}, {UpAxis::x, "x"}};
  return names;
}

const EnumNames<Shading>& shading_names() {
  static const EnumNames<Shading> names = {{Shading::flat, "flat"}, {Shading::smooth, "smooth"}};
  return names;
}

}  // namespace oocsimp
