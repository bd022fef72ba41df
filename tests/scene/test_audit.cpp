// Self-collision audits: known answers on a robot of our own (a pair that collides in a known fraction of
// the joint space, one that never can, one in collision at the default configuration), the statistics,
// determinism, the SRDF written, and the shared Panda.
#include <clearway/load/robot_loader.h>
#include <clearway/scene/audit.h>

#include "load/robot_files.h"
#include "srdf_reader.h"

#include <gtest/gtest.h>
#include <pthread.h>

#include <algorithm>
#include <cmath>
#include <system_error>
#include <tuple>

namespace clearway {
namespace {

using test::TempDir;

// base (a box) with a post beside it (fixed); link1, a 1 m bar on a full-turn shoulder, sweeps past the
// post at 0.7 m; link2, a 0.5 m bar on an elbow limited to ±2.5 rad, can never reach the base; cap, a ball
// on link2 at the elbow, always overlaps link1's end.
const char* kAuditUrdf = R"(<?xml version="1.0"?>
<robot name="audited">
  <link name="base"><collision><origin xyz="0 0 0.05"/><geometry><box size="0.2 0.2 0.1"/></geometry></collision></link>
  <link name="post"><collision><geometry><cylinder radius="0.05" length="0.4"/></geometry></collision></link>
  <link name="link1"><collision><origin xyz="0.5 0 0"/><geometry><box size="1 0.1 0.1"/></geometry></collision></link>
  <link name="link2"><collision><origin xyz="0.25 0 0"/><geometry><box size="0.5 0.1 0.1"/></geometry></collision></link>
  <link name="cap"><collision><geometry><sphere radius="0.12"/></geometry></collision></link>
  <joint name="post_joint" type="fixed"><parent link="base"/><child link="post"/><origin xyz="0.7 0 0.1"/></joint>
  <joint name="shoulder" type="revolute"><parent link="base"/><child link="link1"/><origin xyz="0 0 0.1"/>
    <axis xyz="0 0 1"/><limit lower="-3.141592653589793" upper="3.141592653589793" velocity="1" effort="1"/></joint>
  <joint name="elbow" type="revolute"><parent link="link1"/><child link="link2"/><origin xyz="1 0 0"/>
    <axis xyz="0 0 1"/><limit lower="-2.5" upper="2.5" velocity="1" effort="1"/></joint>
  <joint name="cap_joint" type="fixed"><parent link="link2"/><child link="cap"/></joint>
</robot>
)";

const PairAudit& find(const RobotModel& m, const std::vector<PairAudit>& audit, const char* a, const char* b) {
  const int ia = m.linkIndex(a), ib = m.linkIndex(b);
  for (const PairAudit& p : audit)
    if ((p.a == ia && p.b == ib) || (p.a == ib && p.b == ia)) return p;
  ADD_FAILURE() << "no pair " << a << " / " << b;
  return audit.front();
}

TEST(Audit, KnownAnswers) {
  TempDir dir;
  auto model = std::make_shared<const RobotModel>(loadRobot(dir.write("a.urdf", kAuditUrdf)));
  const auto geometry = std::make_shared<const RobotGeometry>(model);
  AuditOptions options;
  options.samples = 20000;
  const std::vector<PairAudit> audit = auditSelfCollision(geometry, options);
  EXPECT_EQ(audit.size(), 10u);  // 5 links with geometry
  EXPECT_EQ(find(*model, audit, "base", "post").reason, "Adjacent");
  EXPECT_EQ(find(*model, audit, "base", "link1").reason, "Adjacent");
  EXPECT_EQ(find(*model, audit, "link2", "cap").reason, "Adjacent");
  // At the default configuration (all zero) link1 lies across the post, and the cap on link1's end.
  EXPECT_EQ(find(*model, audit, "link1", "post").reason, "Default");
  EXPECT_EQ(find(*model, audit, "link1", "cap").reason, "Default");
  // link2 can never reach the base: Never, and never near (the elbow stops it 0.3 m or more away).
  const PairAudit& never = find(*model, audit, "base", "link2");
  EXPECT_EQ(never.reason, "Never");
  EXPECT_EQ(never.colliding, 0);
  EXPECT_EQ(never.samples, 20000);
  EXPECT_FALSE(never.near_miss);
  EXPECT_GT(never.min_clearance, 0.3);
  EXPECT_NEAR(never.p_upper, 1.0 - std::pow(0.05, 1.0 / 20000), 1e-12);
  // Adjacent pairs are not measured: no samples, no clearance, no warning.
  const PairAudit& adjacent = find(*model, audit, "base", "link1");
  EXPECT_EQ(adjacent.samples, 0);
  EXPECT_TRUE(std::isnan(adjacent.min_clearance));
  EXPECT_EQ(adjacent.warning, "");
  // Default pairs are sampled too. link1 meets the post in 2·asin(0.1/0.7)/2π = 4.6% of the shoulder's
  // turn: MoveIt's rule disables the pair, which hides those collisions, so it is flagged. The cap always
  // overlaps link1's end: disabling it hides nothing a planner could use, so it is not.
  const PairAudit& post = find(*model, audit, "link1", "post");
  EXPECT_EQ(post.samples, 20000);
  EXPECT_NEAR(static_cast<double>(post.colliding) / post.samples, 2.0 * std::asin(0.1 / 0.7) / (2.0 * M_PI), 0.006);
  EXPECT_EQ(post.min_clearance, 0.0);
  EXPECT_NE(post.warning.find("disabled as Default but collides in"), std::string::npos) << post.warning;
  const PairAudit& cap = find(*model, audit, "link1", "cap");
  EXPECT_EQ(cap.colliding, cap.samples);
  EXPECT_EQ(cap.warning, "");
  // With the threshold above its 4.6%, the Default pair is not flagged.
  options.warn_fraction = 0.06;
  options.samples = 5000;
  EXPECT_EQ(find(*model, auditSelfCollision(geometry, options), "link1", "post").warning, "");
}

TEST(Audit, RigidPairsAreMeasuredOnce) {
  // A camera on a mast on the base (fixed joints; the mast has geometry, so base and camera are not
  // adjacent): no joint moves them apart, so their one clearance (0.3 − 0.05 − 0.05 = 0.2 m) holds in
  // every sample, with probability 0 exactly. The arm is not rigid with the base.
  TempDir dir;
  auto model = std::make_shared<const RobotModel>(loadRobot(dir.write("r.urdf", R"(<robot name="r">
    <link name="base"><collision><geometry><box size="0.1 0.1 0.1"/></geometry></collision></link>
    <link name="mast"><collision><geometry><cylinder radius="0.01" length="0.05"/></geometry></collision></link>
    <link name="camera"><collision><geometry><sphere radius="0.05"/></geometry></collision></link>
    <link name="arm"><collision><origin xyz="0.5 0 0"/><geometry><box size="0.6 0.05 0.05"/></geometry></collision></link>
    <joint name="m" type="fixed"><parent link="base"/><child link="mast"/><origin xyz="0 0 0.2"/></joint>
    <joint name="c" type="fixed"><parent link="mast"/><child link="camera"/><origin xyz="0 0 0.1"/></joint>
    <joint name="j" type="revolute"><parent link="base"/><child link="arm"/><axis xyz="0 1 0"/>
      <limit lower="-1" upper="1" velocity="1" effort="1"/></joint>
  </robot>)")));
  AuditOptions options;
  options.samples = 500;
  const auto audit = auditSelfCollision(std::make_shared<const RobotGeometry>(model), options);
  const PairAudit& rigid = find(*model, audit, "base", "camera");
  EXPECT_EQ(rigid.reason, "Never");
  EXPECT_EQ(rigid.samples, 500);
  EXPECT_EQ(rigid.p_upper, 0.0);
  EXPECT_NEAR(rigid.min_clearance, 0.2, 1e-9);
  const PairAudit& moving = find(*model, audit, "camera", "arm");
  EXPECT_GT(moving.p_upper, 0.0);
  EXPECT_EQ(moving.samples, 500);
}

TEST(Audit, KnownFractionAndAlwaysThreshold) {
  // The post at angle π instead: link1 meets it when 0.7·|sin(θ − π)| < 0.1, a fraction
  // 2·asin(0.1/0.7) / 2π = 0.0456 of the shoulder's turn; the default (θ = 0) is free.
  TempDir dir;
  std::string urdf = kAuditUrdf;
  urdf.replace(urdf.find("xyz=\"0.7 0 0.1\""), 15, "xyz=\"-0.7 0 0.1\"");
  auto model = std::make_shared<const RobotModel>(loadRobot(dir.write("a.urdf", urdf)));
  const auto geometry = std::make_shared<const RobotGeometry>(model);
  AuditOptions options;
  options.samples = 20000;
  const std::vector<PairAudit> audit = auditSelfCollision(geometry, options);
  const PairAudit& p = find(*model, audit, "link1", "post");
  EXPECT_EQ(p.reason, "");  // neither Never nor Always: checked
  const double expected = 2.0 * std::asin(0.1 / 0.7) / (2.0 * M_PI);
  EXPECT_NEAR(static_cast<double>(p.colliding) / p.samples, expected, 0.006);
  EXPECT_GT(p.p_upper, static_cast<double>(p.colliding) / p.samples);
  EXPECT_LT(p.p_upper, expected + 0.01);
  EXPECT_EQ(p.min_clearance, 0.0);
  // A lower "always" threshold turns the same evidence into Always.
  options.always_fraction = 0.04;
  EXPECT_EQ(find(*model, auditSelfCollision(geometry, options), "link1", "post").reason, "Always");
  // A checked pair that collides in more than most_fraction of the samples is flagged; at 4.6% it is not
  // by default.
  EXPECT_EQ(p.warning, "");
  options.always_fraction = 0.95;
  options.most_fraction = 0.03;
  const std::string warning = find(*model, auditSelfCollision(geometry, options), "link1", "post").warning;
  EXPECT_NE(warning.find("checked but collides in"), std::string::npos) << warning;
  options.most_fraction = 0.5;
  // The same seed gives the same audit on one thread or two.
  options.always_fraction = 0.95;
  options.samples = 3000;
  options.threads = 1;
  const auto one = auditSelfCollision(geometry, options);
  options.threads = 2;
  const auto two = auditSelfCollision(geometry, options);
  ASSERT_EQ(one.size(), two.size());
  for (std::size_t k = 0; k < one.size(); ++k) {
    EXPECT_EQ(one[k].reason, two[k].reason);
    EXPECT_EQ(one[k].colliding, two[k].colliding);
    if (!std::isnan(one[k].min_clearance)) EXPECT_EQ(one[k].min_clearance, two[k].min_clearance);
    else EXPECT_TRUE(std::isnan(two[k].min_clearance));  // Adjacent pairs are not sampled
  }
  // The SRDF written loads back, with one disabled pair per classified pair.
  const std::string srdf = dir.write("out.srdf", auditSrdf(*model, one));
  const RobotModel again = loadRobot(dir.path("a.urdf"), srdf);
  int classified = 0;
  for (const PairAudit& q : one) classified += !q.reason.empty();
  EXPECT_EQ(static_cast<int>(again.disabledCollisions().size()), classified);
}

TEST(Audit, SrdfKeepsTheInputAndReplacesTheDecidedPairs) {
  TempDir dir;
  auto model = std::make_shared<const RobotModel>(loadRobot(dir.write("a.urdf", kAuditUrdf)));
  AuditOptions options;
  options.samples = 2000;
  const auto audit = auditSelfCollision(std::make_shared<const RobotGeometry>(model), options);
  // A pair the audit decides (link1/base, written link2 > link1 and with the wrong reason), one it does
  // not (a link the URDF lacks), and around them every other kind of element srdfdom reads.
  const std::string input = R"(<?xml version="1.0"?>
<!-- the robot's SRDF -->
<robot name="audited">
  <virtual_joint name="world_joint" type="fixed" parent_frame="world" child_link="base"/>
  <group name="arm"><joint name="shoulder"/><joint name="elbow"/></group>
  <group name="tip"><link name="cap"/></group>
  <group_state name="home" group="arm"><joint name="shoulder" value="0"/><joint name="elbow" value="0"/></group_state>
  <!-- disabled pairs -->
  <disable_collisions link1="link1" link2="base" reason="Never"/>
  <disable_collisions link1="ghost" link2="base" reason="User"/>
  <passive_joint name="cap_joint"/>
  <disable_collisions link1="link2" link2="base" reason="Default"/>
  <end_effector name="tip" group="tip" parent_link="link2" parent_group="arm"/>
  <link_sphere_approximation link="cap"><sphere center="0 0 0" radius="0.12"/></link_sphere_approximation>
  <joint_property joint_name="shoulder" property_name="speed" value="1"/>
</robot>
)";
  const std::string written = auditSrdf(*model, audit, input);
  const test::SrdfContent in = test::readSrdfText(input), out = test::readSrdfText(written);
  ASSERT_TRUE(in.errors.empty()) << in.errors.front();
  for (const std::string& e : out.errors) ADD_FAILURE() << e << "\n" << written;
  EXPECT_EQ(out.semantic, in.semantic) << written;
  EXPECT_EQ(out.semantic.size(), 8u);
  EXPECT_EQ(out.comments, 2);
  // The audited pairs with a reason, by name, link1 < link2, sorted; then the pair naming "ghost", kept.
  std::vector<std::tuple<std::string, std::string, std::string>> expected;
  for (const PairAudit& p : audit)
    if (!p.reason.empty()) {
      const auto names = std::minmax(model->link(p.a).name, model->link(p.b).name);
      expected.emplace_back(names.first, names.second, p.reason);
    }
  std::sort(expected.begin(), expected.end());
  expected.emplace_back("ghost", "base", "User");
  std::vector<std::tuple<std::string, std::string, std::string>> got;
  for (const auto& d : out.disabled) got.emplace_back(d.link1, d.link2, d.reason);
  EXPECT_EQ(got, expected) << written;
  EXPECT_NE(std::find(got.begin(), got.end(), std::make_tuple("base", "link1", "Adjacent")), got.end());
  // Where the first replaced pair stood: after the comment that introduced it.
  EXPECT_NE(written.find("<!-- disabled pairs -->\n  <disable_collisions link1=\"" + std::get<0>(expected[0])), std::string::npos)
      << written;
  // Without an input, a new document naming the robot, with the same pairs.
  const test::SrdfContent fresh = test::readSrdfText(auditSrdf(*model, audit));
  EXPECT_EQ(fresh.robot_name, "audited");
  EXPECT_TRUE(fresh.semantic.empty());
  EXPECT_EQ(fresh.disabled.size(), expected.size() - 1);
  EXPECT_THROW(auditSrdf(*model, audit, "<robot name=\"audited\">"), std::invalid_argument);
  EXPECT_THROW(auditSrdf(*model, audit, "<urdf/>"), std::invalid_argument);
}

TEST(Audit, RobotsWithoutJoints) {
  // A one-link robot has no joint values: the samples were indexed as &v[0] of an empty vector (UBSan:
  // reference binding to null). Two links on a fixed joint have a pair but nothing to sample either.
  TempDir dir;
  for (const std::string& urdf :
       {std::string(R"(<robot name="r"><link name="a"><collision><geometry><box size="0.1 0.1 0.1"/></geometry></collision></link></robot>)"),
        std::string(R"(<robot name="r"><link name="a"><collision><geometry><box size="0.1 0.1 0.1"/></geometry></collision></link>
           <link name="b"><collision><origin xyz="1 0 0"/><geometry><sphere radius="0.1"/></geometry></collision></link>
           <joint name="j" type="fixed"><parent link="a"/><child link="b"/></joint></robot>)")}) {
    auto model = std::make_shared<const RobotModel>(loadRobot(dir.write("r.urdf", urdf)));
    AuditOptions options;
    options.samples = 3;
    const std::vector<PairAudit> audit = auditSelfCollision(std::make_shared<const RobotGeometry>(model), options);
    ASSERT_EQ(audit.size(), model->linkCount() == 1 ? 0u : 1u);
    if (!audit.empty()) EXPECT_EQ(audit[0].reason, "Adjacent");
  }
}

TEST(Audit, ClopperPearson) {
  EXPECT_EQ(clopperPearsonUpper(0, 0), 1.0);
  EXPECT_EQ(clopperPearsonUpper(5, 5), 1.0);
  EXPECT_NEAR(clopperPearsonUpper(0, 10000), 2.9953e-4, 1e-7);
  // Beta(16, 9985) 95% quantile, and Beta(6, 5) for 5 of 10.
  EXPECT_NEAR(clopperPearsonUpper(15, 10000), 0.0023088, 2e-6);
  EXPECT_NEAR(clopperPearsonUpper(5, 10), 0.7778, 1e-3);
}

TEST(Audit, BadInput) {
  TempDir dir;
  auto model = std::make_shared<const RobotModel>(loadRobot(dir.write("a.urdf", kAuditUrdf)));
  const auto geometry = std::make_shared<const RobotGeometry>(model);
  AuditOptions o;
  o.samples = 0;
  EXPECT_THROW(auditSelfCollision(geometry, o), std::invalid_argument);
  o = {};
  o.threads = 0;
  EXPECT_THROW(auditSelfCollision(geometry, o), std::invalid_argument);
  o = {};
  o.always_fraction = 1.5;
  EXPECT_THROW(auditSelfCollision(geometry, o), std::invalid_argument);
  o = {};
  o.warn_fraction = -0.1;
  EXPECT_THROW(auditSelfCollision(geometry, o), std::invalid_argument);
  o = {};
  o.most_fraction = 2;
  EXPECT_THROW(auditSelfCollision(geometry, o), std::invalid_argument);
}

// The same verdicts, counts and clearances.
void expectSameAudit(const std::vector<PairAudit>& a, const std::vector<PairAudit>& b) {
  ASSERT_EQ(a.size(), b.size());
  for (std::size_t k = 0; k < a.size(); ++k) {
    EXPECT_EQ(a[k].reason, b[k].reason);
    EXPECT_EQ(a[k].colliding, b[k].colliding);
    if (!std::isnan(a[k].min_clearance)) EXPECT_EQ(a[k].min_clearance, b[k].min_clearance);
    else EXPECT_TRUE(std::isnan(b[k].min_clearance));
  }
}

// Threads that cannot be created (here: every new thread asks for a 64 TiB stack by default) made
// std::thread throw std::system_error out of the audit, and asking for 100,000 threads, more than the
// system gives, aborted the process. The audit runs on the threads it gets, and asks for at most
// maxAuditThreads().
TEST(Audit, ThreadsThatCannotBeCreatedOrTooManyFallBack) {
  TempDir dir;
  auto model = std::make_shared<const RobotModel>(loadRobot(dir.write("a.urdf", kAuditUrdf)));
  const auto geometry = std::make_shared<const RobotGeometry>(model);
  AuditOptions options;
  options.samples = 400;
  options.threads = 1;
  const std::vector<PairAudit> one = auditSelfCollision(geometry, options);

  pthread_attr_t saved, huge;
  ASSERT_EQ(pthread_getattr_default_np(&saved), 0);
  ASSERT_EQ(pthread_getattr_default_np(&huge), 0);
  ASSERT_EQ(pthread_attr_setstacksize(&huge, std::size_t{1} << 46), 0);
  ASSERT_EQ(pthread_setattr_default_np(&huge), 0);
  std::vector<PairAudit> starved;
  std::string error;
  options.threads = 4;
  try {
    starved = auditSelfCollision(geometry, options);
  } catch (const std::system_error& e) {
    error = e.what();
  }
  pthread_setattr_default_np(&saved);
  pthread_attr_destroy(&saved);
  pthread_attr_destroy(&huge);
  EXPECT_EQ(error, "") << "the audit threw instead of running on the calling thread";
  if (error.empty()) expectSameAudit(one, starved);

  options.threads = 100000;
  expectSameAudit(one, auditSelfCollision(geometry, options));
}

TEST(Audit, SharedPanda) {
  CLEARWAY_SHARED_ROBOT_OR_SKIP(urdf, "panda/panda.urdf");
  auto model = std::make_shared<const RobotModel>(loadRobot(urdf));
  AuditOptions options;
  options.samples = 3000;
  const auto audit = auditSelfCollision(std::make_shared<const RobotGeometry>(model), options);
  EXPECT_EQ(audit.size(), 55u);  // 11 links with geometry
  int adjacent = 0, never = 0;
  for (const PairAudit& p : audit) {
    adjacent += p.reason == "Adjacent";
    never += p.reason == "Never";
    if (p.reason == "Never") EXPECT_EQ(p.colliding, 0);
  }
  EXPECT_EQ(adjacent, 10);  // the chain link0 … link7, hand, and the two fingers on the hand
  EXPECT_GT(never, 10);
  // The shipped SRDF calls link2/link6 Never; random joint vectors do bring them together.
  options.samples = 10000;
  const auto more = auditSelfCollision(std::make_shared<const RobotGeometry>(model), options);
  EXPECT_GT(find(*model, more, "panda_link2", "panda_link6").colliding, 0);
}

}  // namespace
}  // namespace clearway

namespace clearway {
namespace {

TEST(Audit, LimitsOfPlusMinus1e308AreSampledWithinTheLargestJointValue) {
  // A revolute joint with limits of ±1e308 (MoveIt loads it): hi − lo overflowed, every sample was
  // non-finite and collided, and the arm, which meets the post only at some angles, was called Always.
  test::TempDir dir;
  auto model = std::make_shared<const RobotModel>(loadRobot(dir.write("r.urdf", R"(<robot name="r">
    <link name="base"><collision><origin xyz="0.7 0 0"/><geometry><cylinder radius="0.05" length="0.1"/></geometry></collision></link>
    <link name="arm"><collision><origin xyz="-0.5 0 0"/><geometry><box size="0.6 0.05 0.05"/></geometry></collision></link>
    <link name="pad"><collision><origin xyz="0 0 5"/><geometry><sphere radius="0.01"/></geometry></collision></link>
    <joint name="p" type="fixed"><parent link="base"/><child link="pad"/></joint>
    <joint name="j" type="revolute"><parent link="pad"/><child link="arm"/><axis xyz="0 0 1"/>
      <limit lower="-1e308" upper="1e308" velocity="1" effort="1"/></joint>
  </robot>)")));
  AuditOptions options;
  options.samples = 2000;
  const auto audit = auditSelfCollision(std::make_shared<const RobotGeometry>(model), options);
  const PairAudit& pair = find(*model, audit, "base", "arm");
  EXPECT_EQ(pair.reason, "");
  EXPECT_EQ(pair.samples, 2000);
  EXPECT_GT(pair.colliding, 0);
  EXPECT_LT(pair.colliding, 200);  // about 3.4%: the post's 0.1 m seen from 0.7 m
}

}  // namespace
}  // namespace clearway
