#include "dem/dem_case.hpp"

#include <algorithm>
#include <cmath>
#include <map>
#include <numbers>
#include <random>
#include <set>
#include <sstream>

#include <omp.h>

#include "core/io/mesh_files.hpp"
#include "dem/insertion.hpp"
#include "geometry/convex_hull.hpp"

namespace sanguis::dem {

namespace {

constexpr double kPi = std::numbers::pi;

struct MaterialSpec {
  std::string name;
  std::optional<double> density;
  bool used_by_particles = false;
  bool used_by_mobile_particles = false;  // by a group that is not glued (fixed = true)
  bool used_by_obstacles = false;
  double radius_sum = 0.0;  // over particle groups, for the reference radius
  int groups = 0;
  double radius_min = std::numeric_limits<double>::infinity();
};

struct ParticleGroup {
  explicit ParticleGroup(ConfigTable t) : table(std::move(t)) {}
  ConfigTable table;
  std::size_t material = 0;
  double r_min = 0.0, r_max = 0.0;  // spheres; for bodies both are the bounding radius
  int shape = -1;                   // index into DemSetup::shapes, -1 for spheres
  double rate = 0.0, start = 0.0;   // pour: particles per second from `start` [s]
  bool random_orientation = true;   // bodies
  Quaternion orientation;           // bodies, when not random
  std::string arrangement;
  std::int64_t count = 0;
  Vec3 region_min, region_max;
  double spacing = 0.0;
  std::vector<Vec3> positions, velocities, angular_velocities;
  Vec3 velocity, angular_velocity;
  double velocity_noise = 0.0;
  bool fixed = false;  // glued in place (ParticleStore::fix)
};

double sphere_mass(double r, double density) {
  return 4.0 / 3.0 * kPi * r * r * r * density;
}

std::size_t material_index(const ConfigTable& t, const std::string& key,
                           const std::vector<MaterialSpec>& materials) {
  const std::string name = t.get_string(key);
  for (std::size_t m = 0; m < materials.size(); ++m) {
    if (materials[m].name == name) return m;
  }
  std::string known;
  for (const auto& m : materials) known += (known.empty() ? "" : ", ") + ("'" + m.name + "'");
  t.fail(key, "unknown material '" + name + "' (defined: " + known + ")");
}

void check_box(const ConfigTable& t, const Vec3& lo, const Vec3& hi, const std::string& hi_key) {
  for (int k = 0; k < 3; ++k) {
    if (!(hi[k] > lo[k])) t.fail(hi_key, "must be greater than the minimum corner on every axis");
  }
}

Vec3 parse_unit_vector(const ConfigTable& t, const std::string& key) {
  const Vec3 v = t.get_vec3(key);
  const double n = norm(v);
  if (!(n > 0.0)) t.fail(key, "must be a non-zero vector");
  return v / n;
}

// A speed law of an obstacle's translation ([m/s]) or rotation ([rad/s]).
SpeedLaw parse_speed_law(const ConfigTable& t, const std::string& speed_unit,
                         const std::string& acceleration_unit) {
  SpeedLaw law;
  const std::string kind = t.get_choice("law", {"constant", "ramp", "piecewise"});
  const std::string speed_key = "speed_" + speed_unit;
  if (kind == "constant") {
    law.kind = SpeedLaw::Kind::kConstant;
    law.speed = t.get_double(speed_key);
    law.start = t.get_non_negative("start_s", 0.0);
  } else if (kind == "ramp") {
    law.kind = SpeedLaw::Kind::kRamp;
    law.speed = t.get_double(speed_key);
    law.acceleration = t.get_positive("acceleration_" + acceleration_unit);
    if (law.speed < 0.0) {
      t.fail(speed_key, "a ramp's final speed must be >= 0 (reverse the direction instead)");
    }
    law.start = t.get_non_negative("start_s", 0.0);
  } else {
    law.kind = SpeedLaw::Kind::kPiecewise;
    const std::string key = "points_s_" + speed_unit;
    for (const auto& row : t.get_number_rows(key, 2)) {
      if (!law.points.empty() && !(row[0] > law.points.back().first)) {
        t.fail(key, "times must increase strictly");
      }
      law.points.emplace_back(row[0], row[1]);
    }
    if (law.points.empty()) t.fail(key, "needs at least one [time, speed] point");
  }
  return law;
}

Quaternion parse_rotation(const ConfigTable& t);

// Shape obstacles are placed by `position_m` and an optional rotation.
void place_elements(const ConfigTable& t, std::vector<ObstacleElement>& elements) {
  const Vec3 position = t.get_vec3("position_m", {});
  const Quaternion rotation = parse_rotation(t);
  for (ObstacleElement& e : elements) {
    e.position = position + rotate(rotation, e.position);
    e.orientation = normalized(rotation * e.orientation);
  }
}

Obstacle parse_obstacle(const ConfigTable& t, std::vector<MaterialSpec>& materials,
                        std::size_t index, const std::vector<ParticleShape>& shapes,
                        const std::vector<geometry::Composite>& raw_shapes,
                        const std::filesystem::path& source) {
  Obstacle o;
  o.name = t.get_string("name", "obstacle" + std::to_string(index));
  const std::size_t m = material_index(t, "material", materials);
  o.material = static_cast<std::int32_t>(m);
  materials[m].used_by_obstacles = true;
  const std::string type = t.get_choice("type", {"plane", "box", "shape", "mesh"});
  if (type == "shape") {
    const std::string name = t.get_string("shape");
    ShapeObstacle shaped;
    for (std::size_t k = 0; k < shapes.size(); ++k) {
      if (shapes[k].name != name) continue;
      for (const geometry::CompositeElement& e : raw_shapes[k]) {
        shaped.elements.push_back({e.shape, e.position, e.orientation});
      }
    }
    if (shaped.elements.empty())
      t.fail("shape", "unknown shape '" + name + "' (define it in [[shape]])");
    place_elements(t, shaped.elements);
    o.shape = std::move(shaped);
  } else if (type == "mesh") {
    // A triangulated surface (STL or OBJ): each triangle is an element.
    std::filesystem::path file = t.get_string("file");
    if (file.is_relative()) file = source.parent_path() / file;
    io::SurfaceMesh mesh;
    try {
      mesh = io::read_surface_mesh(file);
    } catch (const std::runtime_error& e) {
      t.fail("file", e.what());
    }
    if (mesh.triangles.empty() || mesh.triangles.size() > 65535) {
      t.fail("file", "needs 1 to 65535 triangles, has " + std::to_string(mesh.triangles.size()));
    }
    const double scale = t.get_positive("scale", 1.0);
    ShapeObstacle shaped;
    for (const auto& tri : mesh.triangles) {
      shaped.elements.push_back(
          {geometry::Triangle{scale * mesh.vertices[tri[0]], scale * mesh.vertices[tri[1]],
                              scale * mesh.vertices[tri[2]]},
           {},
           {}});
    }
    place_elements(t, shaped.elements);
    o.shape = std::move(shaped);
  } else if (type == "plane") {
    PlaneShape plane;
    plane.point = t.get_vec3("point_m");
    plane.normal = t.get_vec3("normal");
    const double len = norm(plane.normal);
    if (!(len > 0.0)) t.fail("normal", "must be a non-zero vector");
    plane.normal = plane.normal / len;
    o.shape = plane;
  } else {
    AxisAlignedBoxShape box;
    box.min = t.get_vec3("min_m");
    box.max = t.get_vec3("max_m");
    check_box(t, box.min, box.max, "max_m");
    o.shape = box;
  }
  if (t.has("remove_at_s")) o.remove_at = t.get_non_negative("remove_at_s", 0.0);
  if (auto tr = t.find_table("translation")) {
    o.motion.direction = parse_unit_vector(*tr, "direction");
    o.motion.translation = parse_speed_law(*tr, "m_s", "m_s2");
  }
  if (auto rot = t.find_table("rotation")) {
    o.motion.axis = parse_unit_vector(*rot, "axis");
    o.motion.centre = rot->get_vec3("centre_m");
    o.motion.rotation = parse_speed_law(*rot, "rad_s", "rad_s2");
  }
  return o;
}

// Uniformly distributed orientation (normalised 4D Gaussian, Shoemake).
Quaternion random_orientation(std::mt19937_64& rng) {
  std::normal_distribution<double> gauss(0.0, 1.0);
  Quaternion q{gauss(rng), gauss(rng), gauss(rng), gauss(rng)};
  return normalized(q);
}

Quaternion parse_rotation(const ConfigTable& t) {
  if (!t.has("rotation_axis") && !t.has("rotation_angle_deg")) return {};
  const Vec3 axis = t.get_vec3("rotation_axis", {0.0, 0.0, 1.0});
  if (!(norm(axis) > 0.0)) t.fail("rotation_axis", "must be a non-zero vector");
  return Quaternion::from_axis_angle(
      axis, t.get_double("rotation_angle_deg", 0.0) * std::numbers::pi / 180.0);
}

// One convex element: type and its dimensions.
geometry::ConvexShape parse_convex(const ConfigTable& t, const std::filesystem::path& source) {
  const std::string type =
      t.get_choice("type", {"box", "cylinder", "cone", "ellipsoid", "polyhedron", "sphere"});
  if (type == "sphere") return geometry::Sphere{t.get_positive("radius_m")};
  if (type == "box") {
    const Vec3 size = t.get_vec3("size_m");
    for (int k = 0; k < 3; ++k) {
      if (!(size[k] > 0.0)) t.fail("size_m", "every side must be > 0");
    }
    return geometry::Box{0.5 * size};
  }
  if (type == "cylinder") {
    return geometry::Cylinder{t.get_positive("radius_m"), 0.5 * t.get_positive("height_m")};
  }
  if (type == "cone") return geometry::Cone{t.get_positive("radius_m"), t.get_positive("height_m")};
  if (type == "ellipsoid") {
    const Vec3 a = t.get_vec3("semi_axes_m");
    for (int k = 0; k < 3; ++k) {
      if (!(a[k] > 0.0)) t.fail("semi_axes_m", "every semi-axis must be > 0");
    }
    return geometry::Ellipsoid{a};
  }
  // polyhedron: the convex hull of given vertices or of a mesh file (STL/OBJ)
  std::vector<Vec3> points;
  if (t.has("file")) {
    std::filesystem::path file = t.get_string("file");
    if (file.is_relative()) file = source.parent_path() / file;
    try {
      const io::SurfaceMesh mesh = io::read_surface_mesh(file);
      if (!geometry::is_convex_mesh(mesh)) {
        t.fail("file", "the mesh in '" + file.string() +
                           "' is not convex; split it into convex pieces (type = \"composite\")");
      }
      points = mesh.vertices;
    } catch (const std::runtime_error& e) {
      t.fail("file", e.what());
    }
    const double scale = t.get_positive("scale", 1.0);
    for (Vec3& p : points) p *= scale;
  } else {
    points = t.get_vec3_list("vertices_m");
  }
  try {
    return geometry::make_convex_polyhedron(points);
  } catch (const std::invalid_argument& e) {
    t.fail(t.has("file") ? "file" : "vertices_m", e.what());
  }
}

// A [[shape]] table: a species of non-spherical particles.
ParticleShape parse_shape(const ConfigTable& t, const std::filesystem::path& source,
                          geometry::Composite& raw) {
  const std::string name = t.get_string("name");
  geometry::Composite elements;
  double smallest = std::numeric_limits<double>::infinity();  // smallest element half-size
  const auto note_size = [&](const geometry::ConvexShape& shape) {
    const geometry::Aabb b = geometry::local_bounds(shape);
    for (int k = 0; k < 3; ++k) smallest = std::min(smallest, 0.5 * (b.max[k] - b.min[k]));
  };
  if (t.has("type") && t.get_string("type") == "cross") {
    (void)t.get_choice("type", {"cross"});
    elements = geometry::cross_particle(t.get_positive("length_m"), t.get_positive("width_m"),
                                        t.get_positive("thickness_m"));
  } else if (t.has("type") && t.get_string("type") == "composite") {
    (void)t.get_choice("type", {"composite"});
    for (const ConfigTable& e : t.table_array("element")) {
      geometry::CompositeElement el{parse_convex(e, source), e.get_vec3("position_m", {}),
                                    parse_rotation(e)};
      elements.push_back(std::move(el));
    }
    if (elements.empty()) t.fail("element", "a composite needs at least one [[shape.element]]");
  } else {
    elements.push_back({parse_convex(t, source), {}, {}});
  }
  for (const auto& e : elements) note_size(e.shape);
  raw = elements;
  // Default crust: 10% of the smallest half-size (the core keeps 90%, app. A.2.3).
  const double crust = t.get_positive("crust_m", 0.1 * smallest);
  try {
    return make_particle_shape(name, elements, crust);
  } catch (const std::invalid_argument& e) {
    t.fail("crust_m", e.what());
  }
}

ParticleGroup parse_group(const ConfigTable& t, std::vector<MaterialSpec>& materials,
                          const std::vector<ParticleShape>& shapes) {
  ParticleGroup g(t);
  g.material = material_index(t, "material", materials);
  MaterialSpec& mat = materials[g.material];
  if (!mat.density) {
    t.fail("material", "material '" + mat.name + "' has no density_kg_m3, needed for particles");
  }
  mat.used_by_particles = true;
  if (t.has("shape")) {
    const std::string name = t.get_string("shape");
    for (std::size_t k = 0; k < shapes.size(); ++k) {
      if (shapes[k].name == name) g.shape = static_cast<int>(k);
    }
    if (g.shape < 0) t.fail("shape", "unknown shape '" + name + "' (define it in [[shape]])");
    const ParticleShape& sh = shapes[static_cast<std::size_t>(g.shape)];
    g.r_min = g.r_max = sh.bounding_radius;
    mat.radius_sum += sh.equivalent_radius;
    mat.groups += 1;
    mat.radius_min = std::min(mat.radius_min, sh.equivalent_radius);
    const std::string orientation = t.get_choice("orientation", {"random", "fixed"}, "random");
    g.random_orientation = orientation == "random";
    if (!g.random_orientation) {
      const Vec3 axis = t.get_vec3("orientation_axis", {0.0, 0.0, 1.0});
      if (!(norm(axis) > 0.0)) t.fail("orientation_axis", "must be a non-zero vector");
      g.orientation = Quaternion::from_axis_angle(
          axis, t.get_double("orientation_angle_deg", 0.0) * std::numbers::pi / 180.0);
    }
  } else if (t.has("radius_m")) {
    g.r_min = g.r_max = t.get_positive("radius_m");
    if (t.has("radius_min_m") || t.has("radius_max_m")) {
      t.fail("radius_m", "give either radius_m or radius_min_m and radius_max_m, not both");
    }
  } else {
    g.r_min = t.get_positive("radius_min_m");
    g.r_max = t.get_positive("radius_max_m");
    if (g.r_max < g.r_min) t.fail("radius_max_m", "must be >= radius_min_m");
  }
  if (g.shape < 0) {
    mat.radius_sum += 0.5 * (g.r_min + g.r_max);
    mat.groups += 1;
    mat.radius_min = std::min(mat.radius_min, g.r_min);
  }

  g.arrangement = t.get_choice("arrangement", {"random", "lattice", "list", "pour"});
  g.velocity = t.get_vec3("velocity_m_s", {});
  g.angular_velocity = t.get_vec3("angular_velocity_rad_s", {});
  g.velocity_noise = t.get_non_negative("velocity_noise_m_s", 0.0);
  g.fixed = t.get_bool("fixed", false);
  if (!g.fixed) mat.used_by_mobile_particles = true;
  if (g.fixed) {
    if (g.arrangement == "pour") t.fail("fixed", "a poured group cannot be fixed");
    if (g.shape >= 0) t.fail("fixed", "only spheres can be glued (fixed = true)");
    for (const char* key : {"velocity_m_s", "angular_velocity_rad_s", "velocity_noise_m_s",
                            "velocities_m_s", "angular_velocities_rad_s"}) {
      if (t.has(key)) t.fail(key, "a fixed group does not move: remove this key");
    }
  }
  if (g.arrangement == "list") {
    if (g.r_min != g.r_max) t.fail("radius_min_m", "a 'list' arrangement needs one radius_m");
    // (bodies: positions are centres of mass; their bounding spheres must not overlap)
    g.positions = t.get_vec3_list("positions_m");
    if (g.positions.empty()) t.fail("positions_m", "must list at least one position");
    if (t.has("velocities_m_s")) {
      g.velocities = t.get_vec3_list("velocities_m_s");
      if (g.velocities.size() != g.positions.size()) {
        t.fail("velocities_m_s", "must have as many entries as positions_m");
      }
    }
    if (t.has("angular_velocities_rad_s")) {
      g.angular_velocities = t.get_vec3_list("angular_velocities_rad_s");
      if (g.angular_velocities.size() != g.positions.size()) {
        t.fail("angular_velocities_rad_s", "must have as many entries as positions_m");
      }
    }
    g.count = static_cast<std::int64_t>(g.positions.size());
    return g;
  }
  g.region_min = t.get_vec3("region_min_m");
  g.region_max = t.get_vec3("region_max_m");
  check_box(t, g.region_min, g.region_max, "region_max_m");
  if (g.arrangement == "pour") {
    g.count = t.get_int("count");
    if (g.count <= 0) t.fail("count", "must be a positive integer");
    if (g.r_min != g.r_max) t.fail("radius_min_m", "a 'pour' arrangement needs one radius_m");
    g.rate = t.get_positive("rate_per_s");
    g.start = t.get_non_negative("start_s", 0.0);
  } else if (g.arrangement == "random") {
    g.count = t.get_int("count");
    if (g.count <= 0) t.fail("count", "must be a positive integer");
  } else {
    if (g.r_min != g.r_max) t.fail("radius_min_m", "a 'lattice' arrangement needs one radius_m");
    g.spacing = t.get_positive("spacing_m", 2.0 * g.r_max);
    if (g.spacing < 2.0 * g.r_max * (1.0 - 1e-12)) {
      t.fail("spacing_m", "must be at least one diameter, or the lattice spheres overlap");
    }
    g.count = t.get_int("count", 0);
    if (g.count < 0) t.fail("count", "must be >= 0 (0: fill the region)");
  }
  return g;
}

// Contact time of a pair: eq. 2.17 when underdamped, the clamped impact otherwise.
double contact_time(const ContactParameters& p, double reduced_mass) {
  const double omega0 = std::sqrt(p.normal_stiffness / reduced_mass);
  const double ratio = p.normal_damping / (2.0 * reduced_mass) / omega0;
  if (ratio < 1.0) return kPi / (omega0 * std::sqrt(1.0 - ratio * ratio));
  return scaled_clamped_duration(ratio) / omega0;
}

ResolvedInteraction parse_interaction(const ConfigTable& t,
                                      const std::vector<MaterialSpec>& materials, std::size_t& a,
                                      std::size_t& b) {
  const std::vector<std::string> names = t.get_string_list("materials");
  if (names.size() != 2) t.fail("materials", "must name exactly two materials");
  auto find = [&](const std::string& n) {
    for (std::size_t m = 0; m < materials.size(); ++m)
      if (materials[m].name == n) return m;
    t.fail("materials", "unknown material '" + n + "'");
  };
  a = find(names[0]);
  b = find(names[1]);
  const MaterialSpec& ma = materials[a];
  const MaterialSpec& mb = materials[b];
  for (const MaterialSpec* m : {&ma, &mb}) {
    if (!m->used_by_particles && !m->used_by_obstacles) {
      t.fail("materials", "material '" + m->name +
                              "' is used by no [[particles]] group and no "
                              "[[obstacle]]");
    }
  }
  if (!ma.used_by_particles && !mb.used_by_particles) {
    t.fail("materials",
           "no particle uses either material; interactions between obstacles are "
           "not computed");
  }
  if (!ma.used_by_particles) std::swap(a, b);  // particle material first
  const MaterialSpec& mp = materials[a];
  const MaterialSpec& mo = materials[b];

  ResolvedInteraction out;
  out.first = mp.name;
  out.second = mo.name;
  out.wall = mo.used_by_obstacles && !mo.used_by_particles;
  // Reference sizes: mean radius for the §2.4 procedure, smallest radius for the Tc check.
  const double r_ref_a = mp.radius_sum / mp.groups;
  const double m_ref_a = sphere_mass(r_ref_a, *mp.density);
  const double m_min_a = sphere_mass(mp.radius_min, *mp.density);
  double reduced_mass_ref = m_ref_a, reduced_radius_ref = r_ref_a, reduced_mass_min = m_min_a;
  double overlap_radius = r_ref_a;
  if (!out.wall) {
    const double r_ref_b = mo.radius_sum / mo.groups;
    const double m_ref_b = sphere_mass(r_ref_b, *mo.density);
    const double m_min_b = sphere_mass(mo.radius_min, *mo.density);
    reduced_mass_ref = m_ref_a * m_ref_b / (m_ref_a + m_ref_b);
    reduced_radius_ref = r_ref_a * r_ref_b / (r_ref_a + r_ref_b);
    reduced_mass_min = m_min_a * m_min_b / (m_min_a + m_min_b);
    overlap_radius = std::min(r_ref_a, r_ref_b);
  }
  out.reduced_mass = reduced_mass_min;

  const std::string mode = t.get_choice("mode", {"procedure", "explicit"}, "procedure");
  if (mode == "procedure") {
    ProcedureInput in;
    in.reduced_mass = reduced_mass_ref;
    in.reduced_radius = reduced_radius_ref;
    in.inertia_factor = 2.5;  // spheres: m_ij (R_i^2/I_i + R_j^2/I_j) = 5/2
    in.normal_restitution = t.get_double("normal_restitution");
    if (!(in.normal_restitution > 0.0 && in.normal_restitution <= 1.0)) {
      t.fail("normal_restitution", "must be in (0, 1]");
    }
    in.tangential_restitution = t.get_double("tangential_restitution");
    if (!(in.tangential_restitution > 0.0 && in.tangential_restitution <= 1.0)) {
      t.fail("tangential_restitution", "must be in (0, 1]");
    }
    const double ratio = t.get_positive("max_overlap_ratio");
    if (ratio >= 0.5) t.fail("max_overlap_ratio", "must be well below 1 (0.001-0.01 is usual)");
    in.max_overlap = ratio * overlap_radius;
    in.max_impact_velocity = t.get_positive("max_impact_velocity_m_s");
    in.friction = t.get_non_negative("friction", 0.5);
    in.rolling_friction = t.get_non_negative("rolling_friction", 0.0);
    const std::string model =
        t.get_choice("normal_damping_model", {"thesis", "exact_restitution"}, "thesis");
    in.damping_model = parse_normal_damping_model(model);
    out.procedure = derive_contact_parameters(in);
    out.parameters = out.procedure->parameters;
  } else {
    ContactParameters& p = out.parameters;
    p.normal_stiffness = t.get_positive("normal_stiffness_N_m");
    // Damping as in Table 3.1: either eta directly, or en (eq. 2.22) and gamma_t = eta_t / 2 m_ij
    // with the pair's reduced mass.
    if (t.has("normal_restitution")) {
      if (t.has("normal_damping_N_s_m")) {
        t.fail("normal_restitution", "give normal_restitution or normal_damping_N_s_m, not both");
      }
      const double en = t.get_double("normal_restitution");
      if (!(en > 0.0 && en <= 1.0)) t.fail("normal_restitution", "must be in (0, 1]");
      const double omega0 = std::sqrt(p.normal_stiffness / reduced_mass_ref);
      p.normal_damping = -2.0 * reduced_mass_ref * omega0 * std::log(en) /
                         std::sqrt(kPi * kPi + std::log(en) * std::log(en));
    } else {
      p.normal_damping = t.get_non_negative("normal_damping_N_s_m", 0.0);
    }
    p.tangential_stiffness = t.get_non_negative("tangential_stiffness_N_m", 0.0);
    if (t.has("tangential_damping_rate_1_s")) {
      if (t.has("tangential_damping_N_s_m")) {
        t.fail("tangential_damping_rate_1_s",
               "give tangential_damping_rate_1_s or tangential_damping_N_s_m, not both");
      }
      p.tangential_damping =
          2.0 * reduced_mass_ref * t.get_non_negative("tangential_damping_rate_1_s", 0.0);
    } else {
      p.tangential_damping = t.get_non_negative("tangential_damping_N_s_m", 0.0);
    }
    p.friction = t.get_non_negative("friction", 0.5);
    p.rolling_friction = t.get_non_negative("rolling_friction", 0.0);
    p.rolling_stiffness = t.get_non_negative("rolling_stiffness_N_m_rad", 0.0);
    p.rolling_damping = t.get_non_negative("rolling_damping_N_m_s_rad", 0.0);
  }
  // Without memory the tangential and rolling springs (kt dt and kr dtheta of eq. 2.6 and
  // 2.10) are dropped, leaving dashpots with Coulomb limits: the model of Fig. 2.6's dotted line.
  out.memory = t.get_bool("memory", true);
  if (!out.memory) {
    out.parameters.tangential_stiffness = 0.0;
    out.parameters.rolling_stiffness = 0.0;
  }
  out.contact_time = contact_time(out.parameters, reduced_mass_min);
  return out;
}

}  // namespace

DemCase load_dem_case(const std::filesystem::path& file) {
  return load_dem_case(ConfigTable::parse_file(file), file);
}

DemCase load_dem_case(const ConfigTable& cfg, const std::filesystem::path& source) {
  DemCase c;
  c.source = source;
  DemSetup& s = c.setup;

  // [simulation]
  const ConfigTable sim = cfg.table("simulation");
  c.name = sim.get_string("name", source.stem().string());
  c.stop.end_time = sim.get_positive("end_time_s");
  s.integrator = parse_integrator(sim.get_choice(
      "integrator", {"euler", "leapfrog", "adams_bashforth_2", "adams_bashforth_3"}, "leapfrog"));
  const std::int64_t seed = sim.get_int("seed", 1);
  if (seed < 0) sim.fail("seed", "must be >= 0");
  c.seed = static_cast<std::uint64_t>(seed);
  s.gravity = sim.get_vec3("gravity_m_s2", {0.0, 0.0, -9.81});
  s.skin = sim.get_non_negative("skin_m", 0.0);
  s.max_overlap_ratio = sim.get_positive("abort_overlap_ratio", 0.5);
  const std::int64_t threads = sim.get_int("threads", 0);
  if (threads < 0 || threads > 1024) sim.fail("threads", "must be 0 (all cores) or 1..1024");
  s.threads = threads == 0 ? std::max(1, omp_get_num_procs()) : static_cast<int>(threads);
  const std::int64_t sort_steps = sim.get_int("storage_sort_steps", s.storage_sort_interval);
  if (sort_steps < 0) sim.fail("storage_sort_steps", "must be >= 0 (0: never sort)");
  s.storage_sort_interval = sort_steps;
  s.contact_patches = sim.get_choice("flat_contacts", {"patch", "point"}, "patch") == "patch";
  s.mean_element_contacts = sim.get_choice("element_contacts", {"sum", "mean"}, "sum") == "mean";
  if (sim.has("forget_contact_memory_at_s")) {
    s.forget_contact_memory_at = sim.get_non_negative("forget_contact_memory_at_s", 0.0);
  }
  const bool allow_large_dt = sim.get_bool("allow_large_time_step", false);
  const bool dt_given = sim.has("time_step_s");
  const double dt_value = dt_given ? sim.get_positive("time_step_s") : 0.0;

  // [domain]
  const ConfigTable dom = cfg.table("domain");
  s.domain.min = dom.get_vec3("min_m");
  s.domain.max = dom.get_vec3("max_m");
  check_box(dom, s.domain.min, s.domain.max, "max_m");
  if (dom.has("periodic")) s.domain.periodic = dom.get_bool3("periodic");

  // [[material]]
  std::vector<MaterialSpec> materials;
  for (const ConfigTable& t : cfg.table_array("material")) {
    MaterialSpec m;
    m.name = t.get_string("name");
    if (m.name.empty()) t.fail("name", "must not be empty");
    for (const auto& other : materials) {
      if (other.name == m.name) t.fail("name", "material '" + m.name + "' is defined twice");
    }
    if (t.has("density_kg_m3")) m.density = t.get_positive("density_kg_m3");
    materials.push_back(m);
  }
  if (materials.empty()) cfg.fail("material", "at least one [[material]] is required");

  // [[shape]]: species of non-spherical particles (and shapes for obstacles)
  std::vector<geometry::Composite> raw_shapes;  // unshrunk elements in each shape's frame
  for (const ConfigTable& t : cfg.table_array("shape")) {
    raw_shapes.emplace_back();
    s.shapes.push_back(parse_shape(t, source, raw_shapes.back()));
    for (std::size_t k = 0; k + 1 < s.shapes.size(); ++k) {
      if (s.shapes[k].name == s.shapes.back().name) t.fail("name", "shape defined twice");
    }
  }

  // [[obstacle]] and [[particles]]
  const auto obstacle_tables = cfg.table_array("obstacle");
  for (std::size_t k = 0; k < obstacle_tables.size(); ++k) {
    s.obstacles.push_back(
        parse_obstacle(obstacle_tables[k], materials, k, s.shapes, raw_shapes, source));
  }
  std::vector<ParticleGroup> groups;
  for (const ConfigTable& t : cfg.table_array("particles"))
    groups.push_back(parse_group(t, materials, s.shapes));
  if (groups.empty()) cfg.fail("particles", "at least one [[particles]] group is required");
  for (const auto& m : materials) {
    if (m.used_by_particles && m.used_by_obstacles) {
      cfg.fail("material", "material '" + m.name +
                               "' is used by particles and obstacles; give obstacles their own "
                               "material (particle-wall contacts have their own parameters)");
    }
  }

  // [[interaction]]
  s.material_names.clear();
  for (const auto& m : materials) s.material_names.push_back(m.name);
  s.contacts = ContactTable(materials.size());
  for (const ConfigTable& t : cfg.table_array("interaction")) {
    std::size_t a = 0, b = 0;
    ResolvedInteraction r = parse_interaction(t, materials, a, b);
    if (s.contacts.defined(a, b)) {
      t.fail("materials", "interaction '" + r.first + "'-'" + r.second + "' is defined twice");
    }
    s.contacts.set(a, b, r.parameters);
    c.interactions.push_back(r);
  }
  // Every pair that can touch needs parameters. Glued particles touch neither
  // each other nor obstacles (the neighbour search skips those pairs), so a pair
  // of materials used only by glued groups and obstacles needs none.
  for (std::size_t a = 0; a < materials.size(); ++a) {
    if (!materials[a].used_by_particles) continue;
    for (std::size_t b = 0; b < materials.size(); ++b) {
      if (!(materials[b].used_by_particles || materials[b].used_by_obstacles)) continue;
      if (!materials[a].used_by_mobile_particles && !materials[b].used_by_mobile_particles)
        continue;
      if (!s.contacts.defined(a, b)) {
        cfg.fail("interaction", "no [[interaction]] for materials ['" + materials[a].name + "', '" +
                                    materials[b].name + "']");
      }
    }
  }

  // Time step against the contact time (20 steps per contact recommended, §2.4).
  c.smallest_contact_time = std::numeric_limits<double>::infinity();
  const ResolvedInteraction* stiffest = nullptr;
  for (const auto& r : c.interactions) {
    if (r.contact_time < c.smallest_contact_time) {
      c.smallest_contact_time = r.contact_time;
      stiffest = &r;
    }
  }
  if (dt_given) {
    s.time_step = dt_value;
    if (stiffest && dt_value > c.smallest_contact_time / 10.0 && !allow_large_dt) {
      std::ostringstream why;
      why << dt_value << " s exceeds Tc/10 = " << c.smallest_contact_time / 10.0
          << " s (contact time Tc = " << c.smallest_contact_time << " s, eq. 2.17, for '"
          << stiffest->first << "'-'" << stiffest->second
          << "'); use about Tc/20 = " << c.smallest_contact_time / 20.0
          << " s, or set simulation.allow_large_time_step = true";
      sim.fail("time_step_s", why.str());
    }
  } else {
    s.time_step = c.smallest_contact_time / 20.0;
  }

  // [output] and [stop]
  if (auto out = cfg.find_table("output")) {
    c.output.interval = out->get_positive("interval_s", c.stop.end_time / 100.0);
    c.output.vtk = out->get_bool("vtk", true);
    c.output.checkpoint_interval = out->get_non_negative("checkpoint_interval_s", 0.0);
  } else {
    c.output.interval = c.stop.end_time / 100.0;
  }
  if (c.output.interval < s.time_step) {
    cfg.fail("output.interval_s", "is shorter than the time step");
  }
  if (auto stop = cfg.find_table("stop")) {
    if (stop->has("mean_velocity_below_m_s")) {
      c.stop.mean_velocity_below = stop->get_positive("mean_velocity_below_m_s");
    }
    c.stop.settle_check_after = stop->get_non_negative("check_after_s", 0.0);
  }

  cfg.check_no_unknown_keys();

  // Build the particles (after all keys are known to be valid).
  std::mt19937_64 rng(c.seed);
  s.pour_seed = c.seed + 0x9E3779B97F4A7C15ull;  // its own stream, for restart bit for bit
  std::vector<SphereSeed> seeds;
  std::vector<std::size_t> group_of;
  for (std::size_t gi = 0; gi < groups.size(); ++gi) {
    ParticleGroup& g = groups[gi];
    std::vector<SphereSeed> fresh;
    if (g.arrangement == "pour") {  // inserted during the run
      PourSource src;
      src.material = static_cast<std::int32_t>(g.material);
      src.species = g.shape;
      src.radius = g.r_max;
      src.density = *materials[g.material].density;
      src.random_orientation = g.random_orientation;
      src.orientation = g.orientation;
      src.region_min = g.region_min;
      src.region_max = g.region_max;
      src.velocity = g.velocity;
      src.rate = g.rate;
      src.start = g.start;
      src.count = g.count;
      for (int k = 0; k < 3; ++k) {
        if (g.region_max[k] - g.region_min[k] < 2.0 * g.r_max) {
          g.table.fail("region_max_m", "the region is thinner than one particle");
        }
      }
      s.pour.push_back(src);
      continue;
    }
    if (g.arrangement == "list") {
      for (const Vec3& x : g.positions) fresh.push_back({x, g.r_min});
    } else if (g.arrangement == "lattice") {
      for (const Vec3& x : lattice_sites(g.region_min, g.region_max, g.spacing, g.r_min,
                                         static_cast<std::size_t>(g.count))) {
        fresh.push_back({x, g.r_min});
      }
      if (fresh.empty()) g.table.fail("region_max_m", "the region holds no lattice site");
      if (g.count > 0 && fresh.size() < static_cast<std::size_t>(g.count)) {
        g.table.fail("count", "the region holds only " + std::to_string(fresh.size()) +
                                  " lattice sites, fewer than count = " + std::to_string(g.count));
      }
    } else {
      try {
        fresh = random_spheres(static_cast<std::size_t>(g.count), g.r_min, g.r_max, g.region_min,
                               g.region_max, seeds, s.obstacles, s.domain, rng);
      } catch (const std::runtime_error& e) {
        g.table.fail("count", e.what());
      }
    }
    for (auto& f : fresh) {
      seeds.push_back(f);
      group_of.push_back(gi);
    }
  }
  if (auto overlap = find_overlap(seeds, s.obstacles, s.domain, 1e-9)) {
    cfg.fail("particles", "initial particles overlap: " + *overlap);
  }
  std::uniform_real_distribution<double> noise(-1.0, 1.0);
  std::vector<std::size_t> index_in_group(groups.size(), 0);
  for (std::size_t i = 0; i < seeds.size(); ++i) {
    const ParticleGroup& g = groups[group_of[i]];
    const std::size_t k = index_in_group[group_of[i]]++;
    Vec3 v = g.velocities.empty() ? g.velocity : g.velocities[k];
    const Vec3 w = g.angular_velocities.empty() ? g.angular_velocity : g.angular_velocities[k];
    if (g.velocity_noise > 0.0) {
      const double a = g.velocity_noise / std::sqrt(3.0);
      v += Vec3{a * noise(rng), a * noise(rng), a * noise(rng)};
    }
    const double density = *materials[g.material].density;
    if (g.shape < 0) {
      s.particles.add_sphere(static_cast<std::int64_t>(i), static_cast<std::int32_t>(g.material),
                             seeds[i].radius, density, seeds[i].position, v, w);
    } else {
      const ParticleShape& sh = s.shapes[static_cast<std::size_t>(g.shape)];
      const Quaternion q = g.random_orientation ? random_orientation(rng) : g.orientation;
      s.particles.add_body(static_cast<std::int64_t>(i), static_cast<std::int32_t>(g.material),
                           g.shape, sh.bounding_radius, density * sh.volume,
                           density * sh.inertia_per_density, q, seeds[i].position, v, w);
    }
    if (g.fixed) s.particles.fix(s.particles.size() - 1);
  }
  // Periodic axes need room for the linked cells.
  double r_max = 0.0, r_min = std::numeric_limits<double>::infinity();
  for (double r : s.particles.radius) {
    r_max = std::max(r_max, r);
    r_min = std::min(r_min, r);
  }
  for (const PourSource& src : s.pour) {
    r_max = std::max(r_max, src.radius);
    r_min = std::min(r_min, src.radius);
  }
  const double skin = s.skin > 0.0 ? s.skin : 0.2 * r_min;  // as DemSimulation chooses it
  for (int k = 0; k < 3; ++k) {
    if (s.domain.periodic[static_cast<std::size_t>(k)] &&
        s.domain.max[k] - s.domain.min[k] < 3.0 * (2.0 * r_max + skin)) {
      dom.fail("periodic", "a periodic axis must be at least 3 x (largest diameter + skin) long");
    }
  }
  return c;
}

std::string describe(const DemCase& c) {
  std::ostringstream o;
  o.precision(6);
  const DemSetup& s = c.setup;
  o << "case            " << c.name << "  (" << c.source.string() << ")\n";
  o << "particles       " << s.particles.size() << "\n";
  o << "obstacles       " << s.obstacles.size() << "\n";
  o << "threads         " << s.threads
    << " requested (small systems use fewer; results do not depend on it)\n";
  o << "storage sort    ";
  if (s.storage_sort_interval > 0) {
    o << "along space every " << s.storage_sort_interval << " steps\n";
  } else {
    o << "off (particles stay in the order they were created)\n";
  }
  if (!s.shapes.empty()) {
    o << "flat contacts   "
      << (s.contact_patches ? "patch (spring-dashpots at the patch corners)"
                            : "point (one per element pair, thesis §2.3)")
      << "\n";
    o << "body contacts   "
      << (s.mean_element_contacts ? "mean over the element pairs of two bodies (Grains3D)"
                                  : "summed over the element pairs of two bodies")
      << "\n";
  }
  if (std::isfinite(s.forget_contact_memory_at)) {
    o << "contact memory  forgotten at t = " << s.forget_contact_memory_at
      << " s (every tangential, rolling and twist spring set to zero)\n";
  }
  o << "integrator      " << to_string(s.integrator) << " (order " << order_of(s.integrator)
    << ")\n";
  o << "time step       " << s.time_step << " s  = Tc / " << c.smallest_contact_time / s.time_step
    << "  (smallest contact time Tc = " << c.smallest_contact_time << " s)\n";
  o << "end time        " << c.stop.end_time << " s  ("
    << std::llround(c.stop.end_time / s.time_step) << " steps)\n";
  o << "gravity         [" << s.gravity.x << ", " << s.gravity.y << ", " << s.gravity.z
    << "] m/s^2\n";
  o << "domain          [" << s.domain.min.x << ", " << s.domain.min.y << ", " << s.domain.min.z
    << "] .. [" << s.domain.max.x << ", " << s.domain.max.y << ", " << s.domain.max.z
    << "] m, periodic " << s.domain.periodic[0] << s.domain.periodic[1] << s.domain.periodic[2]
    << "\n";
  o << "seed            " << c.seed << "\n";
  for (const ParticleShape& sh : s.shapes) {
    o << "shape           " << sh.name << ": " << sh.elements.size() << " element(s), volume "
      << sh.volume << " m^3, equivalent radius " << sh.equivalent_radius << " m, bounding radius "
      << sh.bounding_radius << " m, crust " << sh.smallest_crust << " m\n";
  }
  for (const PourSource& src : s.pour) {
    o << "pour            " << src.count << " "
      << (src.species < 0 ? std::string("spheres")
                          : s.shapes[static_cast<std::size_t>(src.species)].name)
      << " at " << src.rate << " /s from t = " << src.start << " s\n";
  }
  for (const auto& r : c.interactions) {
    const ContactParameters& p = r.parameters;
    o << "interaction     " << r.first << " - " << r.second << (r.wall ? " (wall)" : "")
      << (r.memory ? "" : "  WITHOUT MEMORY (kt = kr = 0)") << "\n";
    o << "  kn = " << p.normal_stiffness << " N/m, eta_n = " << p.normal_damping
      << " N s/m, kt = " << p.tangential_stiffness << " N/m, eta_t = " << p.tangential_damping
      << " N s/m, mu_c = " << p.friction << "\n";
    o << "  kr = " << p.rolling_stiffness << " N m/rad, eta_r = " << p.rolling_damping
      << " N m s/rad, mu_r = " << p.rolling_friction << ", Tc = " << r.contact_time << " s\n";
    if (r.procedure) {
      o << "  from §2.4: damping ratio " << r.procedure->damping_ratio
        << ", gamma_t = " << r.procedure->tangential_damping_rate
        << " 1/s, rebound ratio of the clamped law " << r.procedure->effective_restitution << "\n";
    }
  }
  return o.str();
}

}  // namespace sanguis::dem
