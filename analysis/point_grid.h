#pragma once
// Radius queries over mesh vertices for model/ (not public API).

#include <cmath>
#include <map>
#include <tuple>
#include <vector>

#include <Eigen/Core>

namespace orthoface::analysis::detail {

// Vertices bucketed in cubes of side `cell` for radius queries (radius <= cell).
class PointGrid {
 public:
  PointGrid(const std::vector<Eigen::Vector3d>& points, double cell, const std::vector<int>& subset)
      : points_(points), cell_(cell) {
    for (int v : subset) cells_[key(points[v])].push_back(v);
  }
  // Calls f(u) for every stored vertex within `radius` of p.
  template <class F>
  void for_each_near(const Eigen::Vector3d& p, double radius, F&& f) const {
    const auto [kx, ky, kz] = key(p);
    for (long dx = -1; dx <= 1; ++dx)
      for (long dy = -1; dy <= 1; ++dy)
        for (long dz = -1; dz <= 1; ++dz) {
          const auto it = cells_.find({kx + dx, ky + dy, kz + dz});
          if (it == cells_.end()) continue;
          for (int u : it->second)
            if ((points_[u] - p).norm() <= radius) f(u);
        }
  }
  // Nearest stored vertex within `radius` of p, or -1.
  int nearest(const Eigen::Vector3d& p, double radius) const {
    int best = -1;
    double best_d = radius;
    for_each_near(p, radius, [&](int u) {
      const double d = (points_[u] - p).norm();
      if (d <= best_d) best_d = d, best = u;
    });
    return best;
  }

 private:
  using Key = std::tuple<long, long, long>;
  Key key(const Eigen::Vector3d& p) const {
    return {long(std::floor(p.x() / cell_)), long(std::floor(p.y() / cell_)),
            long(std::floor(p.z() / cell_))};
  }
  const std::vector<Eigen::Vector3d>& points_;
  double cell_;
  std::map<Key, std::vector<int>> cells_;
};

}  // namespace orthoface::analysis::detail
