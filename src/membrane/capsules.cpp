#include "membrane/capsules.hpp"

#include <omp.h>

#include <stdexcept>

namespace sanguis::membrane {

CapsuleSet::CapsuleSet(TriangleMesh stress_free, double inflation,
                       const std::vector<CapsulePlacement>& placements)
    : shape_(std::move(stress_free)),
      topology_(shape_.node_count(), shape_.triangles),
      reference_(make_reference(shape_)),
      capsule_count_(placements.size()) {
  if (!(inflation > 0.0))
    throw std::invalid_argument("capsule inflation must be > 0, got " + std::to_string(inflation));
  const std::size_t n = shape_.node_count();
  positions_.resize(capsule_count_ * n);
  forces_.assign(capsule_count_ * n, Vec3{});
  for (std::size_t c = 0; c < capsule_count_; ++c) {
    auto x = positions(c);
    for (std::size_t i = 0; i < n; ++i)
      x[i] = rotate(placements[c].orientation, inflation * shape_.positions[i]) +
             placements[c].position;
  }
}

void CapsuleSet::compute_capsule(std::size_t c, const ElasticLaw& law,
                                 const std::optional<HelfrichParameters>& bending, int threads,
                                 Workspace& ws) {
  const std::size_t n = nodes_per_capsule();
  const std::span<Vec3> f{forces_.data() + c * n, n};
  for (auto& v : f) v = Vec3{};
  add_elastic_forces(law, reference_, shape_.triangles, topology_, positions(c), f, threads,
                     ws.triangle_forces);
  if (bending)
    add_bending_forces(*bending, shape_.triangles, topology_, positions(c), f, ws.geometry,
                       threads);
}

void CapsuleSet::compute_forces(const ElasticLaw& law,
                                const std::optional<HelfrichParameters>& bending, int threads) {
  validate(law);  // once per call: cheap next to the force loops
  if (bending) validate(*bending);
  threads = std::max(threads, 1);
  if (capsule_count_ >= static_cast<std::size_t>(threads) && threads > 1) {
    workspaces_.resize(static_cast<std::size_t>(threads));
#pragma omp parallel num_threads(threads)
    {
      Workspace& ws = workspaces_[static_cast<std::size_t>(omp_get_thread_num())];
#pragma omp for schedule(static)
      for (std::size_t c = 0; c < capsule_count_; ++c) compute_capsule(c, law, bending, 1, ws);
    }
  } else {
    workspaces_.resize(1);
    for (std::size_t c = 0; c < capsule_count_; ++c)
      compute_capsule(c, law, bending, threads, workspaces_[0]);
  }
}

TriangleMesh CapsuleSet::capsule_mesh(std::size_t c) const {
  TriangleMesh m;
  m.triangles = shape_.triangles;
  const auto x = positions(c);
  m.positions.assign(x.begin(), x.end());
  return m;
}

}  // namespace sanguis::membrane
