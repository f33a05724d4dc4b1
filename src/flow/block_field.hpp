#pragma once
// Storage for fields on a forest of blocks: each local block holds a cube of
// b^3 cells surrounded by ghost layers (kGhost = 2 for the flow fields; any
// width, e.g. 4 for the wavelet criterion's parent test), contiguous per block (one
// array per scalar: structure of arrays). A vector field is three scalars; a
// face-centred field (fluxes, face velocities, face coefficients) is three
// scalars of the same shape where component d at cell (i,j,k) is the value on
// the *lower* d-face of that cell, so the faces 0..b of a block are the slots
// 0..b (slot b lies in the ghost layer and equals the neighbour's face 0).

#include <array>
#include <cstddef>
#include <vector>

#include "core/huge_page_allocator.hpp"

namespace sanguis::flow {

/// The values of a field: a flat array on huge pages where it is large
/// (core/huge_page_allocator.hpp).
using FieldStorage = std::vector<double, HugePageAllocator<double>>;

/// Width of the ghost layer around every block (BCG advection needs two).
inline constexpr int kGhost = 2;

/// Index arithmetic of one block of b^3 cells with ghost layers of width
/// `ghost` (kGhost for the flow fields; 1 on coarse multigrid levels, whose
/// 7-point smoother and trilinear prolongation read one layer).
struct BlockLayout {
  int cells = 8;       ///< cells per block edge, b
  int ghost = kGhost;  ///< ghost layers on each side

  [[nodiscard]] constexpr int side() const { return cells + 2 * ghost; }
  [[nodiscard]] constexpr std::ptrdiff_t size() const {
    return std::ptrdiff_t{side()} * side() * side();
  }
  /// Offset of cell (i,j,k), each in [-ghost, b + ghost).
  [[nodiscard]] constexpr std::ptrdiff_t index(int i, int j, int k) const {
    return (std::ptrdiff_t{k + ghost} * side() + (j + ghost)) * side() + (i + ghost);
  }
  /// Offset between neighbouring cells along direction d.
  [[nodiscard]] constexpr std::ptrdiff_t stride(int d) const {
    return d == 0 ? 1 : (d == 1 ? side() : std::ptrdiff_t{side()} * side());
  }
};

// Iteration over one block, so that a kernel is written once for one cell
// (or one row of cells) and runs on every block of any size.

/// Calls body(i, j, k) for the cells 0..b-1 of a block, i fastest.
template <typename Body>
inline void for_each_cell(int b, Body&& body) {
  for (int k = 0; k < b; ++k)
    for (int j = 0; j < b; ++j)
      for (int i = 0; i < b; ++i) body(i, j, k);
}

/// Calls body(i, j, k) for the faces of component d of a face field: slots
/// 0..b along d (slot b, in the ghost layer, is the block's upper face), the
/// cells 0..b-1 across.
template <typename Body>
inline void for_each_face(int b, int d, Body&& body) {
  const int ni = d == 0 ? b + 1 : b, nj = d == 1 ? b + 1 : b, nk = d == 2 ? b + 1 : b;
  for (int k = 0; k < nk; ++k)
    for (int j = 0; j < nj; ++j)
      for (int i = 0; i < ni; ++i) body(i, j, k);
}

/// Calls body(row, j, k) for every row of a block's cells along x, row being
/// the offset of cell (0, j, k): the pointer-and-offset form of
/// for_each_cell for the passes that stream several arrays (contiguous in i,
/// so the compiler vectorises them; the same operations per cell).
template <typename Body>
inline void for_each_row(const BlockLayout& L, Body&& body) {
  for (int k = 0; k < L.cells; ++k)
    for (int j = 0; j < L.cells; ++j) body(L.index(0, j, k), j, k);
}

/// Calls body(c, g) for every cell c of the block's layer beside face (d, side)
/// (side 0: the lower face) and the ghost g just beyond that face.
template <typename Body>
void for_face_cells(const BlockLayout& L, int d, int side, Body&& body) {
  const int b = L.cells;
  const int e1 = (d + 1) % 3, e2 = (d + 2) % 3;
  for (int t2 = 0; t2 < b; ++t2)
    for (int t1 = 0; t1 < b; ++t1) {
      int n[3] = {0, 0, 0};
      n[d] = side == 0 ? 0 : b - 1;
      n[e1] = t1;
      n[e2] = t2;
      const std::ptrdiff_t c = L.index(n[0], n[1], n[2]);
      body(c, side == 0 ? c - L.stride(d) : c + L.stride(d));
    }
}

/// One scalar per cell (interior and ghosts) of every local block.
class BlockField {
 public:
  BlockField() = default;
  BlockField(int blocks, int cells_per_block, int ghost = kGhost)
      : layout_{cells_per_block, ghost},
        blocks_(blocks),
        data_(static_cast<std::size_t>(blocks * layout_.size()), 0.0) {}

  [[nodiscard]] const BlockLayout& layout() const { return layout_; }
  [[nodiscard]] int cells() const { return layout_.cells; }
  [[nodiscard]] int blocks() const { return blocks_; }

  [[nodiscard]] double* block(int b) { return data_.data() + b * layout_.size(); }
  [[nodiscard]] const double* block(int b) const { return data_.data() + b * layout_.size(); }

  double& operator()(int b, int i, int j, int k) { return block(b)[layout_.index(i, j, k)]; }
  double operator()(int b, int i, int j, int k) const { return block(b)[layout_.index(i, j, k)]; }

  void fill(double value) { data_.assign(data_.size(), value); }
  /// Every value zero on `blocks` blocks of the given layout, in the storage
  /// the field already has when it is large enough (a regrid that reuses its
  /// fields touches no fresh page; the storage never shrinks).
  void reshape(int blocks, int cells_per_block, int ghost = kGhost) {
    layout_ = {cells_per_block, ghost};
    blocks_ = blocks;
    data_.assign(static_cast<std::size_t>(blocks * layout_.size()), 0.0);
  }
  [[nodiscard]] FieldStorage& raw() { return data_; }
  [[nodiscard]] const FieldStorage& raw() const { return data_; }

 private:
  BlockLayout layout_{};
  int blocks_ = 0;
  FieldStorage data_;
};

/// Three cell-centred components (velocity, pressure gradient, ...).
using VectorField = std::array<BlockField, 3>;
/// Three face-centred components: component d lives on the lower d-faces.
using FaceField = std::array<BlockField, 3>;

inline VectorField make_vector_field(int blocks, int cells, int ghost = kGhost) {
  return {BlockField(blocks, cells, ghost), BlockField(blocks, cells, ghost),
          BlockField(blocks, cells, ghost)};
}

/// BlockField::reshape for the three components.
inline void reshape(std::array<BlockField, 3>& field, int blocks, int cells, int ghost = kGhost) {
  for (BlockField& component : field) component.reshape(blocks, cells, ghost);
}

}  // namespace sanguis::flow
