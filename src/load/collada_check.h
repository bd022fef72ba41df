#pragma once
// A first pass over a COLLADA file with tinyxml2, before assimp reads it. Assimp 5 trusts the file:
// a letter in an index list makes it loop forever while allocating, a node that instantiates itself
// makes it recurse until the stack overflows, an accessor longer than its array makes it read past
// the array's end, a <skew> makes it abort and names read as positions crash it; a few kilobytes of
// nodes instancing each other twice over expand to millions of triangles. This pass refuses such files
// with the element, its line and the reason.
#include <cstdint>
#include <string>

namespace clearway::detail {

/// Throws LoadError (the file, the element and its line, the reason) when the COLLADA file at path is
/// not well-formed XML (tinyxml2 also refuses elements nested deeper than 100), or has: a token other than
/// an integer in <p>, <vcount>, <v>, <h> or <int_array>, or other than a number in <float_array>; a
/// count, stride or offset attribute that is not a whole number or exceeds the file's size; an <accessor>
/// reaching past the end of its array; a <skew>; an <input> of a <mesh> whose source holds a <Name_array>
/// or <IDREF_array>; two nodes, visual scenes, geometries or controllers with one id, or an instance
/// naming (by name, for want of an id) several nodes; an <instance_node> that leads back to its own node
/// or visual scene (assimp keeps a visual scene as a node, named by its id, its name or "Scene"); a node
/// hierarchy, with its instances expanded, deeper than 256 levels or larger than 100,000 nodes; a node or visual scene
/// whose instances reach more than max_expanded_triangles (MeshOptions; 2^20 by default) triangles, each geometry
/// counted once per path to it (polygons as the triangles they fan into), unless the file's geometries themselves hold
/// more. The default is 24 times the largest mesh of ../shared/robots (43,000 triangles): within it a mesh loads in a
/// few seconds even in a sanitized build, past it in minutes and gigabytes (9.8 million triangles took 31 s and 805 MB
/// in the ASan build; 600,000 take 12 s in the fuzzer's, which sets a lower limit); and it keeps the merged mesh far
/// inside its 32-bit indices and the AABB tree's 2^30 items.
void checkCollada(const std::string& path, std::uint64_t max_expanded_triangles);

}  // namespace clearway::detail
