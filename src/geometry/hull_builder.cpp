#include "geometry/hull_builder.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>
#include <string>

#include "geometry/predicates.hpp"

namespace sanguis::geometry::detail {

std::uint32_t HullBuilder::add_vertex(const Vec3& p) {
  points_.push_back(p);
  return static_cast<std::uint32_t>(points_.size() - 1);
}

// The normal is taken at the corner opposite the longest edge: the cross
// product of the two shorter edges loses the fewest digits for slivers.
void HullBuilder::set_plane(Face& f) const {
  const Vec3& a = points_[f.vertex[0]];
  const Vec3& b = points_[f.vertex[1]];
  const Vec3& c = points_[f.vertex[2]];
  const double ab = norm2(b - a), bc = norm2(c - b), ca = norm2(a - c);
  Vec3 n;
  if (ab >= bc && ab >= ca)
    n = cross(a - c, b - c);
  else if (bc >= ca)
    n = cross(b - a, c - a);
  else
    n = cross(c - b, a - b);
  const double length = norm(n);
  if (!(length > 0.0) || !std::isfinite(length)) {  // degenerate: never visible
    f.normal = {};
    f.offset = 0.0;
    return;
  }
  f.normal = n / length;
  f.offset = (dot(f.normal, a) + dot(f.normal, b) + dot(f.normal, c)) / 3.0;
}

bool HullBuilder::sees(std::uint32_t face, const Vec3& p) const {
  const auto& v = faces_[face].vertex;
  return orientation(points_[v[0]], points_[v[1]], points_[v[2]], p) > 0;
}

void HullBuilder::start(std::uint32_t a, std::uint32_t b, std::uint32_t c, std::uint32_t d) {
  const Vec3 &pa = points_[a], &pb = points_[b], &pc = points_[c], &pd = points_[d];
  if (orientation(pa, pb, pc, pd) > 0) std::swap(b, c);  // d behind (a, b, c)
  faces_.clear();
  faces_.resize(4);
  faces_[0].vertex = {a, b, c};
  faces_[1].vertex = {b, a, d};
  faces_[2].vertex = {c, b, d};
  faces_[3].vertex = {a, c, d};
  faces_[0].neighbour = {1, 2, 3};
  faces_[1].neighbour = {0, 3, 2};
  faces_[2].neighbour = {0, 1, 3};
  faces_[3].neighbour = {0, 2, 1};
  for (Face& f : faces_) set_plane(f);
}

bool HullBuilder::collect_visible(std::uint32_t p, std::uint32_t seed) {
  if (++stamp_ == 0) {  // wrapped around: forget all stamps
    std::fill(visible_stamp_.begin(), visible_stamp_.end(), 0u);
    std::fill(hidden_stamp_.begin(), hidden_stamp_.end(), 0u);
    std::fill(vertex_stamp_.begin(), vertex_stamp_.end(), 0u);
    stamp_ = 1;
  }
  visible_stamp_.resize(faces_.size(), 0u);
  hidden_stamp_.resize(faces_.size(), 0u);
  visible_.clear();
  horizon_.clear();
  stack_.clear();
  const Vec3& eye = points_[p];
  if (!faces_[seed].alive || !sees(seed, eye)) return false;
  visible_stamp_[seed] = stamp_;
  visible_.push_back(seed);
  stack_.push_back(seed);
  while (!stack_.empty()) {
    const std::uint32_t f = stack_.back();
    stack_.pop_back();
    for (int e = 0; e < 3; ++e) {
      const std::uint32_t g = faces_[f].neighbour[e];
      if (visible_stamp_[g] == stamp_) continue;
      if (hidden_stamp_[g] != stamp_ && sees(g, eye)) {
        visible_stamp_[g] = stamp_;
        visible_.push_back(g);
        stack_.push_back(g);
      } else {
        hidden_stamp_[g] = stamp_;
        horizon_.push_back({f, e});
      }
    }
  }
  return true;
}

// The horizon edges, each from vertex[edge] to vertex[edge + 1] of a visible
// face, must chain into exactly one loop through distinct vertices.
bool HullBuilder::horizon_is_simple_loop() {
  vertex_stamp_.resize(points_.size(), 0u);
  starts_at_.resize(points_.size());
  ends_at_.resize(points_.size());
  const auto start_of = [this](const HorizonEdge& h) { return faces_[h.face].vertex[h.edge]; };
  const auto end_of = [this](const HorizonEdge& h) {
    return faces_[h.face].vertex[(h.edge + 1) % 3];
  };
  for (std::uint32_t i = 0; i < horizon_.size(); ++i) {
    const std::uint32_t a = start_of(horizon_[i]);
    if (vertex_stamp_[a] == stamp_) return false;  // the loop pinches at a
    vertex_stamp_[a] = stamp_;
    starts_at_[a] = i;
  }
  std::uint32_t i = 0;
  for (std::size_t steps = 1; steps <= horizon_.size(); ++steps) {
    const std::uint32_t b = end_of(horizon_[i]);
    if (vertex_stamp_[b] != stamp_) return false;
    i = starts_at_[b];
    if (i == 0) return steps == horizon_.size();
  }
  return false;
}

void HullBuilder::cone_horizon(std::uint32_t p) {
  created_.clear();
  for (const HorizonEdge& h : horizon_) {
    const std::uint32_t a = faces_[h.face].vertex[h.edge];
    const std::uint32_t b = faces_[h.face].vertex[(h.edge + 1) % 3];
    const std::uint32_t g = faces_[h.face].neighbour[h.edge];
    const auto id = static_cast<std::uint32_t>(faces_.size());
    Face face;
    face.vertex = {a, b, p};
    face.neighbour = {g, 0, 0};
    set_plane(face);
    faces_.push_back(face);
    Face& hidden = faces_[g];  // its edge b -> a now borders the new face
    for (int k = 0; k < 3; ++k)
      if (hidden.vertex[k] == b && hidden.vertex[(k + 1) % 3] == a) hidden.neighbour[k] = id;
    starts_at_[a] = id;
    ends_at_[b] = id;
    created_.push_back(id);
  }
  for (const std::uint32_t id : created_) {
    Face& face = faces_[id];
    face.neighbour[1] = starts_at_[face.vertex[1]];  // across b -> p: the face (b, c, p)
    face.neighbour[2] = ends_at_[face.vertex[0]];    // across p -> a: the face (z, a, p)
  }
  for (const std::uint32_t f : visible_) faces_[f].alive = false;
}

bool HullBuilder::add_point(std::uint32_t p, std::uint32_t seed) {
  if (!collect_visible(p, seed) || !horizon_is_simple_loop()) {
    visible_.clear();
    return false;
  }
  cone_horizon(p);
  return true;
}

std::vector<std::uint32_t> alive_faces(const HullBuilder& hull) {
  std::vector<std::uint32_t> alive;
  for (std::uint32_t f = 0; f < hull.faces().size(); ++f)
    if (hull.faces()[f].alive) alive.push_back(f);
  return alive;
}

// ---------------------------------------------------------------- Quickhull

namespace {

[[noreturn]] void degenerate(const std::string& what, std::size_t count, double tolerance) {
  throw std::invalid_argument("convex hull: the " + std::to_string(count) + " points are " + what +
                              " (within tolerance " + std::to_string(tolerance) +
                              "); a convex polyhedron needs a volume");
}

// Four points spanning the largest tetrahedron we can find cheaply: the two
// farthest apart among the six axis extremes, the farthest from their line,
// the farthest from the plane of the three.
std::array<std::uint32_t, 4> initial_tetrahedron(const HullBuilder& hull) {
  const std::size_t n = hull.point_count();
  const double tol = hull.tolerance();
  std::array<std::uint32_t, 6> extreme{};
  for (std::uint32_t i = 1; i < n; ++i)
    for (int k = 0; k < 3; ++k) {
      if (hull.point(i)[k] < hull.point(extreme[2 * k])[k]) extreme[2 * k] = i;
      if (hull.point(i)[k] > hull.point(extreme[2 * k + 1])[k]) extreme[2 * k + 1] = i;
    }
  std::uint32_t i0 = 0, i1 = 0;
  double widest = -1.0;
  for (int s = 0; s < 6; ++s)
    for (int t = s + 1; t < 6; ++t) {
      const double d2 = norm2(hull.point(extreme[s]) - hull.point(extreme[t]));
      if (d2 > widest) {
        widest = d2;
        i0 = extreme[s];
        i1 = extreme[t];
      }
    }
  if (!(std::sqrt(widest) > tol)) degenerate("coincident", n, tol);
  const Vec3 p0 = hull.point(i0);
  const Vec3 axis = (hull.point(i1) - p0) / std::sqrt(widest);
  std::uint32_t i2 = 0;
  double farthest = -1.0;
  for (std::uint32_t i = 0; i < n; ++i) {
    const double d2 = norm2(cross(hull.point(i) - p0, axis));
    if (d2 > farthest) {
      farthest = d2;
      i2 = i;
    }
  }
  if (!(std::sqrt(farthest) > tol)) degenerate("collinear", n, tol);
  const Vec3 normal = cross(hull.point(i1) - p0, hull.point(i2) - p0);
  const Vec3 unit = normal / norm(normal);
  std::uint32_t i3 = 0;
  farthest = -1.0;
  for (std::uint32_t i = 0; i < n; ++i) {
    const double d = std::abs(dot(hull.point(i) - p0, unit));
    if (d > farthest) {
      farthest = d;
      i3 = i;
    }
  }
  if (!(farthest > tol)) degenerate("coplanar", n, tol);
  return {i0, i1, i2, i3};
}

// Assigns each point to the candidate face it is farthest above (by more than
// the tolerance, and seeing it exactly); points above none are inside within
// the tolerance and dropped.
void assign_outside(const HullBuilder& hull, const std::vector<std::uint32_t>& points,
                    const std::vector<std::uint32_t>& candidates,
                    std::vector<std::vector<std::uint32_t>>& outside) {
  for (const std::uint32_t q : points) {
    double best = hull.tolerance();
    std::uint32_t best_face = std::numeric_limits<std::uint32_t>::max();
    for (const std::uint32_t f : candidates) {
      const double d = hull.distance(f, hull.point(q));
      if (d > best && hull.sees(f, hull.point(q))) {
        best = d;
        best_face = f;
      }
    }
    if (best_face != std::numeric_limits<std::uint32_t>::max()) outside[best_face].push_back(q);
  }
}

// Adds the farthest outside point of face f. Refused points (inconsistent
// visibility) are set aside in `deferred`.
void expand_face(HullBuilder& hull, std::uint32_t f,
                 std::vector<std::vector<std::uint32_t>>& outside, std::vector<std::uint32_t>& work,
                 std::vector<std::uint32_t>& deferred) {
  std::vector<std::uint32_t>& candidates = outside[f];
  const auto farthest =
      std::max_element(candidates.begin(), candidates.end(), [&](std::uint32_t p, std::uint32_t q) {
        return hull.distance(f, hull.point(p)) < hull.distance(f, hull.point(q));
      });
  const std::uint32_t eye = *farthest;
  if (!hull.add_point(eye, f)) {
    candidates.erase(farthest);
    deferred.push_back(eye);
    if (!candidates.empty()) work.push_back(f);
    return;
  }
  std::vector<std::uint32_t> orphans;
  for (const std::uint32_t r : hull.removed_faces()) {
    for (const std::uint32_t q : outside[r])
      if (q != eye) orphans.push_back(q);
    outside[r].clear();
    outside[r].shrink_to_fit();
  }
  outside.resize(hull.faces().size());
  assign_outside(hull, orphans, hull.created_faces(), outside);
  for (const std::uint32_t g : hull.created_faces())
    if (!outside[g].empty()) work.push_back(g);
}

// A refused point may be accepted once the hull around it has changed.
void retry_deferred(HullBuilder& hull, std::vector<std::uint32_t>& deferred) {
  for (bool progress = true; progress && !deferred.empty();) {
    progress = false;
    std::vector<std::uint32_t> still;
    for (const std::uint32_t q : deferred) {
      std::uint32_t seed = std::numeric_limits<std::uint32_t>::max();
      double best = hull.tolerance();
      for (const std::uint32_t f : alive_faces(hull)) {
        const double d = hull.distance(f, hull.point(q));
        if (d > best && hull.sees(f, hull.point(q))) {
          best = d;
          seed = f;
        }
      }
      if (seed == std::numeric_limits<std::uint32_t>::max()) continue;  // now inside
      if (hull.add_point(q, seed))
        progress = true;
      else
        still.push_back(q);
    }
    deferred.swap(still);
  }
}

}  // namespace

void quickhull(HullBuilder& hull) {
  if (hull.point_count() < 4)
    throw std::invalid_argument("convex hull: needs at least 4 points, got " +
                                std::to_string(hull.point_count()));
  const std::array<std::uint32_t, 4> tet = initial_tetrahedron(hull);
  hull.start(tet[0], tet[1], tet[2], tet[3]);
  std::vector<std::uint32_t> rest;
  for (std::uint32_t i = 0; i < hull.point_count(); ++i)
    if (std::find(tet.begin(), tet.end(), i) == tet.end()) rest.push_back(i);
  std::vector<std::vector<std::uint32_t>> outside(4);
  assign_outside(hull, rest, {0, 1, 2, 3}, outside);
  std::vector<std::uint32_t> work, deferred;
  for (std::uint32_t f = 0; f < 4; ++f)
    if (!outside[f].empty()) work.push_back(f);
  while (!work.empty()) {
    const std::uint32_t f = work.back();
    work.pop_back();
    if (hull.faces()[f].alive && !outside[f].empty()) expand_face(hull, f, outside, work, deferred);
  }
  retry_deferred(hull, deferred);
}

}  // namespace sanguis::geometry::detail
