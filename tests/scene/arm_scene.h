#pragma once
// A scene file of our arm (robots/arm6) for tests of attached bodies and changing worlds.
#include "load/robot_files.h"

#include <string>

namespace clearway::test {

/// Our 6-joint arm holding `attached` (YAML list items, indented 4, or "") among `obstacles` (the same,
/// or "" for none), checking self, environment and continuous.
inline std::string armScene(const std::string& attached, const std::string& obstacles) {
  return "format: 1\nname: arm\nrobot:\n  urdf: " + sourceRobot("arm6/arm6.urdf") + "\n  srdf: " +
         sourceRobot("arm6/arm6.srdf") +
         "\n  group: [shoulder_pan_joint, shoulder_lift_joint, elbow_joint, wrist_1_joint, wrist_2_joint, wrist_3_joint]\n" +
         (attached.empty() ? "" : "  attached:\n" + attached) + "environment:\n" +
         (obstacles.empty() ? "  obstacles: []\n" : "  obstacles:\n" + obstacles) +
         "checks: [self, environment, continuous]\n";
}

}  // namespace clearway::test
