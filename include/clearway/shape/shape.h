#pragma once
// The closed set of convex shapes. Queries on a Shape visit the variant once and then run a
// template specialised for the concrete pair, so GJK's inner loop never branches on the type.
#include <clearway/shape/convex_hull.h>
#include <clearway/shape/primitives.h>

#include <variant>

namespace clearway {

/// Any convex shape Clearway knows, in its local frame.
using Shape = std::variant<Point, Segment, Triangle, Box, Sphere, Capsule, Cylinder, Cone, ConvexHull>;

/// The shape's type name as used in query files ("box", "convex", ...).
const char* shapeTypeName(const Shape& shape) noexcept;

/// The radius of the local-frame ball around the origin that contains the shape.
double boundingRadius(const Shape& shape) noexcept;

}  // namespace clearway
