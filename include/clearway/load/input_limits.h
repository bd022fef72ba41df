#pragma once
// What a robot, mesh, scene or map file may ask for. Lengths beyond kMaxInputLength are refused at load
// time with the file, element and reason: past it, sums and squares of coordinates overflow (a box at
// 1e308 has an infinite centre), and no robot or workcell comes near it. A body smaller than
// kMinInputLength (a sphere of radius 1e-310 has no hull) is grown to it, with a warning: the grown
// solid holds the one given, so no contact is lost; an octree cell that small is refused.
namespace clearway {

/// The largest coordinate, length or size (m) an input may give: 1000 km.
constexpr double kMaxInputLength = 1e6;
/// The smallest radius or non-zero size (m) computed with: 1 nm; smaller bodies are grown to it.
constexpr double kMinInputLength = 1e-9;

/// The largest magnitude of a joint value (m or rad) a state may hold: a planar or floating joint, or a
/// revolute one with limits of ±1e308, has no finite limit of its own, and a translation of 1e16 m leaves
/// no digit of a link's size (a segment starting inside a wall was called free).
constexpr double kMaxJointValue = 1e6;

/// The most links a robot may have (the URDF's, its attached bodies not counted). The checker keeps per-pair
/// and per-chain tables, quadratic in the links: a 5,000-link chain took 3 GB and 17 s to load, one of
/// 50,000 ran out of memory; the largest robots planned for have a few hundred.
constexpr int kMaxLinks = 4096;

/// The largest magnitude of a moment (s) a query may place moving obstacles at: an obstacle's path over
/// a longer span leaves no digit of its size (a segment of 1e17 s was called free).
constexpr double kMaxTime = 1e6;

}  // namespace clearway
