// Frames of the discrete elastic rod (Bergou et al. 2008 §4, Bergou et al. 2010 §5):
// parallel transport of a frame vector between unit tangents, the time-parallel
// reference frame of an edge and its twist rate, and the grasp map u -> (grasped nodes,
// last material angle) with exact first and second derivatives (second-order jets).
//
// Time-parallel reference frame of an edge (2010 §5.1): a(t) = P_{t_s}^{t} a_s, the
// reference director a_s of the last accepted tangent t_s carried to the current tangent t
// by the rotation about t_s × t (parallel transport, 2008 §4.1 / 2010 (3)). Its variation
// has a rotation about t as well as the obvious tilt:
//   da = -(a·dt) t + (Â·dt) b,   b = t × a,   Â(t) = (t × t_s) / (1 + t_s·t),
// Â is the twist rate (the connection one-form of transport from the pole t_s). It is 0 at
// t = t_s, which is why the usual DER gradients (which drop it) are exact only there;
// here it is kept, so E, E_x and E_xx are exact at every state.
#pragma once

#include <cmath>
#include <numbers>

#include <Eigen/Core>
#include <Eigen/Geometry>

namespace snapthread::rod {

using V3 = Eigen::Vector3d;
using M3 = Eigen::Matrix3d;

inline M3 Cross(const V3& v) {
  M3 m;
  m << 0.0, -v.z(), v.y(), v.z(), 0.0, -v.x(), -v.y(), v.x(), 0.0;
  return m;
}

// The rotation that takes unit t0 to unit t1 about t0 × t1, applied to any v
// (Rodrigues; 2008 §4.1 "discrete parallel transport"). Undefined for t1 = -t0.
inline V3 Transport(const V3& t0, const V3& t1, const V3& v) {
  const V3 k = t0.cross(t1);
  const double c = t0.dot(t1);
  return c * v + k.cross(v) + (k.dot(v) / (1.0 + c)) * k;
}

// Twist rate Â(t) of the time-parallel reference frame transported from t_s, and its
// Jacobian dÂ/dt = -([t_s]× + Â t_sᵀ) / (1 + t_s·t).
inline V3 TwistRate(const V3& ts, const V3& t) { return t.cross(ts) / (1.0 + ts.dot(t)); }
inline M3 TwistRateJacobian(const V3& ts, const V3& t) {
  return -(Cross(ts) + TwistRate(ts, t) * ts.transpose()) / (1.0 + ts.dot(t));
}

// The signed angle from the director u to the director v about the unit tangent t
// (both ⊥ t), continued from `near` (the value at the last accepted state) so it never
// jumps by 2π while the rod twists.
inline double AngleAbout(const V3& t, const V3& u, const V3& v, double near) {
  const double raw = std::atan2(u.cross(v).dot(t), u.dot(v));
  return near + std::remainder(raw - near, 2.0 * std::numbers::pi);
}

// ---------------------------------------------------------------------------------
// A second-order jet in three variables (value, gradient, Hessian): exact first and
// second derivatives of the small map φ -> exp([φ]×) R_start v by forward propagation.
struct Jet {
  double v = 0.0;
  V3 g = V3::Zero();
  M3 h = M3::Zero();

  static Jet Constant(double c) {
    Jet j;
    j.v = c;
    return j;
  }
  static Jet Variable(double value, int index) {
    Jet j;
    j.v = value;
    j.g[index] = 1.0;
    return j;
  }
};

inline Jet operator+(const Jet& a, const Jet& b) { return {a.v + b.v, a.g + b.g, a.h + b.h}; }
inline Jet operator-(const Jet& a, const Jet& b) { return {a.v - b.v, a.g - b.g, a.h - b.h}; }
inline Jet operator*(double s, const Jet& a) { return {s * a.v, s * a.g, s * a.h}; }
inline Jet operator*(const Jet& a, const Jet& b) {
  const M3 gg = a.g * b.g.transpose();
  return {a.v * b.v, a.v * b.g + b.v * a.g, a.v * b.h + b.v * a.h + gg + gg.transpose()};
}
// f(a) from f, f', f'' at a.v.
inline Jet Chain(const Jet& a, double f, double f1, double f2) {
  return {f, f1 * a.g, f1 * a.h + f2 * (a.g * a.g.transpose())};
}
inline Jet Inverse(const Jet& a) {
  const double r = 1.0 / a.v;
  return Chain(a, r, -r * r, 2.0 * r * r * r);
}
// atan2(y, x) with its first and second partial derivatives.
inline Jet Atan2(const Jet& y, const Jet& x) {
  const double r2 = x.v * x.v + y.v * y.v;
  const double r4 = r2 * r2;
  const double fy = x.v / r2, fx = -y.v / r2;
  const double fyy = -2.0 * x.v * y.v / r4, fxx = -fyy, fxy = (y.v * y.v - x.v * x.v) / r4;
  const M3 xy = x.g * y.g.transpose();
  return {std::atan2(y.v, x.v), fy * y.g + fx * x.g,
          fy * y.h + fx * x.h + fyy * (y.g * y.g.transpose()) + fxx * (x.g * x.g.transpose()) +
              fxy * (xy + xy.transpose())};
}

struct JetVec {
  Jet c[3];
  static JetVec Constant(const V3& v) {
    JetVec r;
    for (int k = 0; k < 3; ++k) r.c[k] = Jet::Constant(v[k]);
    return r;
  }
  V3 Value() const { return V3(c[0].v, c[1].v, c[2].v); }
};
inline JetVec operator+(const JetVec& a, const JetVec& b) {
  return {{a.c[0] + b.c[0], a.c[1] + b.c[1], a.c[2] + b.c[2]}};
}
inline JetVec operator-(const JetVec& a, const JetVec& b) {
  return {{a.c[0] - b.c[0], a.c[1] - b.c[1], a.c[2] - b.c[2]}};
}
inline JetVec operator*(const Jet& s, const JetVec& a) {
  return {{s * a.c[0], s * a.c[1], s * a.c[2]}};
}
inline Jet Dot(const JetVec& a, const JetVec& b) {
  return a.c[0] * b.c[0] + a.c[1] * b.c[1] + a.c[2] * b.c[2];
}
inline Jet Dot(const V3& a, const JetVec& b) {
  return a[0] * b.c[0] + a[1] * b.c[1] + a[2] * b.c[2];
}
inline JetVec CrossJ(const JetVec& a, const JetVec& b) {
  return {{a.c[1] * b.c[2] - a.c[2] * b.c[1], a.c[2] * b.c[0] - a.c[0] * b.c[2],
           a.c[0] * b.c[1] - a.c[1] * b.c[0]}};
}

// exp([φ]×) v = v + A(s) φ×v + B(s) φ×(φ×v), s = |φ|², A = sin|φ|/|φ|,
// B = (1 - cos|φ|)/|φ|² (Rodrigues), with φ the three jet variables. A and B are taken as
// functions of s (smooth at φ = 0: a series below s = 0.1, closed form above).
JetVec RotateJet(const V3& phi, const V3& v);

// The rotation matrix exp([φ]×) (plain values).
inline M3 ExpMap(const V3& phi) {
  const double angle = phi.norm();
  if (angle < 1e-300) return M3::Identity();
  return Eigen::AngleAxisd(angle, phi / angle).toRotationMatrix();
}

}  // namespace snapthread::rod
