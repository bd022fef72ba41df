// RobotModel built by hand: what the constructor checks and assigns (variables, mimics, axes, pairs),
// and adjacentLinkPairs as MoveIt's Setup Assistant defines adjacency.
#include <clearway/kinematics/robot_model.h>

#include <gtest/gtest.h>

#include <stdexcept>
#include <string>
#include <utility>
#include <vector>

using namespace clearway;

namespace {

Link link(const std::string& name, int parent_joint, bool geometry) {
  Link l;
  l.name = name;
  l.parent_joint = parent_joint;
  if (geometry) {
    CollisionElement c;
    c.primitive = Sphere(0.1);
    l.collisions.push_back(c);
  }
  return l;
}

Joint joint(const std::string& name, JointType type, int parent, int child) {
  Joint j;
  j.name = name;
  j.type = type;
  j.parent_link = parent;
  j.child_link = child;
  j.axis = Vec3::UnitZ();
  if (type == JointType::Revolute || type == JointType::Prismatic) {
    j.lower = -1.0;
    j.upper = 1.0;
  }
  return j;
}

// A chain root – l1 – l2 ... with the given joint types; every link has geometry.
std::pair<std::vector<Link>, std::vector<Joint>> chain(const std::vector<JointType>& types) {
  std::vector<Link> links{link("root", -1, true)};
  std::vector<Joint> joints;
  for (std::size_t i = 0; i < types.size(); ++i) {
    links.push_back(link("l" + std::to_string(i + 1), static_cast<int>(i), true));
    joints.push_back(joint("j" + std::to_string(i + 1), types[i], static_cast<int>(i), static_cast<int>(i + 1)));
  }
  return {links, joints};
}

void expectInvalid(std::vector<Link> links, std::vector<Joint> joints, const std::string& message,
                   std::vector<TriangleMesh> meshes = {}) {
  try {
    RobotModel("bad", std::move(links), std::move(joints), std::move(meshes));
    ADD_FAILURE() << "no exception, expected: " << message;
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find(message), std::string::npos) << e.what();
  }
}

}  // namespace

TEST(RobotModel, VariablesInJointOrder) {
  auto [links, joints] = chain({JointType::Floating, JointType::Fixed, JointType::Revolute, JointType::Planar,
                                JointType::Prismatic, JointType::Continuous});
  joints[4].mimic.joint = 2;  // the prismatic joint follows the revolute one
  joints[4].mimic.multiplier = -0.5;
  const RobotModel m("m", links, joints, {});
  std::vector<std::string> names;
  for (const JointVariable& v : m.variables()) names.push_back(v.name);
  EXPECT_EQ(names, (std::vector<std::string>{"j1/x", "j1/y", "j1/z", "j1/qx", "j1/qy", "j1/qz", "j1/qw", "j3", "j4/x",
                                             "j4/y", "j4/theta", "j6"}));
  EXPECT_EQ(m.joint(0).first_variable, 0);
  EXPECT_EQ(m.joint(1).first_variable, -1);
  EXPECT_EQ(m.joint(2).first_variable, 7);
  EXPECT_EQ(m.joint(3).first_variable, 8);
  EXPECT_EQ(m.joint(4).first_variable, -1);  // mimic
  EXPECT_EQ(m.joint(5).first_variable, 11);
  EXPECT_EQ(m.variables()[7].lower, -1.0);
  EXPECT_TRUE(std::isinf(m.variables()[11].upper));
  EXPECT_EQ(m.variableIndex("j4/theta"), 10);
  EXPECT_EQ(m.variableIndex("j4"), -1);
  EXPECT_EQ(m.parentLink(0), -1);
  EXPECT_EQ(m.parentLink(3), 2);
  EXPECT_EQ(jointVariableCount(JointType::Floating), 7);
  EXPECT_STREQ(jointTypeName(JointType::Continuous), "continuous");
}

TEST(RobotModel, ChecksItsInput) {
  {
    auto [links, joints] = chain({JointType::Revolute, JointType::Revolute});
    std::swap(links[1], links[2]);  // l2 before its parent l1
    links[1].parent_joint = 1;
    links[2].parent_joint = 0;
    joints[0].child_link = 2;
    joints[1].parent_link = 2;
    joints[1].child_link = 1;
    expectInvalid(links, joints, "topological order");
  }
  {
    auto [links, joints] = chain({JointType::Revolute});
    joints[0].axis = Vec3::Zero();
    expectInvalid(links, joints, "zero or non-finite axis");
  }
  {
    auto [links, joints] = chain({JointType::Revolute});
    joints[0].lower = 2.0;
    expectInvalid(links, joints, "invalid limits");
  }
  {
    auto [links, joints] = chain({JointType::Planar, JointType::Revolute});
    joints[1].mimic.joint = 0;
    expectInvalid(links, joints, "one-variable leader");
  }
  {
    auto [links, joints] = chain({JointType::Revolute});
    links[1].collisions[0].mesh = 0;  // both a primitive and a mesh
    expectInvalid(links, joints, "either a primitive or a mesh");
    links[1].collisions[0].primitive.reset();
    expectInvalid(links, joints, "names mesh 0 of 0");
  }
  {
    auto [links, joints] = chain({JointType::Revolute});
    links[1].name = "root";
    expectInvalid(links, joints, "two links named 'root'");
  }
  {
    auto [links, joints] = chain({JointType::Revolute});
    joints.push_back(joints[0]);
    expectInvalid(links, joints, "has 1 joints, got 2");
  }
}

TEST(RobotModel, NormalisesAxesAndSortsDisabledPairs) {
  auto [links, joints] = chain({JointType::Prismatic, JointType::Continuous});
  joints[0].axis = Vec3(0, 3, 4);
  joints[1].lower = 5.0;  // a continuous joint has no position limits, whatever it is given
  const RobotModel m("m", links, joints, {},
                     {{2, 0, "Never"}, {0, 1, "Adjacent"}, {1, 0, "Duplicate"}, {1, 2, "Adjacent"}});
  EXPECT_TRUE(m.joint(0).axis.isApprox(Vec3(0, 0.6, 0.8)));
  EXPECT_TRUE(std::isinf(m.joint(1).lower));
  ASSERT_EQ(m.disabledCollisions().size(), 3u);
  EXPECT_EQ(m.disabledCollisions()[0].reason, "Adjacent");  // (0,1): the first one given is kept
  EXPECT_EQ(m.disabledCollisions()[1].link_a, 0);
  EXPECT_EQ(m.disabledCollisions()[1].link_b, 2);
  EXPECT_EQ(m.disabledCollisions()[2].link_a, 1);
}

TEST(AdjacentLinkPairs, ThroughLinksWithoutGeometry) {
  // A(geom) – x(none) – y(none) – B(geom); y – C(geom); B – D(geom); A – E(none) (a leaf).
  std::vector<Link> links{link("A", -1, true), link("x", 0, false), link("y", 1, false), link("B", 2, true),
                          link("C", 3, true),  link("D", 4, true),  link("E", 5, false)};
  std::vector<Joint> joints{joint("jx", JointType::Fixed, 0, 1),    joint("jy", JointType::Revolute, 1, 2),
                            joint("jB", JointType::Revolute, 2, 3), joint("jC", JointType::Fixed, 2, 4),
                            joint("jD", JointType::Revolute, 3, 5), joint("jE", JointType::Fixed, 0, 6)};
  const RobotModel m("m", links, joints, {});
  const auto pairs = adjacentLinkPairs(m);
  // A, B and C meet through x and y; D is adjacent to B only; links without geometry are never listed.
  EXPECT_EQ(pairs, (std::vector<std::pair<int, int>>{{0, 3}, {0, 4}, {3, 4}, {3, 5}}));
}
