#pragma once
// A robot's collision elements as FCL objects, for benchmarks that run FCL side by side with Clearway on
// the same meshes, primitives and link poses.
#include <clearway/kinematics/robot_model.h>

#include <fcl/fcl.h>

#include <memory>
#include <stdexcept>
#include <type_traits>
#include <vector>

namespace clearway::bench {

inline fcl::Transform3d toFcl(const clearway::Pose& p) {
  fcl::Transform3d t = fcl::Transform3d::Identity();
  t.linear() = p.R;
  t.translation() = p.t;
  return t;
}

// One FCL object per collision element, made once (as MoveIt keeps them: FCL's CollisionObject
// constructor recomputes the model's bounds over every vertex); a query only moves them.
template <class BV>
struct FclRobot {
  std::vector<std::vector<std::shared_ptr<fcl::CollisionGeometryd>>> geometry;  // per link
  std::vector<std::vector<clearway::Pose>> origins;                                   // per link, per element
  mutable std::vector<std::vector<std::unique_ptr<fcl::CollisionObjectd>>> objects;  // per link, per element

  explicit FclRobot(const clearway::RobotModel& m) : geometry(m.linkCount()), origins(m.linkCount()) {
    for (int i = 0; i < m.linkCount(); ++i)
      for (const clearway::CollisionElement& e : m.link(i).collisions) {
        origins[i].push_back(e.origin);
        if (e.mesh >= 0) {
          const clearway::TriangleMesh& mesh = m.meshes()[e.mesh];
          auto model = std::make_shared<fcl::BVHModel<BV>>();
          std::vector<fcl::Triangle> tris;
          for (const auto& t : mesh.triangles) tris.emplace_back(t[0], t[1], t[2]);
          model->beginModel();
          model->addSubModel(mesh.vertices, tris);
          model->endModel();
          geometry[i].push_back(model);
        } else {
          geometry[i].push_back(std::visit(
              [](const auto& s) -> std::shared_ptr<fcl::CollisionGeometryd> {
                using S = std::decay_t<decltype(s)>;
                if constexpr (std::is_same_v<S, clearway::Box>) return std::make_shared<fcl::Boxd>(2.0 * s.half);
                else if constexpr (std::is_same_v<S, clearway::Sphere>) return std::make_shared<fcl::Sphered>(s.r);
                else if constexpr (std::is_same_v<S, clearway::Cylinder>) return std::make_shared<fcl::Cylinderd>(s.r, 2.0 * s.h);
                else if constexpr (std::is_same_v<S, clearway::Capsule>) return std::make_shared<fcl::Capsuled>(s.r, 2.0 * s.h);
                else throw std::runtime_error("unsupported primitive for FCL");
              },
              *e.primitive));
        }
      }
    objects.resize(m.linkCount());
    for (int i = 0; i < m.linkCount(); ++i)
      for (const auto& g : geometry[i]) objects[i].push_back(std::make_unique<fcl::CollisionObjectd>(g));
  }

  bool pairCollides(int a, int b, const clearway::Pose* poses) const {
    fcl::CollisionRequestd request;  // one contact, no contact data: a boolean query
    for (std::size_t i = 0; i < geometry[a].size(); ++i)
      for (std::size_t j = 0; j < geometry[b].size(); ++j) {
        fcl::CollisionResultd result;
        fcl::CollisionObjectd& oa = *objects[a][i];
        fcl::CollisionObjectd& ob = *objects[b][j];
        oa.setTransform(toFcl(poses[a] * origins[a][i]));
        ob.setTransform(toFcl(poses[b] * origins[b][j]));
        if (fcl::collide(&oa, &ob, request, result) > 0) return true;
      }
    return false;
  }
};

}  // namespace clearway::bench
