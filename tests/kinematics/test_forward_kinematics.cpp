// computeLinkPoses against closed forms: the planar arm (analytic), every joint type on a small robot,
// and the Panda at two configurations whose poses are derived by hand from its URDF origins below.
// validateJointVector: NaN, infinity, limits with their tolerance, continuous joints, zero quaternions.
#include <clearway/kinematics/forward_kinematics.h>
#include <clearway/load/robot_loader.h>

#include "load/robot_files.h"

#include <gtest/gtest.h>

#include <atomic>
#include <cmath>
#include <cstdlib>
#include <new>
#include <random>
#include <vector>

// Counts every allocation in this test program, so that a test can prove computeLinkPoses makes none.
// Every unaligned form of new and delete is replaced, so that (under AddressSanitizer too) each block is
// freed by the family that allocated it; the aligned forms stay the runtime's.
namespace {
std::atomic<long> g_allocations{0};
void* countedAllocation(std::size_t n) noexcept {
  ++g_allocations;
  return std::malloc(n == 0 ? 1 : n);
}
void* countedAllocationOrThrow(std::size_t n) {
  if (void* p = countedAllocation(n)) return p;
  throw std::bad_alloc();
}
}  // namespace
void* operator new(std::size_t n) { return countedAllocationOrThrow(n); }
void* operator new[](std::size_t n) { return countedAllocationOrThrow(n); }
void* operator new(std::size_t n, const std::nothrow_t&) noexcept { return countedAllocation(n); }
void* operator new[](std::size_t n, const std::nothrow_t&) noexcept { return countedAllocation(n); }
void operator delete(void* p) noexcept { std::free(p); }
void operator delete[](void* p) noexcept { std::free(p); }
void operator delete(void* p, std::size_t) noexcept { std::free(p); }
void operator delete[](void* p, std::size_t) noexcept { std::free(p); }
void operator delete(void* p, const std::nothrow_t&) noexcept { std::free(p); }
void operator delete[](void* p, const std::nothrow_t&) noexcept { std::free(p); }

using namespace clearway;
using clearway::test::TempDir;

namespace {

Mat3 rotX(double a) { return Eigen::AngleAxisd(a, Vec3::UnitX()).toRotationMatrix(); }
Mat3 rotY(double a) { return Eigen::AngleAxisd(a, Vec3::UnitY()).toRotationMatrix(); }
Mat3 rotZ(double a) { return Eigen::AngleAxisd(a, Vec3::UnitZ()).toRotationMatrix(); }

std::vector<Pose> poses(const RobotModel& m, const std::vector<double>& q) {
  EXPECT_EQ(static_cast<int>(q.size()), m.variableCount());
  std::vector<Pose> out(m.linkCount());
  computeLinkPoses(m, q.data(), out.data());
  return out;
}

void expectPose(const Pose& p, const Mat3& R, const Vec3& t, double tol, const std::string& what) {
  EXPECT_LE((p.t - t).cwiseAbs().maxCoeff(), tol) << what << ": t = " << p.t.transpose() << ", expected " << t.transpose();
  EXPECT_LE((p.R - R).cwiseAbs().maxCoeff(), tol) << what << ": R =\n" << p.R << "\nexpected\n" << R;
}

}  // namespace

TEST(ForwardKinematics, PlanarArmAnalytic) {
  const RobotModel m = loadRobot(test::sourceRobot("planar_arm/planar_arm.urdf"));
  const int link1 = m.linkIndex("link1"), link2 = m.linkIndex("link2"), tool = m.linkIndex("tool");
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> angle(-2.5, 2.5);
  for (int k = 0; k < 200; ++k) {
    const double q1 = angle(rng), q2 = angle(rng);
    const std::vector<Pose> p = poses(m, {q1, q2});
    const double L1 = 1.0, L2 = 0.5, z = 0.1;
    expectPose(p[0], Mat3::Identity(), Vec3::Zero(), 0.0, "base");
    expectPose(p[link1], rotZ(q1), Vec3(0, 0, z), 1e-14, "link1");
    expectPose(p[link2], rotZ(q1 + q2), Vec3(L1 * std::cos(q1), L1 * std::sin(q1), z), 1e-14, "link2");
    expectPose(p[tool], rotZ(q1 + q2),
               Vec3(L1 * std::cos(q1) + L2 * std::cos(q1 + q2), L1 * std::sin(q1) + L2 * std::sin(q1 + q2), z), 1e-14,
               "tool");
    // The elbow cylinder's far end (local z = +h after the pitch) is the tool point.
    const CollisionElement& c = m.link(link2).collisions[0];
    const Pose cylinder = p[link2] * c.origin;
    EXPECT_LT((cylinder * Vec3(0, 0, 0.25) - p[tool].t).norm(), 1e-14);
  }
}

TEST(ForwardKinematics, EveryJointType) {
  TempDir dir;
  // base → (prismatic along y, origin (1,0,0)) p → (continuous about x, rpy (0,0,π/2)) c →
  // (mimic of the prismatic: 2·d + 0.5 along z) m; base → (planar, normal z, origin z = 1) pl →
  // (floating) f; base → (fixed, rpy (π/2, 0, 0), xyz (0,0,3)) fx.
  const std::string urdf = dir.write("types.urdf", R"(<robot name="types">
    <link name="base"/><link name="p"/><link name="c"/><link name="m"/><link name="pl"/><link name="f"/><link name="fx"/>
    <joint name="slide" type="prismatic"><parent link="base"/><child link="p"/><origin xyz="1 0 0"/>
      <axis xyz="0 2 0"/><limit lower="-1" upper="1" velocity="0.5" effort="1"/></joint>
    <joint name="spin" type="continuous"><parent link="p"/><child link="c"/><origin rpy="0 0 1.5707963267948966"/>
      <axis xyz="1 0 0"/></joint>
    <joint name="follow" type="prismatic"><parent link="c"/><child link="m"/><axis xyz="0 0 1"/>
      <limit lower="-10" upper="10" velocity="1" effort="1"/><mimic joint="slide" multiplier="2" offset="0.5"/></joint>
    <joint name="base_plane" type="planar"><parent link="base"/><child link="pl"/><origin xyz="0 0 1"/><axis xyz="0 0 1"/></joint>
    <joint name="free" type="floating"><parent link="pl"/><child link="f"/></joint>
    <joint name="weld" type="fixed"><parent link="base"/><child link="fx"/><origin xyz="0 0 3" rpy="1.5707963267948966 0 0"/></joint>
  </robot>)");
  const RobotModel m = loadRobot(urdf);
  // Variables: slide, spin, base_plane/{x,y,theta}, free/{x,y,z,qx,qy,qz,qw}; follow and weld own none.
  ASSERT_EQ(m.variableCount(), 12);
  EXPECT_EQ(m.variables()[2].name, "base_plane/x");
  EXPECT_EQ(m.variables()[4].name, "base_plane/theta");
  EXPECT_EQ(m.variables()[11].name, "free/qw");
  EXPECT_EQ(m.joint(m.jointIndex("free")).first_variable, 5);
  EXPECT_TRUE(std::isinf(m.variables()[3].upper));
  EXPECT_TRUE(m.joint(m.jointIndex("slide")).axis.isApprox(Vec3::UnitY()));  // normalised

  const double d = 0.3, a = 0.7, x = 0.2, y = -0.4, th = 1.1;
  const Eigen::Quaterniond rot(Eigen::AngleAxisd(0.9, Vec3(1, 2, 3).normalized()));
  // The floating quaternion is given at twice its length: it is normalised.
  const std::vector<double> q{d, a, x, y, th, 0.1, 0.2, 0.3, 2 * rot.x(), 2 * rot.y(), 2 * rot.z(), 2 * rot.w()};
  const std::vector<Pose> p = poses(m, q);
  expectPose(p[m.linkIndex("p")], Mat3::Identity(), Vec3(1, d, 0), 1e-15, "prismatic");
  const Mat3 Rc = rotZ(M_PI / 2) * rotX(a);
  expectPose(p[m.linkIndex("c")], Rc, Vec3(1, d, 0), 1e-15, "continuous");
  expectPose(p[m.linkIndex("m")], Rc, Vec3(1, d, 0) + Rc * Vec3(0, 0, 2 * d + 0.5), 1e-15, "mimic");
  expectPose(p[m.linkIndex("pl")], rotZ(th), Vec3(x, y, 1), 1e-15, "planar");
  expectPose(p[m.linkIndex("f")], rotZ(th) * rot.toRotationMatrix(), Vec3(x, y, 1) + rotZ(th) * Vec3(0.1, 0.2, 0.3),
             1e-15, "floating");
  expectPose(p[m.linkIndex("fx")], rotX(M_PI / 2), Vec3(0, 0, 3), 1e-15, "fixed");
}

TEST(ForwardKinematics, EveryStepKindMatchesTheComposedChain) {
  // Revolute about ±z, x, y and skew axes (two mimics), prismatic along skew axes (one a mimic of another)
  // and fixed joints, each with a turned origin: every pose equals origin · motion composed down the chain,
  // whichever of the load-time step kinds computes it.
  struct Spec {
    const char* type;
    const char* axis;
    const char* mimic;  // the leader joint, or null
  };
  const Spec specs[] = {{"revolute", "0 0 1", nullptr},  {"prismatic", "0.3 -0.5 0.8", nullptr},
                        {"fixed", "1 0 0", nullptr},     {"revolute", "-2 1 0.5", nullptr},
                        {"prismatic", "0 1 0", "j1"},    {"revolute", "0 0 -1", nullptr},
                        {"fixed", "1 0 0", nullptr},     {"prismatic", "0 0 1", nullptr},
                        {"revolute", "1 0 0", "j0"},     {"revolute", "0 1 0", nullptr},
                        {"revolute", "0.3 -0.5 0.8", "j3"}};
  const int n = static_cast<int>(std::size(specs));
  TempDir dir;
  std::string urdf = "<robot name=\"kinds\"><link name=\"l0\"/>";
  for (int k = 0; k < n; ++k) {
    const std::string type = specs[k].type;
    urdf += "<link name=\"l" + std::to_string(k + 1) + "\"/><joint name=\"j" + std::to_string(k) + "\" type=\"" + type +
            "\"><parent link=\"l" + std::to_string(k) + "\"/><child link=\"l" + std::to_string(k + 1) +
            "\"/><origin xyz=\"0.1 " + std::to_string(0.2 * k) + " -0.3\" rpy=\"0.4 " + std::to_string(-0.3 * k) +
            " 1.2\"/>";
    if (type != "fixed")
      urdf += std::string("<axis xyz=\"") + specs[k].axis + "\"/><limit lower=\"-4\" upper=\"4\" velocity=\"1\" effort=\"1\"/>";
    if (specs[k].mimic) urdf += std::string("<mimic joint=\"") + specs[k].mimic + "\" multiplier=\"-1.5\" offset=\"0.25\"/>";
    urdf += "</joint>";
  }
  urdf += "</robot>";
  const RobotModel m = loadRobot(dir.write("kinds.urdf", urdf));
  std::mt19937 rng(9);
  std::uniform_real_distribution<double> u(-4.0, 4.0);
  for (int trial = 0; trial < 50; ++trial) {
    std::vector<double> q(m.variableCount());
    for (double& v : q) v = u(rng);
    const std::vector<Pose> p = poses(m, q);
    Pose expected = Pose::identity();
    for (int k = 0; k < n; ++k) {
      const Joint& j = m.joint(m.jointIndex("j" + std::to_string(k)));
      const std::string type = specs[k].type;
      double value = 0.0;
      if (specs[k].mimic) {
        value = -1.5 * q[m.joint(m.jointIndex(specs[k].mimic)).first_variable] + 0.25;
      } else if (type != "fixed") {
        value = q[j.first_variable];
      }
      Pose motion;
      if (type == "revolute") motion.R = Eigen::AngleAxisd(value, j.axis).toRotationMatrix();
      if (type == "prismatic") motion.t = value * j.axis;
      expected = expected * j.origin * motion;
      expectPose(p[m.linkIndex("l" + std::to_string(k + 1))], expected.R, expected.t, 1e-13,
                 "joint " + std::to_string(k) + " (" + type + ")");
    }
  }
}

TEST(ForwardKinematics, PlanarJointAboutAnotherAxis) {
  // A plane with normal x: (x, y) move along the basis planarBasis gives, θ turns about x.
  TempDir dir;
  const std::string urdf = dir.write("plane_x.urdf", R"(<robot name="px"><link name="a"/><link name="b"/>
    <joint name="pl" type="planar"><parent link="a"/><child link="b"/><axis xyz="1 0 0"/></joint></robot>)");
  const RobotModel m = loadRobot(urdf);
  Vec3 u, v;
  planarBasis(Vec3::UnitX(), &u, &v);
  EXPECT_NEAR(u.dot(Vec3::UnitX()), 0.0, 1e-15);
  EXPECT_NEAR(u.cross(v).dot(Vec3::UnitX()), 1.0, 1e-15);  // right-handed (u, v, n)
  const std::vector<Pose> p = poses(m, {0.5, -0.25, 0.3});
  expectPose(p[1], rotX(0.3), 0.5 * u - 0.25 * v, 1e-15, "planar about x");
  // For the usual normal z the basis is x, y.
  planarBasis(Vec3::UnitZ(), &u, &v);
  EXPECT_TRUE(u.isApprox(Vec3::UnitX()) && v.isApprox(Vec3::UnitY()));
}

// Hand derivation from panda.urdf (R = rotation, p = position, world = panda_link0; the URDF writes
// π/2 as 1.57079632679, so tolerances are 1e-10):
//   joint1 origin (0,0,0.333);  joint2 rpy (−π/2,0,0);  joint3 (0,−0.316,0) rpy (π/2,0,0);
//   joint4 (0.0825,0,0) rpy (π/2,0,0);  joint5 (−0.0825,0.384,0) rpy (−π/2,0,0);  joint6 rpy (π/2,0,0);
//   joint7 (0.088,0,0) rpy (π/2,0,0);  joint8 fixed (0,0,0.107);  hand fixed rpy (0,0,−π/4);
//   fingers (0,0,0.0584) along ±y of the hand.
// At q = 0: link1 p (0,0,0.333); link2 R Rx(−90) which maps (0,−0.316,0) to (0,0,0.316): link3 at
// (0,0,0.649), R = I; link4 at (0.0825,0,0.649), R Rx(90); Rx(90) maps (−0.0825,0.384,0) to
// (−0.0825,0,0.384): link5 at (0,0,1.033), R = I; link6 same point, R Rx(90); link7 at (0.088,0,1.033),
// R Rx(180); link8 0.107 further along −z: (0.088,0,0.926), R Rx(180).
TEST(ForwardKinematics, PandaAtZero) {
  CLEARWAY_SHARED_ROBOT_OR_SKIP(urdf, "panda/panda.urdf");
  const RobotModel m = loadRobot(urdf);
  const std::vector<Pose> p = poses(m, std::vector<double>(8, 0.0));
  const double tol = 1e-10;
  expectPose(p[m.linkIndex("panda_link1")], Mat3::Identity(), Vec3(0, 0, 0.333), tol, "link1");
  expectPose(p[m.linkIndex("panda_link2")], rotX(-M_PI / 2), Vec3(0, 0, 0.333), tol, "link2");
  expectPose(p[m.linkIndex("panda_link3")], Mat3::Identity(), Vec3(0, 0, 0.649), tol, "link3");
  expectPose(p[m.linkIndex("panda_link4")], rotX(M_PI / 2), Vec3(0.0825, 0, 0.649), tol, "link4");
  expectPose(p[m.linkIndex("panda_link5")], Mat3::Identity(), Vec3(0, 0, 1.033), tol, "link5");
  expectPose(p[m.linkIndex("panda_link6")], rotX(M_PI / 2), Vec3(0, 0, 1.033), tol, "link6");
  expectPose(p[m.linkIndex("panda_link7")], rotX(M_PI), Vec3(0.088, 0, 1.033), tol, "link7");
  expectPose(p[m.linkIndex("panda_link8")], rotX(M_PI), Vec3(0.088, 0, 0.926), tol, "link8");
}

// q = (0, 0, 0, −π/2, 0, π/2, 0), fingers d = 0.03. Up to link3 as at zero. link4 R = Rx(90)·Rz(−90);
// Rz(−90) maps (−0.0825,0.384,0) to (0.384,0.0825,0) and Rx(90) that to (0.384,0,0.0825): link5 at
// (0.4665,0,0.7315); its R = Rx(90)·Rz(−90)·Rx(−90) is −90° about Rx(90)·z = −y, i.e. Ry(90): the
// forearm points along +x. link6 R = Ry(90)·Rx(90)·Rz(90), which maps x to (1,0,0): link7 at
// (0.5545,0,0.7315); link7 R = link6 R·Rx(90) maps z to (0,0,−1) and x to (1,0,0): R = Rx(180), and
// link8 is 0.107 lower, (0.5545,0,0.6245). The hand is turned −45° about z: its y axis is
// (sin 45°, −cos 45°, 0) in the world, its origin link8's; the fingers sit 0.0584 below (z 0.5661),
// the left one d along the hand's y, the right one (axis −y, mimic) d the other way.
TEST(ForwardKinematics, PandaHandDerived) {
  CLEARWAY_SHARED_ROBOT_OR_SKIP(urdf, "panda/panda.urdf");
  const RobotModel m = loadRobot(urdf);
  const double d = 0.03, s = std::sqrt(0.5), tol = 1e-10;
  const std::vector<Pose> p = poses(m, {0, 0, 0, -M_PI / 2, 0, M_PI / 2, 0, d});
  expectPose(p[m.linkIndex("panda_link4")], rotX(M_PI / 2) * rotZ(-M_PI / 2), Vec3(0.0825, 0, 0.649), tol, "link4");
  expectPose(p[m.linkIndex("panda_link5")], rotY(M_PI / 2), Vec3(0.4665, 0, 0.7315), tol, "link5");
  expectPose(p[m.linkIndex("panda_link7")], rotX(M_PI), Vec3(0.5545, 0, 0.7315), tol, "link7");
  expectPose(p[m.linkIndex("panda_link8")], rotX(M_PI), Vec3(0.5545, 0, 0.6245), tol, "link8");
  const Mat3 hand = rotX(M_PI) * rotZ(-M_PI / 4);
  expectPose(p[m.linkIndex("panda_hand")], hand, Vec3(0.5545, 0, 0.6245), tol, "hand");
  expectPose(p[m.linkIndex("panda_leftfinger")], hand, Vec3(0.5545 + s * d, -s * d, 0.5661), tol, "left finger");
  expectPose(p[m.linkIndex("panda_rightfinger")], hand, Vec3(0.5545 - s * d, s * d, 0.5661), tol, "right finger");
}

TEST(ForwardKinematics, NoAllocation) {
  const RobotModel m = loadRobot(test::sourceRobot("arm6/arm6.urdf"));
  std::vector<Pose> p(m.linkCount());
  const std::vector<double> q{0.1, -0.2, 0.3, -0.4, 0.5, -0.6};
  const long before = g_allocations.load();
  for (int k = 0; k < 100; ++k) computeLinkPoses(m, q.data(), p.data());
  EXPECT_EQ(g_allocations.load(), before);
  // And the arm's tool is where its joint origins put it: straight up at q = 0.
  const std::vector<double> zero(6, 0.0);
  computeLinkPoses(m, zero.data(), p.data());
  EXPECT_TRUE(p[m.linkIndex("tool0")].t.isApprox(Vec3(0, 0, 0.1 + 0.15 + 0.4 + 0.35 + 0.1 + 0.08 + 0.1)));
}

TEST(ValidateJointVector, RejectsNonFiniteAndOutOfLimits) {
  const RobotModel m = loadRobot(test::sourceRobot("planar_arm/planar_arm.urdf"));
  std::string why;
  EXPECT_TRUE(validateJointVector(m, std::vector<double>{0.0, 2.5}.data(), &why)) << why;
  EXPECT_TRUE(validateJointVector(m, std::vector<double>{0.0, 2.5 + 0.5 * kJointLimitTolerance}.data(), &why)) << why;
  EXPECT_FALSE(validateJointVector(m, std::vector<double>{0.0, 2.5 + 1e-6}.data(), &why));
  EXPECT_NE(why.find("variable 1 'elbow' = 2.500001"), std::string::npos) << why;
  EXPECT_NE(why.find("outside its limits [-2.5, 2.5]"), std::string::npos) << why;
  EXPECT_FALSE(validateJointVector(m, std::vector<double>{NAN, 0.0}.data(), &why));
  EXPECT_NE(why.find("'shoulder' is nan"), std::string::npos) << why;
  EXPECT_FALSE(validateJointVector(m, std::vector<double>{0.0, -INFINITY}.data(), &why));
  EXPECT_TRUE(validateJointVector(m, std::vector<double>{-M_PI, 0.0}.data()));  // no reason asked for
}

TEST(ValidateJointVector, ContinuousPlanarAndFloating) {
  TempDir dir;
  const std::string urdf = dir.write("free.urdf", R"(<robot name="f">
    <link name="a"/><link name="b"/><link name="c"/><link name="d"/>
    <joint name="spin" type="continuous"><parent link="a"/><child link="b"/><limit lower="-1" upper="1" velocity="2" effort="1"/></joint>
    <joint name="plane" type="planar"><parent link="b"/><child link="c"/><axis xyz="0 0 1"/></joint>
    <joint name="free" type="floating"><parent link="c"/><child link="d"/></joint>
  </robot>)");
  const RobotModel m = loadRobot(urdf);
  ASSERT_EQ(m.variableCount(), 11);
  EXPECT_TRUE(std::isinf(m.joint(0).upper));  // a continuous joint's <limit> bounds are not position limits
  EXPECT_DOUBLE_EQ(m.joint(0).velocity, 2.0);
  std::vector<double> q{100.0, -50.0, 70.0, 40.0, 1e3, 1e3, 1e3, 0, 0, 0, 1};
  std::string why;
  EXPECT_TRUE(validateJointVector(m, q.data(), &why)) << why;
  q[10] = 0.0;
  EXPECT_FALSE(validateJointVector(m, q.data(), &why));
  EXPECT_NE(why.find("floating joint 'free' has a zero quaternion"), std::string::npos) << why;
  // FK gives NaN for it rather than inventing a rotation.
  std::vector<Pose> p(m.linkCount());
  computeLinkPoses(m, q.data(), p.data());
  EXPECT_FALSE(p[3].isFinite());
}
