#include "geometry/contact_patch.hpp"

#include <algorithm>
#include <cmath>
#include <span>
#include <type_traits>
#include <utility>
#include <variant>

namespace sanguis::geometry {
namespace {

// A face steeper than this to the contact normal (cosine) is not measured along the
// normal: its heights would blow up. The faces chosen by facing_face lean by at most
// 55 degrees for a box (cosine 1/sqrt 3).
constexpr double kSteepestCosine = 0.1;

// No member initialisers: the polygons below are scratch space, filled before use
// (zeroing them cost more than clipping them).
struct Point2 {
  double x, y;
};

// A convex polygon in the patch plane, with room for the clipping to grow it.
struct Polygon2 {
  int count = 0;
  std::array<Point2, ContactPatch::kCapacity> p;
};

double cross2(const Point2& o, const Point2& a, const Point2& b) {
  return (a.x - o.x) * (b.y - o.y) - (a.y - o.y) * (b.x - o.x);
}

double signed_area2(const Polygon2& poly) {
  double twice = 0.0;
  for (int k = 0, prev = poly.count - 1; k < poly.count; prev = k++) {
    twice += poly.p[prev].x * poly.p[k].y - poly.p[k].x * poly.p[prev].y;
  }
  return twice;
}

// Keeps the part of `in` where the affine function value_at is >= 0 (Sutherland-Hodgman
// against one half-plane), into `out`. (A branch-free version, writing both candidates
// of each edge and keeping them by flags, was 20 % slower on bench dem-crosses.)
template <typename ValueAt>
void clip(const Polygon2& in, ValueAt value_at, Polygon2& out) {
  out.count = 0;
  if (in.count == 0) return;
  Point2 a = in.p[in.count - 1];
  double va = value_at(a);
  for (int k = 0; k < in.count; ++k) {
    const Point2 b = in.p[k];
    const double vb = value_at(b);
    if ((va >= 0.0) != (vb >= 0.0)) {
      const double t = va / (va - vb);
      out.p[out.count++] = {a.x + t * (b.x - a.x), a.y + t * (b.y - a.y)};
    }
    if (vb >= 0.0) out.p[out.count++] = b;
    if (out.count + 2 > ContactPatch::kCapacity) return;  // only for non-convex round-off
    a = b;
    va = vb;
  }
}

// Projects a face onto the patch plane (origin o, axes t1, t2), counter-clockwise.
bool project(const SpaceFace& f, const Vec3& o, const Vec3& t1, const Vec3& t2, Polygon2& out) {
  out.count = f.count;
  for (int k = 0; k < f.count; ++k) {
    const Vec3 r = f.corner[k] - o;
    out.p[k] = {dot(r, t1), dot(r, t2)};
  }
  const double area = signed_area2(out);
  if (!(std::abs(area) > 0.0)) return false;
  if (area < 0.0) {
    for (int k = 0; k < f.count / 2; ++k) std::swap(out.p[k], out.p[f.count - 1 - k]);
  }
  return true;
}

// Height along n, above the patch plane, of the plane dot(normal, x) = offset at the
// patch-plane point (p.x, p.y): affine in p.
struct PlaneHeight {
  double at_origin = 0.0, slope_x = 0.0, slope_y = 0.0;
  PlaneHeight(const Vec3& normal, double offset, const Vec3& n, const Vec3& o, const Vec3& t1,
              const Vec3& t2) {
    const double along = 1.0 / dot(normal, n);
    at_origin = (offset - dot(normal, o)) * along;
    slope_x = -dot(normal, t1) * along;
    slope_y = -dot(normal, t2) * along;
  }
  double operator()(const Point2& p) const { return at_origin + slope_x * p.x + slope_y * p.y; }
};

// The shared construction: face a against face b (or, with b null, against the plane
// `b_normal`, `b_offset`).
bool patch(const SpaceFace& a, const SpaceFace* b, const Vec3& b_normal, double b_offset,
           const Vec3& n, double crust_a, double crust_b, ContactPatch& out) {
  out.count = 0;
  if (dot(a.normal, n) < kSteepestCosine || dot(b_normal, n) > -kSteepestCosine) return false;
  Vec3 o;
  for (int k = 0; k < a.count; ++k) o += a.corner[k];
  o = o / static_cast<double>(a.count);
  const Vec3 helper = std::abs(n.x) < 0.6 ? Vec3{1.0, 0.0, 0.0} : Vec3{0.0, 1.0, 0.0};
  const Vec3 side = cross(n, helper);
  const Vec3 t1 = side / norm(side);
  const Vec3 t2 = cross(n, t1);

  // Two buffers: each clip writes the other.
  Polygon2 buffer[2];
  int current = 0;
  if (!project(a, o, t1, t2, buffer[0])) return false;
  if (b != nullptr) {
    Polygon2 window;
    if (!project(*b, o, t1, t2, window)) return false;
    for (int e = 0, prev = window.count - 1; e < window.count && buffer[current].count > 0;
         prev = e++) {
      const Point2 from = window.p[prev], to = window.p[e];
      clip(
          buffer[current], [&](const Point2& p) { return cross2(from, to, p); },
          buffer[1 - current]);
      current = 1 - current;
    }
  }
  const PlaneHeight height_a(a.normal, a.offset, n, o, t1, t2);
  const PlaneHeight height_b(b_normal, b_offset, n, o, t1, t2);
  const double reach = crust_a + crust_b;
  const auto overlap = [&](const Point2& p) { return reach - (height_b(p) - height_a(p)); };
  clip(buffer[current], overlap, buffer[1 - current]);
  const Polygon2& poly = buffer[1 - current];
  if (poly.count == 0) return false;

  bool any = false;
  const auto edge = [&](int from, int to) {
    const double dx = poly.p[to].x - poly.p[from].x, dy = poly.p[to].y - poly.p[from].y;
    return std::sqrt(dx * dx + dy * dy);
  };
  double before = edge(poly.count - 1, 0);
  for (int k = 0; k < poly.count; ++k) {
    const Point2& p = poly.p[k];
    const double after = edge(k, k + 1 < poly.count ? k + 1 : 0);
    const double mid = 0.5 * (height_a(p) + crust_a + height_b(p) - crust_b);
    out.point[k] = o + p.x * t1 + p.y * t2 + mid * n;
    out.overlap[k] = std::max(overlap(p), 0.0);
    out.perimeter_share[k] = 0.5 * (before + after);
    any = any || out.overlap[k] > 0.0;
    before = after;
  }
  out.count = poly.count;
  return any;
}

bool box_face(const Box& box, const Pose& pose, const Vec3& d, SpaceFace& out) {
  // The body axes in space (the columns of the rotation matrix of the unit quaternion),
  // which give both the body-frame direction and the face.
  const Quaternion& q = pose.orientation;
  const Vec3 axis[3] = {{1.0 - 2.0 * (q.y * q.y + q.z * q.z), 2.0 * (q.x * q.y + q.w * q.z),
                         2.0 * (q.x * q.z - q.w * q.y)},
                        {2.0 * (q.x * q.y - q.w * q.z), 1.0 - 2.0 * (q.x * q.x + q.z * q.z),
                         2.0 * (q.y * q.z + q.w * q.x)},
                        {2.0 * (q.x * q.z + q.w * q.y), 2.0 * (q.y * q.z - q.w * q.x),
                         1.0 - 2.0 * (q.x * q.x + q.y * q.y)}};
  const double c[3] = {dot(axis[0], d), dot(axis[1], d), dot(axis[2], d)};
  const double h[3] = {box.half_extents.x, box.half_extents.y, box.half_extents.z};
  int i = 0;
  for (int k = 1; k < 3; ++k) {
    if (std::abs(c[k]) > std::abs(c[i])) i = k;
  }
  if (!(std::abs(c[i]) > 0.0)) return false;
  const int j = (i + 1) % 3, l = (i + 2) % 3;
  out.normal = c[i] > 0.0 ? axis[i] : -axis[i];
  const Vec3 centre = pose.position + h[i] * out.normal;
  const Vec3 u = h[j] * axis[j], v = h[l] * axis[l];
  out.count = 4;
  out.corner[0] = centre + u + v;
  out.corner[1] = centre - u + v;
  out.corner[2] = centre - u - v;
  out.corner[3] = centre + u - v;
  out.offset = dot(out.normal, centre);
  return true;
}

bool polyhedron_face(const ConvexPolyhedron& poly, const Pose& pose, const Vec3& d,
                     SpaceFace& out) {
  const Vec3 d_body = rotate_inverse(pose.orientation, d);
  const std::uint32_t top = poly.support_index(d_body);
  const double length = norm(d_body);
  std::size_t best = poly.face_count();
  double best_lean = kSteepestCosine * length;
  for (std::size_t f = 0; f < poly.face_count(); ++f) {
    const double lean = dot(poly.face_planes()[f].normal, d_body);
    if (lean <= best_lean) continue;
    const std::span<const std::uint32_t> loop = poly.face(f);
    if (std::find(loop.begin(), loop.end(), top) == loop.end()) continue;
    best = f;
    best_lean = lean;
  }
  if (best == poly.face_count()) return false;
  const std::span<const std::uint32_t> loop = poly.face(best);
  if (loop.size() > static_cast<std::size_t>(SpaceFace::kCapacity)) return false;
  out.count = static_cast<int>(loop.size());
  for (int k = 0; k < out.count; ++k) {
    out.corner[k] = pose.position + rotate(pose.orientation, poly.vertices()[loop[k]]);
  }
  out.normal = rotate(pose.orientation, poly.face_planes()[best].normal);
  out.offset = dot(out.normal, out.corner[0]);
  return true;
}

bool triangle_face(const Triangle& t, const Pose& pose, const Vec3& d, SpaceFace& out) {
  const Vec3 d_body = rotate_inverse(pose.orientation, d);
  const Vec3 normal = cross(t.b - t.a, t.c - t.a);
  const double length = norm(normal);
  if (!(length > 0.0)) return false;
  const bool flip = dot(normal, d_body) < 0.0;
  out.count = 3;
  const Vec3 corners[3] = {t.a, flip ? t.c : t.b, flip ? t.b : t.c};
  for (int k = 0; k < 3; ++k) out.corner[k] = pose.position + rotate(pose.orientation, corners[k]);
  out.normal = rotate(pose.orientation, (flip ? -1.0 / length : 1.0 / length) * normal);
  out.offset = dot(out.normal, out.corner[0]);
  return true;
}

}  // namespace

bool facing_face(const ConvexShape& shape, const Pose& pose, const Vec3& d, SpaceFace& out) {
  return std::visit(
      [&](const auto& s) {
        using S = std::decay_t<decltype(s)>;
        if constexpr (std::is_same_v<S, Box>) {
          return box_face(s, pose, d, out);
        } else if constexpr (std::is_same_v<S, ConvexPolyhedron>) {
          return polyhedron_face(s, pose, d, out);
        } else if constexpr (std::is_same_v<S, Triangle>) {
          return triangle_face(s, pose, d, out);
        } else {
          return false;
        }
      },
      shape);
}

bool face_pair_patch(const SpaceFace& a, const SpaceFace& b, const Vec3& n, double crust_a,
                     double crust_b, ContactPatch& out) {
  return patch(a, &b, b.normal, b.offset, n, crust_a, crust_b, out);
}

bool face_plane_patch(const SpaceFace& a, const Vec3& plane_point, const Vec3& plane_normal,
                      double crust, ContactPatch& out) {
  return patch(a, nullptr, plane_normal, dot(plane_normal, plane_point), -plane_normal, crust, 0.0,
               out);
}

namespace {

constexpr double kGauss = 0.211324865405187;  // two-point Gauss-Legendre on [0, 1]

// The parameter in [0, 1] of the point of the segment p + u e nearest the origin: where
// |p + u e| has its kink when the origin lies on the segment.
double foot_on(const Vec3& p, const Vec3& e) {
  const double e2 = norm2(e);
  return e2 > 0.0 ? std::clamp(-dot(p, e) / e2, 0.0, 1.0) : 0.0;
}

// Calls f(u, w) at the two-point Gauss nodes of [0, 1] cut at `foot`, w the node's weight.
template <typename F>
void gauss_either_side(double foot, F&& f) {
  for (const auto& [from, to] : {std::pair{0.0, foot}, std::pair{foot, 1.0}}) {
    for (const double t : {kGauss, 1.0 - kGauss}) f(from + t * (to - from), 0.5 * (to - from));
  }
}

}  // namespace

PatchPressure::PatchPressure(const ContactPatch& patch, const Vec3& centre, const Vec3& normal)
    : n_(patch.count), overlap_(patch.overlap), normal_(normal) {
  if (n_ < 2) return;
  double farthest2 = 0.0;
  for (int k = 0; k < n_; ++k) {
    const Vec3 x = patch.point[k] - centre;
    r_[k] = x - dot(x, normal) * normal;
    farthest2 = std::max(farthest2, norm2(r_[k]));
  }
  farthest_ = std::sqrt(farthest2);
  Vec3 mid, turn;
  double mid_overlap = 0.0, edges2 = 0.0;
  for (int k = 0; k < n_; ++k) {
    mid += r_[k];
    mid_overlap += overlap_[k];
    edges2 += norm2(r_[next(k)] - r_[k]);
    turn += cross(r_[k], r_[next(k)]);
  }
  mid = mid / static_cast<double>(n_);
  mid_overlap /= n_;                            // a linear overlap's value at the corners' mean
  const double twice_area = dot(turn, normal);  // signed: the corners' sense about n
  flat_ = n_ > 2 && std::abs(twice_area) > 1e-9 * edges2;
  if (!flat_) {
    line_integrals();
    return;
  }
  // The overlap's gradient in the plane (divergence theorem: the integral of grad d over
  // the area is that of d times the outward normal around it), hence its value at the
  // centre.
  Vec3 gradient;
  for (int k = 0; k < n_; ++k) {
    gradient += 0.5 * (overlap_[k] + overlap_[next(k)]) * cross(r_[next(k)] - r_[k], normal);
  }
  centre_overlap_ = mid_overlap - dot(gradient, mid) / (0.5 * twice_area);
  // Triangle (centre, P, Q) in polar form: x = s w(u), w = (1 - u) P + u Q, dA = s |P x Q|
  // ds du, overlap (1 - s) dc + s dw(u), dw = (1 - u) dP + u dQ. Over s exactly: dc/6 +
  // dw/3 for the area, dc/12 + dw/4 for |r| and dc/20 + dw/5 for r^2; over u the area and
  // r^2 here in closed form (polynomials), |r| in mean_arm.
  const double dc = centre_overlap_;
  double area = 0.0, second = 0.0;  // 6 and 60 times the integrals
  for (int k = 0; k < n_; ++k) {
    const Vec3 &p = r_[k], &q = r_[next(k)];
    const double size = std::abs(dot(cross(p, q), normal));
    const double dp = overlap_[k], dq = overlap_[next(k)];
    const double pp = norm2(p), pq = dot(p, q), qq = norm2(q);
    area += size * (dc + dp + dq);
    second +=
        size * (dc * (pp + pq + qq) + dp * (3 * pp + 2 * pq + qq) + dq * (pp + 2 * pq + 3 * qq));
  }
  if (area > 0.0) second_moment_ = 0.1 * second / area;
}

// No area: the corners lie on a line through the centre, and the pressure acts along it:
// each edge (a two-corner patch's one edge; otherwise each twice, which the ratios do not
// see), cut at the centre's foot, two-point Gauss on each piece (exact: |r| is linear on
// each).
void PatchPressure::line_integrals() {
  double weight = 0.0, arm = 0.0, arm2 = 0.0;
  for (int k = 0; k < (n_ == 2 ? 1 : n_); ++k) {
    const Vec3& p = r_[k];
    const Vec3 edge = r_[next(k)] - p;
    const double length = std::sqrt(norm2(edge));
    gauss_either_side(foot_on(p, edge), [&](double u, double w) {
      const double d = w * length * ((1.0 - u) * overlap_[k] + u * overlap_[next(k)]);
      const double r2 = norm2(p + u * edge);
      weight += d;
      arm += d * std::sqrt(r2);
      arm2 += d * r2;
    });
  }
  if (weight > 0.0) {
    second_moment_ = arm2 / weight;
    line_mean_arm_ = arm / weight;
  }
}

double PatchPressure::mean_arm() const {
  if (!flat_ || !(second_moment_ > 0.0)) return line_mean_arm_;
  // Two-point Gauss on each side of the foot of the centre on each edge, where |w| has its
  // kink; the weights 12 times those of the constructor's comment.
  const double dc = centre_overlap_;
  double weight = 0.0, arm = 0.0;
  for (int k = 0; k < n_; ++k) {
    const Vec3 &p = r_[k], &q = r_[next(k)];
    const double size = std::abs(dot(cross(p, q), normal_));
    if (!(size > 0.0)) continue;
    const Vec3 edge = q - p;
    gauss_either_side(foot_on(p, edge), [&](double u, double w) {
      const double dw = (1.0 - u) * overlap_[k] + u * overlap_[next(k)];
      weight += w * size * (2 * dc + 4 * dw);
      arm += w * size * (dc + 3 * dw) * std::sqrt(norm2(p + u * edge));
    });
  }
  return arm / weight;
}

PatchArms pressure_arms(const ContactPatch& patch, const Vec3& centre, const Vec3& normal) {
  const PatchPressure pressure(patch, centre, normal);
  return {pressure.second_moment(), pressure.mean_arm()};
}

}  // namespace sanguis::geometry
