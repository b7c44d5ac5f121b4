#include "curvature/integral_invariants.hpp"

#include <algorithm>
#include <array>
#include <cmath>

#include "common/math_constants.hpp"
#include "common/symmetric_eigen.hpp"
#include "common/triangle_geometry.hpp"
#include "common/vec3_math.hpp"

namespace oocsimp {

namespace {

// The ball's quadrature: Gauss-Legendre nodes in the radius, even ones in the angle.
// On an icosphere fewer nodes hardly change the worst error: the mesh's facets, not
// the rule, set it (docs/curvature.md, Accuracy, has the errors for each rule).
constexpr int kRadialNodes = LocalHeightField::kBallRadii;
constexpr int kAngularNodes = LocalHeightField::kBallAngles;
// The sphere's azimuths, and the fixed-point steps that find where the surface meets
// the sphere along each (the height moves the meeting point inwards by z^2 / 2r).
constexpr int kAzimuths = 64;
constexpr int kMeetingSteps = 4;

// Gauss-Legendre nodes and weights on [-1, 1], by Newton's method on P_n.
struct GaussLegendre {
  std::array<double, kRadialNodes> node{}, weight{};
  GaussLegendre() {
    const int n = kRadialNodes;
    for (int i = 0; i < n; ++i) {
      double x = std::cos(kPi * (i + 0.75) / (n + 0.5)), derivative = 1;
      for (int step = 0; step < 100; ++step) {
        double p0 = 1, p1 = x;
        for (int k = 2; k <= n; ++k) {
          const double p2 = ((2 * k - 1) * x * p1 - (k - 1) * p0) / k;
          p0 = p1;
          p1 = p2;
        }
        derivative = n * (x * p1 - p0) / (x * x - 1);
        const double dx = p1 / derivative;
        x -= dx;
        if (std::fabs(dx) < 1e-16) break;
      }
      node[std::size_t(i)] = x;
      weight[std::size_t(i)] = 2 / ((1 - x * x) * derivative * derivative);
    }
  }
};

const GaussLegendre& gauss_legendre() {
  static const GaussLegendre rule;
  return rule;
}

// The distance from p of the ball's quadrature lines at radial node i: the Gauss
// rule's node mapped from [-1, 1] onto [0, r].
double node_radius(double r, int i) { return 0.5 * r * (gauss_legendre().node[std::size_t(i)] + 1); }

// cos and sin of n angles (j + 1/2) 2 pi / n.
template <int n>
struct EvenAngles {
  std::array<double, n> cos{}, sin{};
  EvenAngles() {
    for (int j = 0; j < n; ++j) {
      cos[std::size_t(j)] = std::cos((j + 0.5) * 2 * kPi / n);
      sin[std::size_t(j)] = std::sin((j + 0.5) * 2 * kPi / n);
    }
  }
};

template <int n>
const EvenAngles<n>& even_angles() {
  static const EvenAngles<n> angles;
  return angles;
}

// The zeroth, first and second moments of a neighbourhood about p.
struct Moments {
  double mass = 0;
  double first[3] = {0, 0, 0};
  double second[3][3] = {{0, 0, 0}, {0, 0, 0}, {0, 0, 0}};

  // Adds weight w at the point (x, y) times the column moments c0 = int 1, c1 = int z,
  // c2 = int z^2 over the column's part.
  void add_column(double w, double x, double y, double c0, double c1, double c2) {
    mass += w * c0;
    first[0] += w * x * c0;
    first[1] += w * y * c0;
    first[2] += w * c1;
    second[0][0] += w * x * x * c0;
    second[0][1] += w * x * y * c0;
    second[1][1] += w * y * y * c0;
    second[0][2] += w * x * c1;
    second[1][2] += w * y * c1;
    second[2][2] += w * c2;
  }
};

// Hua et al. eq. 10: J = int x x^T - V S S^T, and its two tangential eigenvalues
// M1, M2 (the normal one is the eigenvector nearest z).
void tangential_eigenvalues(const Moments& m, double* m1, double* m2) {
  double j[3][3];
  for (int a = 0; a < 3; ++a)
    for (int b = a; b < 3; ++b) j[a][b] = j[b][a] = m.second[a][b] - m.first[a] * m.first[b] / m.mass;
  double v[3][3];
  jacobi3(j, v);
  int normal = 0;
  for (int i = 1; i < 3; ++i)
    if (std::fabs(v[2][i]) > std::fabs(v[2][normal])) normal = i;
  *m1 = j[(normal + 1) % 3][(normal + 1) % 3];
  *m2 = j[(normal + 2) % 3][(normal + 2) % 3];
}

bool finish(double k1, double k2, PrincipalCurvatures* out) {
  if (!std::isfinite(k1) || !std::isfinite(k2)) return false;
  out->k1 = std::max(k1, k2);
  out->k2 = std::min(k1, k2);
  return true;
}

}  // namespace

// --- The height field --------------------------------------------------------------

void LocalHeightField::reset(double radius, Lines lines) {
  radius_ = radius;
  lines_ = lines;
  // The square around the disk and the margin the surface is gathered in.
  lo_ = -kHeightFieldReach * radius;
  bucket_size_ = -2 * lo_ / kBuckets;
  per_line_bucket_ = kLineBuckets / (-2 * lo_);
  triangles_.clear();
  corners_.clear();
  corner_shapes_.clear();
  for (std::vector<std::uint32_t>& list : bucket_lists_) list.clear();
  if (lines_ == Lines::of_the_ball) {
    if (lines_radius_ != radius) place_ball_lines();
    for (BallLine& line : ball_lines_) line.count = 0;
  }
}

// The lines at the nodes of ball_curvatures' rule, and their buckets. A run's fields
// share one radius, so this is done once per thread.
void LocalHeightField::place_ball_lines() {
  const EvenAngles<kAngularNodes>& angles = even_angles<kAngularNodes>();
  std::array<int, kBallLines> bucket_of{};
  line_bucket_start_.fill(0);
  for (int i = 0; i < kRadialNodes; ++i) {
    const double rho = node_radius(radius_, i);
    for (int j = 0; j < kAngularNodes; ++j) {
      const int l = i * kAngularNodes + j;
      BallLine& line = ball_lines_[std::size_t(l)];
      line.x = rho * angles.cos[std::size_t(j)];
      line.y = rho * angles.sin[std::size_t(j)];
      bucket_of[std::size_t(l)] = line_bucket(line.y) * kLineBuckets + line_bucket(line.x);
      ++line_bucket_start_[std::size_t(bucket_of[std::size_t(l)]) + 1];
    }
  }
  for (std::size_t b = 0; b + 1 < line_bucket_start_.size(); ++b) line_bucket_start_[b + 1] += line_bucket_start_[b];
  std::array<std::uint16_t, kLineBuckets * kLineBuckets> fill{};
  for (int l = 0; l < kBallLines; ++l) {
    const std::size_t b = std::size_t(bucket_of[std::size_t(l)]);
    line_bucket_lines_[line_bucket_start_[b] + fill[b]++] = std::uint16_t(l);
  }
  lines_radius_ = radius_;
}

int LocalHeightField::bucket(double coordinate) const {
  const double b = std::floor((coordinate - lo_) / bucket_size_);
  return int(std::clamp(b, 0.0, double(kBuckets - 1)));
}

void LocalHeightField::add_triangle(const Vec3d& a, const Vec3d& b, const Vec3d& c) {
  Projected t;
  t.ax = a.x;
  t.ay = a.y;
  t.ux = b.x - a.x;
  t.uy = b.y - a.y;
  t.vx = c.x - a.x;
  t.vy = c.y - a.y;
  const double area2 = t.ux * t.vy - t.uy * t.vx;
  corners_.push_back({a, b, c});
  // Seen edge-on (or degenerate): it crosses no vertical line.
  if (!(std::fabs(area2) > 1e-14 * radius_ * radius_)) return;
  t.inverse_area2 = 1 / area2;
  t.za = a.z;
  t.zu = b.z - a.z;
  t.zv = c.z - a.z;
  const double x0 = std::min({a.x, b.x, c.x}), x1 = std::max({a.x, b.x, c.x});
  const double y0 = std::min({a.y, b.y, c.y}), y1 = std::max({a.y, b.y, c.y});
  const double hi = -lo_;
  if (x1 < lo_ || y1 < lo_ || x0 > hi || y0 > hi) return;
  if (lines_ == Lines::of_the_ball) {
    // The lines in the buckets its box covers, each in the order triangles come.
    const int bx0 = line_bucket(x0), bx1 = line_bucket(x1), by0 = line_bucket(y0), by1 = line_bucket(y1);
    for (int by = by0; by <= by1; ++by)
      for (int bx = bx0; bx <= bx1; ++bx) {
        const std::size_t cell = std::size_t(by * kLineBuckets + bx);
        for (std::uint16_t i = line_bucket_start_[cell]; i < line_bucket_start_[cell + 1]; ++i) {
          BallLine& line = ball_lines_[line_bucket_lines_[i]];
          SurfaceCrossing crossing;
          if (meets(t, line.x, line.y, &crossing)) insert_crossing(crossing, line.crossings, &line.count);
        }
      }
    return;
  }
  const std::uint32_t index = std::uint32_t(triangles_.size());
  triangles_.push_back(t);
  const int bx0 = bucket(x0), bx1 = bucket(x1), by0 = bucket(y0), by1 = bucket(y1);
  for (int by = by0; by <= by1; ++by)
    for (int bx = bx0; bx <= bx1; ++bx) bucket_lists_[by * kBuckets + bx].push_back(index);
}

bool LocalHeightField::meets(const Projected& t, double x, double y, SurfaceCrossing* c) {
  // Barycentric coordinates with a little slack, so that a line through a shared edge
  // meets one of its triangles whatever the rounding (it may meet both: the solid is
  // then the same on either account, see ball_curvatures).
  constexpr double kSlack = 1e-9;
  const double dx = x - t.ax, dy = y - t.ay;
  const double beta = (dx * t.vy - dy * t.vx) * t.inverse_area2;
  const double gamma = (t.ux * dy - t.uy * dx) * t.inverse_area2;
  if (beta < -kSlack || gamma < -kSlack || beta + gamma > 1 + kSlack) return false;
  *c = {t.za + beta * t.zu + gamma * t.zv, t.inverse_area2 > 0};
  return true;
}

void LocalHeightField::insert_crossing(const SurfaceCrossing& c, SurfaceCrossing* out, int* n) {
  int at = *n < kMostCrossings ? (*n)++ : kMostCrossings - 1;
  if (at == kMostCrossings - 1 && *n == kMostCrossings && c.z >= out[at].z) return;
  for (; at > 0 && out[at - 1].z > c.z; --at) out[at] = out[at - 1];
  out[at] = c;
}

int LocalHeightField::crossings(double x, double y, SurfaceCrossing* out) const {
  int n = 0;
  for (const std::uint32_t i : bucket_lists_[bucket(y) * kBuckets + bucket(x)]) {
    SurfaceCrossing c;
    if (meets(triangles_[i], x, y, &c)) insert_crossing(c, out, &n);
  }
  return n;
}

bool LocalHeightField::inside(const Vec3d& q) const {
  double nearest = HUGE_VAL, squareness = -1;
  bool in = false;
  if (corner_shapes_.size() != corners_.size()) {
    corner_shapes_.resize(corners_.size());
    for (std::size_t i = 0; i < corners_.size(); ++i) {
      const Corners& t = corners_[i];
      CornerShape& k = corner_shapes_[i];
      k.normal = cross(t.b - t.a, t.c - t.a);
      k.normal_length = length(k.normal);
      k.lo = {std::min({t.a.x, t.b.x, t.c.x}), std::min({t.a.y, t.b.y, t.c.y}), std::min({t.a.z, t.b.z, t.c.z})};
      k.hi = {std::max({t.a.x, t.b.x, t.c.x}), std::max({t.a.y, t.b.y, t.c.y}), std::max({t.a.z, t.b.z, t.c.z})};
    }
  }
  for (std::size_t i = 0; i < corners_.size(); ++i) {
    const Corners& t = corners_[i];
    const CornerShape& k = corner_shapes_[i];
    const Vec3d& normal = k.normal;
    const double normal_length = k.normal_length;
    if (!(normal_length > 0)) continue;
    // A triangle whose box is beyond the nearest distance (and its tie margin) is
    // farther still: it would change nothing below.
    const Vec3d gap{std::max({k.lo.x - q.x, q.x - k.hi.x, 0.0}), std::max({k.lo.y - q.y, q.y - k.hi.y, 0.0}),
                    std::max({k.lo.z - q.z, q.z - k.hi.z, 0.0})};
    const double reach = nearest * (1 + 1e-9);
    if (squared_length(gap) > reach * reach * (1 + 1e-6)) continue;
    const Vec3d d = q - metrics::closest_point_on_triangle(q, t.a, t.b, t.c);
    const double distance = length(d);
    // Several triangles share the nearest point where it is on an edge or a corner;
    // the one whose plane q faces most squarely says on which side q is.
    const double facing = distance > 0 ? std::fabs(dot(d, normal)) / (distance * normal_length) : 1;
    if (distance < nearest * (1 - 1e-9) || (distance <= nearest * (1 + 1e-9) && facing > squareness)) {
      nearest = std::min(nearest, distance);
      squareness = facing;
      in = dot(d, normal) < 0;
    }
  }
  return in;
}

bool LocalHeightField::height(double x, double y, double* z) const {
  SurfaceCrossing found[kMostCrossings];
  const int n = crossings(x, y, found);
  bool any = false;
  for (int i = 0; i < n; ++i)
    if (found[i].outward_up && (!any || std::fabs(found[i].z) < std::fabs(*z))) *z = found[i].z, any = true;
  return any;
}

// --- The invariants ----------------------------------------------------------------

bool ball_curvatures(const LocalHeightField& heights, bool closed, PrincipalCurvatures* out) {
  const double r = heights.radius();
  const GaussLegendre& rule = gauss_legendre();
  // The half ball below the tangent plane, exactly: volume 2 pi r^3 / 3, int z = -pi
  // r^4 / 4, int x^2 = int y^2 = int z^2 = 2 pi r^5 / 15.
  Moments m;
  m.mass = 2 * kPi * r * r * r / 3;
  m.first[2] = -kPi * r * r * r * r / 4;
  m.second[0][0] = m.second[1][1] = m.second[2][2] = 2 * kPi * std::pow(r, 5) / 15;
  // Then, per vertical line within the ball (|z| <= s = sqrt(r^2 - rho^2)), the solid
  // along it less the half ball's part, [-s, 0]. Going up, a crossing whose outward
  // normal points up leaves the solid and one pointing down enters it; below the
  // lowest crossing is inside when that one leaves.
  const double angle_weight = 2 * kPi / kAngularNodes;
  const EvenAngles<kAngularNodes>& angles = even_angles<kAngularNodes>();
  SurfaceCrossing found[LocalHeightField::kMostCrossings];
  for (int i = 0; i < kRadialNodes; ++i) {
    const double rho = node_radius(r, i);
    const double s = std::sqrt(std::max(r * r - rho * rho, 0.0));
    const double w = 0.5 * r * rule.weight[std::size_t(i)] * angle_weight * rho;
    for (std::size_t j = 0; j < kAngularNodes; ++j) {
      const double x = rho * angles.cos[j], y = rho * angles.sin[j];
      // The field found the crossings of its ball lines (these) as the triangles came.
      const SurfaceCrossing* line = found;
      int n = 0;
      if (heights.has_ball_lines()) {
        const LocalHeightField::BallLine& l = heights.ball_line(i * kAngularNodes + int(j));
        line = l.crossings;
        n = l.count;
      } else {
        n = heights.crossings(x, y, found);
      }
      if (n == 0 && !closed) return false;
      // int z^k dz over [lo, hi], k = 0, 1, 2, summed over the solid's intervals.
      double c0 = 0, c1 = 0, c2 = 0, from = -s;
      bool inside = n > 0 ? line[0].outward_up : heights.inside({x, y, 0});
      auto add = [&](double lo, double hi) {
        c0 += hi - lo;
        c1 += (hi * hi - lo * lo) / 2;
        c2 += (hi * hi * hi - lo * lo * lo) / 3;
      };
      for (int k = 0; k < n; ++k) {
        const double z = std::clamp(line[k].z, -s, s);
        if (inside && z > from) add(from, z);
        from = std::max(from, z);
        inside = !line[k].outward_up;
      }
      if (inside && s > from) add(from, s);
      add(0, -s);  // less [-s, 0]: adding [0, -s] subtracts it
      m.add_column(w, x, y, c0, c1, c2);
    }
  }
  double m1, m2;
  tangential_eigenvalues(m, &m1, &m2);
  const double r6 = std::pow(r, 6);
  return finish(6 * (m2 - 3 * m1) / (kPi * r6) + 8 / (5 * r), 6 * (m1 - 3 * m2) / (kPi * r6) + 8 / (5 * r), out);
}

bool sphere_curvatures(const LocalHeightField& heights, PrincipalCurvatures* out) {
  const double r = heights.radius();
  // The lower hemisphere, exactly: area 2 pi r^2, int z = -pi r^3, int x^2 = int y^2 =
  // int z^2 = 2 pi r^4 / 3.
  Moments m;
  m.mass = 2 * kPi * r * r;
  m.first[2] = -kPi * r * r * r;
  m.second[0][0] = m.second[1][1] = m.second[2][2] = 2 * kPi * std::pow(r, 4) / 3;
  // Then, along each azimuth, the band from the equator to the height zb where the
  // surface meets the sphere. With rho(z) = sqrt(r^2 - z^2) and area r dphi dz:
  // int 1 = r zb, int z = r zb^2 / 2, int z^2 = r zb^3 / 3, int rho = r (zb rho(zb) +
  // r^2 asin(zb / r)) / 2, int rho^2 = r (r^2 zb - zb^3 / 3), int z rho = r (r^3 -
  // rho(zb)^3) / 3; x = rho cos phi, y = rho sin phi.
  const double w = 2 * kPi / kAzimuths;
  const EvenAngles<kAzimuths>& angles = even_angles<kAzimuths>();
  for (std::size_t j = 0; j < kAzimuths; ++j) {
    const double c = angles.cos[j], s = angles.sin[j];
    double zb = 0;
    for (int step = 0; step < kMeetingSteps; ++step) {
      const double rb = std::sqrt(std::max(r * r - zb * zb, 0.0));
      if (!heights.height(rb * c, rb * s, &zb)) return false;
      zb = std::clamp(zb, -r, r);
    }
    const double rb = std::sqrt(std::max(r * r - zb * zb, 0.0));
    const double band = r * zb, band_z = r * zb * zb / 2, band_z2 = r * zb * zb * zb / 3;
    const double band_rho = r * (zb * rb + r * r * std::asin(zb / r)) / 2;
    const double band_rho2 = r * (r * r * zb - zb * zb * zb / 3);
    const double band_z_rho = r * (r * r * r - rb * rb * rb) / 3;
    m.mass += w * band;
    m.first[0] += w * c * band_rho;
    m.first[1] += w * s * band_rho;
    m.first[2] += w * band_z;
    m.second[0][0] += w * c * c * band_rho2;
    m.second[0][1] += w * c * s * band_rho2;
    m.second[1][1] += w * s * s * band_rho2;
    m.second[0][2] += w * c * band_z_rho;
    m.second[1][2] += w * s * band_z_rho;
    m.second[2][2] += w * band_z2;
  }
  double m1, m2;
  tangential_eigenvalues(m, &m1, &m2);
  const double r5 = std::pow(r, 5);
  return finish((m2 - 3 * m1) / (kPi * r5) + 4 / (3 * r), (m1 - 3 * m2) / (kPi * r5) + 4 / (3 * r), out);
}

bool quadratic_fit_curvatures(const std::vector<Vec3d>& points, PrincipalCurvatures* out) {
  if (points.size() < 5) return false;
  // In units of the farthest point's distance, so that the normal equations are well
  // scaled: z = a x^2 + b xy + c y^2 + d x + e y.
  double scale = 0;
  for (const Vec3d& p : points) scale = std::max(scale, std::sqrt(p.x * p.x + p.y * p.y));
  if (!(scale > 0)) return false;
  double n[5][6] = {};
  for (const Vec3d& p : points) {
    const double x = p.x / scale, y = p.y / scale, z = p.z / scale;
    const double row[5] = {x * x, x * y, y * y, x, y};
    for (int i = 0; i < 5; ++i) {
      for (int k = 0; k < 5; ++k) n[i][k] += row[i] * row[k];
      n[i][5] += row[i] * z;
    }
  }
  // Gaussian elimination with partial pivoting.
  for (int col = 0; col < 5; ++col) {
    int pivot = col;
    for (int i = col + 1; i < 5; ++i)
      if (std::fabs(n[i][col]) > std::fabs(n[pivot][col])) pivot = i;
    if (!(std::fabs(n[pivot][col]) > 1e-12 * double(points.size()))) return false;
    for (int k = 0; k < 6; ++k) std::swap(n[col][k], n[pivot][k]);
    for (int i = 0; i < 5; ++i) {
      if (i == col) continue;
      const double f = n[i][col] / n[col][col];
      for (int k = col; k < 6; ++k) n[i][k] -= f * n[col][k];
    }
  }
  const double a = n[0][5] / n[0][0], b = n[1][5] / n[1][1], c = n[2][5] / n[2][2];
  // The Hessian [2a b; b 2c], back in model units; convex (positive) bends away from
  // the normal, towards -z.
  const double mean = -(a + c) / scale, spread = std::hypot((a - c) / scale, b / scale);
  return finish(mean + spread, mean - spread, out);
}

}  // namespace oocsimp
