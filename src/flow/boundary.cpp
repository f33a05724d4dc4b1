#include "flow/boundary.hpp"

#include <algorithm>

namespace sanguis::flow {

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

void fill_face(const Block& block, BlockField& field, int blk, int d, int side, BcKind kind,
               const FaceValue* value, int width) {
  const BlockLayout& L = field.layout();
  const int b = L.cells;
  double* data = field.block(blk);
  const double h = block.length / b;
  for (int m = 0; m < width; ++m) {
    const int ghost = side == 0 ? -1 - m : b + m;
    const int mirror = side == 0 ? m : b - 1 - m;
    for (int t2 = -width; t2 < b + width; ++t2) {
      for (int t1 = -width; t1 < b + width; ++t1) {
        const auto g = along(d, ghost, t1, t2);
        const auto s = along(d, mirror, t1, t2);
        const double inner = data[L.index(s[0], s[1], s[2])];
        double& out = data[L.index(g[0], g[1], g[2])];
        if (kind == BcKind::Neumann) {
          out = inner;
        } else if (value == nullptr) {
          out = -inner;  // homogeneous (multigrid corrections): linear closure
        } else if (!*value) {
          if (m == 0 && b >= 2) {
            const auto s1 = along(d, side == 0 ? 1 : b - 2, t1, t2);
            out = (-6.0 * inner + data[L.index(s1[0], s1[1], s1[2])]) / 3.0;
          } else {
            out = -inner;
          }
        } else {
          Vec3 x = block.lower;
          for (int e = 0; e < 3; ++e) {
            x[e] += (static_cast<double>(s[static_cast<std::size_t>(e)]) + 0.5) * h;
          }
          x[d] = block.lower[d] + (side == 0 ? 0.0 : block.length);
          const double g = (*value)(x);
          if (m == 0 && b >= 2) {
            // Quadratic through the face value and the two first cells:
            // exact for parabolic profiles (third-order boundary closure).
            const auto s1 = along(d, side == 0 ? 1 : b - 2, t1, t2);
            const double next = data[L.index(s1[0], s1[1], s1[2])];
            out = (8.0 * g - 6.0 * inner + next) / 3.0;
          } else {
            out = 2.0 * g - inner;
          }
        }
      }
    }
  }
}

void fill_all(const Forest& forest, BlockField& field, const std::array<BcKind, 6>& kinds,
              const std::array<FaceValue, 6>* values, int width) {
  width = std::min({width, field.cells(), kGhost});
  forest.for_each_block([&](int blk) {
    const Block& block = forest.block(blk);
    for (int d = 0; d < 3; ++d) {
      for (int side = 0; side < 2; ++side) {
        std::array<int, 3> o{0, 0, 0};
        o[static_cast<std::size_t>(d)] = side == 0 ? -1 : 1;
        const Neighbour nb =
            block.neighbours[static_cast<std::size_t>(neighbour_slot(o[0], o[1], o[2]))];
        if (nb.link != Link::Boundary) continue;
        const auto f = static_cast<std::size_t>(face_index(d, side));
        fill_face(block, field, blk, d, side, kinds[f], values ? &(*values)[f] : nullptr, width);
      }
    }
  });
}

}  // namespace

void fill_face_field_ghosts(const Forest& forest, FaceField& uf, int width) {
  const int b = uf[0].cells();
  width = std::min({width, b, kGhost});
  const BlockLayout& L = uf[0].layout();
  forest.for_each_block([&](int blk) {
    const Block& block = forest.block(blk);
    for (int d = 0; d < 3; ++d) {
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
            for (int t2 = -width; t2 < b + width; ++t2)
              for (int t1 = -width; t1 < b + width; ++t1) {
                const auto g = along(d, ghost, t1, t2);
                const auto src = along(d, mirror, t1, t2);
                if (g[static_cast<std::size_t>(d)] >= b + kGhost) continue;
                data[L.index(g[0], g[1], g[2])] = data[L.index(src[0], src[1], src[2])];
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
