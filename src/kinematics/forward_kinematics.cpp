#include <clearway/kinematics/forward_kinematics.h>

#include <cmath>
#include <limits>
#include <sstream>

#include "kinematics/pose_lanes.h"
#include "kinematics/sincos.h"

namespace clearway {
namespace {

// The motion of a joint in its own frame for its variables (or, for a mimic, its computed value).
Pose jointMotion(const Joint& j, const double* v) noexcept {
  Pose m;
  switch (j.type) {
    case JointType::Fixed: break;
    case JointType::Revolute:
    case JointType::Continuous: m.R = Eigen::AngleAxisd(v[0], j.axis).toRotationMatrix(); break;
    case JointType::Prismatic: m.t = v[0] * j.axis; break;
    case JointType::Planar: {
      Vec3 u, w;
      planarBasis(j.axis, &u, &w);
      m.t = v[0] * u + v[1] * w;
      m.R = Eigen::AngleAxisd(v[2], j.axis).toRotationMatrix();
      break;
    }
    case JointType::Floating: {
      m.t = Vec3(v[0], v[1], v[2]);
      const double norm = std::sqrt(v[3] * v[3] + v[4] * v[4] + v[5] * v[5] + v[6] * v[6]);
      // A zero quaternion (rejected by validateJointVector) gives NaN rather than a made-up rotation.
      m.R = norm > 0.0 ? Mat3(Eigen::Quaterniond(v[6] / norm, v[3] / norm, v[4] / norm, v[5] / norm).toRotationMatrix())
                       : Mat3::Constant(std::numeric_limits<double>::quiet_NaN());
      break;
    }
  }
  return m;
}

// A mimic joint's value: its leader's times the multiplier, plus the offset.
double mimicValue(const RobotModel& model, const Joint& j, const double* q) noexcept {
  return j.mimic.multiplier * q[model.joint(j.mimic.joint).first_variable] + j.mimic.offset;
}

std::string show(double x) {
  std::ostringstream s;
  s.precision(17);
  s << x;
  return s.str();
}

}  // namespace

void planarBasis(const Vec3& axis, Vec3* u, Vec3* v) noexcept {
  // u = ŷ × n for axes away from ŷ (for n = ẑ: u = x̂), else n × ẑ; then v = n × u.
  const Vec3 w = std::abs(axis.y()) < 0.9 ? Vec3(Vec3::UnitY().cross(axis)) : Vec3(axis.cross(Vec3::UnitZ()));
  *u = w.normalized();
  *v = axis.cross(*u);
}

void computeLinkPose(const RobotModel& model, const double* q, Pose* link_poses, int i) noexcept {
  using Kind = detail::KinematicStep::Kind;
  const detail::KinematicStep& st = model.kinematicStep(i);
  const Pose& parent = link_poses[st.parent];
  // parent · origin, written out in scalars (column-major) for every step but Other: the compiler does not
  // inline Eigen's fixed-size products here, and this runs for every link of every state checked.
  // M = parent.R · origin.R; t = parent.R · (origin.t + shift) + parent.t.
  const auto place = [&](const Vec3& shift, double* M, Pose& out) {
    const double* P = parent.R.data();
    const double* O = st.origin.R.data();
    for (int col = 0; col < 3; ++col)
      for (int r = 0; r < 3; ++r) M[3 * col + r] = P[r] * O[3 * col] + P[3 + r] * O[3 * col + 1] + P[6 + r] * O[3 * col + 2];
    const double o0 = st.origin.t[0] + shift[0], o1 = st.origin.t[1] + shift[1], o2 = st.origin.t[2] + shift[2];
    for (int r = 0; r < 3; ++r) out.t[r] = P[r] * o0 + P[3 + r] * o1 + P[6 + r] * o2 + parent.t[r];
  };
  Pose& out = link_poses[i];
  if (st.kind == Kind::TurnZ) {
    // parent · origin · Rot(±z, angle): only M's first two columns turn.
    double c, s;
    detail::sinCos(st.value(q), &s, &c);
    s *= st.axis_sign;
    double M[9];
    place(Vec3::Zero(), M, out);
    double* R = out.R.data();
    for (int r = 0; r < 3; ++r) {
      R[r] = c * M[r] + s * M[3 + r];
      R[3 + r] = c * M[3 + r] - s * M[r];
      R[6 + r] = M[6 + r];
    }
    return;
  }
  if (st.kind == Kind::Fixed) {
    place(Vec3::Zero(), out.R.data(), out);
    return;
  }
  if (st.kind == Kind::Slide) {  // parent · origin · Trans(value · axis)
    place(st.value(q) * st.axis, out.R.data(), out);
    return;
  }
  if (st.kind == Kind::Turn) {
    // parent · origin · Rot(u, angle) without forming the rotation: M · Rot = c·M + s·M[u]× + (1 − c)·(M u) uᵀ,
    // column by column. Written out in scalars, in the order the lanes (kinematic_lanes.cpp) repeat.
    double c, s;
    detail::sinCos(st.value(q), &s, &c);
    double M[9];
    place(Vec3::Zero(), M, out);
    const double ux = st.axis[0], uy = st.axis[1], uz = st.axis[2];
    double* R = out.R.data();
    for (int r = 0; r < 3; ++r) {
      const double w = (1.0 - c) * (M[r] * ux + M[3 + r] * uy + M[6 + r] * uz);
      R[r] = c * M[r] + s * (uz * M[3 + r] - uy * M[6 + r]) + ux * w;
      R[3 + r] = c * M[3 + r] + s * (ux * M[6 + r] - uz * M[r]) + uy * w;
      R[6 + r] = c * M[6 + r] + s * (uy * M[r] - ux * M[3 + r]) + uz * w;
    }
    return;
  }
  const Joint& j = model.joints()[model.links()[i].parent_joint];
  const Pose frame = parent * j.origin;
  if (j.isMimic()) {
    const double value = mimicValue(model, j, q);
    link_poses[i] = frame * jointMotion(j, &value);
  } else {
    link_poses[i] = frame * jointMotion(j, q + j.first_variable);
  }
}

void computeLinkPoses(const RobotModel& model, const double* q, Pose* link_poses) noexcept {
  link_poses[0] = Pose::identity();
  detail::computeLinksInLanes(model, q, link_poses, nullptr, 1, model.linkCount() - 1);
}

void computeLinkPoses(const RobotModel& model, const double* q, Pose* link_poses, const int* links,
                      int count) noexcept {
  detail::computeLinksInLanes(model, q, link_poses, links, 0, count);
}

bool validateJointVector(const RobotModel& model, const double* q, std::string* why) {
  const std::vector<JointVariable>& vars = model.variables();
  for (std::size_t i = 0; i < vars.size(); ++i) {
    const JointVariable& v = vars[i];
    if (!std::isfinite(q[i])) {
      if (why) *why = "variable " + std::to_string(i) + " '" + v.name + "' is " + show(q[i]);
      return false;
    }
    if (q[i] < v.lower - kJointLimitTolerance || q[i] > v.upper + kJointLimitTolerance) {
      if (why)
        *why = "variable " + std::to_string(i) + " '" + v.name + "' = " + show(q[i]) + " is outside its limits [" +
               show(v.lower) + ", " + show(v.upper) + "]";
      return false;
    }
  }
  for (const Joint& j : model.joints()) {
    if (j.type != JointType::Floating) continue;
    const double* r = q + j.first_variable + 3;
    if (!(r[0] * r[0] + r[1] * r[1] + r[2] * r[2] + r[3] * r[3] > 0.0)) {
      if (why) *why = "floating joint '" + j.name + "' has a zero quaternion";
      return false;
    }
  }
  return true;
}

}  // namespace clearway
