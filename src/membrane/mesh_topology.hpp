#pragma once
// Connectivity of a closed triangulated membrane, computed once from the
// triangles (it never changes during a run): the edges, each node's one-ring
// of neighbours in counter-clockwise order seen from outside (the paraboloid
// fits of §4.3.4 use it), each node's incident triangle corners (to gather
// per-triangle forces in a fixed order: deterministic for any thread count),
// and the twelve valence-5 nodes of a subdivided icosahedron.
//
// Lists are compressed rows (offsets of size n + 1 into one flat array), so
// each lives in one contiguous allocation.
#include <array>
#include <cstdint>
#include <span>
#include <vector>

#include "membrane/triangle_mesh.hpp"

namespace sanguis::membrane {

// A triangle corner: triangle index and which of its three nodes (0, 1, 2).
struct TriangleCorner {
  std::int32_t triangle = 0;
  std::int32_t corner = 0;
};

class MeshTopology {
 public:
  // Throws std::invalid_argument if the triangles are not a closed,
  // consistently oriented 2-manifold (every edge shared by exactly two
  // triangles in opposite directions, every node's fan a single closed ring).
  MeshTopology(std::size_t node_count, const std::vector<Triangle>& triangles);

  std::size_t node_count() const { return ring_offsets_.size() - 1; }
  std::size_t triangle_count() const { return triangle_count_; }

  // Unique edges, lower node index first.
  const std::vector<std::array<NodeIndex, 2>>& edges() const { return edges_; }

  // Neighbours of node i, counter-clockwise around the outward normal.
  std::span<const NodeIndex> ring(std::size_t i) const {
    return {ring_nodes_.data() + ring_offsets_[i], ring_nodes_.data() + ring_offsets_[i + 1]};
  }
  std::size_t valence(std::size_t i) const { return ring_offsets_[i + 1] - ring_offsets_[i]; }

  // Triangle corners at node i, in increasing triangle order.
  std::span<const TriangleCorner> corners(std::size_t i) const {
    return {corners_.data() + corner_offsets_[i], corners_.data() + corner_offsets_[i + 1]};
  }

  // Nodes with five neighbours (twelve on a subdivided icosahedron).
  const std::vector<NodeIndex>& valence5_nodes() const { return valence5_; }

  // Largest valence (for fixed-size local buffers in the fits).
  std::size_t max_valence() const { return max_valence_; }

 private:
  std::size_t triangle_count_ = 0;
  std::vector<std::array<NodeIndex, 2>> edges_;
  std::vector<std::size_t> ring_offsets_;
  std::vector<NodeIndex> ring_nodes_;
  std::vector<std::size_t> corner_offsets_;
  std::vector<TriangleCorner> corners_;
  std::vector<NodeIndex> valence5_;
  std::size_t max_valence_ = 0;
};

}  // namespace sanguis::membrane
