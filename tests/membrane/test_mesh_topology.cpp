// MeshTopology: edges, counter-clockwise one-rings, corners and the twelve
// valence-5 nodes of a subdivided icosahedron; invalid surfaces are rejected.
#include "membrane/mesh_topology.hpp"

#include <gtest/gtest.h>

#include <algorithm>

using namespace sanguis;
using namespace sanguis::membrane;

TEST(MeshTopology, IcosphereHasTwelveValenceFiveNodesAndEulerCounts) {
  for (int k = 0; k <= 4; ++k) {
    const TriangleMesh m = icosphere(k);
    const MeshTopology topo(m.node_count(), m.triangles);
    EXPECT_EQ(topo.edges().size(), 3 * m.triangle_count() / 2);
    ASSERT_EQ(topo.valence5_nodes().size(), 12u);
    for (std::size_t i = 0; i < m.node_count(); ++i) {
      const bool five = std::count(topo.valence5_nodes().begin(), topo.valence5_nodes().end(),
                                   static_cast<NodeIndex>(i)) == 1;
      EXPECT_EQ(topo.valence(i), five ? 5u : 6u);
      EXPECT_EQ(topo.corners(i).size(), topo.valence(i));
    }
    EXPECT_EQ(topo.max_valence(), k == 0 ? 5u : 6u);
  }
}

TEST(MeshTopology, RingsAreCounterClockwiseSeenFromOutside) {
  const TriangleMesh m = icosphere(2);
  const MeshTopology topo(m.node_count(), m.triangles);
  for (std::size_t i = 0; i < m.node_count(); ++i) {
    const auto ring = topo.ring(i);
    const Vec3 xi = m.positions[i];
    for (std::size_t k = 0; k < ring.size(); ++k) {
      const Vec3 a = m.positions[ring[k]], b = m.positions[ring[(k + 1) % ring.size()]];
      // (i, a, b) is a triangle of the mesh, oriented outward.
      ASSERT_GT(dot(cross(a - xi, b - xi), xi), 0.0);
      const bool found =
          std::any_of(topo.corners(i).begin(), topo.corners(i).end(), [&](const auto& c) {
            const auto& t = m.triangles[c.triangle];
            return t[(c.corner + 1) % 3] == ring[k] &&
                   t[(c.corner + 2) % 3] == ring[(k + 1) % ring.size()];
          });
      ASSERT_TRUE(found);
    }
  }
}

TEST(MeshTopology, CornersListTrianglesInIncreasingOrder) {
  const TriangleMesh m = icosphere(2);
  const MeshTopology topo(m.node_count(), m.triangles);
  for (std::size_t i = 0; i < m.node_count(); ++i) {
    const auto c = topo.corners(i);
    for (std::size_t k = 0; k < c.size(); ++k) {
      EXPECT_EQ(m.triangles[c[k].triangle][c[k].corner], static_cast<NodeIndex>(i));
      if (k > 0) {
        EXPECT_LT(c[k - 1].triangle, c[k].triangle);
      }
    }
  }
}

TEST(MeshTopology, RejectsOpenOrInconsistentSurfaces) {
  TriangleMesh m = icosphere(1);
  auto open = m.triangles;
  open.pop_back();
  EXPECT_THROW(MeshTopology(m.node_count(), open), std::invalid_argument);
  auto flipped = m.triangles;
  std::swap(flipped[3][1], flipped[3][2]);
  EXPECT_THROW(MeshTopology(m.node_count(), flipped), std::invalid_argument);
  auto out_of_range = m.triangles;
  out_of_range[0][0] = 1000;
  EXPECT_THROW(MeshTopology(m.node_count(), out_of_range), std::invalid_argument);
}
