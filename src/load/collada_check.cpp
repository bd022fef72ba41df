#include "load/collada_check.h"
#include "load/mesh_uri.h"

#include <clearway/load/load_error.h>

#include <tinyxml2.h>

#include <algorithm>
#include <cctype>
#include <cerrno>
#include <cstdint>
#include <cstdlib>
#include <cstring>
#include <unordered_map>
#include <unordered_set>
#include <vector>

namespace clearway::detail {
namespace {

using tinyxml2::XMLElement;

// The node hierarchy assimp builds, instances expanded: its recursion depth and its size.
constexpr int kMaxNodeDepth = 256;
constexpr std::int64_t kMaxExpandedNodes = 100000;

std::uint64_t saturatingAdd(std::uint64_t a, std::uint64_t b) { return a > UINT64_MAX - b ? UINT64_MAX : a + b; }

// A reader's message (tinyxml2's) is cut to this many characters: it may quote the file.
constexpr std::size_t kReaderChars = 80;

// The separators of a list (<p>, <float_array>, ...): XML's whitespace, as assimp skips it. A form feed
// or vertical tab (std::isspace) stops assimp's reader without consuming it: it then reads the same
// place forever, one 0 index after another, until memory runs out.
bool listSpace(char c) { return c == ' ' || c == '\t' || c == '\r' || c == '\n'; }

std::string where(const XMLElement* e) { return "<" + std::string(e->Name()) + "> (line " + std::to_string(e->GetLineNum()) + ")"; }

class Checker {
 public:
  Checker(std::string path, std::uint64_t file_size) : path_(std::move(path)), file_size_(file_size) {}

  [[noreturn]] void fail(const XMLElement* e, const std::string& reason) const { throw LoadError(path_, where(e), reason); }

  // Every element, depth first (tinyxml2 bounds the depth), with the checks that need one element.
  void visit(const XMLElement* e) {
    const std::string name = e->Name();
    // Assimp 5.2 asserts (aborts) when it composes a node's transform from a <skew>.
    if (name == "skew") fail(e, "<skew> is not supported (assimp aborts on it): write the node's transform as a <matrix>");
    if (name == "input" && inMesh(e)) mesh_inputs_.push_back(e);
    if (name == "visual_scene") {
      // Assimp keeps each visual scene as a node (its root node, named "Scene" unless it has a name), which
      // an <instance_node> may name by id or name like any other: a node of the scene instancing it made
      // assimp recurse until the stack overflowed.
      visual_scenes_.push_back(e);
      const char* n = e->Attribute("name");
      if (!names_.emplace(n != nullptr ? n : "Scene", e).second) repeated_names_.insert(n != nullptr ? n : "Scene");
    }
    const std::uint64_t outer = triangles_;  // a <geometry> counts its own primitives' triangles
    if (name == "geometry") triangles_ = 0;
    if (name == "p" || name == "vcount" || name == "v" || name == "h" || name == "int_array") tokens(e, true);
    if (name == "float_array") tokens(e, false);
    for (const char* attribute : {"count", "stride", "offset"}) wholeNumber(e, attribute);
    if (const char* id = e->Attribute("id")) {
      // Instances name nodes, geometries and controllers by id: with two of one id, the one counted here
      // and the one assimp expands could differ (a fuzzed file hid 2.5 million triangles so).
      const auto [first, added] = ids_.emplace(id, e);
      if (!added && (instanced(name) || instanced(first->second->Name())))
        fail(e, "a second element with id '" + inputExcerpt(id) + "' (the first is on line " +
                    std::to_string(first->second->GetLineNum()) + "): ids must be unique");
    }
    if (name == "node") {
      nodes_.push_back(e);
      if (const char* n = e->Attribute("name")) {
        if (!names_.emplace(n, e).second) repeated_names_.insert(n);
      }
    }
    if (name == "accessor") accessors_.push_back(e);
    for (const XMLElement* c = e->FirstChildElement(); c != nullptr; c = c->NextSiblingElement()) visit(c);
    // A primitive once its lists are known to be numbers: their count, then what the counts ask for.
    if (name == "triangles" || name == "polylist" || name == "polygons") primitiveCount(e);
    if (name == "polylist") polylist(e);
    if (name == "triangles" || name == "polylist" || name == "polygons" || name == "lines" || name == "linestrips" ||
        name == "trifans" || name == "tristrips") {
      vertexInput(e);
      triangles_ = saturatingAdd(triangles_, primitiveTriangles(e));
    }
    if (name == "geometry") {
      geometry_triangles_[e] = triangles_;
      written_triangles_ = saturatingAdd(written_triangles_, triangles_);
      triangles_ = outer;
    }
  }

  // The inputs of a <mesh> read numbers: one whose source is an array of names (<Name_array>,
  // <IDREF_array>) crashes assimp, which reads it as floats.
  void checkMeshInputs() const {
    for (const XMLElement* input : mesh_inputs_) {
      const char* semantic = input->Attribute("semantic");
      const char* source = input->Attribute("source");
      if (semantic == nullptr || std::strcmp(semantic, "VERTEX") == 0 || source == nullptr || source[0] != '#') continue;
      const XMLElement* s = byId(source + 1);
      if (s == nullptr || std::strcmp(s->Name(), "source") != 0) continue;
      // The arrays it holds, and the one its accessor reads (which may be anywhere in the file).
      std::vector<const XMLElement*> arrays;
      for (const XMLElement* a = s->FirstChildElement(); a != nullptr; a = a->NextSiblingElement()) arrays.push_back(a);
      const XMLElement* common = s->FirstChildElement("technique_common");
      const XMLElement* accessor = common != nullptr ? common->FirstChildElement("accessor") : nullptr;
      const char* read = accessor != nullptr ? accessor->Attribute("source") : nullptr;
      if (read != nullptr && read[0] == '#' && byId(read + 1) != nullptr) arrays.push_back(byId(read + 1));
      for (const XMLElement* a : arrays)
        if (std::strcmp(a->Name(), "Name_array") == 0 || std::strcmp(a->Name(), "IDREF_array") == 0)
          fail(input, "its source '" + inputExcerpt(source + 1) + "' holds a <" + a->Name() + ">" +
                          (a->Attribute("id") != nullptr ? " '" + inputExcerpt(a->Attribute("id")) + "'" : "") + " (line " +
                          std::to_string(a->GetLineNum()) + "): names, where " + inputExcerpt(semantic) +
                          " needs numbers (assimp crashes reading names as vertex data)");
    }
  }

  // Accessors within their arrays: assimp reads offset + index·stride unchecked.
  void checkAccessors() const {
    for (const XMLElement* a : accessors_) {
      const char* source = a->Attribute("source");
      if (source == nullptr || source[0] != '#') fail(a, "an accessor needs source=\"#ARRAY\"");
      const auto it = ids_.find(source + 1);
      if (it == ids_.end()) fail(a, "source '" + inputExcerpt(source) + "' names no element");
      const std::uint64_t count = wholeNumber(a, "count"), stride = std::max<std::uint64_t>(1, wholeNumber(a, "stride", 1)),
                          offset = wholeNumber(a, "offset");
      std::uint64_t params = 0;
      for (const XMLElement* p = a->FirstChildElement("param"); p != nullptr; p = p->NextSiblingElement("param")) ++params;
      // Assimp reads as many values as the array's count="N" says (none when it is missing), at most
      // the values written.
      const std::uint64_t length = std::min(countTokens(it->second), wholeNumber(it->second, "count"));
      // Each of these is at most the file size (wholeNumber), so the sum cannot overflow 64 bits. Without
      // a <param> assimp still reads one value per item (every component at sub-offset 0).
      const std::uint64_t needed = offset + (count - 1) * stride + std::max<std::uint64_t>(params, 1);
      if (count > 0 && needed > length)
        fail(a, "reaches value " + std::to_string(needed) + " of '" + inputExcerpt(source + 1) + "', which holds " +
                    std::to_string(length));
    }
  }

  // A <polylist> of N polygons: assimp takes each polygon's corner count from <vcount> unchecked (a null
  // read when <vcount> is missing, past its end when it is short).
  void polylist(const XMLElement* e) const {
    const std::uint64_t count = wholeNumber(e, "count");
    const XMLElement* vcount = e->FirstChildElement("vcount");
    const std::uint64_t given = vcount != nullptr ? countTokens(vcount) : 0;
    if (given < count)
      fail(e, "count=\"" + std::to_string(count) + "\" polygons, but <vcount> gives " + std::to_string(given) +
                  " corner counts");
    // Assimp reserves room for every corner the first count="N" entries give before reading <p>: their
    // sum, times the indices per corner, must be indices that <p> holds.
    const std::uint64_t held = cornersHeld(e);
    std::uint64_t corners = 0;
    const char* p = vcount != nullptr ? vcount->GetText() : nullptr;
    for (std::uint64_t i = 0; p != nullptr && i < count; ++i) {
      while (listSpace(*p)) ++p;
      char* end = nullptr;
      errno = 0;
      const unsigned long long n = *p == '-' ? ~0ULL : std::strtoull(p, &end, 10);
      if (*p == '-' || errno == ERANGE || n > held || (corners += n) > held)
        fail(vcount, std::string(*p == '-' ? "a negative corner count" : "the corner counts add up to more than " + std::to_string(held)) +
                         ", the corners <p> holds (" + std::to_string(offsets(e)) + " indices each)");
      p = end;
    }
  }

  // Indices per corner of a primitive: the largest offset="N" of its inputs, plus 1.
  std::uint64_t offsets(const XMLElement* e) const {
    std::uint64_t n = 1;
    for (const XMLElement* i = e->FirstChildElement("input"); i != nullptr; i = i->NextSiblingElement("input"))
      n = std::max(n, wholeNumber(i, "offset") + 1);
    return n;
  }

  // Corners the <p> elements of a primitive hold whole: their indices over offsets(e).
  std::uint64_t cornersHeld(const XMLElement* e) const {
    std::uint64_t indices = 0;
    for (const XMLElement* p = e->FirstChildElement("p"); p != nullptr; p = p->NextSiblingElement("p")) indices += countTokens(p);
    return indices / offsets(e);
  }

  // Assimp asserts (aborts) unless it reads exactly count="N" primitives: for <triangles> and <polylist>
  // all of them from one <p>, for <polygons> one per <p>.
  void primitiveCount(const XMLElement* e) const {
    const std::uint64_t count = wholeNumber(e, "count");
    std::uint64_t ps = 0;
    for (const XMLElement* p = e->FirstChildElement("p"); p != nullptr; p = p->NextSiblingElement("p")) ++ps;
    const bool polygons = std::strcmp(e->Name(), "polygons") == 0;
    const std::uint64_t read = polygons ? ps : ps * count;
    if (read != count)
      fail(e, "count=\"" + std::to_string(count) + "\" primitives, but " +
                  (polygons ? "it has " + std::to_string(ps) + " <p> elements (one per polygon)"
                            : "it has " + std::to_string(ps) + " <p> elements (one holds them all)"));

    // Assimp reserves room for count="N" triangles before reading them: <p> must hold their corners.
    if (std::strcmp(e->Name(), "triangles") == 0 && count > cornersHeld(e) / 3)
      fail(e, "count=\"" + std::to_string(count) + "\" triangles, but <p> holds " + std::to_string(cornersHeld(e)) +
                  " corners (" + std::to_string(offsets(e)) + " indices each)");
  }

  // Primitives whose inputs name no VERTEX (positions): assimp reads before the start of its vertex
  // arrays (an invalid read that ASan cannot see in the uninstrumented library, found with valgrind).
  void vertexInput(const XMLElement* e) const {
    for (const XMLElement* i = e->FirstChildElement("input"); i != nullptr; i = i->NextSiblingElement("input")) {
      const char* semantic = i->Attribute("semantic");
      if (semantic != nullptr && std::strcmp(semantic, "VERTEX") == 0) return;
    }
    fail(e, "no <input semantic=\"VERTEX\">: its primitives have no vertex positions");
  }

  // No cycle through <instance_node>, and a bounded hierarchy once instances are expanded: its depth, its
  // nodes, and the triangles its instances reach (each geometry's times the paths to it through the node
  // graph), within the limit unless the file writes out more triangles than that itself.
  void checkNodes(std::uint64_t max_expanded_triangles) {
    triangle_limit_ = std::max(max_expanded_triangles, written_triangles_);
    for (const XMLElement* n : nodes_) expand(n, 1);
    // A visual scene is the root above its nodes (level 0): its nodes stand at level 1.
    for (const XMLElement* scene : visual_scenes_) expand(scene, 0);
  }

 private:
  struct Expanded {
    int state = 0;  // 0 unseen, 1 on the current path, 2 done
    int depth = 0;
    std::int64_t size = 0;
    std::uint64_t triangles = 0;  // reached through the node's instances (saturating)
  };

  const XMLElement* byId(const char* id) const {
    const auto it = ids_.find(id);
    return it != ids_.end() ? it->second : nullptr;
  }

  static bool inMesh(const XMLElement* e) {
    const tinyxml2::XMLNode* parent = e->Parent();
    const XMLElement* mesh = parent != nullptr && parent->Parent() != nullptr ? parent->Parent()->ToElement() : nullptr;
    return mesh != nullptr && std::strcmp(mesh->Name(), "mesh") == 0;
  }

  // The triangles of a primitive once assimp triangulates it: count="N" of <triangles>, a fan per
  // polygon of a <polylist>; for the others, as many as their corners (at least as many).
  std::uint64_t primitiveTriangles(const XMLElement* e) const {
    if (std::strcmp(e->Name(), "triangles") == 0) return wholeNumber(e, "count");
    if (std::strcmp(e->Name(), "polylist") != 0) {
      std::uint64_t tokens = 0;
      for (const XMLElement* p = e->FirstChildElement(); p != nullptr; p = p->NextSiblingElement()) {
        if (std::strcmp(p->Name(), "p") == 0) tokens += countTokens(p);
        for (const XMLElement* h = p->FirstChildElement(); h != nullptr; h = h->NextSiblingElement()) tokens += countTokens(h);
      }
      return tokens / offsets(e);
    }
    // The corner counts are whole numbers adding up to at most the corners held (polylist()).
    const XMLElement* vcount = e->FirstChildElement("vcount");
    const char* p = vcount != nullptr ? vcount->GetText() : nullptr;
    std::uint64_t triangles = 0;
    for (std::uint64_t i = 0, count = wholeNumber(e, "count"); p != nullptr && i < count; ++i) {
      char* end = nullptr;
      const unsigned long long n = std::strtoull(p, &end, 10);
      if (end == p) break;
      triangles += n > 3 ? n - 2 : 1;
      p = end;
    }
    return triangles;
  }

  // The geometry an <instance_geometry> or <instance_controller> (through its <skin> or <morph>) names.
  const XMLElement* instancedGeometry(const XMLElement* instance) const {
    const char* url = instance->Attribute("url");
    const XMLElement* target = url != nullptr && url[0] == '#' ? byId(url + 1) : nullptr;
    if (target != nullptr && std::strcmp(target->Name(), "controller") == 0) {
      const XMLElement* skin = target->FirstChildElement("skin");
      if (skin == nullptr) skin = target->FirstChildElement("morph");
      const char* source = skin != nullptr ? skin->Attribute("source") : nullptr;
      target = source != nullptr && source[0] == '#' ? byId(source + 1) : nullptr;
    }
    return target != nullptr && std::strcmp(target->Name(), "geometry") == 0 ? target : nullptr;
  }

  std::string tooManyTriangles(std::uint64_t triangles) const {
    return "its instances expand to " + (triangles == UINT64_MAX ? "over " : std::string()) + std::to_string(triangles) +
           " triangles, more than " + std::to_string(triangle_limit_) +
           ": the most <instance_node> and <instance_geometry> may reach (unless the file writes out more itself)";
  }

  // The node a url="#X" names: the one with id X, else the one named X (assimp's own fallback); null
  // when none (assimp skips it).
  const XMLElement* target(const XMLElement* instance) const {
    const char* url = instance->Attribute("url");
    if (url == nullptr || url[0] != '#') return nullptr;
    const auto by_id = ids_.find(url + 1);
    if (by_id != ids_.end() && nodeLike(by_id->second)) return by_id->second;
    const auto by_name = names_.find(url + 1);
    if (by_name != names_.end() && repeated_names_.count(url + 1) > 0)
      fail(instance, "url=\"" + inputExcerpt(url) + "\" names no id but several nodes' name: which one is instanced is unclear");
    return by_name != names_.end() ? by_name->second : nullptr;
  }

  static bool instanced(const std::string& name) {
    return name == "node" || name == "visual_scene" || name == "geometry" || name == "controller";
  }
  // What an <instance_node> may name: a node, or a visual scene (assimp's root nodes).
  static bool nodeLike(const XMLElement* e) {
    return std::strcmp(e->Name(), "node") == 0 || std::strcmp(e->Name(), "visual_scene") == 0;
  }

  const Expanded& expand(const XMLElement* node, int level) {
    Expanded& x = expanded_[node];
    if (x.state == 2) return x;
    if (x.state == 1) fail(node, "the " + std::string(node->Name()) + " contains itself through <instance_node>: its hierarchy never ends");
    if (level > kMaxNodeDepth)
      fail(node, "nodes nested deeper than " + std::to_string(kMaxNodeDepth) + " levels (instances expanded)");
    x.state = 1;
    int depth = 0;
    std::int64_t size = 1;
    std::uint64_t triangles = 0;
    for (const XMLElement* c = node->FirstChildElement(); c != nullptr; c = c->NextSiblingElement()) {
      if (std::strcmp(c->Name(), "instance_geometry") == 0 || std::strcmp(c->Name(), "instance_controller") == 0) {
        if (const XMLElement* g = instancedGeometry(c)) triangles = saturatingAdd(triangles, geometry_triangles_[g]);
        continue;
      }
      const XMLElement* child = std::strcmp(c->Name(), "node") == 0            ? c
                                : std::strcmp(c->Name(), "instance_node") == 0 ? target(c)
                                                                               : nullptr;
      if (child == nullptr) continue;
      const Expanded& e = expand(child, level + 1);
      depth = std::max(depth, e.depth);
      size = std::min(kMaxExpandedNodes + 1, size + e.size);
      triangles = saturatingAdd(triangles, e.triangles);
    }
    Expanded& done = expanded_[node];  // the map may have grown
    done = {2, depth + 1, size, triangles};
    if (size > kMaxExpandedNodes)
      fail(node, "more than " + std::to_string(kMaxExpandedNodes) + " nodes once <instance_node> is expanded");
    if (done.depth + level - 1 > kMaxNodeDepth)
      fail(node, "nodes nested deeper than " + std::to_string(kMaxNodeDepth) + " levels (instances expanded)");
    if (triangles > triangle_limit_) fail(node, tooManyTriangles(triangles));
    return done;
  }

  // A count-like attribute: absent → fallback; else a whole number no larger than the file.
  std::uint64_t wholeNumber(const XMLElement* e, const char* attribute, std::uint64_t fallback = 0) const {
    const char* text = e->Attribute(attribute);
    if (text == nullptr) return fallback;
    const char* p = text;
    while (std::isspace(static_cast<unsigned char>(*p))) ++p;
    if (!std::isdigit(static_cast<unsigned char>(*p)))
      fail(e, std::string(attribute) + "=\"" + inputExcerpt(text) + "\" is not a whole number");
    errno = 0;
    char* end = nullptr;
    const unsigned long long v = std::strtoull(p, &end, 10);
    while (std::isspace(static_cast<unsigned char>(*end))) ++end;
    if (*end != '\0') fail(e, std::string(attribute) + "=\"" + inputExcerpt(text) + "\" is not a whole number");
    if (errno == ERANGE || v > file_size_)
      fail(e, std::string(attribute) + "=\"" + inputExcerpt(text) + "\" exceeds the size of the file (" + std::to_string(file_size_) +
                  " bytes)");
    return v;
  }

  // Integers (integers = true) or numbers in the element's text, separated by XML whitespace (listSpace).
  void tokens(const XMLElement* e, bool integers) const {
    const char* p = e->GetText();
    if (p == nullptr) return;
    while (*p != '\0') {
      while (listSpace(*p)) ++p;
      if (*p == '\0') break;
      const char* start = p;
      while (*p != '\0' && !listSpace(*p)) ++p;
      const std::string token(start, p);
      bool ok = false;
      if (integers) {
        std::size_t i = token[0] == '-' || token[0] == '+' ? 1 : 0;
        ok = i < token.size() && std::all_of(token.begin() + static_cast<std::ptrdiff_t>(i), token.end(),
                                             [](char c) { return std::isdigit(static_cast<unsigned char>(c)); });
      } else {
        char* end = nullptr;
        std::strtod(token.c_str(), &end);
        ok = end != token.c_str() && *end == '\0';
      }
      if (!ok)
        fail(e, "'" + inputExcerpt(token) + "' is not " + (integers ? "an integer" : "a number") +
                    " (assimp would never finish reading this list)");
    }
  }

  std::uint64_t countTokens(const XMLElement* e) const {
    const char* p = e->GetText();
    std::uint64_t n = 0;
    for (bool in_token = false; p != nullptr && *p != '\0'; ++p) {
      const bool space = listSpace(*p);
      if (!space && !in_token) ++n;
      in_token = !space;
    }
    return n;
  }

  std::string path_;
  std::uint64_t file_size_;
  std::unordered_map<std::string, const XMLElement*> ids_, names_;
  std::unordered_set<std::string> repeated_names_;  // node names given to more than one node
  std::vector<const XMLElement*> nodes_, accessors_, mesh_inputs_, visual_scenes_;
  std::unordered_map<const XMLElement*, Expanded> expanded_;
  std::unordered_map<const XMLElement*, std::uint64_t> geometry_triangles_;
  std::uint64_t triangles_ = 0;          // of the <geometry> being visited
  std::uint64_t written_triangles_ = 0;  // of every <geometry>, each once
  std::uint64_t triangle_limit_ = 0;     // (set by checkNodes)
};

}  // namespace

void checkCollada(const std::string& path, std::uint64_t max_expanded_triangles) {
  const std::string text = readRegularFile(path);
  tinyxml2::XMLDocument doc;
  if (doc.Parse(text.c_str(), text.size()) != tinyxml2::XML_SUCCESS)
    throw LoadError(path, "line " + std::to_string(doc.ErrorLineNum()), "malformed XML: " + inputExcerpt(doc.ErrorStr(), kReaderChars));
  const XMLElement* root = doc.RootElement();
  if (root == nullptr || std::strcmp(root->Name(), "COLLADA") != 0)
    throw LoadError(path, "", "not a COLLADA file: the root element is not <COLLADA>");
  Checker checker(path, text.size());
  checker.visit(root);
  checker.checkAccessors();
  checker.checkMeshInputs();
  checker.checkNodes(max_expanded_triangles);
}

}  // namespace clearway::detail
