#include "flow/boundary.hpp"

#include <algorithm>

namespace sanguis::flow {

Vec3 wrap_periodic(const Forest& forest, Vec3 x) {
  const ForestSpec& spec = forest.spec();
  const Vec3 extent = forest.extent();
  for (int e = 0; e < 3; ++e) {
    if (!spec.periodic[static_cast<std::size_t>(e)]) continue;
    if (x[e] < spec.origin[e]) x[e] += extent[e];
    if (x[e] > spec.origin[e] + extent[e]) x[e] -= extent[e];
  }
  return x;
}

std::array<BcKind, 6> uniform_kinds(const Forest& forest, BcKind kind) {
  std::array<BcKind, 6> kinds{};
  for (int d = 0; d < 3; ++d) {
    const BcKind k = forest.spec().periodic[static_cast<std::size_t>(d)] ? BcKind::Periodic : kind;
    kinds[static_cast<std::size_t>(face_index(d, 0))] = k;
    kinds[static_cast<std::size_t>(face_index(d, 1))] = k;
  }
  return kinds;
}

namespace {

/// Cell (i,j,k) with the coordinate along d replaced by `n`.
std::array<int, 3> along(int d, int n, int t1, int t2) {
  std::array<int, 3> c{};
  c[static_cast<std::size_t>(d)] = n;
  c[static_cast<std::size_t>((d + 1) % 3)] = t1;
  c[static_cast<std::size_t>((d + 2) % 3)] = t2;
  return c;
}

/// x moved into the domain across the face's transverse directions e1, e2:
/// wrapped one period over where the domain is periodic, onto the boundary
/// where it is not. The ghosts at a block's edges lie beyond the face; a
/// boundary value (an inflow profile) is read only inside the domain.
Vec3 into_domain(const Forest& forest, Vec3 x, int e1, int e2) {
  x = wrap_periodic(forest, x);
  const ForestSpec& spec = forest.spec();
  const Vec3 extent = forest.extent();
  for (const int e : {e1, e2}) {
    if (spec.periodic[static_cast<std::size_t>(e)]) continue;
    x[e] = std::clamp(x[e], spec.origin[e], spec.origin[e] + extent[e]);
  }
  return x;
}

void fill_face(const Forest& forest, const Block& block, BlockField& field, int blk, int d,
               int side, BcKind kind, const FaceValue* value, int width, int colour) {
  const BlockLayout& L = field.layout();
  const int b = L.cells;
  double* data = field.block(blk);
  const double h = block.length / b;
  const int e1 = (d + 1) % 3, e2 = (d + 2) % 3;
  const std::ptrdiff_t s1 = L.stride(e1), s2 = L.stride(e2);
  const bool given = value != nullptr && static_cast<bool>(*value);
  // Every ghost is written from interior cells only, so the order is free:
  // the inner loop runs along the transverse direction with the smaller
  // stride (rows of x where the face allows it), and each kind of closure
  // has its own loop (this fill runs before every smoothing of a block).
  const bool e1_inner = s1 < s2;
  const std::ptrdiff_t s_in = e1_inner ? s1 : s2, s_out = e1_inner ? s2 : s1;
  // colour >= 0: the face ghosts of that colour only, (ghost + t1 + t2 +
  // parity) & 1 == colour as in Forest::copy_face_ghosts, without the edge
  // and corner ghosts (the smoother's 7-point stencil reads neither).
  const bool one_colour = colour >= 0;
  const int parity = static_cast<int>((block.coord[0] + block.coord[1] + block.coord[2]) * b) & 1;
  const int t_lo = one_colour ? 0 : -width, t_hi = one_colour ? b : b + width;
  const int t_step = one_colour ? 2 : 1;
  for (int m = 0; m < width; ++m) {
    const int ghost = side == 0 ? -1 - m : b + m;
    const int mirror = side == 0 ? m : b - 1 - m;
    const int next = side == 0 ? 1 : b - 2;  // the second interior cell (quadratic closure)
    const bool quadratic = m == 0 && b >= 2;
    // Offsets of the slab's (t1, t2) = (0, 0) cells; the rest by the strides.
    const auto g0 = along(d, ghost, 0, 0), m0 = along(d, mirror, 0, 0), n0 = along(d, next, 0, 0);
    const std::ptrdiff_t og = L.index(g0[0], g0[1], g0[2]), om = L.index(m0[0], m0[1], m0[2]),
                         on = L.index(n0[0], n0[1], n0[2]);
    for (int t_out = t_lo; t_out < t_hi; ++t_out) {
      const std::ptrdiff_t row = t_out * s_out;
      double* out = data + og + row;
      const double* inner = data + om + row;
      const double* second = data + on + row;
      const int t0 = one_colour ? (colour + ghost + t_out + parity) & 1 : t_lo;
      if (kind == BcKind::Neumann) {
        for (int t = t0; t < t_hi; t += t_step) out[t * s_in] = inner[t * s_in];
      } else if (value == nullptr) {
        // Homogeneous (multigrid corrections): linear closure.
        for (int t = t0; t < t_hi; t += t_step) out[t * s_in] = -inner[t * s_in];
      } else if (!given) {
        // A wall at rest: the closures below with g = 0.
        const double g = 0.0;
        if (quadratic) {
          for (int t = t0; t < t_hi; t += t_step)
            out[t * s_in] = (8.0 * g - 6.0 * inner[t * s_in] + second[t * s_in]) / 3.0;
        } else {
          for (int t = t0; t < t_hi; t += t_step) out[t * s_in] = 2.0 * g - inner[t * s_in];
        }
      } else {
        for (int t = t0; t < t_hi; t += t_step) {
          const int t1 = e1_inner ? t : t_out, t2 = e1_inner ? t_out : t;
          Vec3 x = block.lower;
          x[e1] += (t1 + 0.5) * h;
          x[e2] += (t2 + 0.5) * h;
          x[d] += side == 0 ? 0.0 : block.length;
          const double g = (*value)(into_domain(forest, x, e1, e2));
          // Quadratic through the face value and the two first cells: exact
          // for parabolic profiles (third-order boundary closure).
          out[t * s_in] = quadratic ? (8.0 * g - 6.0 * inner[t * s_in] + second[t * s_in]) / 3.0
                                    : 2.0 * g - inner[t * s_in];
        }
      }
    }
  }
}

void fill_all(const Forest& forest, BlockField& field, const std::array<BcKind, 6>& kinds,
              const std::array<FaceValue, 6>* values, int width) {
  forest.for_each_block(
      [&](int blk) { fill_block_boundary_ghosts(forest, field, blk, kinds, values, width); });
}

}  // namespace

void fill_block_boundary_ghosts(const Forest& forest, BlockField& field, int blk,
                                const std::array<BcKind, 6>& kinds,
                                const std::array<FaceValue, 6>* values, int width, int colour,
                                bool neumann) {
  width = std::min({width, field.cells(), field.layout().ghost});
  const Block& block = forest.block(blk);
  for (int d = 0; d < 3; ++d) {
    for (int side = 0; side < 2; ++side) {
      if (block.neighbours[face_neighbour_slot(d, side)].link != Link::Boundary) continue;
      const auto f = static_cast<std::size_t>(face_index(d, side));
      if (!neumann && kinds[f] == BcKind::Neumann) continue;
      fill_face(forest, block, field, blk, d, side, kinds[f], values ? &(*values)[f] : nullptr,
                width, colour);
    }
  }
}

void fill_face_field_ghosts(const Forest& forest, FaceField& uf, int width) {
  const int b = uf[0].cells();
  width = std::min({width, b, uf[0].layout().ghost});
  const BlockLayout& L = uf[0].layout();
  forest.for_each_block([&](int blk) {
    const Block& block = forest.block(blk);
    for (int d = 0; d < 3; ++d) {
      // The plane's cells by (t1, t2) along the other two directions, the inner loop along
      // the one with the smaller stride.
      const int e1 = (d + 1) % 3, e2 = (d + 2) % 3;
      const std::ptrdiff_t s_in = std::min(L.stride(e1), L.stride(e2));
      const std::ptrdiff_t s_out = std::max(L.stride(e1), L.stride(e2));
      for (int side = 0; side < 2; ++side) {
        std::array<int, 3> o{0, 0, 0};
        o[static_cast<std::size_t>(d)] = side == 0 ? -1 : 1;
        if (block.neighbours[static_cast<std::size_t>(neighbour_slot(o[0], o[1], o[2]))].link !=
            Link::Boundary) {
          continue;
        }
        for (int e = 0; e < 3; ++e) {
          double* data = uf[static_cast<std::size_t>(e)].block(blk);
          for (int m = 0; m < width; ++m) {
            int ghost = side == 0 ? -1 - m : b + m;
            int mirror = side == 0 ? m : b - 1 - m;
            if (e == d) {
              // Normal component: faces beyond the boundary face copy it.
              if (side == 1) ++ghost;
              mirror = side == 0 ? 0 : b;
            }
            if (ghost >= b + L.ghost) continue;  // beyond the stored layers
            const auto g0 = along(d, ghost, 0, 0), m0 = along(d, mirror, 0, 0);
            double* to = data + L.index(g0[0], g0[1], g0[2]);
            const double* from = data + L.index(m0[0], m0[1], m0[2]);
            for (int t_out = -width; t_out < b + width; ++t_out) {
              double* row_to = to + t_out * s_out;
              const double* row_from = from + t_out * s_out;
              for (int t = -width; t < b + width; ++t) row_to[t * s_in] = row_from[t * s_in];
            }
          }
        }
      }
    }
  });
}

void fill_boundary_ghosts(const Forest& forest, BlockField& field, const ScalarBoundary& bc,
                          int width, bool homogeneous) {
  fill_all(forest, field, bc.kind, homogeneous ? nullptr : &bc.value, width);
}

void fill_boundary_ghosts(const Forest& forest, BlockField& field,
                          const std::array<BcKind, 6>& kinds, int width) {
  fill_all(forest, field, kinds, nullptr, width);
}

}  // namespace sanguis::flow
