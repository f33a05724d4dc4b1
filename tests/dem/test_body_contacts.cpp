// Contacts of non-spherical bodies (thesis §2.3 contact law with memory, §2.5.2
// rotation, app. A.2.3 crusts; body_contacts.hpp): boxes and the crosses of §3.2.2
// resting on a plane, sliding down an incline, resting on one another, carrying a
// sphere, and bouncing elastically; and the patch response itself.
//
// Flat faces touch through a contact patch (geometry/contact_patch.hpp): a bed of normal
// spring-dashpots at the corners of the part of the facing faces within reach, the
// tangential spring at their centre of pressure and a torsional spring for twisting.
// Before the patches an element touched a plane at the overlap-weighted centre of its
// supporting feature and another element at GJK's single point, a corner of the overlap
// of two faces: stacks rocked by corner jumps, and a box slid down an incline 2-3 % too
// fast with the soft Table 3.1 spring (the two tests that were disabled then, below).
// The time step is taken from the contact time at a corner (corner_contact_time below),
// not from the body mass: for a 10 x 6 x 4 mm box the effective mass at a corner is
// about m/5.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <numbers>
#include <string>

#include "dem/body_contacts.hpp"
#include "dem/simulation.hpp"
#include "geometry/mass_properties.hpp"

namespace sanguis::dem {
namespace {

constexpr double kPi = std::numbers::pi;
constexpr double kG = 9.81;

// Linear spring-dashpot law of §2.3 given as in Table 3.1: kn, en (-> eta_n with the
// pair's reduced mass, eq. 2.22), kt, gamma_t = eta_t / (2 m_ij), mu_c.
struct Law {
  double kn = 4.5e5;     // [N/m]
  double en = 0.85;      // [-]
  double kt = 3e2;       // [N/m]
  double gamma_t = 1e3;  // [1/s]
  double mu = 0.62;      // [-]
  double mu_r = 0.0;     // rolling friction (0: none, as in Table 3.1); kr, eta_r by eq. 2.28
  double rolling_radius = 0.0;  // R_ij of eq. 2.28 [m]
};

ContactParameters contact_parameters(const Law& law, double reduced_mass) {
  const double ln = std::log(law.en);
  ContactParameters p;
  p.normal_stiffness = law.kn;
  p.normal_damping = -2.0 * ln / std::sqrt(kPi * kPi + ln * ln) * std::sqrt(law.kn * reduced_mass);
  p.tangential_stiffness = law.kt;
  p.tangential_damping = 2.0 * reduced_mass * law.gamma_t;
  p.friction = law.mu;
  const double r2 = law.rolling_radius * law.rolling_radius;
  p.rolling_friction = law.mu_r;
  p.rolling_stiffness = 3.0 * law.kn * law.mu_r * law.mu_r * r2;
  p.rolling_damping = 3.0 * p.normal_damping * law.mu_r * law.mu_r * r2;
  return p;
}

// A species and the rotation that takes its body (principal) frame to the frame the
// composite was written in: a body added with orientation q * frame appears as the
// composite rotated by q.
struct Species {
  ParticleShape shape;
  Quaternion frame;
};

Species make_species(const std::string& name, const geometry::Composite& elements, double crust) {
  const geometry::MassProperties m = geometry::composite_mass_properties(elements);
  EXPECT_LT(norm(m.centroid), 1e-12);  // all the composites below are centred
  return {make_particle_shape(name, elements, crust), m.principal_axes};
}

Species box_species(const Vec3& half_extents, double crust) {
  return make_species("box", {{geometry::Box{half_extents}, {}, {}}}, crust);
}

Species cross_species() {  // §3.2.2: two orthogonal 27 x 2 x 3 mm boxes
  return make_species("cross", geometry::cross_particle(0.027, 0.002, 0.003), 1e-4);
}

constexpr double kCrossDensity = 770.0;  // [kg/m^3], §3.2.2

// Material 0: particles; material 1: walls.
DemSetup make_setup(const Vec3& gravity, double time_step) {
  DemSetup s;
  s.domain.min = {-0.1, -0.1, -0.02};
  s.domain.max = {0.1, 0.1, 0.1};
  s.gravity = gravity;
  s.time_step = time_step;
  s.material_names = {"particle", "wall"};
  s.contacts = ContactTable(2);
  return s;
}

void add_floor(DemSetup& s) {
  Obstacle o;
  o.material = 1;
  o.shape = PlaneShape{{0.0, 0.0, 0.0}, {0.0, 0.0, 1.0}};
  s.obstacles.push_back(o);
}

std::size_t add_body(DemSetup& s, const Species& sp, double density, const Quaternion& q,
                     const Vec3& x, const Vec3& v = {}, const Vec3& w = {}) {
  auto species = static_cast<std::int32_t>(s.shapes.size());
  for (std::size_t k = 0; k < s.shapes.size(); ++k) {
    if (s.shapes[k].name == sp.shape.name) species = static_cast<std::int32_t>(k);
  }
  if (species == static_cast<std::int32_t>(s.shapes.size())) s.shapes.push_back(sp.shape);
  const auto id = static_cast<std::int64_t>(s.particles.size());
  return s.particles.add_body(id, 0, species, sp.shape.bounding_radius, density * sp.shape.volume,
                              density * sp.shape.inertia_per_density, normalized(q * sp.frame), x,
                              v, w);
}

// Duration of a contact at a point of the body (Tc of eq. 2.17 without damping) with
// the smallest effective mass a point of the body can have, 1/m_eff = 1/m + R^2/I_min
// (R: bounding radius): a contact at a corner is shorter than one through the centre.
double corner_contact_time(const Species& sp, double density, double kn) {
  const double m = density * sp.shape.volume;
  const Vec3 i = density * sp.shape.inertia_per_density;
  const double r = sp.shape.bounding_radius;
  const double m_eff = 1.0 / (1.0 / m + r * r / std::min({i.x, i.y, i.z}));
  return kPi / std::sqrt(kn / m_eff);
}

// Angle of the rotation taking q0 to q1 [rad].
double rotation_angle(const Quaternion& q1, const Quaternion& q0) {
  const Quaternion d = q1 * conjugate(q0);
  return 2.0 * std::atan2(norm(d.vector()), std::abs(d.w));
}

double kinetic_energy(const DemSimulation& sim) {
  const DemDiagnostics d = sim.diagnostics();
  return d.kinetic_energy_translational + d.kinetic_energy_rotational;
}

// An element contact is touching when its history holds a normal (reset to zero when
// the elements separate).
bool touching_at(const BodyContactList& list, std::size_t k) {
  const Vec3& n = list.history[k].normal;
  return n.x != 0.0 || n.y != 0.0 || n.z != 0.0;
}

std::int64_t touching(const BodyContactList& list) {
  std::int64_t n = 0;
  for (std::size_t k = 0; k < list.size(); ++k) n += touching_at(list, k) ? 1 : 0;
  return n;
}

// ---------------------------------------------------------------- resting

struct RestResult {
  double drift = 0.0;  // |x(T) - x(0)| [m]
  double turn = 0.0;   // rotation angle between q(0) and q(T) [rad]
  double speed = 0.0;  // |v(T)| [m/s]
  double spin = 0.0;   // |omega(T)| [rad/s]
  std::int64_t wall_contacts = 0;
};

// A body at rest on the floor z = 0, its lowest face at `height` below its centre,
// started at the static overlap with the weight shared by `feet` element contacts.
RestResult rest_on_floor(const Species& sp, double density, double height, int feet, const Law& law,
                         double time_step, double duration) {
  const double mass = density * sp.shape.volume;
  DemSetup s = make_setup({0.0, 0.0, -kG}, time_step);
  s.contacts.set(0, 0, contact_parameters(law, 0.5 * mass));
  s.contacts.set(0, 1, contact_parameters(law, mass));
  add_floor(s);
  add_body(s, sp, density, {}, {0.0, 0.0, height - mass * kG / (feet * law.kn)});
  DemSimulation sim(std::move(s));
  const Vec3 x0 = sim.particles().position[0];
  const Quaternion q0 = sim.particles().orientation[0];
  sim.run_until(duration);
  RestResult r;
  r.drift = norm(sim.particles().position[0] - x0);
  r.turn = rotation_angle(sim.particles().orientation[0], q0);
  r.speed = norm(sim.particles().velocity[0]);
  r.spin = norm(sim.particles().angular_velocity[0]);
  r.wall_contacts = sim.diagnostics().wall_contacts;
  return r;
}

// 10 x 6 x 4 mm box, crust 0.2 mm, 770 kg/m^3 (m = 0.18 g), lying on its 10 x 6 face.
Species flat_box() {
  return box_species({5e-3, 3e-3, 2e-3}, 2e-4);
}

TEST(BodyContacts, BoxRestingFaceDownStaysStillWithRollingMemory) {
  // Table 3.1 law plus a rolling spring (eq. 2.10, kr and eta_r of eq. 2.28 with mu_r 0.1,
  // R 3 mm), dt = Tc/20 at a corner. The face's patch holds the box: measured drift 0,
  // turn 0, |v| 4e-14 m/s, |omega| 0. (With one point at a corner the box was held by the
  // chatter between opposite corners and the rolling spring: drift 1.0e-10 m, turn
  // 1.1e-7 rad, |omega| 4e-12 rad/s; with mu_r 0.5 and R >= 3 mm it rocked for ever.)
  const Species box = flat_box();
  Law law;
  law.mu_r = 0.1;
  law.rolling_radius = 3e-3;
  const double dt = corner_contact_time(box, kCrossDensity, law.kn) / 20.0;
  const RestResult r = rest_on_floor(box, kCrossDensity, 2e-3, 1, law, dt, 1.0);
  EXPECT_EQ(r.wall_contacts, 1);
  EXPECT_LT(r.drift, 1e-9);
  EXPECT_LT(r.turn, 1e-6);
  EXPECT_LT(r.speed, 1e-10);
  EXPECT_LT(r.spin, 1e-8);
}

TEST(BodyContacts, BoxRestingFaceDownStaysStillWithTheTable31Law) {
  // With the contact point at a corner (support point on ties) this box rocked from
  // corner to corner for ever (|omega| = 0.024 rad/s after 1 s, a spurious spin of
  // 6e-3 rad/s about the vertical); the overlap-weighted face centre kept it still, and
  // so does the patch: measured drift 0, turn 0, |v| 4e-14 m/s, |omega| 0.
  const Species box = flat_box();
  const Law law;
  const double dt = corner_contact_time(box, kCrossDensity, law.kn) / 20.0;
  const RestResult r = rest_on_floor(box, kCrossDensity, 2e-3, 1, law, dt, 1.0);
  EXPECT_LT(r.drift, 1e-9);
  EXPECT_LT(r.turn, 1e-6);
  EXPECT_LT(r.speed, 1e-10);
  EXPECT_LT(r.spin, 1e-8);
}

TEST(BodyContacts, CrossRestingFlatOnAPlaneStaysStill) {
  // Table 3.1 (particle-wall): kn 4.5e5 N/m, en 0.85, kt 3e2 N/m, gamma_t 1e3 1/s,
  // mu 0.62, dt 2.5e-6 s (Tc = 7.3e-5 s for the 0.24 g cross). Both arms touch the plane
  // (two element contacts). Measured: drift 0, turn 0, |v| 2e-15 m/s, |omega| 0 (with the
  // face centre as single point: 2.3e-10 m, 4.8e-9 rad, 4e-14 m/s, 3e-13 rad/s, the
  // same for dt 1.5e-6 to 3e-6 s and mu 0.46).
  const RestResult r = rest_on_floor(cross_species(), kCrossDensity, 1.5e-3, 2, Law{}, 2.5e-6, 1.0);
  EXPECT_EQ(r.wall_contacts, 2);
  EXPECT_LT(r.drift, 1e-9);
  EXPECT_LT(r.turn, 1e-6);
  EXPECT_LT(r.speed, 1e-10);
  EXPECT_LT(r.spin, 1e-8);
}

TEST(BodyContacts, TheMeanOfTheElementContactsCarriesTheWeightOnDeeperArms) {
  // element_contacts = "mean" (Grains3D's composite particles): the plane's force on the
  // cross is the mean of its two arms' contacts, not their sum, so at rest each arm sinks
  // m g / kn instead of m g / (2 kn). Both runs start at the summed depth; the mean one
  // settles 2.6e-9 m lower (measured: within 1.4e-11 of that; the summed one stays put).
  const Species cross = cross_species();
  const double mass = kCrossDensity * cross.shape.volume;
  const Law law;
  const double z0 = 1.5e-3 - mass * kG / (2.0 * law.kn);
  const auto rest_height = [&](bool mean) {
    DemSetup s = make_setup({0.0, 0.0, -kG}, 2.5e-6);
    s.mean_element_contacts = mean;
    s.contacts.set(0, 0, contact_parameters(law, 0.5 * mass));
    s.contacts.set(0, 1, contact_parameters(law, mass));
    add_floor(s);
    add_body(s, cross, kCrossDensity, {}, {0.0, 0.0, z0});
    DemSimulation sim(std::move(s));
    sim.run_until(0.2);
    EXPECT_EQ(sim.diagnostics().wall_contacts, 2);
    EXPECT_LT(norm(sim.particles().velocity[0]), 1e-9);
    return sim.particles().position[0].z;
  };
  const double sink = mass * kG / (2.0 * law.kn);
  EXPECT_NEAR(rest_height(false), z0, 1e-6 * sink);
  EXPECT_NEAR(z0 - rest_height(true), sink, 1e-6 * sink);
}

// ---------------------------------------------------------------- sliding

struct SlideResult {
  double acceleration_ratio = 0.0;  // measured / g (sin theta - mu cos theta)
  double turn = 0.0;                // [rad]
  double lift = 0.0;                // largest |z - z0| of the centre [m]
};

// The flat box on a 40 degree incline (gravity tilted from -z towards +x), sliding
// along its long axis from rest; acceleration from the velocities at 0.02 s and 0.1 s.
SlideResult slide(const Law& law, bool patches = true) {
  const double theta = 40.0 * kPi / 180.0;
  const Species box = flat_box();
  const double mass = kCrossDensity * box.shape.volume;
  DemSetup s = make_setup({kG * std::sin(theta), 0.0, -kG * std::cos(theta)},
                          corner_contact_time(box, kCrossDensity, law.kn) / 20.0);
  s.contact_patches = patches;
  s.contacts.set(0, 0, contact_parameters(law, 0.5 * mass));
  s.contacts.set(0, 1, contact_parameters(law, mass));
  add_floor(s);
  const double z0 = 2e-3 - mass * kG * std::cos(theta) / law.kn;
  add_body(s, box, kCrossDensity, {}, {-0.05, 0.0, z0});
  DemSimulation sim(std::move(s));
  const Quaternion q0 = sim.particles().orientation[0];
  SlideResult r;
  sim.run_until(0.02);
  const double v0 = sim.particles().velocity[0].x, t0 = sim.time();
  while (sim.time() < 0.1) {
    sim.step();
    r.lift = std::max(r.lift, std::abs(sim.particles().position[0].z - z0));
  }
  const double a = (sim.particles().velocity[0].x - v0) / (sim.time() - t0);
  r.acceleration_ratio = a / (kG * (std::sin(theta) - law.mu * std::cos(theta)));
  r.turn = rotation_angle(sim.particles().orientation[0], q0);
  return r;
}

TEST(BodyContacts, BoxSlidesDownAnInclineWithTheCoulombAcceleration) {
  // tan 40 deg = 0.84 > mu 0.62 (Table 3.1 particle-wall) and < 2.5 = half length /
  // half height: the box slides on its face without tipping, a = g (sin - mu cos).
  // Stiff tangential spring kt = 2/7 kn (Cundall & Strack's ratio). Measured: a within
  // 1e-10 of the prediction, the box turns by 8e-8 rad and its centre stays within
  // 5e-11 m of its height (with one contact point: within 4e-5, rocking on its corners
  // at |omega| ~ 0.01 rad/s, 2e-6 rad and 1e-9 m).
  Law law;
  law.kt = 2.0 / 7.0 * law.kn;
  const SlideResult r = slide(law);
  EXPECT_NEAR(r.acceleration_ratio, 1.0, 1e-4);
  EXPECT_LT(r.turn, 1e-6);
  EXPECT_LT(r.lift, 1e-9);
}

TEST(BodyContacts, BoxSlidesDownAnInclineWithTheTable31TangentialSpring) {
  // The soft Table 3.1 spring (kt 3e2 N/m = 6.7e-4 kn). Measured: a within 1e-10 of the
  // prediction, as with the stiff spring: the patch keeps Fn = m g cos theta on every
  // step, so friction stays saturated at mu Fn. With one contact point this was 1.019
  // (1.034 with corner points): every jump of the point changed Fn and the soft spring
  // needed ~mu dFn / (kt v) to load up again, friction was saturated on only 70 % of
  // the steps.
  const SlideResult r = slide(Law{});
  EXPECT_NEAR(r.acceleration_ratio, 1.0, 1e-4);
  EXPECT_LT(r.turn, 1e-6);
  EXPECT_LT(r.lift, 1e-9);
}

TEST(BodyContacts, FlatContactsAsPointsGiveTheThesisModelBack) {
  // flat_contacts = "point" (DemSetup::contact_patches false): one point per contact, the
  // overlap-weighted face centre on the incline, as before the patches: 1.019 x the
  // Coulomb acceleration with the Table 3.1 spring (above).
  EXPECT_NEAR(slide(Law{}, false).acceleration_ratio, 1.019, 0.001);
}

// ---------------------------------------------------------------- two crosses

// A Table 3.1 cross resting flat on the floor and a second one dropped 0.2 mm onto it,
// rotated by 45 degrees about z: each arm of the upper cross lies across both arms of
// the lower one near the centre (four element pairs).
DemSimulation cross_on_cross() {
  const Species cross = cross_species();
  const double mass = kCrossDensity * cross.shape.volume;
  Law wall;
  Law pair;
  pair.mu = 0.46;  // Table 3.1 particle-particle
  DemSetup s = make_setup({0.0, 0.0, -kG}, 2.5e-6);
  s.contacts.set(0, 0, contact_parameters(pair, 0.5 * mass));
  s.contacts.set(0, 1, contact_parameters(wall, mass));
  add_floor(s);
  add_body(s, cross, kCrossDensity, {}, {0.0, 0.0, 1.5e-3 - mass * kG / (2.0 * wall.kn)});
  add_body(s, cross, kCrossDensity, Quaternion::from_axis_angle({0.0, 0.0, 1.0}, 0.25 * kPi),
           {0.0, 0.0, 4.5e-3 + 2e-4});
  return DemSimulation(std::move(s));
}

TEST(BodyContacts, CrossOnACrossTouchesAtSeveralPointsEachWithItsOwnHistory) {
  // Measured: the four element pairs touch together from t = 6.4 ms on (and at 0.3 s),
  // each with its own normal and tangential displacement.
  DemSimulation sim = cross_on_cross();
  std::int64_t most = 0;
  BodyContactList at_most;
  while (sim.time() < 0.3) {
    sim.step();
    const std::int64_t n = touching(sim.body_contacts());
    if (n > most) {
      most = n;
      at_most = sim.body_contacts();
    }
  }
  EXPECT_GE(most, 2);
  const BodyContactList& c = sim.body_contacts();
  EXPECT_GE(touching(c), 2) << "still touching each other at the end";
  for (const BodyContactList* list : {static_cast<const BodyContactList*>(&at_most), &c}) {
    for (std::size_t k = 0; k < list->size(); ++k) {
      EXPECT_EQ(list->first[k], 0u);
      EXPECT_EQ(list->second[k], 1u);
      // Each touching element pair is its own entry (own key, own memory); in this
      // symmetric stack two memories may hold equal values, so compare keys, not values.
      for (std::size_t l = 0; l < k; ++l) {
        if (touching_at(*list, k) && touching_at(*list, l)) {
          EXPECT_TRUE(list->element_first[k] != list->element_first[l] ||
                      list->element_second[k] != list->element_second[l])
              << "element pairs " << k << " and " << l << " are the same entry";
        }
      }
    }
  }
}

TEST(BodyContacts, CrossOnACrossComesToRest) {
  // The four arm pairs of the two crosses touch on patches that all surround the centre
  // of the lower cross. Measured: mean |v| 3e-13 m/s and mean |omega| 7e-5 rad/s at 0.1 s,
  // 8e-14 m/s and 1e-13 rad/s at 0.6 s.
  // With one point per pair (a corner of the overlap of the faces) the pair never
  // settled: mean |v| 2e-7 to 1.2e-6 m/s and mean |omega| ~ 0.01 rad/s from 0.2 s to 1 s.
  // The patches' overlap-weighted centres alone (tried on 2026-11-25) were worse (mean
  // |v| 5.8e-5 m/s at 0.6 s): a single point at the centre of a patch carries the normal
  // damping of no rocking mode. Without the patch's torsional spring the upper cross
  // kept spinning about the vertical at 0.06 rad/s: four centres of pressure at one
  // place resist no twist.
  DemSimulation sim = cross_on_cross();
  sim.run_until(0.6);
  EXPECT_LT(sim.diagnostics().mean_velocity, 1e-11);
  EXPECT_LT(sim.diagnostics().mean_angular_velocity, 1e-10);
}

// ---------------------------------------------------------------- sphere on a body

struct SphereOnBox {
  double height_error = 0.0;    // z - (box top + R - static overlaps) [m]
  double sphere_overlap = 0.0;  // static overlap of the sphere on the box [m]
  double total_overlap = 0.0;   // sphere-box plus box-floor static overlaps [m]
  double sphere_speed = 0.0;    // [m/s]
};

// A 1 mm glass sphere dropped (0.3 mm) onto the centre of the top face of a 10 x 6 x 4 mm
// steel box body lying on the floor, Table 3.1 law everywhere (sphere-element contact:
// the sphere is a point core with a crust equal to its radius).
SphereOnBox sphere_on_box(double duration) {
  const double hz = 2e-3, radius = 1e-3, steel = 7800.0, glass = 2500.0;
  const Species box = flat_box();
  const double box_mass = steel * box.shape.volume;
  const double sphere_mass = 4.0 / 3.0 * kPi * std::pow(radius, 3) * glass;
  const Law law;
  const double dt =
      std::min(kPi / std::sqrt(law.kn / sphere_mass), corner_contact_time(box, steel, law.kn)) /
      20.0;
  DemSetup s = make_setup({0.0, 0.0, -kG}, dt);
  s.contacts.set(0, 0, contact_parameters(law, sphere_mass * box_mass / (sphere_mass + box_mass)));
  s.contacts.set(0, 1, contact_parameters(law, box_mass));
  add_floor(s);
  const double box_overlap = (box_mass + sphere_mass) * kG / law.kn;
  const double sphere_overlap = sphere_mass * kG / law.kn;
  add_body(s, box, steel, {}, {0.0, 0.0, hz - box_overlap});
  s.particles.add_sphere(1, 0, radius, glass, {0.0, 0.0, 2.0 * hz + radius + 3e-4}, {}, {});
  DemSimulation sim(std::move(s));
  sim.run_until(duration);
  SphereOnBox r;
  r.height_error =
      sim.particles().position[1].z - (2.0 * hz + radius - box_overlap - sphere_overlap);
  r.sphere_overlap = sphere_overlap;
  r.total_overlap = box_overlap + sphere_overlap;
  r.sphere_speed = norm(sim.particles().velocity[1]);
  return r;
}

TEST(BodyContacts, SphereOnABoxBodyRestsAtTheBoxTopPlusItsRadius) {
  // Height of the sphere's centre: box top (2 hz) + R less the two static overlaps
  // (box-floor 4.1e-8 m, sphere-box 2.3e-10 m): within the sphere's own static overlap.
  const SphereOnBox r = sphere_on_box(0.2);
  EXPECT_LT(std::abs(r.height_error), r.sphere_overlap);
}

TEST(BodyContacts, SphereOnABoxBodyComesToRest) {
  // With corner contacts the box rocked (|omega| ~ 0.01-0.02 rad/s) and the sphere on it
  // kept moving at 5e-8 to 1e-7 m/s; with the face-centre contact, and with the patch,
  // both come to rest (patch: 7e-14 m/s at 0.4 s).
  EXPECT_LT(sphere_on_box(0.4).sphere_speed, 1e-8);
}

// ---------------------------------------------------------------- energy

// The flat box thrown without gravity at 0.5 m/s against the floor, en = 1 (eta_n = 0),
// no friction: the ratio of the kinetic energy (translation + rotation) once the box
// has left the floor to the initial one.
double bounce_energy_ratio(const Quaternion& q, const Vec3& w) {
  const Species box = flat_box();
  const double mass = kCrossDensity * box.shape.volume;
  Law law;
  law.en = 1.0;
  law.mu = 0.0;
  DemSetup s = make_setup({}, corner_contact_time(box, kCrossDensity, law.kn) / 20.0);
  s.contacts.set(0, 0, contact_parameters(law, 0.5 * mass));
  s.contacts.set(0, 1, contact_parameters(law, mass));
  add_floor(s);
  add_body(s, box, kCrossDensity, q, {0.0, 0.0, box.shape.bounding_radius + 1e-4},
           {0.1, 0.05, -0.5}, w);
  DemSimulation sim(std::move(s));
  const double e0 = kinetic_energy(sim);
  bool hit = false;
  while (sim.time() < 0.05) {
    sim.step();
    const bool touching_now = sim.diagnostics().wall_contacts > 0;
    hit = hit || touching_now;
    if (hit && !touching_now && sim.particles().velocity[0].z > 0.0) break;
  }
  EXPECT_TRUE(hit);
  EXPECT_GT(sim.particles().velocity[0].z, 0.0);
  return kinetic_energy(sim) / e0;
}

TEST(BodyContacts, ElasticFrictionlessBounceKeepsTheKineticEnergy) {
  // Tilted and spinning (two successive corner impacts) and flat (the four corners at
  // once). Measured: 0.99966 and 0.99997 with dt = Tc/20 at a corner (0.99966 and 0.99983
  // with one contact point; with dt = Tc/20 from the body mass, 0.982 and 1.0044: the
  // corner contact is 2.3 times shorter).
  EXPECT_NEAR(
      bounce_energy_ratio(Quaternion::from_axis_angle({1.0, 2.0, 0.5}, 0.4), {3.0, -2.0, 1.0}), 1.0,
      0.01);
  EXPECT_NEAR(bounce_energy_ratio({}, {}), 1.0, 0.01);
}

// ---------------------------------------------------------------- the patch response

// A 10 x 6 x 4 mm box (crust 0.2 mm) over the plane z = 0, turned by `tilt` about y,
// its deepest core point `overlap` into the crust: the contact and its patch.
struct BoxOnPlane {
  geometry::ConvexShape core;
  geometry::Pose pose;
  ElementContact contact;
  geometry::ContactPatch patch;
  bool flat = false;
};

BoxOnPlane box_on_plane(double tilt, double overlap) {
  const double crust = 2e-4;
  BoxOnPlane b;
  b.core = geometry::Box{{5e-3 - crust, 3e-3 - crust, 2e-3 - crust}};
  const Quaternion q = Quaternion::from_axis_angle({0.0, 1.0, 0.0}, tilt);
  const Vec3 lowest = rotate(q, geometry::support(b.core, rotate_inverse(q, {0.0, 0.0, -1.0})));
  b.pose = {{1e-3, 2e-3, crust - overlap - lowest.z}, q};
  b.contact = element_plane_contact(b.core, b.pose, crust, {}, {0.0, 0.0, 1.0});
  geometry::SpaceFace face;
  b.flat = geometry::facing_face(b.core, b.pose, b.contact.normal, face) &&
           geometry::face_plane_patch(face, {}, {0.0, 0.0, 1.0}, crust, b.patch);
  return b;
}

// The Table 3.1 law (particle-wall) for the box of flat_box() on a plane.
ContactParameters patch_law() {
  return contact_parameters(Law{}, kCrossDensity * flat_box().shape.volume);
}

ElementResponse respond(const BoxOnPlane& b, const ContactParameters& law, const Vec3& omega,
                        ContactHistory& h, double& twist, double dt) {
  const auto still = [](const Vec3&) { return Vec3{}; };
  return element_contact_response(law, b.contact, &b.patch, b.pose.position, {}, omega, still, {},
                                  nullptr, h, twist, dt);
}

TEST(BodyContacts, PatchOfAFacePressedEvenlyPushesAtItsCentreWithTheNormalSpring) {
  const BoxOnPlane b = box_on_plane(0.0, 1e-7);
  ASSERT_TRUE(b.flat);
  EXPECT_EQ(b.patch.count, 4);
  ContactHistory h;
  double twist = 0.0;
  // The overlap comes from millimetre positions: round-off ~1e-19 m, 1e-12 of it.
  const ElementResponse r = respond(b, patch_law(), {}, h, twist, 1e-6);
  EXPECT_NEAR(r.response.normal_force, 4.5e5 * 1e-7, 1e-10 * 4.5e5 * 1e-7);
  EXPECT_NEAR(r.response.force.z, 4.5e5 * 1e-7, 1e-10 * 4.5e5 * 1e-7);
  EXPECT_NEAR(r.point.x, 1e-3, 1e-15);
  EXPECT_NEAR(r.point.y, 2e-3, 1e-15);
  EXPECT_NEAR(r.overlap, 1e-7, 1e-17);
}

TEST(BodyContacts, PatchOnAnEdgeIsThePointLawAtTheMiddleOfTheEdge) {
  // Tilted by 0.1 rad the patch is a strip 1e-6 m wide along the lowest edge: the force
  // is eq. 2.5 with the edge's overlap, as a single point there would give.
  const BoxOnPlane b = box_on_plane(0.1, 1e-7);
  ASSERT_TRUE(b.flat);
  ContactHistory h;
  double twist = 0.0;
  const ElementResponse r = respond(b, patch_law(), {}, h, twist, 1e-6);
  EXPECT_NEAR(r.response.normal_force, 4.5e5 * 1e-7, 1e-9 * 4.5e5 * 1e-7);
  EXPECT_NEAR(r.point.y, 2e-3, 1e-15);
  const Vec3 edge =
      b.pose.position + rotate(b.pose.orientation, Vec3{4.8e-3, 0.0, -1.8e-3});  // lowest edge
  EXPECT_NEAR(r.point.x, edge.x, 1e-9);
}

TEST(BodyContacts, PatchDampsARockingFace) {
  // A face resting evenly and rocking about x at omega: the corners' dashpots give the
  // torque -eta_n b^2 omega (b the core's half width, corners weighing 1/4 each), which a
  // single point at the centre of the face would not (its normal speed is zero).
  // No tangential spring or dashpot here, so the torque is the normal forces' alone.
  const BoxOnPlane b = box_on_plane(0.0, 1e-7);
  ContactParameters law = patch_law();
  law.tangential_stiffness = 0.0;
  law.tangential_damping = 0.0;
  ContactHistory h;
  double twist = 0.0;
  const double omega = 0.1, half_width = 3e-3 - 2e-4;
  const ElementResponse r = respond(b, law, {omega, 0.0, 0.0}, h, twist, 1e-6);
  const Vec3 torque = cross(r.arm_first, r.response.force) + r.twist_torque;
  EXPECT_NEAR(torque.x, -law.normal_damping * half_width * half_width * omega,
              1e-9 * law.normal_damping * half_width * half_width * omega);
}

TEST(BodyContacts, PatchResistsTwistWithASpringThatSlipsAtTheCoulombMoment) {
  // Spinning about the normal: the spring's moment grows by -kt J dtheta each step and
  // the dashpot adds -eta_t J spin, J = <r^2> = (a^2 + b^2)/3 for an evenly pressed
  // rectangle of half sides a, b, until |M| reaches mu Fn <|r|>; then it stays there,
  // and the spring holds the slip moment less the dashpot's, as eq. 2.8 does.
  const BoxOnPlane b = box_on_plane(0.0, 1e-7);
  const ContactParameters law = patch_law();
  const double a = 4.8e-3, half_width = 2.8e-3, j = (a * a + half_width * half_width) / 3;
  const int n = 400;  // cells per side of the midpoint sum of <|r|> below
  const double spin = 0.01, dt = 1e-3;
  ContactHistory h;
  double twist = 0.0;
  ElementResponse r = respond(b, law, {0.0, 0.0, spin}, h, twist, dt);
  // The relative rotation about the contact normal (-z) is -spin.
  EXPECT_NEAR(twist, law.tangential_stiffness * j * spin * dt, 1e-9 * twist);
  const double expected =
      (law.tangential_stiffness * spin * dt + law.tangential_damping * spin) * j;
  EXPECT_NEAR(r.twist_torque.z, -expected, 1e-9 * expected);
  // The slip moment, where the moment stops growing, against <|r|> of the rectangle by a
  // midpoint sum, to the 1 % of geometry::pressure_arms.
  double slip = 0.0;
  for (int k = 0; k < 200000; ++k) {
    const double before = r.twist_torque.z;
    r = respond(b, law, {0.0, 0.0, spin}, h, twist, dt);
    if (r.twist_torque.z == before) {
      slip = -r.twist_torque.z;
      break;
    }
  }
  double rectangle_arm = 0.0;
  for (int i = 0; i < n; ++i) {
    for (int k = 0; k < n; ++k) {
      rectangle_arm +=
          std::hypot(2 * a * ((i + 0.5) / n - 0.5), 2 * half_width * ((k + 0.5) / n - 0.5));
    }
  }
  rectangle_arm /= static_cast<double>(n) * n;
  const double limit = law.friction * 4.5e5 * 1e-7 * rectangle_arm;
  EXPECT_NEAR(slip, limit, 0.01 * limit);
  // Slipping: the spring holds what keeps the moment continuous once the spin stops.
  r = respond(b, law, {}, h, twist, dt);
  EXPECT_NEAR(r.twist_torque.z, -slip + law.tangential_damping * spin * j, 1e-9 * slip);
}

TEST(BodyContacts, APatchThatGrowsWithoutTurningGainsNoTwist) {
  // The spring's moment grows with the rotation times the patch's J at the time, as the
  // rolling spring of eq. 2.10 does: a tiny patch (a corner just touching) spun for a
  // long time holds almost nothing, and when the whole face then lands without turning
  // the moment is still that, not the face's J times the accumulated angle.
  BoxOnPlane tiny = box_on_plane(0.0, 1e-7);
  const BoxOnPlane face = box_on_plane(0.0, 1e-7);
  const Vec3 c = face.patch.point[0];
  const double s = 1e-7;  // a 0.1 um square at a corner of the face
  for (int k = 0; k < 4; ++k) {
    tiny.patch.point[k] = c + Vec3{k == 1 || k == 2 ? s : 0.0, k >= 2 ? s : 0.0, 0.0};
    tiny.patch.overlap[k] = 1e-7;
    tiny.patch.perimeter_share[k] = s;
  }
  tiny.patch.count = 4;
  const ContactParameters law = patch_law();
  ContactHistory h;
  double twist = 0.0;
  for (int k = 0; k < 10000; ++k) respond(tiny, law, {0.0, 0.0, 1.0}, h, twist, 1e-4);
  const double held = std::abs(twist);
  EXPECT_GT(held, 0.0);
  EXPECT_LT(held, law.friction * 4.5e5 * 1e-7 * s);  // at most the tiny patch's slip
  const ElementResponse r = respond(face, law, {}, h, twist, 1e-4);
  EXPECT_NEAR(std::abs(r.twist_torque.z), held, 1e-12 * held + 1e-30);
}

TEST(BodyContacts, PatchLeavesTheTwistToTheTorsionalSpring) {
  // With rolling resistance on (eq. 2.9-2.13, mu_r 0.1, R 3 mm), a spin about the normal
  // is resisted by the torsional spring alone: the rolling spring gets the relative
  // rotation less its twist, here nothing. A rocking rotation still reaches it.
  const BoxOnPlane b = box_on_plane(0.0, 1e-7);
  Law with_rolling;
  with_rolling.mu_r = 0.1;
  with_rolling.rolling_radius = 3e-3;
  const ContactParameters law =
      contact_parameters(with_rolling, kCrossDensity * flat_box().shape.volume);
  ContactHistory h;
  double twist = 0.0;
  ElementResponse r = respond(b, law, {0.0, 0.0, 0.01}, h, twist, 1e-3);
  EXPECT_EQ(norm(r.response.rolling_torque), 0.0);
  EXPECT_GT(std::abs(r.twist_torque.z), 0.0);
  ContactHistory h_rock;
  double twist_rock = 0.0;
  r = respond(b, law, {0.01, 0.0, 0.0}, h_rock, twist_rock, 1e-3);
  EXPECT_GT(std::abs(r.response.rolling_torque.x), 0.0);
  EXPECT_EQ(twist_rock, 0.0);
}

}  // namespace
}  // namespace sanguis::dem
