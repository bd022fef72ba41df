#pragma once
// The environment's boxes, as the obstacle store (environment.cpp) builds its trees and the link queries
// (environment_queries.cpp) test against them: one definition, so that a box a query meets is the box
// the tree holds.
#include <clearway/detail/margins.h>
#include <clearway/environment/environment.h>

namespace clearway::environment_detail {

// The world box of a shape placed by `pose`, widened by a few roundings of its coordinates: the trees
// must never drop what the box only just reaches.
inline Aabb shapeWorldBox(const Shape& shape, const Pose& pose) noexcept {
  const Aabb box = placedBox(shape, pose);
  const double scale = box.min.cwiseAbs().cwiseMax(box.max.cwiseAbs()).maxCoeff();
  return box.inflated(margins::boxRounding(scale));
}

// An obstacle's box placed by `pose`: its mesh's box placed, or its shape's world box.
inline Aabb obstacleBox(const Obstacle& o, const Pose& pose) noexcept {
  return o.mesh ? transformed(o.mesh->bounds(), pose) : shapeWorldBox(o.shape, pose);
}

// The largest |coordinate| of a box (0 for the empty box).
inline double maxAbs(const Aabb& b) noexcept {
  return b.isEmpty() ? 0.0 : b.min.cwiseAbs().cwiseMax(b.max.cwiseAbs()).maxCoeff();
}

}  // namespace clearway::environment_detail
