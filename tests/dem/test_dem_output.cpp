// ParaView output of a DEM run: contact points and branch network (forces
// re-evaluated from the stored contact histories), obstacles at their pose at each
// output time, and the true surfaces of non-spherical bodies.
#include <gtest/gtest.h>

#include <bit>
#include <cmath>
#include <cstdint>
#include <filesystem>
#include <fstream>
#include <numbers>
#include <sstream>
#include <stdexcept>
#include <string>
#include <utility>
#include <vector>

#include "core/config.hpp"
#include "dem/dem_run.hpp"
#include "geometry/mass_properties.hpp"

namespace sanguis::dem {
namespace {

namespace fs = std::filesystem;

// ------------------------------------------------------------ reading the frames back

std::string read_text(const fs::path& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in) throw std::runtime_error("cannot read " + path.string());
  std::ostringstream s;
  s << in.rdbuf();
  return s.str();
}

// The value of an attribute of the <Piece> element (NumberOfPoints, NumberOfPolys, ...).
long piece_attribute(const std::string& xml, const std::string& name) {
  const std::size_t piece = xml.find("<Piece ");
  const std::size_t at = xml.find(" " + name + "=\"", piece);
  if (piece == std::string::npos || at == std::string::npos) {
    throw std::runtime_error("no " + name + " in the piece");
  }
  return std::stol(xml.substr(at + name.size() + 3));
}

std::vector<std::uint8_t> base64_decode(const std::string& text) {
  const std::string alphabet = "ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
  std::vector<std::uint8_t> bytes;
  std::uint32_t bits = 0;
  int count = 0;
  for (const char c : text) {
    const std::size_t v = alphabet.find(c);
    if (v == std::string::npos) continue;  // whitespace and padding
    bits = (bits << 6) | static_cast<std::uint32_t>(v);
    if (++count == 4) {
      bytes.push_back(static_cast<std::uint8_t>(bits >> 16));
      bytes.push_back(static_cast<std::uint8_t>(bits >> 8));
      bytes.push_back(static_cast<std::uint8_t>(bits));
      bits = 0;
      count = 0;
    }
  }
  if (count == 3) {  // one '=' of padding: 2 bytes
    bytes.push_back(static_cast<std::uint8_t>(bits >> 10));
    bytes.push_back(static_cast<std::uint8_t>(bits >> 2));
  } else if (count == 2) {  // two '=': 1 byte
    bytes.push_back(static_cast<std::uint8_t>(bits >> 4));
  }
  return bytes;
}

// The 8-byte words of the binary DataArray named `name` (after the UInt64 byte count).
std::vector<std::uint64_t> array_words(const std::string& xml, const std::string& name) {
  const std::size_t at = xml.find("Name=\"" + name + "\"");
  if (at == std::string::npos) throw std::runtime_error("no array " + name);
  const std::size_t begin = xml.find('>', at) + 1;
  const std::size_t end = xml.find("</DataArray>", begin);
  const std::vector<std::uint8_t> bytes = base64_decode(xml.substr(begin, end - begin));
  std::vector<std::uint64_t> words;
  for (std::size_t offset = 8; offset + 8 <= bytes.size(); offset += 8) {
    std::uint64_t w = 0;
    for (int k = 7; k >= 0; --k) w = (w << 8) | bytes[offset + static_cast<std::size_t>(k)];
    words.push_back(w);
  }
  return words;
}

std::vector<double> float_array(const std::string& xml, const std::string& name) {
  std::vector<double> values;
  for (const std::uint64_t w : array_words(xml, name)) values.push_back(std::bit_cast<double>(w));
  return values;
}

std::vector<std::int64_t> int_array(const std::string& xml, const std::string& name) {
  std::vector<std::int64_t> values;
  for (const std::uint64_t w : array_words(xml, name)) {
    values.push_back(static_cast<std::int64_t>(w));
  }
  return values;
}

int count_of(const std::string& text, const std::string& what) {
  int n = 0;
  for (std::size_t at = text.find(what); at != std::string::npos; at = text.find(what, at + 1)) {
    ++n;
  }
  return n;
}

std::string frame_name(const char* series, int frame, const char* extension) {
  char name[96];
  std::snprintf(name, sizeof name, "%s/%s_%08d.%s",
                series == std::string("branches") ? "contacts" : series, series, frame, extension);
  return name;
}

// ------------------------------------------------------------------------ the case

// Three glass spheres resting apart on a floor and a fourth stacked on the first, plus
// a box (clear of the spheres) translating upwards at 10 mm/s.
const char* kStack = R"(
[simulation]
end_time_s = 0.4
[domain]
min_m = [0.0, 0.0, 0.0]
max_m = [0.04, 0.04, 0.04]
[[material]]
name = "glass"
density_kg_m3 = 2500.0
[[material]]
name = "wall"
[[interaction]]
materials = ["glass", "glass"]
normal_restitution = 0.3
tangential_restitution = 0.3
max_overlap_ratio = 0.01
max_impact_velocity_m_s = 0.5
rolling_friction = 0.1
[[interaction]]
materials = ["glass", "wall"]
normal_restitution = 0.3
tangential_restitution = 0.3
max_overlap_ratio = 0.01
max_impact_velocity_m_s = 0.5
rolling_friction = 0.1
[[obstacle]]
name = "floor"
type = "plane"
material = "wall"
point_m = [0.0, 0.0, 0.0]
normal = [0.0, 0.0, 1.0]
[[obstacle]]
name = "gate"
type = "box"
material = "wall"
min_m = [0.025, 0.0, 0.0]
max_m = [0.027, 0.02, 0.01]
translation = { direction = [0.0, 0.0, 1.0], law = "constant", speed_m_s = 0.01 }
[[particles]]
material = "glass"
radius_m = 1e-3
arrangement = "list"
positions_m = [[0.005, 0.01, 0.0011], [0.01, 0.01, 0.0011], [0.015, 0.01, 0.0011],
               [0.005, 0.01, 0.0032]]
[output]
interval_s = 0.05
)";

constexpr double kRadius = 1e-3;
constexpr double kDensity = 2500.0;
constexpr double kGravity = 9.81;

TEST(DemOutput, ContactFramesCarryTheWeightAndTheGateIsDrawnWhereItIs) {
  const fs::path dir = fs::temp_directory_path() / "sanguis_test_dem_output_stack";
  fs::remove_all(dir);
  const DemCase c = load_dem_case(ConfigTable::parse_string(kStack, "stack.toml"), "stack.toml");
  RunOptions options;
  options.output_dir = dir;
  options.quiet = true;
  std::ostringstream console;
  const RunSummary summary = run_dem_case(c, options, console);
  ASSERT_NEAR(summary.simulated_time, 0.4, c.setup.time_step);
  EXPECT_LT(summary.last.mean_velocity, 1e-5);  // settled

  // One frame per 0.05 s in every series; no bodies for a case of spheres.
  const int frames = 9;
  const std::pair<const char*, const char*> series_list[] = {
      {"particles", "vtu"}, {"obstacles", "vtp"}, {"contacts", "vtu"}, {"branches", "vtp"}};
  for (const auto& [series, extension] : series_list) {
    const std::string pvd = read_text(dir / (std::string(series) + ".pvd"));
    EXPECT_EQ(count_of(pvd, "<DataSet"), frames) << series;
    const std::string last = frame_name(series, frames - 1, extension);
    EXPECT_NE(pvd.find(last), std::string::npos) << series;
    EXPECT_TRUE(fs::is_regular_file(dir / last)) << last;
  }
  EXPECT_FALSE(fs::exists(dir / "bodies.pvd"));
  EXPECT_FALSE(fs::exists(dir / "bodies"));

  // Last frame: 3 sphere-floor contacts and 1 sphere pair, forces carrying the weight.
  const std::string contacts = read_text(dir / frame_name("contacts", frames - 1, "vtu"));
  ASSERT_EQ(piece_attribute(contacts, "NumberOfPoints"), 4);
  const std::vector<std::int64_t> kind = int_array(contacts, "kind");
  const std::vector<double> fn = float_array(contacts, "normal_force");
  const std::vector<double> force = float_array(contacts, "force");
  const std::vector<double> points = float_array(contacts, "Points");
  const std::vector<std::int64_t> first = int_array(contacts, "first_id");
  const std::vector<std::int64_t> second = int_array(contacts, "second_id");
  ASSERT_EQ(kind.size(), 4u);
  ASSERT_EQ(force.size(), 12u);
  const double weight = 4.0 / 3.0 * std::numbers::pi * std::pow(kRadius, 3) * kDensity * kGravity;
  double floor_total = 0.0;
  int floor_contacts = 0;
  for (std::size_t k = 0; k < kind.size(); ++k) {
    if (kind[k] == 1) {
      ++floor_contacts;
      EXPECT_EQ(second[k], 0);  // obstacle index of the floor
      floor_total += fn[k];
      EXPECT_NEAR(points[3 * k + 2], 0.0, 1e-3 * kRadius);  // on the floor
      EXPECT_GT(force[3 * k + 2], 0.0);                     // pushes the sphere up
      EXPECT_NEAR(force[3 * k + 2], fn[k], 1e-6 * fn[k]);   // at rest: purely normal
    } else {
      ASSERT_EQ(kind[k], 0);
      EXPECT_EQ(first[k], 0);   // the bottom sphere of the stack...
      EXPECT_EQ(second[k], 3);  // ...and the one on it
      EXPECT_NEAR(fn[k], weight, 0.01 * weight);
      EXPECT_NEAR(force[3 * k + 2], -fn[k], 1e-6 * fn[k]);  // on the first (lower) sphere
      EXPECT_NEAR(points[3 * k + 0], 0.005, 1e-9);
      EXPECT_NEAR(points[3 * k + 2], 2.0 * kRadius, 2e-6);  // midway between the centres
    }
  }
  EXPECT_EQ(floor_contacts, 3);
  EXPECT_NEAR(floor_total, 4.0 * weight, 0.01 * 4.0 * weight);

  // The branch network: one line between the two stacked centres.
  const std::string branches = read_text(dir / frame_name("branches", frames - 1, "vtp"));
  EXPECT_EQ(piece_attribute(branches, "NumberOfLines"), 1);
  EXPECT_EQ(piece_attribute(branches, "NumberOfPoints"), 2);
  const std::vector<double> magnitude = float_array(branches, "force_magnitude");
  ASSERT_EQ(magnitude.size(), 1u);
  EXPECT_NEAR(magnitude[0], weight, 0.01 * weight);
  const std::vector<double> ends = float_array(branches, "Points");
  ASSERT_EQ(ends.size(), 6u);
  EXPECT_NEAR(ends[5] - ends[2], 2.0 * kRadius, 1e-5);

  // The particle cloud has the orientation quaternion (identity for spheres).
  const std::string particles = read_text(dir / frame_name("particles", frames - 1, "vtu"));
  EXPECT_NE(particles.find("Name=\"orientation\" NumberOfComponents=\"4\""), std::string::npos);
  const std::vector<double> q = float_array(particles, "orientation");
  ASSERT_EQ(q.size(), 16u);
  EXPECT_EQ(q[0], 1.0);

  // The gate (obstacle 1, points after the floor's 4) has risen by 10 mm/s x t.
  const std::string gate0 = read_text(dir / frame_name("obstacles", 0, "vtp"));
  const std::string gate_last = read_text(dir / frame_name("obstacles", frames - 1, "vtp"));
  const std::vector<double> p0 = float_array(gate0, "Points");
  const std::vector<double> p1 = float_array(gate_last, "Points");
  ASSERT_EQ(p0.size(), 3u * (4 + 24));
  ASSERT_EQ(p1.size(), p0.size());
  double lowest = 1.0;
  for (std::size_t k = 3 * 4; k < p0.size(); k += 3) {
    EXPECT_EQ(p1[k], p0[k]);
    EXPECT_EQ(p1[k + 1], p0[k + 1]);
    EXPECT_NEAR(p1[k + 2] - p0[k + 2], 0.01 * summary.simulated_time, 1e-12);
    lowest = std::min(lowest, p1[k + 2]);
  }
  EXPECT_NEAR(lowest, 0.01 * summary.simulated_time, 1e-12);
  for (std::size_t k = 0; k < 3 * 4; ++k) EXPECT_EQ(p1[k], p0[k]);  // the floor stays
  fs::remove_all(dir);
}

// Sum over the touching contacts of the force each gives particle i, and their number.
void sum_contact_forces(const DemSimulation& sim, std::vector<Vec3>& sum, std::vector<int>& count) {
  sum.assign(sim.particles().size(), Vec3{});
  count.assign(sim.particles().size(), 0);
  for (const ContactRecord& r : touching_contacts(sim)) {
    EXPECT_NEAR(norm(r.normal), 1.0, 1e-12);
    EXPECT_GT(r.overlap, 0.0);
    sum[r.first] += r.force;
    ++count[r.first];
    if (r.kind == ContactKind::kSpherePair || r.kind == ContactKind::kBodyPair) {
      sum[r.second] -= r.force;
      ++count[r.second];
    }
  }
}

TEST(DemOutput, ReEvaluatedContactForcesAddUpToTheParticleForces) {
  const DemCase c = load_dem_case(ConfigTable::parse_string(kStack, "stack.toml"), "stack.toml");
  // Euler and Adams-Bashforth evaluate the forces with the velocities of the end of the
  // step: the re-evaluation is exact at any time (in flight, impacts, at rest).
  {
    DemSetup setup = c.setup;
    setup.integrator = IntegratorKind::kAdamsBashforth2;
    DemSimulation sim(setup);
    for (const double t : {0.0005, 0.002, 0.004, 0.01, 0.2}) {
      sim.run_until(t);
      const ParticleStore& p = sim.particles();
      std::vector<Vec3> sum;
      std::vector<int> count;
      sum_contact_forces(sim, sum, count);
      for (std::size_t i = 0; i < p.size(); ++i) {
        EXPECT_EQ(count[i], p.coordination[i]) << "t = " << t << ", particle " << i;
        EXPECT_LE(norm(sum[i] - p.force[i]), 1e-10 * norm(p.force[i]))
            << "t = " << t << ", particle " << i;
      }
    }
  }
  // Leapfrog's forces saw the predicted velocity v_n + dt a_n, not v_{n+1}: the damping
  // terms differ while the accelerations change, and agree once at rest.
  DemSimulation sim(c.setup);
  for (const double t : {0.01, 0.2, 0.3}) {
    sim.run_until(t);
    const ParticleStore& p = sim.particles();
    std::vector<Vec3> sum;
    std::vector<int> count;
    sum_contact_forces(sim, sum, count);
    const double weight = p.mass[0] * kGravity;
    for (std::size_t i = 0; i < p.size(); ++i) {
      EXPECT_EQ(count[i], p.coordination[i]) << "t = " << t << ", particle " << i;
      const double tolerance = t < 0.1 ? 0.1 * weight : 1e-6 * weight;
      EXPECT_LE(norm(sum[i] - p.force[i]), tolerance) << "t = " << t << ", particle " << i;
    }
  }
}

TEST(DemOutput, ObstaclesAreDrawnAtTheirRotatedPose) {
  DemSetup s;
  s.domain.min = {0.0, 0.0, 0.0};
  s.domain.max = {1.0, 1.0, 1.0};
  Obstacle box;
  box.shape = AxisAlignedBoxShape{{0.4, 0.45, 0.0}, {0.6, 0.55, 0.1}};  // 0.2 x 0.1
  box.motion.axis = {0.0, 0.0, 1.0};
  box.motion.centre = {0.5, 0.5, 0.0};
  box.motion.rotation.kind = SpeedLaw::Kind::kConstant;
  box.motion.rotation.speed = 0.5 * std::numbers::pi;  // a quarter turn per second
  s.obstacles.push_back(box);
  Obstacle plane;
  plane.shape = PlaneShape{{0.5, 0.5, 0.2}, {0.0, 0.0, 1.0}};
  plane.motion.axis = {1.0, 0.0, 0.0};
  plane.motion.centre = {0.5, 0.5, 0.2};
  plane.motion.rotation.kind = SpeedLaw::Kind::kConstant;
  plane.motion.rotation.speed = 0.5 * std::numbers::pi;
  s.obstacles.push_back(plane);

  const io::PolyMesh mesh = obstacle_mesh(s, 1.0);
  ASSERT_EQ(mesh.polygons.size(), 7u);
  Vec3 lo{1e9, 1e9, 1e9}, hi{-1e9, -1e9, -1e9};
  for (std::size_t k = 0; k < 24; ++k) {
    for (int a = 0; a < 3; ++a) {
      lo[a] = std::min(lo[a], mesh.points[k][a]);
      hi[a] = std::max(hi[a], mesh.points[k][a]);
    }
  }
  EXPECT_NEAR(hi.x - lo.x, 0.1, 1e-12);  // the long side now along y
  EXPECT_NEAR(hi.y - lo.y, 0.2, 1e-12);
  EXPECT_NEAR(0.5 * (hi.x + lo.x), 0.5, 1e-12);
  // The plane turned a quarter about x (normal from +z to -y): its patch lies in y = 0.5.
  for (std::size_t k = 24; k < 28; ++k) EXPECT_NEAR(mesh.points[k].y, 0.5, 1e-12);
  // Removed obstacles are not drawn.
  s.obstacles[0].remove_at = 0.5;
  EXPECT_EQ(obstacle_mesh(s, 1.0).polygons.size(), 1u);
}

// ---------------------------------------------------------------------------- bodies

// The stack case with a cross (thesis §3.2.2, 27 x 2 x 3 mm, crust 0.1 mm) lying flat
// on the floor under a sphere dropped on its centre, where both arms overlap.
DemCase cross_case(Quaternion* orientation_out = nullptr) {
  std::string text = kStack;
  text.replace(text.find("end_time_s = 0.4"), 16, "end_time_s = 0.1");
  text.replace(text.find("interval_s = 0.05"), 17, "interval_s = 0.025");
  DemCase c = load_dem_case(ConfigTable::parse_string(text, "cross.toml"), "cross.toml");
  ParticleStore spheres;
  spheres.add_sphere(0, 0, kRadius, kDensity, {0.02, 0.02, 0.0052}, {}, {});
  const ParticleShape cross =
      make_particle_shape("cross", geometry::cross_particle(0.027, 0.002, 0.003), 1e-4);
  c.setup.shapes = {make_sphere_shape("glass", kRadius), cross};
  // A small tilt about z so that the arms are not along the axes.
  const Quaternion q = Quaternion::from_axis_angle({0.0, 0.0, 1.0}, 0.3);
  if (orientation_out) *orientation_out = q;
  spheres.add_body(1, 0, 1, cross.bounding_radius, kDensity * cross.volume,
                   kDensity * cross.inertia_per_density, q, {0.02, 0.02, 0.0016}, {}, {});
  c.setup.particles = spheres;
  c.setup.obstacles.resize(1);  // just the floor
  return c;
}

TEST(DemOutput, BodiesAreWrittenAsTheirSurfaceAtTheirPose) {
  const fs::path dir = fs::temp_directory_path() / "sanguis_test_dem_output_cross";
  fs::remove_all(dir);
  const DemCase c = cross_case();
  const ParticleShape& cross = c.setup.shapes[1];
  ASSERT_GT(cross.mesh.triangles.size(), 0u);
  RunOptions options;
  options.output_dir = dir;
  options.quiet = true;
  std::ostringstream console;
  run_dem_case(c, options, console);
  EXPECT_NE(console.str().find("bodies.pvd"), std::string::npos);

  const std::string pvd = read_text(dir / "bodies.pvd");
  EXPECT_EQ(count_of(pvd, "<DataSet"), 5);
  for (int frame = 0; frame < 5; ++frame) {
    const std::string bodies = read_text(dir / frame_name("bodies", frame, "vtp"));
    EXPECT_EQ(piece_attribute(bodies, "NumberOfPolys"),
              static_cast<long>(cross.mesh.triangles.size()));
    EXPECT_EQ(piece_attribute(bodies, "NumberOfPoints"),
              static_cast<long>(cross.mesh.vertices.size()));
    EXPECT_EQ(piece_attribute(bodies, "NumberOfLines"), 0);
    const std::vector<std::int64_t> ids = int_array(bodies, "id");
    const std::vector<std::int64_t> species = int_array(bodies, "species");
    ASSERT_EQ(ids.size(), cross.mesh.triangles.size());
    ASSERT_EQ(float_array(bodies, "velocity").size(), 3 * cross.mesh.triangles.size());
    EXPECT_EQ(int_array(bodies, "material").size(), cross.mesh.triangles.size());
    for (std::size_t k = 0; k < ids.size(); ++k) {
      EXPECT_EQ(ids[k], 1);
      EXPECT_EQ(species[k], 1);
    }

    // The surface is the body-frame mesh moved to the pose of the particle frame.
    const std::string particles = read_text(dir / frame_name("particles", frame, "vtu"));
    const std::vector<double> x = float_array(particles, "Points");
    const std::vector<double> q = float_array(particles, "orientation");
    const std::vector<std::int64_t> spherical = int_array(particles, "spherical");
    ASSERT_EQ(spherical, (std::vector<std::int64_t>{1, 0}));
    const Vec3 centre{x[3], x[4], x[5]};
    const Quaternion pose{q[4], q[5], q[6], q[7]};
    EXPECT_NEAR(pose.w * pose.w + pose.x * pose.x + pose.y * pose.y + pose.z * pose.z, 1.0, 1e-12);
    const std::vector<double> surface = float_array(bodies, "Points");
    for (std::size_t v = 0; v < cross.mesh.vertices.size(); ++v) {
      const Vec3 expected = centre + rotate(pose, cross.mesh.vertices[v]);
      for (int a = 0; a < 3; ++a) {
        EXPECT_NEAR(surface[3 * v + static_cast<std::size_t>(a)], expected[a], 1e-15)
            << "frame " << frame << ", vertex " << v;
      }
    }
  }
  // The sphere landed on the cross: element contacts (kind 2), one branch line per pair.
  const std::string contacts = read_text(dir / frame_name("contacts", 4, "vtu"));
  const std::vector<std::int64_t> kind = int_array(contacts, "kind");
  int body_pairs = 0, body_walls = 0;
  for (const std::int64_t k : kind) {
    body_pairs += k == 2;
    body_walls += k == 3;
  }
  EXPECT_GE(body_pairs, 1);
  EXPECT_GE(body_walls, 1);
  const std::string branches = read_text(dir / frame_name("branches", 4, "vtp"));
  EXPECT_EQ(piece_attribute(branches, "NumberOfLines"), 1);
  fs::remove_all(dir);
}

TEST(DemOutput, BodyMeshAndContactsOfABodyDirectly) {
  Quaternion q;
  DemCase c = cross_case(&q);
  // Adams-Bashforth: the forces of a step see the velocities of its end, so the
  // re-evaluation is exact (leapfrog: see ReEvaluatedContactForces...).
  c.setup.integrator = IntegratorKind::kAdamsBashforth2;
  DemSimulation sim(c.setup);
  const ParticleShape& cross = sim.setup().shapes[1];
  const io::PolyMesh mesh = body_mesh(sim.setup().shapes, sim.particles());
  ASSERT_EQ(mesh.polygons.size(), cross.mesh.triangles.size());
  ASSERT_EQ(mesh.points.size(), cross.mesh.vertices.size());
  const Vec3 centre = sim.particles().position[1];
  for (std::size_t v = 0; v < mesh.points.size(); ++v) {
    EXPECT_LT(norm(mesh.points[v] - (centre + rotate(q, cross.mesh.vertices[v]))), 1e-15);
  }
  EXPECT_EQ(mesh.polygons[0][0], cross.mesh.triangles[0][0]);
  EXPECT_TRUE(has_non_spherical(sim.particles()));

  // Contact forces re-evaluated for element contacts add up to the particle forces.
  for (const double t : {0.002, 0.02, 0.04, 0.1, 0.2}) {
    sim.run_until(t);
    const ParticleStore& p = sim.particles();
    std::vector<Vec3> sum;
    std::vector<int> count;
    sum_contact_forces(sim, sum, count);
    for (std::size_t i = 0; i < p.size(); ++i) {
      EXPECT_EQ(count[i], p.coordination[i]) << "t = " << t << ", particle " << i;
      EXPECT_LE(norm(sum[i] - p.force[i]), 1e-10 * norm(p.force[i]))
          << "t = " << t << ", particle " << i;
    }
  }
  // Resting sphere on the cross's centre: both arms touch it (two element contacts), the
  // cross touches the floor.
  const std::vector<ContactRecord> contacts = touching_contacts(sim);
  int body_pairs = 0, body_walls = 0;
  for (const ContactRecord& r : contacts) {
    body_pairs += r.kind == ContactKind::kBodyPair;
    body_walls += r.kind == ContactKind::kBodyWall;
  }
  EXPECT_EQ(body_pairs, 2);
  EXPECT_GE(body_walls, 1);
  const ContactNetwork net = contact_network(sim);
  EXPECT_EQ(net.points.points.size(), touching_contacts(sim).size());
  EXPECT_EQ(net.branches.lines.size(), 1u);  // sphere on cross: one pair, however many points
}

}  // namespace
}  // namespace sanguis::dem
