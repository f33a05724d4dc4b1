#include "dem/neighbor_search.hpp"

#include <algorithm>
#include <cmath>
#include <stdexcept>

#include "core/parallel.hpp"

namespace sanguis::dem {

NeighborSearch::NeighborSearch(const Domain& domain, double skin, double max_radius)
    : domain_(domain), skin_(skin) {
  const double cutoff = 2.0 * max_radius + skin;
  const Vec3 length = domain.length();
  for (int k = 0; k < 3; ++k) {
    const auto ku = static_cast<std::size_t>(k);
    const auto n = static_cast<std::int64_t>(std::floor(length[k] / cutoff));
    // Bound the grid so that a huge, sparse domain does not allocate billions of cells.
    cells_[ku] = std::clamp<std::int64_t>(n, 1, 1024);
    if (domain.periodic[ku] && cells_[ku] < 3) {
      throw std::invalid_argument("periodic length along axis " + std::to_string(k) +
                                  " must be at least 3 cut-offs (3 x (2 R_max + skin) = " +
                                  std::to_string(3 * cutoff) + " m)");
    }
    cell_size_[k] = length[k] / static_cast<double>(cells_[ku]);
  }
}

double NeighborSearch::obstacle_travel(const Obstacle& o, double t0, double t1) const {
  // Bound on how far any point of the obstacle inside the domain moved between t0 and t1.
  const ObstacleMotion& m = o.motion;
  double travel = norm(m.offset_at(t1) - m.offset_at(t0));
  if (m.rotation.moving()) {
    const double reach = norm(domain_.max - domain_.min) +
                         norm(m.centre - 0.5 * (domain_.min + domain_.max)) + norm(m.offset_at(t1));
    travel += std::abs(m.rotation.distance_at(t1) - m.rotation.distance_at(t0)) * reach;
  }
  return travel;
}

bool NeighborSearch::needs_rebuild(const ParticleStore& particles,
                                   const std::vector<Obstacle>& obstacles, double time,
                                   int threads) const {
  for (const Obstacle& o : obstacles) {
    if (!o.motion.is_static() && o.active(time) &&
        obstacle_travel(o, reference_time_, time) > 0.5 * skin_) {
      return true;
    }
  }
  return needs_rebuild(particles, threads);
}

bool NeighborSearch::needs_rebuild(const ParticleStore& particles, int threads) const {
  const std::size_t n = particles.size();
  if (reference_.size() != n) return true;
  const double limit = 0.5 * skin_;
  const double limit2 = limit * limit;
  const Vec3* x = particles.position.data();
  const Vec3* r = reference_.data();
  const bool bodies = !reference_orientation_.empty();  // empty: no bodies at last build
  // Spheres: the plain distance test (a loop the compiler vectorizes). A rotating body
  // moves its surface points by up to R_bound * angle more.
  const auto moved_too_far = [&](std::size_t i) {
    if (!bodies || particles.spherical[i]) return norm2(x[i] - r[i]) > limit2;
    const Quaternion& q = particles.orientation[i];
    const Quaternion& q0 = reference_orientation_[i];
    const double c = std::min(1.0, std::abs(q.w * q0.w + q.x * q0.x + q.y * q0.y + q.z * q0.z));
    return norm(x[i] - r[i]) + particles.radius[i] * 2.0 * std::acos(c) > limit;
  };
  if (!bodies) {
    return parallel_any(n, threads, [&](std::size_t i) { return norm2(x[i] - r[i]) > limit2; });
  }
  return parallel_any(n, threads, moved_too_far);
}

std::array<std::int64_t, 3> NeighborSearch::cell_coordinates(const Vec3& x) const {
  std::array<std::int64_t, 3> index{};
  for (int k = 0; k < 3; ++k) {
    const auto ku = static_cast<std::size_t>(k);
    double c = std::floor((x[k] - domain_.min[k]) / cell_size_[k]);
    // Outside a closed domain: clamp into the boundary cell (safe, see README).
    c = std::clamp(c, 0.0, static_cast<double>(cells_[ku] - 1));
    index[ku] = c >= 0.0 ? static_cast<std::int64_t>(c) : 0;  // NaN: a blown-up particle
  }
  return index;
}

std::int64_t NeighborSearch::cell_of(const Vec3& x) const {
  const std::array<std::int64_t, 3> index = cell_coordinates(x);
  return (index[2] * cells_[1] + index[1]) * cells_[0] + index[0];
}

namespace {

// Interleaves the low 21 bits of a and b (bit k of a to bit 2k, of b to bit 2k + 1).
std::uint64_t interleave(std::uint64_t a, std::uint64_t b) {
  std::uint64_t out = 0;
  for (int bit = 0; bit < 21; ++bit) {
    out |= ((a >> bit) & 1u) << (2 * bit);
    out |= ((b >> bit) & 1u) << (2 * bit + 1);
  }
  return out;
}

}  // namespace

std::vector<std::uint64_t> NeighborSearch::space_keys(const ParticleStore& particles,
                                                      int axis) const {
  const auto along = static_cast<std::size_t>(axis);
  const std::size_t u = (along + 1) % 3, v = (along + 2) % 3;
  std::vector<std::uint64_t> keys(particles.size());
  for (std::size_t i = 0; i < particles.size(); ++i) {
    Vec3 x = particles.position[i];
    domain_.wrap(x);  // as the list build will
    const std::array<std::int64_t, 3> c = cell_coordinates(x);
    const auto cell = [&c](std::size_t k) { return static_cast<std::uint64_t>(c[k]); };
    keys[i] = (cell(along) << 42) | interleave(cell(u), cell(v));
  }
  return keys;
}

void NeighborSearch::bin(const ParticleStore& particles) {
  const std::size_t n_cells = static_cast<std::size_t>(cells_[0] * cells_[1] * cells_[2]);
  cell_start_.assign(n_cells + 1, 0);
  std::vector<std::uint32_t> cell_index(particles.size());
  for (std::size_t i = 0; i < particles.size(); ++i) {
    cell_index[i] = static_cast<std::uint32_t>(cell_of(particles.position[i]));
    ++cell_start_[cell_index[i] + 1];
  }
  for (std::size_t c = 0; c < n_cells; ++c) cell_start_[c + 1] += cell_start_[c];
  cell_members_.resize(particles.size());
  std::vector<std::uint32_t> fill(cell_start_.begin(), cell_start_.end() - 1);
  for (std::size_t i = 0; i < particles.size(); ++i) {
    cell_members_[fill[cell_index[i]]++] = static_cast<std::uint32_t>(i);
  }
}

void NeighborSearch::pairs_of(const ParticleStore& particles, std::size_t i,
                              const std::uint8_t* ghost, std::vector<std::uint32_t>& out) const {
  const Vec3 xi = particles.position[i];
  const double ri = particles.radius[i];
  const bool fixed_i = particles.is_fixed(i);  // two glued particles never interact
  std::int64_t ci[3];
  for (int k = 0; k < 3; ++k) {
    const auto ku = static_cast<std::size_t>(k);
    ci[k] = std::clamp<std::int64_t>(
        static_cast<std::int64_t>(std::floor((xi[k] - domain_.min[k]) / cell_size_[k])), 0,
        cells_[ku] - 1);
  }
  const std::size_t begin = out.size();
  for (int dz = -1; dz <= 1; ++dz) {
    std::int64_t cz = ci[2] + dz;
    if (cz < 0 || cz >= cells_[2]) {
      if (!domain_.periodic[2]) continue;
      cz = (cz + cells_[2]) % cells_[2];
    }
    for (int dy = -1; dy <= 1; ++dy) {
      std::int64_t cy = ci[1] + dy;
      if (cy < 0 || cy >= cells_[1]) {
        if (!domain_.periodic[1]) continue;
        cy = (cy + cells_[1]) % cells_[1];
      }
      for (int dx = -1; dx <= 1; ++dx) {
        std::int64_t cx = ci[0] + dx;
        if (cx < 0 || cx >= cells_[0]) {
          if (!domain_.periodic[0]) continue;
          cx = (cx + cells_[0]) % cells_[0];
        }
        const auto c = static_cast<std::size_t>((cz * cells_[1] + cy) * cells_[0] + cx);
        for (std::uint32_t m = cell_start_[c]; m < cell_start_[c + 1]; ++m) {
          const std::uint32_t j = cell_members_[m];
          if (j <= i || (ghost != nullptr && ghost[i] && ghost[j])) continue;
          if (fixed_i && particles.is_fixed(j)) continue;
          const double cut = ri + particles.radius[j] + skin_;
          const Vec3 d = domain_.minimum_image(particles.position[j] - xi);
          if (norm2(d) < cut * cut) out.push_back(j);
        }
      }
    }
  }
  std::sort(out.begin() + static_cast<std::ptrdiff_t>(begin), out.end());
}

template <typename Find>
void NeighborSearch::collect(std::size_t n, int threads, ContactList& list, Find&& find) {
  // Contiguous ranges of particles, several per thread (their costs differ), each filling
  // its own buffers; joined in range order, the list is the one a single loop builds.
  const std::size_t ranges =
      threads > 1 ? std::min<std::size_t>(n, 4 * static_cast<std::size_t>(threads)) : 1;
  if (range_first_.size() < ranges) {
    range_first_.resize(ranges);
    range_second_.resize(ranges);
  }
  const auto range_begin = [n, ranges](std::size_t r) { return n * r / ranges; };
  const auto fill = [&](std::size_t r) {
    std::vector<std::uint32_t>& first = range_first_[r];
    std::vector<std::uint32_t>& second = range_second_[r];
    first.clear();
    second.clear();
    for (std::size_t i = range_begin(r); i < range_begin(r + 1); ++i) {
      find(i, second);
      first.resize(second.size(), static_cast<std::uint32_t>(i));
    }
  };
  std::vector<std::size_t>& offset = range_offset_;
  offset.assign(ranges + 1, 0);
  if (threads > 1) {
#pragma omp parallel for schedule(dynamic, 1) num_threads(threads)
    for (std::size_t r = 0; r < ranges; ++r) fill(r);
  } else {
    for (std::size_t r = 0; r < ranges; ++r) fill(r);
  }
  for (std::size_t r = 0; r < ranges; ++r) offset[r + 1] = offset[r] + range_second_[r].size();
  list.first.resize(offset[ranges]);
  list.second.resize(offset[ranges]);
  list.history.assign(offset[ranges], ContactHistory{});
  parallel_for(ranges, threads, [&](std::size_t r) {
    std::copy(range_first_[r].begin(), range_first_[r].end(),
              list.first.begin() + static_cast<std::ptrdiff_t>(offset[r]));
    std::copy(range_second_[r].begin(), range_second_[r].end(),
              list.second.begin() + static_cast<std::ptrdiff_t>(offset[r]));
  });
}

void NeighborSearch::rebuild(ParticleStore& particles, const std::vector<Obstacle>& obstacles,
                             double time, ContactList& pairs, ContactList& walls,
                             const std::uint8_t* ghost, int threads) {
  const std::size_t n = particles.size();
  threads = std::max(threads, 1);
  parallel_for(n, threads, [&](std::size_t i) { domain_.wrap(particles.position[i]); });
  bin(particles);

  // Particle pairs: each particle looks at the 27 surrounding cells and keeps j > i,
  // so each pair appears once, and the list comes out sorted by (i, j).
  collect(n, threads, scratch_, [&](std::size_t i, std::vector<std::uint32_t>& out) {
    pairs_of(particles, i, ghost, out);
  });
  carry_history(pairs, scratch_, threads);
  std::swap(pairs, scratch_);

  // Particle-obstacle pairs, sorted by (particle, obstacle).
  collect(n, threads, scratch_, [&](std::size_t i, std::vector<std::uint32_t>& out) {
    if ((ghost != nullptr && ghost[i]) || particles.is_fixed(i)) return;  // glued: no force
    for (std::size_t o = 0; o < obstacles.size(); ++o) {
      if (!obstacles[o].active(time)) continue;
      const SphereObstacleGap gap =
          sphere_gap(obstacles[o], time, particles.position[i], particles.radius[i]);
      if (gap.overlap > -skin_) out.push_back(static_cast<std::uint32_t>(o));
    }
  });
  carry_history(walls, scratch_, threads);
  std::swap(walls, scratch_);

  reference_ = particles.position;
  if (has_non_spherical(particles)) {
    reference_orientation_ = particles.orientation;
  } else {
    reference_orientation_.clear();
  }
  reference_time_ = time;
  ++rebuilds_;
}

}  // namespace sanguis::dem
