#pragma once
// What a robot, mesh, scene or map file may ask for. Inputs beyond these limits are refused at load
// time with the file, element and reason: past them, sums and squares of coordinates overflow or lose
// every digit (a box at 1e308 has an infinite centre; a sphere of radius 1e-310 has no hull), and no
// robot or workcell comes near them.
namespace clearway {

/// The largest coordinate, length or size (m) an input may give: 1000 km.
constexpr double kMaxInputLength = 1e6;
/// The smallest radius, or non-zero length or size (m), an input may give: 1 nm.
constexpr double kMinInputLength = 1e-9;

}  // namespace clearway
