#pragma once
// A first pass over a COLLADA file with tinyxml2, before assimp reads it. Assimp 5 trusts the file:
// a letter in an index list makes it loop forever while allocating, a node that instantiates itself
// makes it recurse until the stack overflows, and an accessor longer than its array makes it read past
// the array's end. This pass refuses such files with the element, its line and the reason.
#include <string>

namespace clearway::detail {

/// Throws LoadError (the file, the element and its line, the reason) when the COLLADA file at path is
/// not well-formed XML (tinyxml2 also refuses elements nested deeper than 100), or has: a token other than
/// an integer in <p>, <vcount>, <v>, <h> or <int_array>, or other than a number in <float_array>; a
/// count, stride or offset attribute that is not a whole number or exceeds the file's size; an <accessor>
/// reaching past the end of its array; an <instance_node> that leads back to its own node;
/// a node hierarchy, with its instances expanded, deeper than 256 levels or larger than 100,000 nodes.
void checkCollada(const std::string& path);

}  // namespace clearway::detail
