#include "dem/dem_run.hpp"

#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <iomanip>
#include <iostream>
#include <memory>
#include <optional>
#include <sstream>

#include "core/error.hpp"
#include "core/io/atomic_file.hpp"
#include "core/io/csv.hpp"
#include "core/io/vtk.hpp"
#include "core/progress.hpp"
#include "dem/body_contacts.hpp"
#include "dem/domain_decomposition.hpp"

namespace sanguis::dem {

namespace {

const std::vector<std::string> kDiagnosticColumns = {"time_s",
                                                     "kinetic_energy_translational_J",
                                                     "kinetic_energy_rotational_J",
                                                     "mean_velocity_m_s",
                                                     "max_velocity_m_s",
                                                     "mean_angular_velocity_rad_s",
                                                     "particle_contacts",
                                                     "wall_contacts",
                                                     "max_overlap_over_radius"};

std::vector<double> diagnostic_row(const DemDiagnostics& d) {
  return {d.time,
          d.kinetic_energy_translational,
          d.kinetic_energy_rotational,
          d.mean_velocity,
          d.max_velocity,
          d.mean_angular_velocity,
          static_cast<double>(d.particle_contacts),
          static_cast<double>(d.wall_contacts),
          d.max_overlap_ratio};
}

// A sphere is one element for the narrow phase: its centre point with a crust equal to
// its radius (as in the simulation's force loop).
const geometry::ConvexShape kPointCore = geometry::Sphere{0.0};

struct ElementGeometry {
  const geometry::ConvexShape* core;
  geometry::Pose pose;  // space frame
  double crust;
};

ElementGeometry element_geometry(const ParticleStore& p, const std::vector<ParticleShape>& shapes,
                                 std::size_t i, std::size_t e, const Vec3& centre) {
  if (p.spherical[i]) return {&kPointCore, {centre, Quaternion{}}, p.radius[i]};
  const ShapeElement& el = shapes[static_cast<std::size_t>(p.species[i])].elements[e];
  return {&el.core, element_pose(el, centre, p.orientation[i]), el.crust};
}

// A point of an obstacle (given at t = 0) at its pose at time t.
Vec3 obstacle_point_at(const ObstacleMotion& m, double t, const Vec3& x) {
  if (m.is_static()) return x;
  return m.centre + m.offset_at(t) + rotate(m.rotation_at(t), x - m.centre);
}

io::DataArray vector_array(const char* name, const std::vector<Vec3>& values) {
  io::DataArray a{name, 3, {}};
  a.values.reserve(3 * values.size());
  for (const Vec3& v : values) a.values.insert(a.values.end(), {v.x, v.y, v.z});
  return a;
}

std::vector<std::int64_t> fixed_flags(const ParticleStore& p) {
  std::vector<std::int64_t> flags(p.size());
  for (std::size_t i = 0; i < p.size(); ++i) flags[i] = p.is_fixed(i) ? 1 : 0;
  return flags;
}

}  // namespace

io::PointCloud particle_cloud(const ParticleStore& p) {
  io::PointCloud cloud;
  cloud.points = p.position;
  cloud.point_data.push_back({"radius", 1, p.radius});
  cloud.point_data.push_back({"mass", 1, p.mass});
  cloud.point_data.push_back(vector_array("velocity", p.velocity));
  cloud.point_data.push_back(vector_array("angular_velocity", p.angular_velocity));
  cloud.point_data.push_back(vector_array("force", p.force));
  io::DataArray orientation{"orientation", 4, {}};
  orientation.values.reserve(4 * p.size());
  for (const Quaternion& q : p.orientation) {
    orientation.values.insert(orientation.values.end(), {q.w, q.x, q.y, q.z});
  }
  cloud.point_data.push_back(std::move(orientation));
  cloud.int_point_data = {
      {"id", 1, {p.id.begin(), p.id.end()}},
      {"coordination", 1, {p.coordination.begin(), p.coordination.end()}},
      {"material", 1, {p.material.begin(), p.material.end()}},
      {"species", 1, {p.species.begin(), p.species.end()}},
      {"spherical", 1, {p.spherical.begin(), p.spherical.end()}},
      {"fixed", 1, fixed_flags(p)},
  };
  return cloud;
}

// Obstacles as polygons: boxes as their 6 faces, planes as a square patch covering the
// domain, so that ParaView shows the container, the gate lifting and disappearing.
io::PolyMesh obstacle_mesh(const DemSetup& s, double time) {
  io::PolyMesh mesh;
  std::vector<std::int64_t> ids;
  const auto add_quad = [&](const Vec3& a, const Vec3& b, const Vec3& c, const Vec3& d,
                            std::int64_t id) {
    const auto base = static_cast<std::int64_t>(mesh.points.size());
    mesh.points.insert(mesh.points.end(), {a, b, c, d});
    mesh.polygons.push_back({base, base + 1, base + 2, base + 3});
    ids.push_back(id);
  };
  const Vec3 centre = 0.5 * (s.domain.min + s.domain.max);
  const double half = 0.5 * norm(s.domain.max - s.domain.min);
  for (std::size_t o = 0; o < s.obstacles.size(); ++o) {
    const Obstacle& ob = s.obstacles[o];
    if (!ob.active(time)) continue;
    const ObstacleMotion& m = ob.motion;
    const auto id = static_cast<std::int64_t>(o);
    if (const auto* plane = std::get_if<PlaneShape>(&ob.shape)) {
      // The plane where it is at `time`; the patch axes are those at t = 0 turned with the
      // obstacle (no jump when the normal passes the helper's threshold), and the patch
      // stays centred on the domain: an infinite plane sliding along itself looks still.
      const Vec3 n0 = plane->normal;
      const Vec3 helper = std::abs(n0.x) < 0.9 ? Vec3{1, 0, 0} : Vec3{0, 1, 0};
      const Vec3 u0 = cross(n0, helper) / norm(cross(n0, helper));
      const Vec3 v0 = cross(n0, u0);
      const Vec3 n = m.direction_to_space(time, n0);
      const Vec3 u = m.direction_to_space(time, u0);
      const Vec3 v = m.direction_to_space(time, v0);
      const Vec3 point = obstacle_point_at(m, time, plane->point);
      const Vec3 c = centre - dot(centre - point, n) * n;
      add_quad(c - half * u - half * v, c + half * u - half * v, c + half * u + half * v,
               c - half * u + half * v, id);
    } else if (const auto* shaped = std::get_if<ShapeObstacle>(&ob.shape)) {
      for (const ObstacleElement& e : shaped->elements) {
        const geometry::TriangleMesh piece = geometry::tessellate(e.shape, 24);
        const Quaternion q = m.rotation_at(time) * e.orientation;
        const Vec3 origin = m.point_at(time, e.position);
        const auto base = static_cast<std::int64_t>(mesh.points.size());
        for (const Vec3& v : piece.vertices) mesh.points.push_back(origin + rotate(q, v));
        for (const auto& t : piece.triangles) {
          mesh.polygons.push_back({base + t[0], base + t[1], base + t[2]});
          ids.push_back(id);
        }
      }
    } else {
      const auto& b = std::get<AxisAlignedBoxShape>(ob.shape);
      Vec3 p[8] = {{b.min.x, b.min.y, b.min.z}, {b.max.x, b.min.y, b.min.z},
                   {b.max.x, b.max.y, b.min.z}, {b.min.x, b.max.y, b.min.z},
                   {b.min.x, b.min.y, b.max.z}, {b.max.x, b.min.y, b.max.z},
                   {b.max.x, b.max.y, b.max.z}, {b.min.x, b.max.y, b.max.z}};
      for (Vec3& corner : p) corner = obstacle_point_at(m, time, corner);
      const int faces[6][4] = {{0, 3, 2, 1}, {4, 5, 6, 7}, {0, 1, 5, 4},
                               {2, 3, 7, 6}, {1, 2, 6, 5}, {0, 4, 7, 3}};
      for (const auto& f : faces) add_quad(p[f[0]], p[f[1]], p[f[2]], p[f[3]], id);
    }
  }
  mesh.int_cell_data.push_back({"obstacle", 1, ids});
  return mesh;
}

// Whether the run has (or will have, by pouring) non-spherical particles: then it
// writes bodies.pvd from its first frame, so that every particle frame has its
// body surfaces.
bool has_bodies(const DemSetup& s, const ParticleStore& p) {
  return has_non_spherical(p) ||
         std::any_of(s.pour.begin(), s.pour.end(),
                     [](const PourSource& src) { return src.species >= 0; });
}

io::PolyMesh body_mesh(const std::vector<ParticleShape>& shapes, const ParticleStore& p) {
  io::PolyMesh mesh;
  io::IntDataArray ids{"id", 1, {}}, material{"material", 1, {}}, species{"species", 1, {}};
  io::DataArray velocity{"velocity", 3, {}};
  for (std::size_t i = 0; i < p.size(); ++i) {
    if (p.spherical[i]) continue;
    const geometry::TriangleMesh& surface = shapes.at(static_cast<std::size_t>(p.species[i])).mesh;
    const auto base = static_cast<std::int64_t>(mesh.points.size());
    for (const Vec3& x : surface.vertices) {
      mesh.points.push_back(p.position[i] + rotate(p.orientation[i], x));
    }
    const Vec3& v = p.velocity[i];
    for (const auto& t : surface.triangles) {
      mesh.polygons.push_back({base + t[0], base + t[1], base + t[2]});
      ids.values.push_back(p.id[i]);
      material.values.push_back(p.material[i]);
      species.values.push_back(p.species[i]);
      velocity.values.insert(velocity.values.end(), {v.x, v.y, v.z});
    }
  }
  mesh.int_cell_data = {std::move(ids), std::move(material), std::move(species)};
  mesh.cell_data = {std::move(velocity)};
  return mesh;
}

ParticleStore owned_particles(const DemSimulation& sim) {
  // In id order, whatever the storage order (see DemSetup::storage_sort_interval).
  const ParticleStore& p = sim.particles();
  if (sim.ghost_flags().empty() && std::is_sorted(p.id.begin(), p.id.end())) return p;
  ParticleStore owned;
  for (const std::uint32_t i : id_order(p.id)) {
    if (!sim.is_ghost(i)) owned.append_from(p, i);
  }
  return owned;
}

std::vector<ContactRecord> touching_contacts(const DemSimulation& sim) {
  const DemSetup& s = sim.setup();
  const ParticleStore& p = sim.particles();
  const auto& shapes = s.shapes;
  const double now = sim.time();
  const Domain& domain = s.domain;
  const bool periodic = domain.periodic[0] || domain.periodic[1] || domain.periodic[2];
  const std::vector<Vec3>& x = p.position;
  const std::vector<Vec3>& v = p.velocity;
  const std::vector<Vec3>& w = p.angular_velocity;
  const std::vector<double>& rad = p.radius;
  const auto params = [&](std::int32_t a, std::int32_t b) -> const ContactParameters& {
    return s.contacts.get(static_cast<std::size_t>(a), static_cast<std::size_t>(b));
  };
  // dt = 0: the stored history already holds this step's increments (see the header).
  const auto respond = [&](const ContactParameters& law, const ContactKinematics& c,
                           const ContactHistory& stored, ContactRecord& r) {
    ContactHistory h = stored;
    const ContactResponse response = evaluate_contact(law, c, h, 0.0);
    r.normal = c.normal;
    r.overlap = c.overlap;
    r.force = response.force;
    r.normal_force = response.normal_force;
  };
  // A blown-up state (the last snapshot of a failed run) may hold non-finite positions:
  // their contacts are left out rather than fed to GJK/EPA.
  const auto finite = [&](std::size_t i) {
    const Vec3& xi = x[i];
    const Quaternion& q = p.orientation[i];
    return std::isfinite(xi.x + xi.y + xi.z + q.w + q.x + q.y + q.z);
  };
  std::vector<ContactRecord> out;

  // Sphere pairs: contact point midway in the overlap on the line of centres.
  const ContactList& pairs = sim.particle_contacts();
  for (std::size_t k = 0; k < pairs.size(); ++k) {
    const std::uint32_t i = pairs.first[k], j = pairs.second[k];
    if (!finite(i) || !finite(j) || sim.is_ghost(i)) continue;  // ghost first: another's share
    Vec3 d = x[j] - x[i];
    if (periodic) d = domain.near_image(d);
    const double sum_r = rad[i] + rad[j];
    const double dist2 = norm2(d);
    if (dist2 > sum_r * sum_r) continue;
    const double dist = std::sqrt(dist2);
    ContactKinematics c;
    c.normal = dist > 0.0 ? (1.0 / dist) * d : Vec3{0.0, 0.0, 1.0};
    c.overlap = sum_r - dist;
    const double a_i = rad[i] - 0.5 * c.overlap;
    const double a_j = rad[j] - 0.5 * c.overlap;
    c.relative_velocity = (v[i] - v[j]) + cross(a_i * w[i] + a_j * w[j], c.normal);
    c.relative_angular_velocity = w[i] - w[j];
    c.reduced_radius = rad[i] * rad[j] / sum_r;
    ContactRecord r;
    r.kind = ContactKind::kSpherePair;
    r.first = i;
    r.second = j;
    r.point = x[i] + a_i * c.normal;
    r.first_centre = x[i];
    r.second_centre = x[i] + d;
    respond(params(p.material[i], p.material[j]), c, pairs.history[k], r);
    out.push_back(r);
  }

  // Spheres on obstacles at their pose at `now`.
  const ContactList& walls = sim.wall_contacts();
  for (std::size_t k = 0; k < walls.size(); ++k) {
    const std::uint32_t i = walls.first[k];
    const Obstacle& obstacle = s.obstacles[walls.second[k]];
    if (!obstacle.active(now) || !finite(i)) continue;
    const SphereObstacleGap gap = sphere_gap(obstacle, now, x[i], rad[i]);
    if (gap.overlap < 0.0) continue;
    Vec3 arm_i;
    const ContactKinematics c =
        sphere_wall_kinematics(obstacle, now, x[i], v[i], w[i], rad[i], gap, arm_i);
    ContactRecord r;
    r.kind = ContactKind::kSphereWall;
    r.first = i;
    r.second = walls.second[k];
    r.point = x[i] + arm_i;
    r.first_centre = x[i];
    r.second_centre = r.point;
    respond(params(p.material[i], obstacle.material), c, walls.history[k], r);
    out.push_back(r);
  }

  // Element contacts: the simulation's narrow phase again, from the stored warm starts,
  // and its patch or point response (body_contacts.hpp) at dt = 0.
  const auto element_record = [&](const ContactParameters& law, std::size_t i,
                                  const ElementContact& ec, const geometry::ContactPatch* patch,
                                  const auto& other_velocity, const Vec3& other_omega,
                                  const Vec3* other_centre, const ContactHistory& stored,
                                  double stored_twist, ContactRecord& r) {
    ContactHistory h = stored;
    double twist = stored_twist;
    const ElementResponse e = element_contact_response(
        law, ec, patch, x[i], v[i], w[i], other_velocity, other_omega, other_centre, h, twist, 0.0);
    r.point = e.point;
    r.first_centre = x[i];
    r.second_centre = other_centre != nullptr ? *other_centre : e.point;
    r.normal = ec.normal;
    r.overlap = e.overlap;
    r.force = e.response.force;
    r.normal_force = e.response.normal_force;
  };
  // With mean_element_contacts each element contact applied its share of the mean over the
  // element contacts of its two bodies (simulation.cpp): records [from, end), consecutive
  // per pair of bodies or body and obstacle (list order), divided by how many there are.
  const auto share_the_mean = [&out, &s](std::size_t from) {
    if (!s.mean_element_contacts) return;
    for (std::size_t a = from; a < out.size();) {
      std::size_t b = a + 1;
      while (b < out.size() && out[b].first == out[a].first && out[b].second == out[a].second) {
        ++b;
      }
      const double share = 1.0 / static_cast<double>(b - a);
      for (std::size_t k = a; k < b; ++k) {  // share 1 for a single contact: unchanged
        out[k].force *= share;
        out[k].normal_force *= share;
      }
      a = b;
    }
  };
  const BodyContactList& body_pairs = sim.body_contacts();
  const std::size_t body_pairs_from = out.size();
  for (std::size_t k = 0; k < body_pairs.size(); ++k) {
    const std::uint32_t i = body_pairs.first[k], j = body_pairs.second[k];
    if (!finite(i) || !finite(j) || sim.is_ghost(i)) continue;
    Vec3 d = x[j] - x[i];
    if (periodic) d = domain.near_image(d);
    const Vec3 xj = x[i] + d;
    const ElementGeometry a = element_geometry(p, shapes, i, body_pairs.element_first[k], x[i]);
    const ElementGeometry b = element_geometry(p, shapes, j, body_pairs.element_second[k], xj);
    geometry::GjkWarmStart warm = body_pairs.warm[k];
    const ElementContact ec =
        element_pair_contact(*a.core, a.pose, a.crust, *b.core, b.pose, b.crust, &warm);
    if (!ec.touching) continue;
    const auto patch = s.contact_patches ? element_pair_patch(*a.core, a.pose, a.crust, *b.core,
                                                              b.pose, b.crust, ec)
                                         : std::nullopt;
    ContactRecord r;
    r.kind = ContactKind::kBodyPair;
    r.first = i;
    r.second = j;
    const auto vj = [&](const Vec3& point) { return v[j] + cross(w[j], point - xj); };
    element_record(params(p.material[i], p.material[j]), i, ec, patch ? &*patch : nullptr, vj, w[j],
                   &xj, body_pairs.history[k], body_pairs.twist[k], r);
    out.push_back(r);
  }

  share_the_mean(body_pairs_from);
  const BodyContactList& body_walls = sim.body_wall_contacts();
  const std::size_t body_walls_from = out.size();
  for (std::size_t k = 0; k < body_walls.size(); ++k) {
    const std::uint32_t i = body_walls.first[k];
    const Obstacle& obstacle = s.obstacles[body_walls.second[k]];
    if (!obstacle.active(now) || !finite(i)) continue;
    const ElementGeometry a = element_geometry(p, shapes, i, body_walls.element_first[k], x[i]);
    const ObstacleMotion& m = obstacle.motion;
    geometry::GjkWarmStart warm = body_walls.warm[k];
    const ElementContact ec = element_obstacle_contact(obstacle, body_walls.element_second[k], now,
                                                       *a.core, a.pose, a.crust, &warm);
    if (!ec.touching) continue;
    const auto patch = s.contact_patches
                           ? element_obstacle_patch(obstacle, body_walls.element_second[k], now,
                                                    *a.core, a.pose, a.crust, ec)
                           : std::nullopt;
    ContactRecord r;
    r.kind = ContactKind::kBodyWall;
    r.first = i;
    r.second = body_walls.second[k];
    const auto wall_velocity = [&](const Vec3& point) {
      return m.is_static() ? Vec3{} : m.velocity_at(now, point);
    };
    const Vec3 wall_omega = m.rotation.moving() ? m.rotation.speed_at(now) * m.axis : Vec3{};
    element_record(params(p.material[i], obstacle.material), i, ec, patch ? &*patch : nullptr,
                   wall_velocity, wall_omega, nullptr, body_walls.history[k], body_walls.twist[k],
                   r);
    out.push_back(r);
  }
  share_the_mean(body_walls_from);
  // A pair is reported from its particle of smaller id: the storage order, which orients
  // the lists, changes at each storage sort, and outputs must not flip with it.
  for (ContactRecord& r : out) {
    const bool pair = r.kind == ContactKind::kSpherePair || r.kind == ContactKind::kBodyPair;
    if (!pair || p.id[r.first] < p.id[r.second]) continue;
    std::swap(r.first, r.second);
    std::swap(r.first_centre, r.second_centre);  // the same segment, the other way
    r.normal = -r.normal;
    r.force = -r.force;
  }
  return out;
}

ContactNetwork contact_network(const DemSimulation& sim) {
  const ParticleStore& p = sim.particles();
  const std::vector<ContactRecord> contacts = touching_contacts(sim);
  ContactNetwork net;

  io::PointCloud& points = net.points;
  io::DataArray force{"force", 3, {}}, normal_force{"normal_force", 1, {}},
      overlap{"overlap", 1, {}};
  io::IntDataArray kind{"kind", 1, {}}, first_id{"first_id", 1, {}}, second_id{"second_id", 1, {}};
  const auto second_label = [&](const ContactRecord& r) -> std::int64_t {
    const bool wall = r.kind == ContactKind::kSphereWall || r.kind == ContactKind::kBodyWall;
    return wall ? static_cast<std::int64_t>(r.second) : p.id[r.second];
  };
  for (const ContactRecord& r : contacts) {
    points.points.push_back(r.point);
    force.values.insert(force.values.end(), {r.force.x, r.force.y, r.force.z});
    normal_force.values.push_back(r.normal_force);
    overlap.values.push_back(r.overlap);
    kind.values.push_back(static_cast<std::int64_t>(r.kind));
    first_id.values.push_back(p.id[r.first]);
    second_id.values.push_back(second_label(r));
  }
  points.point_data = {std::move(force), std::move(normal_force), std::move(overlap)};
  points.int_point_data = {std::move(kind), std::move(first_id), std::move(second_id)};

  // Branch vectors of the touching particle pairs. Element contacts of one pair are
  // consecutive in the list (sorted by first, second, elements): summed into one line.
  io::PolyMesh& lines = net.branches;
  io::DataArray magnitude{"force_magnitude", 1, {}}, line_normal{"normal_force", 1, {}};
  io::IntDataArray line_kind{"kind", 1, {}}, line_first{"first_id", 1, {}},
      line_second{"second_id", 1, {}};
  for (std::size_t k = 0; k < contacts.size();) {
    const ContactRecord& r = contacts[k];
    if (r.kind == ContactKind::kSphereWall || r.kind == ContactKind::kBodyWall) {
      ++k;
      continue;
    }
    Vec3 total = r.force;
    double fn = r.normal_force;
    std::size_t next = k + 1;
    while (r.kind == ContactKind::kBodyPair && next < contacts.size() &&
           contacts[next].kind == ContactKind::kBodyPair && contacts[next].first == r.first &&
           contacts[next].second == r.second) {
      total += contacts[next].force;
      fn += contacts[next].normal_force;
      ++next;
    }
    const auto base = static_cast<std::int64_t>(lines.points.size());
    lines.points.insert(lines.points.end(), {r.first_centre, r.second_centre});
    lines.lines.push_back({base, base + 1});
    magnitude.values.push_back(norm(total));
    line_normal.values.push_back(fn);
    line_kind.values.push_back(static_cast<std::int64_t>(r.kind));
    line_first.values.push_back(p.id[r.first]);
    line_second.values.push_back(p.id[r.second]);
    k = next;
  }
  lines.cell_data = {std::move(magnitude), std::move(line_normal)};
  lines.int_cell_data = {std::move(line_kind), std::move(line_first), std::move(line_second)};
  return net;
}

namespace {

// One frame = one file per data set, each with its .pvd index: particles, obstacles,
// contacts (points) and branches (lines), and bodies when the case has non-spherical
// particles (fixed for a run: particles never change shape).
class SnapshotWriter {
 public:
  // With several processes each writes its piece (`_rN` files) and the first one the
  // indexes, with one part per process at each time (a multiblock dataset in ParaView).
  SnapshotWriter(const std::filesystem::path& dir, bool enabled, bool bodies, bool restart,
                 double t, int rank = 0, int ranks = 1)
      : dir_(dir), enabled_(enabled), bodies_(bodies), rank_(rank), ranks_(ranks) {
    if (!enabled_) return;
    const std::vector<std::string> names =
        bodies_
            ? std::vector<std::string>{"particles", "obstacles", "contacts", "branches", "bodies"}
            : std::vector<std::string>{"particles", "obstacles", "contacts", "branches"};
    for (const std::string& name : names) {
      std::filesystem::create_directories(dir / (name == "branches" ? "contacts" : name));
      series_.emplace_back(dir / (name + ".pvd"));
      if (restart) series_.back().load_existing(t);
    }
    if (restart) {
      // One entry per frame, or one per process and frame (part 0 starts each frame).
      const auto& entries = series_[0].entries();
      next_frame_ = std::count_if(entries.begin(), entries.end(),
                                  [](const io::PvdIndex::Entry& e) { return e.part == 0; });
    }
  }

  // Frames are numbered in the order they are written (not by time), so an extra
  // snapshot (end time off the output grid, a blow-up) never overwrites another.
  void write(const DemSimulation& sim) {
    if (!enabled_) return;
    char number[64];
    std::snprintf(number, sizeof number, "%08lld", static_cast<long long>(next_frame_++));
    const auto piece = [&](int r) {
      return ranks_ == 1 ? std::string(number) : std::string(number) + "_r" + std::to_string(r);
    };
    const auto files = [&](int r) {
      return std::vector<std::string>{
          "particles/particles_" + piece(r) + ".vtu", "obstacles/obstacles_" + piece(0) + ".vtp",
          "contacts/contacts_" + piece(r) + ".vtu", "contacts/branches_" + piece(r) + ".vtp",
          "bodies/bodies_" + piece(r) + ".vtp"};
    };
    const std::vector<std::string> mine = files(rank_);
    const ParticleStore owned = owned_particles(sim);
    io::write_point_cloud_vtu(dir_ / mine[0], particle_cloud(owned));
    if (rank_ == 0) io::write_polymesh_vtp(dir_ / mine[1], obstacle_mesh(sim.setup(), sim.time()));
    const ContactNetwork net = contact_network(sim);
    io::write_point_cloud_vtu(dir_ / mine[2], net.points);
    io::write_polymesh_vtp(dir_ / mine[3], net.branches);
    if (bodies_) io::write_polymesh_vtp(dir_ / mine[4], body_mesh(sim.setup().shapes, owned));
    if (rank_ != 0) return;
    for (std::size_t k = 0; k < series_.size(); ++k) {
      const int parts = k == 1 ? 1 : ranks_;  // one obstacle file
      for (int r = 0; r < parts; ++r) series_[k].add(sim.time(), files(r)[k], r);
      series_[k].write();
    }
  }

 private:
  std::filesystem::path dir_;
  bool enabled_;
  bool bodies_;
  int rank_ = 0, ranks_ = 1;
  std::vector<io::PvdIndex> series_;  // in the order of the files of write()
  std::int64_t next_frame_ = 0;
};

// obstacles.csv: index, kind, removal time and name of each obstacle, so that the
// analysis tools can name the walls of the contacts (second_id of wall contacts is
// the obstacle index) and find the gate opening without the case file.
void write_obstacle_table(const std::filesystem::path& path,
                          const std::vector<Obstacle>& obstacles) {
  io::write_file_atomically(path, [&](std::ostream& out) {
    out << "index,type,remove_at_s,name\n";
    for (std::size_t k = 0; k < obstacles.size(); ++k) {
      const Obstacle& o = obstacles[k];
      const char* type = std::holds_alternative<PlaneShape>(o.shape)            ? "plane"
                         : std::holds_alternative<AxisAlignedBoxShape>(o.shape) ? "box"
                                                                                : "shape";
      char removal[32];
      std::snprintf(removal, sizeof removal, "%.17g", o.remove_at);
      out << k << "," << type << "," << removal << "," << o.name << "\n";
    }
  });
}

std::int64_t steps_for(double duration, double dt) {
  return std::max<std::int64_t>(1, std::llround(duration / dt));
}

// run.log's record of a checkpoint written on the way, in the form of the `done:`
// line (the time to 10 digits, the wall time of this segment so far).
std::string checkpoint_line(double time, std::int64_t steps, const ProgressReporter& progress) {
  std::ostringstream line;
  line << "checkpoint: t = " << std::setprecision(10) << time << " s, " << steps << " steps in "
       << ProgressReporter::format_duration(progress.elapsed_seconds()) << ", "
       << ProgressReporter::wall_clock_stamp() << "\n";
  return line.str();
}

}  // namespace

RunSummary run_dem_case(const DemCase& c, const RunOptions& options, std::ostream& console) {
  namespace fs = std::filesystem;
  const fs::path dir = options.output_dir;
  const fs::path checkpoint = dir / "checkpoint.bin";
  const fs::path csv_path = dir / "diagnostics.csv";
  int rank = 0, ranks = 1;
  if (options.comm != MPI_COMM_NULL) {
    MPI_Comm_rank(options.comm, &rank);
    MPI_Comm_size(options.comm, &ranks);
  }
  const bool root = rank == 0;
  if (options.restart && !fs::exists(checkpoint)) {
    throw InputError(checkpoint.string(), "", "no checkpoint to restart from");
  }

  // Several processes: each runs its slab of the domain (domain_decomposition.hpp).
  std::unique_ptr<SlabDecomposition> decomposition;
  if (ranks > 1) {
    try {
      decomposition = std::make_unique<SlabDecomposition>(options.comm);
    } catch (const std::invalid_argument& e) {
      throw InputError(c.source.string(), "", e.what());
    }
  }
  // The whole system on one process, for a decomposed run's restart (on every process)
  // and checkpoints (on the first): checkpoints are in the one-process format.
  std::unique_ptr<DemSimulation> whole;
  if (decomposition && options.restart) {
    whole = std::make_unique<DemSimulation>(c.setup);
    whole->load_checkpoint(checkpoint);
  }
  const auto local_setup = [&]() {
    try {
      DemSetup local = decomposition->local_setup(whole ? whole->setup() : c.setup);
      if (whole) local.start_step = whole->step_index();
      return local;
    } catch (const std::invalid_argument& e) {
      throw InputError(c.source.string(), "", e.what());
    }
  };
  DemSimulation sim(decomposition ? local_setup() : c.setup);
  if (decomposition && whole) {
    decomposition->attach_restart(sim, *whole);
  } else if (decomposition) {
    decomposition->attach(sim);
  }
  if (!root) whole.reset();
  const auto diagnostics = [&]() {
    return decomposition ? decomposition->diagnostics(sim) : sim.diagnostics();
  };
  const auto save_checkpoint = [&]() {
    if (!decomposition) {
      sim.save_checkpoint(checkpoint);
      return;
    }
    if (root && !whole) whole = std::make_unique<DemSimulation>(c.setup);
    decomposition->save_checkpoint(sim, whole.get(), checkpoint);
  };
  const double dt = sim.time_step();
  if (options.restart && !decomposition) sim.load_checkpoint(checkpoint);
  if (options.restart && root && fs::exists(csv_path)) {
    io::CsvWriter::truncate_after(csv_path, sim.time());
  }
  fs::create_directories(dir);

  // run.log: resolved parameters first, then events (first process only).
  std::ofstream log;
  if (root) {
    log = open_run_log(dir, options.restart, sim.time());
    log << describe(c);
    if (decomposition) {
      log << "domain decomposition: " << ranks << " MPI processes, slabs along "
          << "xyz"[decomposition->axis()] << "\n";
    }
    log << std::flush;
  }

  const std::int64_t total_steps = steps_for(c.stop.end_time, dt);
  const std::int64_t stop_step =
      options.stop_at >= 0 ? std::min(total_steps, steps_for(options.stop_at, dt)) : total_steps;
  const std::int64_t output_every = steps_for(c.output.interval, dt);
  const std::int64_t checkpoint_every =
      c.output.checkpoint_interval > 0 ? steps_for(c.output.checkpoint_interval, dt) : 0;
  const std::int64_t settle_after = std::llround(c.stop.settle_check_after / dt);

  if (root) write_obstacle_table(dir / "obstacles.csv", c.setup.obstacles);
  SnapshotWriter snapshots(dir, c.output.vtk, has_bodies(c.setup, c.setup.particles),
                           options.restart, sim.time(), rank, ranks);
  std::optional<io::CsvWriter> csv;
  if (root) csv.emplace(csv_path, kDiagnosticColumns, options.restart && fs::exists(csv_path));
  const auto record = [&]() {
    // Ghosts take their owners' end-of-step velocities: the contact forces written for
    // pairs across processes use them (the state the step leaves ghosts in is stale).
    if (decomposition) decomposition->refresh_ghosts(sim);
    snapshots.write(sim);
    const DemDiagnostics d = diagnostics();
    if (csv) csv->row(diagnostic_row(d));
  };
  if (!options.restart) record();

  // A decomposed run pours nothing: its count is fixed (summed once over the processes).
  long long decomposed_count = 0;
  if (decomposition) {
    decomposed_count = static_cast<long long>(sim.owned_count());
    MPI_Allreduce(MPI_IN_PLACE, &decomposed_count, 1, MPI_LONG_LONG, MPI_SUM, options.comm);
  }
  const auto particle_count = [&]() {
    return decomposition ? static_cast<std::size_t>(decomposed_count) : sim.particles().size();
  };
  if (root) {
    console << "sanguis run: " << c.name << ": " << particle_count() << " particles, "
            << total_steps << " steps of " << dt << " s, ";
    if (decomposition) console << ranks << " MPI processes, ";
    console << "output to " << dir.string() << "\n";
  }
  ProgressReporter progress(std::cerr, root && !options.quiet && isatty(STDERR_FILENO) != 0);
  const std::int64_t first_step = sim.step_index();
  double particle_steps = 0.0;  // summed per step: pouring changes the count

  RunSummary summary;
  try {
    while (sim.step_index() < stop_step) {
      sim.step();
      particle_steps += static_cast<double>(particle_count());
      const std::int64_t s = sim.step_index();
      const bool output_now = s % output_every == 0;
      if (output_now) record();
      if (checkpoint_every > 0 && s % checkpoint_every == 0) {
        save_checkpoint();
        // A run killed later continues from here (--restart): the line tells scripts
        // how far it got and what the kept part cost (validation/dem/_outputs.py).
        if (root) log << checkpoint_line(sim.time(), s - first_step, progress) << std::flush;
      }
      if (output_now && c.stop.mean_velocity_below && s >= settle_after &&
          diagnostics().mean_velocity < *c.stop.mean_velocity_below) {
        summary.settled = true;
        log << "settled at t = " << sim.time() << " s: mean velocity below "
            << *c.stop.mean_velocity_below << " m/s\n";
        break;
      }
      if (root && !options.quiet && (s & 255) == 0) {
        char status[128];
        std::snprintf(status, sizeof status, "t = %.4g / %.4g s", sim.time(), c.stop.end_time);
        progress.update(static_cast<double>(s) / static_cast<double>(total_steps), status,
                        particle_steps);
      }
    }
  } catch (const SimulationError& e) {
    // Keep what the run had: a last snapshot to look at, and the reason in the log.
    record();
    log << "ERROR: " << e.what() << "\nended by this error, "
        << ProgressReporter::wall_clock_stamp() << "\n";
    throw;
  }
  // A last record at the end time if it is off the output grid; not when stopping early
  // for a later restart, so that a split run writes exactly the rows of a whole one.
  const bool stopped_early = sim.step_index() < total_steps && !summary.settled;
  if (sim.step_index() % output_every != 0 && !stopped_early) record();
  save_checkpoint();

  summary.steps = sim.step_index() - first_step;
  summary.simulated_time = sim.time();
  summary.wall_seconds = progress.elapsed_seconds();
  summary.last = diagnostics();
  if (!root) return summary;
  std::ostringstream done;
  done.precision(4);
  // The time to 10 digits: scripts read it to tell a finished run from a stopped one
  // (validation/dem/_outputs.py), and 4 digits could round an end time down.
  done << "done: t = " << std::setprecision(10) << sim.time() << std::setprecision(4) << " s, "
       << summary.steps << " steps in " << ProgressReporter::format_duration(summary.wall_seconds)
       << " (" << (summary.wall_seconds > 0 ? particle_steps / summary.wall_seconds : 0.0)
       << " particle-steps/s), ended " << ProgressReporter::wall_clock_stamp()
       << (summary.settled ? ", settled" : "");
  progress.finish(done.str());
  log << done.str() << "\n";
  console << "outputs:\n"
          << "  ParaView    " << (dir / "particles.pvd").string()
          << "  (and obstacles.pvd, contacts.pvd, branches.pvd"
          << (has_bodies(c.setup, c.setup.particles) ? ", bodies.pvd" : "") << ")"
          << (decomposition ? ", one block per process" : "") << "\n"
          << "  diagnostics " << csv_path.string() << "\n"
          << "  log         " << (dir / "run.log").string() << "\n"
          << "  checkpoint  " << checkpoint.string() << "\n";
  return summary;
}

}  // namespace sanguis::dem
