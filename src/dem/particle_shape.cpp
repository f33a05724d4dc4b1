#include "dem/particle_shape.hpp"

#include <cmath>
#include <numbers>
#include <stdexcept>

namespace sanguis::dem {

ParticleShape make_sphere_shape(const std::string& name, double radius) {
  ParticleShape s;
  s.name = name;
  s.volume = 4.0 / 3.0 * std::numbers::pi * radius * radius * radius;
  const double i = 0.4 * s.volume * radius * radius;
  s.inertia_per_density = {i, i, i};
  s.bounding_radius = radius;
  s.equivalent_radius = radius;
  s.smallest_crust = radius;
  return s;
}

ParticleShape make_particle_shape(const std::string& name, const geometry::Composite& elements,
                                  double crust) {
  if (elements.empty()) throw std::invalid_argument("shape '" + name + "' has no element");
  if (!(crust > 0.0)) throw std::invalid_argument("shape '" + name + "': crust must be > 0");
  const geometry::MassProperties m = geometry::composite_mass_properties(elements);
  ParticleShape s;
  s.name = name;
  s.volume = m.volume;
  s.inertia_per_density = m.principal_moments;
  s.equivalent_radius = std::cbrt(3.0 * m.volume / (4.0 * std::numbers::pi));
  s.smallest_crust = crust;
  // Body frame = principal frame: x_body = R^T (x_composite - centroid), R = principal_axes.
  const Quaternion to_body = conjugate(m.principal_axes);
  for (const geometry::CompositeElement& e : elements) {
    ShapeElement out;
    out.position = rotate(to_body, e.position - m.centroid);
    out.orientation = normalized(to_body * e.orientation);
    try {
      out.core = geometry::shrunk(e.shape, crust);
    } catch (const std::invalid_argument& err) {
      throw std::invalid_argument("shape '" + name + "': crust " + std::to_string(crust) +
                                  " m does not fit an element (" + err.what() + ")");
    }
    out.crust = crust;
    out.reach = geometry::bounding_radius(out.core) + crust;
    s.bounding_radius = std::max(s.bounding_radius, norm(out.position) + out.reach);
    // Output surface: each element's true (unshrunk) surface in the body frame.
    const geometry::TriangleMesh piece = geometry::tessellate(e.shape, 24);
    const auto base = static_cast<std::uint32_t>(s.mesh.vertices.size());
    for (const Vec3& v : piece.vertices) {
      s.mesh.vertices.push_back(out.position + rotate(out.orientation, v));
    }
    for (const auto& t : piece.triangles) {
      s.mesh.triangles.push_back({t[0] + base, t[1] + base, t[2] + base});
    }
    s.elements.push_back(std::move(out));
  }
  return s;
}

}  // namespace sanguis::dem
