// What a viewer draws of the rod beyond its nodes: the material
// director m1 of each edge and the twist density. The twist at interior vertex i is
// θ_i − θ_{i−1} + m_i with m_i the reference twist [DVT (2), (4); docs/models-rod.md],
// the same quantity the twist energy ½ GJ (θ_i − θ_{i−1} + m_i)² / ℓ̄ uses.
#include "models/rod_model.h"

#include <cmath>

namespace snapthread {

using V3 = Eigen::Vector3d;

void RodModel::MaterialFrames(const Vec& x, const Vec& u, Eigen::Matrix3Xd* d1,
                              Vec* twist_density) const {
  const GraspMaps gm = Grasp(u, false);
  Eigen::Matrix3Xd nodes(3, n_ + 1);
  for (int k = 0; k <= n_; ++k) nodes.col(k) = Node(k, x, gm);
  Vec theta(n_);
  for (int j = 0; j < n_; ++j) theta[j] = Theta(j, x, gm);
  if (d1 != nullptr) {
    d1->resize(3, n_);
    for (int j = 0; j < n_; ++j) {
      const V3 t = (nodes.col(j + 1) - nodes.col(j)).normalized();
      V3 a, b;
      rod::ReferenceFrame(sources_[j], t, &a, &b);
      d1->col(j) = std::cos(theta[j]) * a + std::sin(theta[j]) * b;
    }
  }
  if (twist_density == nullptr) return;
  // Vertex twists (vertex i joins edges i−1 and i), continued from the accepted state's
  // reference twists as the energy does.
  Vec vertex_twist = Vec::Zero(n_ + 1);
  for (int i = 1; i <= n_ - 1; ++i) {
    const double m = rod::ReferenceTwist(nodes.col(i) - nodes.col(i - 1),
                                         nodes.col(i + 1) - nodes.col(i), sources_[i - 1],
                                         sources_[i], twist_near_[i]);
    vertex_twist[i] = theta[i] - theta[i - 1] + m;
  }
  // ℓ̄ = ℓ at every interior vertex (uniform rest edges).
  twist_density->resize(n_);
  for (int j = 0; j < n_; ++j) {
    double sum = 0.0;
    int count = 0;
    for (int i : {j, j + 1}) {
      if (i >= 1 && i <= n_ - 1) {
        sum += vertex_twist[i];
        count++;
      }
    }
    (*twist_density)[j] = sum / count / rest_;
  }
}

Vec RodModel::TwistDensity(const Vec& x, const Vec& u) const {
  Vec density;
  MaterialFrames(x, u, nullptr, &density);
  return density;
}

}  // namespace snapthread
