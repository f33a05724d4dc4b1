#include "membrane/mesh_topology.hpp"

#include <algorithm>
#include <stdexcept>
#include <string>

namespace sanguis::membrane {

MeshTopology::MeshTopology(std::size_t node_count, const std::vector<Triangle>& triangles)
    : triangle_count_(triangles.size()) {
  const auto fail = [](const std::string& why) {
    throw std::invalid_argument("membrane mesh is not a closed oriented surface: " + why);
  };
  // Corners per node (counting pass, then filling pass: triangle order kept).
  corner_offsets_.assign(node_count + 1, 0);
  for (const auto& t : triangles)
    for (const auto n : t) {
      if (n < 0 || static_cast<std::size_t>(n) >= node_count)
        fail("node index " + std::to_string(n) + " out of range");
      ++corner_offsets_[n + 1];
    }
  for (std::size_t i = 0; i < node_count; ++i) corner_offsets_[i + 1] += corner_offsets_[i];
  corners_.resize(corner_offsets_.back());
  std::vector<std::size_t> fill(corner_offsets_.begin(), corner_offsets_.end() - 1);
  for (std::size_t t = 0; t < triangles.size(); ++t)
    for (int c = 0; c < 3; ++c)
      corners_[fill[triangles[t][c]]++] = {static_cast<std::int32_t>(t), c};

  // One-ring: in triangle (i, a, b) seen from outside, b follows a
  // counter-clockwise around i. Walk that successor map once round.
  ring_offsets_.assign(node_count + 1, 0);
  ring_nodes_.reserve(corners_.size());
  std::vector<std::pair<NodeIndex, NodeIndex>> successor;
  for (std::size_t i = 0; i < node_count; ++i) {
    const auto fan = corners(i);
    if (fan.size() < 3) fail("node " + std::to_string(i) + " has fewer than 3 triangles");
    successor.clear();
    for (const auto& c : fan) {
      const auto& t = triangles[c.triangle];
      successor.emplace_back(t[(c.corner + 1) % 3], t[(c.corner + 2) % 3]);
    }
    std::sort(successor.begin(), successor.end());
    NodeIndex current = successor.front().first;
    for (std::size_t k = 0; k < fan.size(); ++k) {
      ring_nodes_.push_back(current);
      const auto it = std::lower_bound(successor.begin(), successor.end(),
                                       std::pair<NodeIndex, NodeIndex>{current, -1});
      if (it == successor.end() || it->first != current ||
          (it + 1 != successor.end() && (it + 1)->first == current))
        fail("the triangles around node " + std::to_string(i) + " are not one oriented fan");
      current = it->second;
    }
    if (current != successor.front().first)
      fail("the triangles around node " + std::to_string(i) + " do not close");
    ring_offsets_[i + 1] = ring_nodes_.size();
    max_valence_ = std::max(max_valence_, fan.size());
    if (fan.size() == 5) valence5_.push_back(static_cast<NodeIndex>(i));
    for (const auto j : ring(i))
      if (static_cast<NodeIndex>(i) < j) edges_.push_back({static_cast<NodeIndex>(i), j});
  }
  // Euler characteristic of a sphere: V - E + F = 2 (also catches a ring that
  // was closed early, i.e. a non-manifold node).
  if (static_cast<long>(node_count) - static_cast<long>(edges_.size()) +
          static_cast<long>(triangles.size()) !=
      2)
    fail("V - E + F != 2");
}

}  // namespace sanguis::membrane
