#pragma once
// Several capsules of one shape: the stress-free shape, its connectivity and
// per-triangle reference state are stored once; the node positions and
// forces of all capsules are two contiguous arrays (capsule c owns nodes
// [c n, (c+1) n)). Capsules are placed by a rotation and a translation of the
// (pre-inflated) shape.
//
// compute_forces() evaluates elastic (eq. 4.3-4.8) and, if asked, Helfrich
// bending (eq. 4.9-4.10) nodal forces of every capsule: with at least as many
// capsules as threads the capsules are shared among the threads (each capsule
// computed serially), otherwise each capsule is computed with all threads.
// Either way every node's sum runs in the same order: results do not depend
// on the thread count.
#include <optional>
#include <span>
#include <vector>

#include "core/quaternion.hpp"
#include "membrane/bending.hpp"
#include "membrane/elasticity.hpp"
#include "membrane/mesh_topology.hpp"
#include "membrane/triangle_mesh.hpp"

namespace sanguis::membrane {

struct CapsulePlacement {
  Vec3 position;           // where the shape's origin goes
  Quaternion orientation;  // rotation applied to the shape
};

class CapsuleSet {
 public:
  // `stress_free`: the reference shape (centred on the origin), e.g. an
  // icosphere mapped to a sphere or a biconcave cell. Each capsule starts as
  // that shape scaled by `inflation` (pre-inflation, >= 1 usually), rotated
  // and translated by its placement.
  CapsuleSet(TriangleMesh stress_free, double inflation,
             const std::vector<CapsulePlacement>& placements);

  std::size_t capsule_count() const { return capsule_count_; }
  std::size_t nodes_per_capsule() const { return shape_.node_count(); }
  const TriangleMesh& shape() const { return shape_; }
  const MeshTopology& topology() const { return topology_; }
  const std::vector<ReferenceTriangle>& reference() const { return reference_; }

  std::span<Vec3> positions(std::size_t c) {
    return {positions_.data() + c * nodes_per_capsule(), nodes_per_capsule()};
  }
  std::span<const Vec3> positions(std::size_t c) const {
    return {positions_.data() + c * nodes_per_capsule(), nodes_per_capsule()};
  }
  std::span<const Vec3> forces(std::size_t c) const {
    return {forces_.data() + c * nodes_per_capsule(), nodes_per_capsule()};
  }
  std::vector<Vec3>& all_positions() { return positions_; }
  const std::vector<Vec3>& all_forces() const { return forces_; }

  // Overwrites the forces with elastic (+ bending if given) nodal forces.
  // Checks the parameters first (std::invalid_argument naming the value).
  void compute_forces(const ElasticLaw& law, const std::optional<HelfrichParameters>& bending,
                      int threads);

  // The mesh of capsule c (positions copied), for output and measures.
  TriangleMesh capsule_mesh(std::size_t c) const;

 private:
  struct Workspace {
    std::vector<std::array<Vec3, 3>> triangle_forces;
    SurfaceGeometry geometry;
  };
  void compute_capsule(std::size_t c, const ElasticLaw& law,
                       const std::optional<HelfrichParameters>& bending, int threads,
                       Workspace& ws);

  TriangleMesh shape_;
  MeshTopology topology_;
  std::vector<ReferenceTriangle> reference_;
  std::size_t capsule_count_ = 0;
  std::vector<Vec3> positions_;
  std::vector<Vec3> forces_;
  std::vector<Workspace> workspaces_;
};

}  // namespace sanguis::membrane
