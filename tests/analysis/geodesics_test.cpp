#include "analysis/geodesics.h"
#include "analysis/bucket_queue.h"

#include <gtest/gtest.h>

#include <Eigen/Geometry>

#include <cmath>
#include <limits>

#include "tests/analysis/analysis_test_meshes.h"

namespace orthoface::analysis {
namespace {

using testing::great_circle;
using testing::icosphere;
using testing::plane_grid;

TEST(GeodesicDistances, SphereMatchesGreatCircle) {
  const double r = 100.0;
  const mesh::TriMesh m = icosphere(5, r);  // 10242 vertices
  const std::vector<double> d = geodesic_distances(m, {0});
  double sum_rel = 0.0, max_rel = 0.0;
  int count = 0;
  for (size_t i = 0; i < m.vertices.size(); ++i) {
    const double truth = great_circle(m.vertices[0], m.vertices[i], r);
    if (truth < 5.0) continue;
    const double rel = std::abs(d[i] - truth) / truth;
    sum_rel += rel, max_rel = std::max(max_rel, rel), ++count;
  }
  EXPECT_LT(sum_rel / count, 0.003);  // measured 0.15 %
  EXPECT_LT(max_rel, 0.012);          // measured 0.69 %
  // The antipode is half a great circle away.
  int far = 0;
  for (size_t i = 0; i < m.vertices.size(); ++i)
    if (m.vertices[i].dot(m.vertices[0]) < m.vertices[far].dot(m.vertices[0])) far = int(i);
  EXPECT_NEAR(d[far], M_PI * r, 0.01 * M_PI * r);
}

TEST(GeodesicDistances, FastMarchingBeatsEdgeGraphOnSphere) {
  const mesh::TriMesh m = icosphere(4, 50.0);
  const auto fm = geodesic_distances(m, {3});
  const auto eg = edge_graph_distances(m, {3});
  double err_fm = 0.0, err_eg = 0.0;
  for (size_t i = 0; i < m.vertices.size(); ++i) {
    const double truth = great_circle(m.vertices[3], m.vertices[i], 50.0);
    err_fm += std::abs(fm[i] - truth), err_eg += std::abs(eg[i] - truth);
    EXPECT_LE(fm[i], eg[i] + 1e-9);  // the edge paths are one of the candidates
  }
  EXPECT_LT(err_fm * 10.0, err_eg);
}

TEST(GeodesicDistances, PlaneIsExactEuclidean) {
  const mesh::TriMesh m = plane_grid(30, 2.0);
  const int src = 15 * 31 + 15;  // centre
  const auto d = geodesic_distances(m, {src});
  for (size_t i = 0; i < m.vertices.size(); ++i)
    EXPECT_NEAR(d[i], (m.vertices[i] - m.vertices[src]).norm(), 1e-9) << "vertex " << i;
}

TEST(GeodesicDistances, MaxDistanceStopsAndMarksUnreached) {
  const mesh::TriMesh m = plane_grid(20, 1.0);
  GeodesicOptions o;
  o.max_distance = 5.0;
  const auto d = geodesic_distances(m, {0}, o);
  for (size_t i = 0; i < m.vertices.size(); ++i) {
    const double e = m.vertices[i].norm();
    if (e > 5.0 + 1e-9) {
      EXPECT_TRUE(std::isinf(d[i])) << i;
    }
    if (e < 4.9) {
      EXPECT_NEAR(d[i], e, 1e-9) << i;
    }
  }
}

// m plus a separate right triangle with legs 1 at `corner` (a second component).
mesh::TriMesh with_island(mesh::TriMesh m, const Eigen::Vector3d& corner) {
  const int n = int(m.vertices.size());
  m.vertices.push_back(corner);
  m.vertices.push_back(corner + Eigen::Vector3d(1, 0, 0));
  m.vertices.push_back(corner + Eigen::Vector3d(0, 1, 0));
  m.triangles.push_back({n, n + 1, n + 2});
  return m;
}

TEST(GeodesicDistances, OtherComponentIsUnreached) {
  const int n = int(plane_grid(2, 1.0).vertices.size());
  const mesh::TriMesh m = with_island(plane_grid(2, 1.0), {10, 10, 0});
  const auto d = geodesic_distances(m, {0});
  EXPECT_TRUE(std::isinf(d[n]));
  EXPECT_TRUE(std::isinf(edge_graph_distances(m, {0})[n + 1]));
  EXPECT_DOUBLE_EQ(geodesic_distances(m, {n})[n + 1], 1.0);
}

TEST(GeodesicDistances, DegenerateTrianglesDoNotBreakIt) {
  mesh::TriMesh m = plane_grid(4, 1.0);
  m.vertices.push_back(m.vertices[0]);  // a zero-area sliver glued at vertex 0
  m.triangles.push_back({0, 1, int(m.vertices.size()) - 1});
  const auto d = geodesic_distances(m, {6});
  for (double x : d) EXPECT_TRUE(std::isfinite(x));
  EXPECT_NEAR(d.back(), d[0], 1e-12);
}

TEST(GeodesicDistances, BadInputThrows) {
  const mesh::TriMesh m = icosphere(1, 1.0);
  EXPECT_THROW(geodesic_distances(m, {int(m.vertices.size())}), std::invalid_argument);
  EXPECT_THROW(geodesic_distances(m, {-1}), std::invalid_argument);
  EXPECT_THROW(geodesic_distances(m, {}), std::invalid_argument);
  EXPECT_THROW(geodesic_distances(mesh::TriMesh{}, {0}), std::invalid_argument);
  EXPECT_THROW(edge_graph_distances(mesh::TriMesh{}, {0}), std::invalid_argument);
  GeodesicOptions o;
  o.max_distance = std::numeric_limits<double>::quiet_NaN();
  EXPECT_THROW(geodesic_distances(m, {0}, o), std::invalid_argument);
  mesh::TriMesh nan = m;
  nan.vertices[2].x() = std::numeric_limits<double>::quiet_NaN();
  EXPECT_THROW(geodesic_distances(nan, {0}), std::invalid_argument);
}

TEST(GeodesicSolver, RepeatedRunsMatchOneOffAndLocalRunsStop) {
  const mesh::TriMesh m = icosphere(3, 20.0);
  GeodesicSolver solver(m);
  const auto once = geodesic_distances(m, {5});
  GeodesicOptions near;
  near.max_distance = 10.0;
  const auto local = solver.reached({9}, near);
  for (const auto& [v, d] : local) EXPECT_LE(d, 10.0) << v;
  EXPECT_LT(local.size(), m.vertices.size() / 4);
  EXPECT_EQ(solver.distances({5}), once);  // the scratch state is reset between runs
  EXPECT_EQ(solver.distances({5}), once);
  EXPECT_THROW(solver.reached({}), std::invalid_argument);
  EXPECT_THROW(solver.reached({int(m.vertices.size())}), std::invalid_argument);
  EXPECT_THROW(GeodesicSolver(mesh::TriMesh{}), std::invalid_argument);
}

TEST(DistanceMatrices, RowsMatchSingleSourceAndAreSymmetric) {
  const mesh::TriMesh m = icosphere(2, 10.0);  // 162 vertices
  const DistanceMatrix g = geodesic_matrix(m, GeodesicMethod::kFastMarching);
  const DistanceMatrix e = euclidean_matrix(m);
  const DistanceMatrix eg = geodesic_matrix(m, GeodesicMethod::kEdgeGraph);
  ASSERT_EQ(g.n, 162);
  const auto row7 = geodesic_distances(m, {7});
  for (int j = 0; j < g.n; ++j) {
    // The smaller of the run from 7 and the run from j (162 vertices: they differ by ~1 %).
    const double from_j = geodesic_distances(m, {j})[7];
    EXPECT_NEAR(g.at(7, j), std::min(row7[j], from_j), 1e-4);
    EXPECT_NEAR(row7[j], from_j, 0.02 * row7[j] + 1e-3);
    EXPECT_EQ(g.at(7, j), g.at(j, 7));
    EXPECT_NEAR(eg.at(7, j), eg.at(j, 7), 1e-6 * eg.at(7, j));  // float sums in either order
    EXPECT_LE(e.at(7, j), g.at(7, j) + 1e-4);                   // chord <= arc
    EXPECT_GE(eg.at(7, j), g.at(7, j) - 1e-3);
  }
  EXPECT_THROW(geodesic_matrix(m, GeodesicMethod::kEdgeGraph, 100), std::invalid_argument);
  EXPECT_THROW(euclidean_matrix(m, 100), std::invalid_argument);
}

TEST(DistanceMatrices, EdgeGraphMatrixIsDijkstraRowByRow) {
  // 642 vertices: 20 full blocks of sources and a part block; a second component stays at +inf.
  const int n = int(icosphere(3, 20.0).vertices.size());
  const mesh::TriMesh m = with_island(icosphere(3, 20.0), {50, 50, 50});
  const DistanceMatrix eg = geodesic_matrix(m, GeodesicMethod::kEdgeGraph);
  ASSERT_EQ(eg.n, n + 3);
  for (int s : {0, 1, 31, 32, 333, n - 1, n, n + 2}) {
    const auto d = edge_graph_distances(m, {s});
    for (int j = 0; j < eg.n; ++j) {
      if (std::isinf(d[j])) {
        EXPECT_TRUE(std::isinf(eg.at(s, j))) << s << " " << j;
        continue;
      }
      EXPECT_NEAR(eg.at(s, j), d[j], 1e-6 * d[j]) << s << " " << j;  // float vs double sums
    }
  }
  EXPECT_FLOAT_EQ(eg.at(n, n + 1), 1.0f);
  EXPECT_TRUE(std::isinf(eg.at(0, n)));
}

TEST(GeodesicSolver, DistancesIntoMatchesDistances) {
  const mesh::TriMesh m = icosphere(3, 20.0);
  GeodesicSolver solver(m);
  ASSERT_EQ(solver.vertex_count(), int(m.vertices.size()));
  std::vector<float> row(m.vertices.size(), -1.0f);
  solver.distances_into(11, row.data());
  const auto d = solver.distances({11});
  for (size_t i = 0; i < d.size(); ++i) EXPECT_EQ(row[i], float(d[i])) << i;
  EXPECT_EQ(row[11], 0.0f);
  EXPECT_THROW(solver.distances_into(-1, row.data()), std::invalid_argument);
  EXPECT_THROW(solver.distances_into(int(m.vertices.size()), row.data()), std::invalid_argument);
  EXPECT_THROW(solver.distances_into(0, nullptr), std::invalid_argument);
  // Another component stays +inf.
  mesh::TriMesh two = m;
  const int n = int(two.vertices.size());
  two.vertices.push_back({100, 0, 0}), two.vertices.push_back({101, 0, 0});
  two.vertices.push_back({100, 1, 0});
  two.triangles.push_back({n, n + 1, n + 2});
  GeodesicSolver two_solver(two);
  std::vector<float> row2(two.vertices.size());
  two_solver.distances_into(0, row2.data());
  EXPECT_TRUE(std::isinf(row2[n + 1]));
  two_solver.distances_into(n, row2.data());
  EXPECT_FLOAT_EQ(row2[n + 1], 1.0f);
  EXPECT_TRUE(std::isinf(row2[0]));
}

TEST(BucketQueue, BucketsInKeyOrderFifoWithinAndOverflow) {
  BucketQueue<int> q(1.0, 3.0);  // buckets [0,1), [1,2), ...; span 3
  for (auto [key, v] : {std::pair{2.5, 1}, {0.7, 2}, {0.2, 3}, {1.5, 4}, {10.0, 5}, {2.2, 6}})
    q.push(key, v);
  std::vector<int> order;
  while (!q.empty()) {
    const auto [key, v] = q.pop();
    order.push_back(v);
    if (v == 2) q.push(0.1, 7);  // below the bucket being read: read later in that bucket
  }
  EXPECT_EQ(order, (std::vector<int>{2, 3, 7, 4, 1, 6, 5}));
  q.clear();
  EXPECT_TRUE(q.empty());
  q.push(0.0, 8);
  EXPECT_EQ(q.pop(), (std::pair<float, int>{0.0f, 8}));
  EXPECT_THROW(q.pop(), std::out_of_range);
  EXPECT_THROW(q.push(-1.0, 0), std::invalid_argument);
  EXPECT_THROW(q.push(std::numeric_limits<double>::quiet_NaN(), 0), std::invalid_argument);
  EXPECT_THROW(q.push(std::numeric_limits<double>::infinity(), 0), std::invalid_argument);
  EXPECT_THROW(BucketQueue<int>().push(1.0, 0), std::invalid_argument);
  EXPECT_THROW(BucketQueue<int>(0.0, 1.0), std::invalid_argument);
  EXPECT_THROW(BucketQueue<int>(1.0, -1.0), std::invalid_argument);
  EXPECT_THROW(BucketQueue<int>(1e-9, 1e9), std::invalid_argument);
}

TEST(EdgeGraphDistances, ExactOnAMeshWithATinyEdge) {
  // One edge 10^-7 of the longest: wider buckets than the shortest edge, still exact.
  mesh::TriMesh m = plane_grid(4, 1.0);
  m.vertices[6].x() = m.vertices[5].x() + 1e-7;
  const auto d = edge_graph_distances(m, {0});
  const auto nb = vertex_neighbors(m);
  EXPECT_EQ(d[0], 0.0);
  for (size_t v = 1; v < m.vertices.size(); ++v) {
    double best = std::numeric_limits<double>::infinity();  // Bellman: d[v] = min over neighbours
    for (int u : nb[v]) best = std::min(best, d[u] + (m.vertices[u] - m.vertices[v]).norm());
    EXPECT_NEAR(d[v], best, 1e-12) << v;
  }
}

TEST(VertexNeighbors, IcosahedronHasFiveEach) {
  const auto nb = vertex_neighbors(icosphere(0, 1.0));
  ASSERT_EQ(nb.size(), 12u);
  for (const auto& row : nb) EXPECT_EQ(row.size(), 5u);
  EXPECT_THROW(vertex_neighbors(mesh::TriMesh{}), std::invalid_argument);
}

TEST(GeodesicPath, SphereGeodesicStaysOnGreatCircle) {
  const mesh::TriMesh m = icosphere(4, 100.0);
  const auto d = geodesic_distances(m, {0});
  int target = 0;
  for (size_t i = 0; i < m.vertices.size(); ++i)
    if (std::abs(d[i] - 150.0) < std::abs(d[target] - 150.0)) target = int(i);
  const GeodesicPath path = geodesic_path(m, d, target);
  ASSERT_GE(path.points.size(), 3u);
  EXPECT_TRUE(path.reached_source);
  EXPECT_NEAR((path.points.back() - m.vertices[0]).norm(), 0.0, 1e-9);
  const Eigen::Vector3d plane_n = m.vertices[0].cross(m.vertices[target]).normalized();
  double length = 0.0;
  for (size_t k = 0; k < path.points.size(); ++k) {
    EXPECT_LT(std::abs(path.points[k].dot(plane_n)), 1.5) << k;  // 100 mm sphere
    if (k > 0) {
      length += (path.points[k] - path.points[k - 1]).norm();
      EXPECT_LE(path.distances[k], path.distances[k - 1] + 1e-9);
    }
  }
  EXPECT_NEAR(length, d[target], 0.01 * d[target]);
}

TEST(GeodesicPath, DegenerateAndBadInput) {
  const mesh::TriMesh m = icosphere(2, 10.0);
  const auto d = geodesic_distances(m, {0});
  const GeodesicPath at_source = geodesic_path(m, d, 0);
  ASSERT_EQ(at_source.points.size(), 1u);
  EXPECT_TRUE(at_source.reached_source);
  EXPECT_THROW(geodesic_path(m, d, -1), std::invalid_argument);
  EXPECT_THROW(geodesic_path(m, std::vector<double>(3, 0.0), 0), std::invalid_argument);
  std::vector<double> unreached = d;
  unreached[5] = std::numeric_limits<double>::infinity();
  EXPECT_THROW(geodesic_path(m, unreached, 5), std::invalid_argument);
}

}  // namespace
}  // namespace orthoface::analysis
