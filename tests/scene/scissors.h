#pragma once
// The scissors: a robot built in code for self-collision tests. A base bar lying along x from 0.5 to 1.5,
// a hub (sphere) turning about z at the origin, and an arm bar from 0.2 to 1.0 fixed to the hub: base and
// arm are not adjacent (the hub between them has geometry), so the pair is checked, and they meet when the
// arm swings over the base bar.
#include <clearway/kinematics/robot_model.h>

#include <cmath>
#include <memory>

namespace clearway::test {

struct ScissorsOptions {
  double arm_width = 0.1;
  JointType swing = JointType::Revolute;  ///< the hub's joint, with these limits
  double lower = -M_PI, upper = M_PI;
  bool finger = false;  ///< a box on the arm's tip, on a revolute joint that mimics the swing
};

inline std::shared_ptr<const RobotModel> scissors(const ScissorsOptions& o = {}) {
  std::vector<Link> links(o.finger ? 4 : 3);
  links[0].name = "base";
  links[0].collisions.push_back({Pose::translation(Vec3(1.0, 0, 0)), Shape(Box(Vec3(0.5, 0.05, 0.05))), -1});
  links[1].name = "hub";
  links[1].parent_joint = 0;
  links[1].collisions.push_back({Pose(), Shape(Sphere(0.05)), -1});
  links[2].name = "arm";
  links[2].parent_joint = 1;
  links[2].collisions.push_back({Pose::translation(Vec3(0.6, 0, 0)), Shape(Box(Vec3(0.4, o.arm_width / 2, 0.05))), -1});
  std::vector<Joint> joints(o.finger ? 3 : 2);
  joints[0].name = "swing";
  joints[0].type = o.swing;
  joints[0].parent_link = 0;
  joints[0].child_link = 1;
  joints[0].axis = Vec3::UnitZ();
  joints[0].lower = o.lower;
  joints[0].upper = o.upper;
  joints[1].name = "weld";
  joints[1].type = JointType::Fixed;
  joints[1].parent_link = 1;
  joints[1].child_link = 2;
  if (o.finger) {
    links[3].name = "finger";
    links[3].parent_joint = 2;
    links[3].collisions.push_back({Pose::translation(Vec3(0.1, 0, 0)), Shape(Box(Vec3(0.05, 0.05, 0.05))), -1});
    joints[2].name = "follow";
    joints[2].type = JointType::Revolute;
    joints[2].parent_link = 2;
    joints[2].child_link = 3;
    joints[2].origin = Pose::translation(Vec3(1.0, 0, 0));
    joints[2].axis = Vec3::UnitZ();
    joints[2].lower = -M_PI;
    joints[2].upper = M_PI;
    joints[2].mimic.joint = 0;
  }
  return std::make_shared<const RobotModel>("scissors", std::move(links), std::move(joints), std::vector<TriangleMesh>{});
}

}  // namespace clearway::test
