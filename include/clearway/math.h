#pragma once
// Geometry is double throughout; Eigen's fixed-size types keep it allocation-free.
#include <Eigen/Core>
#include <Eigen/Geometry>

#include <cmath>
#include <vector>

namespace clearway {

using Vec3 = Eigen::Vector3d;  ///< a point or vector (metres where a length; its frame is always stated)
using Mat3 = Eigen::Matrix3d;  ///< a 3×3 matrix (rotations: Pose::R)

/// A rigid transform: a point p in the local frame is R·p + t in the parent frame.
struct Pose {
  Mat3 R = Mat3::Identity();  ///< rotation: orthonormal, det +1 (the caller's promise; not checked)
  Vec3 t = Vec3::Zero();      ///< translation (metres, parent frame)

  /// The identity transform.
  static Pose identity() { return {}; }
  /// A pure translation.
  static Pose translation(const Vec3& t) { Pose p; p.t = t; return p; }
  /// From a quaternion (x, y, z, w; normalised here) and a translation.
  static Pose fromQuaternion(double qx, double qy, double qz, double qw, const Vec3& t) {
    Pose p;
    p.R = Eigen::Quaterniond(qw, qx, qy, qz).normalized().toRotationMatrix();
    p.t = t;
    return p;
  }

  /// Maps a point from the local frame to the parent frame.
  Vec3 operator*(const Vec3& p) const { return R * p + t; }
  /// Composition: (this * other) maps other's local frame into this pose's parent frame.
  Pose operator*(const Pose& o) const { Pose p; p.R = R * o.R; p.t = R * o.t + t; return p; }
  /// The inverse transform.
  Pose inverse() const { Pose p; p.R = R.transpose(); p.t = -(p.R * t); return p; }
  /// True when every entry is finite.
  bool isFinite() const noexcept {
    // x·0 is 0 for finite x and NaN otherwise, and NaN survives the sum: 12 multiply-adds, no branches
    // (it runs for every pair of every query).
    double zero = 0.0;
    for (int i = 0; i < 9; ++i) zero += R.data()[i] * 0.0;
    for (int i = 0; i < 3; ++i) zero += t[i] * 0.0;
    return zero == 0.0;
  }
};

/// Appends p's twelve entries (R column by column, then t) to `out`: the part of a key that results computed
/// at this pose are remembered by (one list for every such key).
inline void appendPose(const Pose& p, std::vector<double>& out) {
  out.insert(out.end(), p.R.data(), p.R.data() + 9);
  out.insert(out.end(), p.t.data(), p.t.data() + 3);
}

/// The pose of frame b expressed in frame a: inverse(a) * b, computed without forming the inverse.
inline Pose relativePose(const Pose& a, const Pose& b) {
  Pose p;
  p.R = a.R.transpose() * b.R;
  p.t = a.R.transpose() * (b.t - a.t);
  return p;
}

}  // namespace clearway
