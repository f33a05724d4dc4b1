#pragma once
// Boundary conditions on the six faces of the domain for cell-centred
// scalars, applied by filling the ghost cells of blocks that touch the
// boundary (after Forest::exchange has filled those facing other blocks).
//
// Face numbering: face 2*d + side, d = 0,1,2 (x,y,z), side 0 = lower, 1 = upper.
// Dirichlet (value g on the face): the first ghost is the quadratic through
// g and the first two interior cells, ghost(-1) = (8 g - 6 u(0) + u(1)) / 3,
// so parabolic profiles (Poiseuille) are reproduced exactly; the second
// ghost is linear, ghost(-2) = 2 g - u(1). Homogeneous fills (multigrid
// corrections on coarse levels) use the linear ghost(-1-m) = -u(m).
// Neumann (zero normal gradient): ghost(-1-m) = interior(m).

#include <array>
#include <cstdint>
#include <functional>

#include "core/vec3.hpp"
#include "flow/block_field.hpp"
#include "flow/forest.hpp"

namespace sanguis::flow {

enum class BcKind : std::uint8_t {
  Periodic,   ///< handled by the forest (the face has a neighbour block)
  Dirichlet,  ///< given value on the face
  Neumann,    ///< zero normal gradient
};

/// Value of a Dirichlet condition at a point of the boundary face (m, s, ...).
using FaceValue = std::function<double(const Vec3& x)>;

inline constexpr int face_index(int d, int side) {
  return 2 * d + side;
}

struct ScalarBoundary {
  std::array<BcKind, 6> kind{};      ///< per face
  std::array<FaceValue, 6> value{};  ///< Dirichlet value per face; empty means 0
};

/// x with its coordinates along the periodic directions brought into the
/// domain (one period over); the others are left as they are.
Vec3 wrap_periodic(const Forest& forest, Vec3 x);

/// Boundary kinds all equal to `kind` except the periodic directions.
std::array<BcKind, 6> uniform_kinds(const Forest& forest, BcKind kind);

/// Fills the ghost cells beyond domain faces, `width` layers, for every local
/// block. Faces are treated in the order x, y, z over the whole ghost slab
/// so edge and corner ghosts end up consistent. With `homogeneous` the
/// Dirichlet values are taken as zero (multigrid corrections).
void fill_boundary_ghosts(const Forest& forest, BlockField& field, const ScalarBoundary& bc,
                          int width, bool homogeneous = false);
/// The same with only the kinds (homogeneous Dirichlet).
void fill_boundary_ghosts(const Forest& forest, BlockField& field,
                          const std::array<BcKind, 6>& kinds, int width);

/// fill_boundary_ghosts() for block `blk` alone (`values` null: homogeneous).
/// With `colour` >= 0 (an even block size, width 1): only the face ghosts of
/// that red-black colour, as Forest::copy_face_ghosts, and no edge or corner
/// ghost: what a half-sweep of the smoother reads, at half the cost.
/// `neumann` false leaves the Neumann faces (for a smoother that reads their
/// mirror cells in place).
void fill_block_boundary_ghosts(const Forest& forest, BlockField& field, int blk,
                                const std::array<BcKind, 6>& kinds,
                                const std::array<FaceValue, 6>* values, int width, int colour = -1,
                                bool neumann = true);

/// Zero-gradient extrapolation of a face field into the ghost cells beyond
/// domain faces (`width` layers). The faces on the domain boundary itself
/// (slot 0 of a lower face, slot b of an upper face of the normal component)
/// are kept: they carry the boundary condition.
void fill_face_field_ghosts(const Forest& forest, FaceField& uf, int width);

}  // namespace sanguis::flow
