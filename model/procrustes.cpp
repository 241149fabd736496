// Procrustes baseline (seed 002 §3.4): similarity transform only.
#include <stdexcept>

#include <Eigen/Geometry>

#include "model/adapt.h"
#include "model/adapt_detail.h"

namespace orthoface::model {

mesh::TriMesh procrustes_fit(const BaseMesh& base, const StereoData& data,
                             const AdaptOptions& options) {
  options.check();
  const LandmarkTargets t = detail::align_and_target(base, data, options, nullptr).targets;
  const int n = static_cast<int>(t.vertices.size());
  if (n < 3)
    throw std::invalid_argument("procrustes_fit: only " + std::to_string(n) +
                                " base vertices have 3D data (need 3)");
  Eigen::Matrix3Xd src(3, n), dst(3, n);
  for (int i = 0; i < n; ++i) {
    src.col(i) = base.mesh.vertices[t.vertices[i]];
    dst.col(i) = t.positions[i];
  }
  const Eigen::Matrix4d m = Eigen::umeyama(src, dst, true);  // rotation, scale, translation
  mesh::TriMesh out = base.mesh;
  for (auto& v : out.vertices) v = m.topLeftCorner<3, 3>() * v + m.topRightCorner<3, 1>();
  return out;
}

}  // namespace orthoface::model
