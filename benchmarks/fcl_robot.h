#pragma once
// A robot's collision elements as FCL objects, for benchmarks that run FCL side by side with Clearway on
// the same meshes, primitives and link poses.
#include <clearway/kinematics/robot_model.h>
#include <clearway/scene/scene.h>

#include <octomap/OcTree.h>

#include <fcl/fcl.h>

#include <limits>
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

/// A box, sphere, cylinder or capsule as FCL's shape (Clearway stores half lengths; FCL full ones).
inline std::shared_ptr<fcl::CollisionGeometryd> toFclShape(const clearway::Shape& shape) {
  return std::visit(
      [](const auto& s) -> std::shared_ptr<fcl::CollisionGeometryd> {
        using S = std::decay_t<decltype(s)>;
        if constexpr (std::is_same_v<S, clearway::Box>) return std::make_shared<fcl::Boxd>(2.0 * s.half);
        else if constexpr (std::is_same_v<S, clearway::Sphere>) return std::make_shared<fcl::Sphered>(s.r);
        else if constexpr (std::is_same_v<S, clearway::Cylinder>) return std::make_shared<fcl::Cylinderd>(s.r, 2.0 * s.h);
        else if constexpr (std::is_same_v<S, clearway::Capsule>) return std::make_shared<fcl::Capsuled>(s.r, 2.0 * s.h);
        else throw std::runtime_error("no FCL counterpart for this Clearway shape");
      },
      shape);
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
          geometry[i].push_back(toFclShape(*e.primitive));
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

// A scene in FCL, as MoveIt's FCL plugin checks it: the scene's self pairs (OBBRSS meshes), its obstacles
// in a DynamicAABBTree manager, and its OctoMap (read by OctoMap) as an fcl::OcTree in the same manager.
class FclScene {
 public:
  explicit FclScene(const clearway::Scene& scene) : scene_(scene), robot_(scene.robot()) {
    for (const auto& shared : scene.environment().obstacles()) {
      const clearway::Obstacle& o = *shared;
      if (o.mesh) throw std::runtime_error("FclScene: mesh obstacles are not converted");
      obstacles_.push_back(std::make_unique<fcl::CollisionObjectd>(toFclShape(o.shape), toFcl(o.pose)));
    }
    if (!scene.description().octomap.empty()) {
      auto tree = std::make_shared<octomap::OcTree>(scene.description().octomap);
      auto fcl_tree = std::make_shared<fcl::OcTreed>(tree);
      // FCL counts cells between its free and occupied thresholds as "uncertain" and collides with
      // them; OctoMap (and Clearway) call a cell occupied at the tree's own threshold, free below it.
      fcl_tree->setOccupancyThres(tree->getOccupancyThres());
      fcl_tree->setFreeThres(tree->getOccupancyThres());
      obstacles_.push_back(std::make_unique<fcl::CollisionObjectd>(fcl_tree));
    }
    std::vector<fcl::CollisionObjectd*> raw;
    for (auto& o : obstacles_) raw.push_back(o.get());
    manager_.registerObjects(raw);
    manager_.setup();
  }

  /// Self pairs and/or the environment at this state (the scene's group order).
  bool isFree(const double* state, bool self = true, bool environment = true) {
    place(state);
    const clearway::Pose* poses = ctx().poses().data();
    if (environment)
      for (int link : scene_.environmentLinks())
        for (auto& obj : robot_.objects[link]) {
          fcl::DefaultCollisionData<double> data;
          manager_.collide(obj.get(), &data, fcl::DefaultCollisionFunction);
          if (data.result.isCollision()) return false;
        }
    if (self)
      for (const clearway::LinkPair& p : scene_.selfCollision().pairs())
        if (robot_.pairCollides(p.a, p.b, poses)) return false;
    return true;
  }

  /// The distance from every link to the environment through the manager (0 on contact).
  double environmentDistance(const double* state) {
    place(state);
    double best = std::numeric_limits<double>::infinity();
    for (int link : scene_.geometry().geometricLinks())
      for (auto& obj : robot_.objects[link]) {
        fcl::DefaultDistanceData<double> data;
        manager_.distance(obj.get(), &data, fcl::DefaultDistanceFunction);
        best = std::min(best, std::max(0.0, data.result.min_distance));
      }
    return best;
  }

 private:
  void place(const double* state) {
    scene_.computePoses(state, ctx());
    const clearway::Pose* poses = ctx().poses().data();
    for (int link : scene_.geometry().geometricLinks())
      for (std::size_t e = 0; e < robot_.objects[link].size(); ++e) {
        fcl::CollisionObjectd& obj = *robot_.objects[link][e];
        obj.setTransform(toFcl(poses[link] * robot_.origins[link][e]));
        obj.computeAABB();
      }
  }
  clearway::SceneContext& ctx() {
    if (!ctx_) ctx_ = std::make_unique<clearway::SceneContext>(scene_.makeContext());
    return *ctx_;
  }
  const clearway::Scene& scene_;
  FclRobot<fcl::OBBRSSd> robot_;
  std::vector<std::unique_ptr<fcl::CollisionObjectd>> obstacles_;
  fcl::DynamicAABBTreeCollisionManagerd manager_;
  std::unique_ptr<clearway::SceneContext> ctx_;
};

}  // namespace clearway::bench
