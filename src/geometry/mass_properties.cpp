#include "geometry/mass_properties.hpp"

#include <Eigen/Dense>
#include <algorithm>
#include <cmath>
#include <numbers>
#include <stdexcept>
#include <string>

#include "geometry/convex_hull.hpp"
#include "geometry/polytope.hpp"

namespace sanguis::geometry {
namespace {

// Quaternion of a rotation matrix (Shepperd, J. Guid. Control 1 (1978) 223):
// take the largest of 4w^2, 4x^2, 4y^2, 4z^2 to divide by.
Quaternion quaternion_from_matrix(const Mat3& m) {
  const double trace = m(0, 0) + m(1, 1) + m(2, 2);
  Quaternion q;
  if (trace >= m(0, 0) && trace >= m(1, 1) && trace >= m(2, 2)) {
    const double s = 2.0 * std::sqrt(1.0 + trace);
    q = {0.25 * s, (m(2, 1) - m(1, 2)) / s, (m(0, 2) - m(2, 0)) / s, (m(1, 0) - m(0, 1)) / s};
  } else if (m(0, 0) >= m(1, 1) && m(0, 0) >= m(2, 2)) {
    const double s = 2.0 * std::sqrt(1.0 + m(0, 0) - m(1, 1) - m(2, 2));
    q = {(m(2, 1) - m(1, 2)) / s, 0.25 * s, (m(0, 1) + m(1, 0)) / s, (m(0, 2) + m(2, 0)) / s};
  } else if (m(1, 1) >= m(2, 2)) {
    const double s = 2.0 * std::sqrt(1.0 + m(1, 1) - m(0, 0) - m(2, 2));
    q = {(m(0, 2) - m(2, 0)) / s, (m(0, 1) + m(1, 0)) / s, 0.25 * s, (m(1, 2) + m(2, 1)) / s};
  } else {
    const double s = 2.0 * std::sqrt(1.0 + m(2, 2) - m(0, 0) - m(1, 1));
    q = {(m(1, 0) - m(0, 1)) / s, (m(0, 2) + m(2, 0)) / s, (m(1, 2) + m(2, 1)) / s, 0.25 * s};
  }
  return normalized(q);
}

void set_principal_axes(MassProperties& mp) {
  Eigen::Matrix3d inertia;
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j) inertia(i, j) = mp.inertia_about_centroid(i, j);
  const Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> solver(inertia);
  Eigen::Matrix3d axes = solver.eigenvectors();  // columns, eigenvalues ascending
  if (axes.determinant() < 0.0) axes.col(2) *= -1.0;
  Mat3 r;
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j) r(i, j) = axes(i, j);
  mp.principal_moments = {solver.eigenvalues()(0), solver.eigenvalues()(1),
                          solver.eigenvalues()(2)};
  mp.principal_axes = quaternion_from_matrix(r);
}

// Inertia tensor I = tr(S) 1 - S from the second moment S about the centroid,
// and back: S = tr(I)/2 1 - I.
Mat3 inertia_from_second_moment(const Mat3& s) {
  const double trace = s(0, 0) + s(1, 1) + s(2, 2);
  return trace * Mat3::identity() - s;
}
Mat3 second_moment_from_inertia(const Mat3& inertia) {
  const double trace = inertia(0, 0) + inertia(1, 1) + inertia(2, 2);
  return (0.5 * trace) * Mat3::identity() - inertia;
}

MassProperties diagonal(double volume, const Vec3& centroid, const Vec3& moments) {
  MassProperties mp;
  mp.volume = volume;
  mp.centroid = centroid;
  mp.inertia_about_centroid = Mat3::diagonal(moments);
  set_principal_axes(mp);
  return mp;
}

struct ClosedForm {
  MassProperties operator()(const Sphere& s) const {
    const double v = 4.0 / 3.0 * std::numbers::pi * std::pow(s.radius, 3);
    const double i = 0.4 * v * s.radius * s.radius;
    return diagonal(v, {}, {i, i, i});
  }
  MassProperties operator()(const Box& b) const {
    const Vec3& h = b.half_extents;
    const double v = 8.0 * h.x * h.y * h.z;
    return diagonal(v, {},
                    {v * (h.y * h.y + h.z * h.z) / 3.0, v * (h.x * h.x + h.z * h.z) / 3.0,
                     v * (h.x * h.x + h.y * h.y) / 3.0});
  }
  MassProperties operator()(const Cylinder& c) const {
    const double r2 = c.radius * c.radius, hh = c.half_height;
    const double v = 2.0 * std::numbers::pi * r2 * hh;
    const double transverse = v * (r2 / 4.0 + hh * hh / 3.0);  // h^2/12 with h = 2 hh
    return diagonal(v, {}, {transverse, transverse, 0.5 * v * r2});
  }
  MassProperties operator()(const Cone& c) const {
    const double r2 = c.radius * c.radius, h2 = c.height * c.height;
    const double v = std::numbers::pi * r2 * c.height / 3.0;
    const double transverse = v * (3.0 / 20.0 * r2 + 3.0 / 80.0 * h2);
    return diagonal(v, {0.0, 0.0, c.axial_offset}, {transverse, transverse, 0.3 * v * r2});
  }
  MassProperties operator()(const Ellipsoid& e) const {
    const Vec3& a = e.semi_axes;
    const double v = 4.0 / 3.0 * std::numbers::pi * a.x * a.y * a.z;
    return diagonal(v, {},
                    {0.2 * v * (a.y * a.y + a.z * a.z), 0.2 * v * (a.x * a.x + a.z * a.z),
                     0.2 * v * (a.x * a.x + a.y * a.y)});
  }
  MassProperties operator()(const ConvexPolyhedron& p) const {
    const VolumeMoments m = volume_moments(to_polytope(p));
    return from_moments(m.volume, m.first, m.second);
  }
  MassProperties operator()(const Triangle&) const {
    throw std::invalid_argument("mass_properties: a Triangle has no volume");
  }
};

// ---------------------------------------------------------------- composites

// An element placed in the composite frame: its exact moments, and the convex
// polytope (exact or inscribed) with its face planes for the intersections.
struct PlacedElement {
  VolumeMoments exact;
  Polytope polytope;
  std::vector<Plane> planes;
  double missing_volume = 0.0;  // exact volume - polytope volume (0 if polyhedral)
};

VolumeMoments placed_moments(const MassProperties& mp, const CompositeElement& e) {
  const Mat3 r = rotation_matrix(e.orientation);
  const Vec3 c = e.position + rotate(e.orientation, mp.centroid);
  const Mat3 s_body = second_moment_from_inertia(mp.inertia_about_centroid);
  return {mp.volume, mp.volume * c, r * s_body * r.transposed() + mp.volume * outer(c, c)};
}

Polytope element_polytope(const CompositeElement& e, int resolution) {
  if (const auto* p = std::get_if<ConvexPolyhedron>(&e.shape))
    return to_polytope(*p, e.position, e.orientation);
  const TriangleMesh mesh = tessellate(e.shape, resolution);
  return to_polytope(convex_hull(mesh.vertices), e.position, e.orientation);
}

std::vector<PlacedElement> place(const std::vector<CompositeElement>& elements, int resolution) {
  if (elements.empty()) throw std::invalid_argument("composite: no elements");
  if (resolution < 3)
    throw std::invalid_argument("composite: curved_resolution must be >= 3, got " +
                                std::to_string(resolution));
  std::vector<PlacedElement> placed;
  for (const CompositeElement& e : elements) {
    if (std::holds_alternative<Triangle>(e.shape))
      throw std::invalid_argument("composite: a Triangle element has no volume");
    PlacedElement p;
    p.exact = placed_moments(mass_properties(e.shape), e);
    p.polytope = element_polytope(e, resolution);
    p.planes = face_planes(p.polytope);
    const bool polyhedral =
        std::holds_alternative<Box>(e.shape) || std::holds_alternative<ConvexPolyhedron>(e.shape);
    p.missing_volume = polyhedral ? 0.0 : p.exact.volume - volume_moments(p.polytope).volume;
    placed.push_back(std::move(p));
  }
  return placed;
}

struct UnionSum {
  double volume = 0.0;
  Vec3 first;
  Mat3 second;
  double error_bound = 0.0;

  void add(double sign, const VolumeMoments& m) {
    volume += sign * m.volume;
    first += sign * m.first;
    second = second + sign * m.second;
  }
};

// Inclusion-exclusion, depth first: `current` is the intersection of the
// elements chosen so far (the last being `last`), with sign (-1)^(k+1).
void add_intersections(const std::vector<PlacedElement>& elements, const Polytope& current,
                       std::size_t last, double sign, double missing, double tolerance,
                       UnionSum& sum) {
  for (std::size_t j = last + 1; j < elements.size(); ++j) {
    const Polytope next = clip(current, elements[j].planes, tolerance);
    if (next.empty()) continue;
    const VolumeMoments m = volume_moments(next);
    if (!(m.volume > 0.0)) continue;
    sum.add(-sign, m);
    sum.error_bound += missing + elements[j].missing_volume;
    add_intersections(elements, next, j, -sign, missing + elements[j].missing_volume, tolerance,
                      sum);
  }
}

UnionSum union_moments(const std::vector<CompositeElement>& elements, int resolution) {
  const std::vector<PlacedElement> placed = place(elements, resolution);
  double size = 0.0;
  for (const PlacedElement& p : placed)
    for (const Vec3& v : p.polytope.vertices) size = std::max(size, norm(v));
  const double tolerance = 1e-12 * size;
  UnionSum sum;
  for (std::size_t i = 0; i < placed.size(); ++i) {
    sum.add(1.0, placed[i].exact);
    add_intersections(placed, placed[i].polytope, i, 1.0, placed[i].missing_volume, tolerance, sum);
  }
  return sum;
}

}  // namespace

MassProperties from_moments(double volume, const Vec3& first, const Mat3& second) {
  MassProperties mp;
  mp.volume = volume;
  mp.centroid = first / volume;
  const Mat3 about_centroid = second - volume * outer(mp.centroid, mp.centroid);
  mp.inertia_about_centroid = inertia_from_second_moment(about_centroid);
  set_principal_axes(mp);
  return mp;
}

MassProperties mass_properties(const ConvexShape& shape) {
  return std::visit(ClosedForm{}, shape);
}

MassProperties composite_mass_properties(const std::vector<CompositeElement>& elements,
                                         int curved_resolution) {
  const UnionSum sum = union_moments(elements, curved_resolution);
  return from_moments(sum.volume, sum.first, sum.second);
}

double composite_volume_error_bound(const std::vector<CompositeElement>& elements,
                                    int curved_resolution) {
  return union_moments(elements, curved_resolution).error_bound;
}

Composite cross_particle(double length, double width, double thickness) {
  if (!(length > 0.0 && width > 0.0 && thickness > 0.0))
    throw std::invalid_argument("cross_particle: length, width and thickness must be > 0");
  const double l = 0.5 * length, w = 0.5 * width, t = 0.5 * thickness;
  return {{Box{{l, w, t}}, {}, {}}, {Box{{w, l, t}}, {}, {}}};
}

}  // namespace sanguis::geometry
