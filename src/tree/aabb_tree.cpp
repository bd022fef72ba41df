// AabbTree construction and refit. Top-down: a node takes the box of its items; with more items than a
// leaf holds, they are divided by a split (median or binned SAH) and the two children are appended to
// the node array together, so a node's children are adjacent and come after it (refit walks the array
// backwards).
#include <clearway/tree/aabb_tree.h>

#include <algorithm>
#include <numeric>
#include <stdexcept>
#include <string>

namespace clearway {
namespace {

constexpr int kSahBins = 16;
// Below this depth the SAH may cut unevenly; from it on the median split halves the items, so the depth
// stays under kSahMaxDepth + ⌈log₂ n⌉ ≤ 32 + 30 < AabbTree::kMaxDepth.
constexpr int kSahMaxDepth = 32;
constexpr std::size_t kMaxItems = std::size_t{1} << 30;

void checkItemBox(const Aabb& b, std::size_t i) {
  if (b.isEmpty() || !b.min.allFinite() || !b.max.allFinite())
    throw std::invalid_argument("AabbTree: the box of item " + std::to_string(i) + " is empty or not finite");
}

int longestAxis(const Vec3& extents) {
  int axis = 0;
  extents.maxCoeff(&axis);
  return axis;
}

// The binned SAH split of items[begin, end): the boundary between bins that minimises
// area(left)·count(left) + area(right)·count(right), over the three axes of the centres' bounds.
// Returns the partition point after moving the left items first, or -1 when no bin boundary separates
// the centres (all centres equal along every axis).
std::int32_t sahSplit(std::vector<std::int32_t>& items, std::int32_t begin, std::int32_t end, const Aabb& centers_box,
                      const std::vector<Aabb>& boxes, const std::vector<Vec3>& centers) {
  double best_cost = std::numeric_limits<double>::infinity();
  int best_axis = -1, best_boundary = 0;  // left = bins [0, best_boundary)
  for (int axis = 0; axis < 3; ++axis) {
    const double lo = centers_box.min[axis];
    const double extent = centers_box.max[axis] - lo;
    if (!(extent > 0.0)) continue;
    const double scale = kSahBins / extent;
    Aabb bin_box[kSahBins];
    int bin_count[kSahBins] = {};
    for (std::int32_t s = begin; s < end; ++s) {
      const std::int32_t item = items[s];
      const int bin = std::min(kSahBins - 1, static_cast<int>((centers[item][axis] - lo) * scale));
      ++bin_count[bin];
      bin_box[bin].merge(boxes[item]);
    }
    double right_area[kSahBins];
    int right_count[kSahBins];
    Aabb acc;
    int count = 0;
    for (int i = kSahBins - 1; i > 0; --i) {
      acc.merge(bin_box[i]);
      count += bin_count[i];
      right_area[i] = acc.surfaceArea();
      right_count[i] = count;
    }
    acc = Aabb::empty();
    count = 0;
    for (int i = 0; i + 1 < kSahBins; ++i) {
      acc.merge(bin_box[i]);
      count += bin_count[i];
      if (count == 0 || right_count[i + 1] == 0) continue;
      const double cost = acc.surfaceArea() * count + right_area[i + 1] * right_count[i + 1];
      if (cost < best_cost) {
        best_cost = cost;
        best_axis = axis;
        best_boundary = i + 1;
      }
    }
  }
  if (best_axis < 0) return -1;
  const double lo = centers_box.min[best_axis];
  const double scale = kSahBins / (centers_box.max[best_axis] - lo);
  const auto mid = std::partition(items.begin() + begin, items.begin() + end, [&](std::int32_t item) {
    return std::min(kSahBins - 1, static_cast<int>((centers[item][best_axis] - lo) * scale)) < best_boundary;
  });
  return static_cast<std::int32_t>(mid - items.begin());
}

}  // namespace

AabbTree::AabbTree(const std::vector<Aabb>& item_boxes, const TreeBuildOptions& options) {
  if (options.leaf_size < 1 || options.leaf_size > kMaxLeafSize)
    throw std::invalid_argument("AabbTree: leaf_size must be in 1 ... " + std::to_string(kMaxLeafSize) + ", got " +
                                std::to_string(options.leaf_size));
  if (item_boxes.size() > kMaxItems)
    throw std::invalid_argument("AabbTree: more than 2^30 items (" + std::to_string(item_boxes.size()) + ")");
  for (std::size_t i = 0; i < item_boxes.size(); ++i) checkItemBox(item_boxes[i], i);
  const auto n = static_cast<std::int32_t>(item_boxes.size());
  if (n == 0) return;
  std::vector<Vec3> centers(n);
  for (std::int32_t i = 0; i < n; ++i) centers[i] = item_boxes[i].center();
  items_.resize(n);
  std::iota(items_.begin(), items_.end(), 0);
  nodes_.reserve(2 * static_cast<std::size_t>(n));  // a binary tree with n leaves or fewer has < 2n nodes
  nodes_.emplace_back();
  build(0, 0, n, 0, item_boxes, centers, options);
  slot_boxes_.resize(n);
  for (std::int32_t s = 0; s < n; ++s) slot_boxes_[s] = item_boxes[items_[s]];
}

void AabbTree::build(std::int32_t node, std::int32_t begin, std::int32_t end, int depth,
                     const std::vector<Aabb>& boxes, const std::vector<Vec3>& centers,
                     const TreeBuildOptions& options) {
  depth_ = std::max(depth_, depth);
  Aabb box, centers_box;
  for (std::int32_t s = begin; s < end; ++s) {
    box.merge(boxes[items_[s]]);
    centers_box.grow(centers[items_[s]]);
  }
  nodes_[node].box = box;
  const std::int32_t count = end - begin;
  if (count <= options.leaf_size) {
    nodes_[node].first = begin;
    nodes_[node].count = count;
    return;
  }
  std::int32_t mid = -1;
  if (options.split == TreeSplit::Sah && depth < kSahMaxDepth) mid = sahSplit(items_, begin, end, centers_box, boxes, centers);
  if (mid <= begin || mid >= end) {
    // Median of the centres along the longest axis of their bounds (the bounds of the items' boxes
    // would let one long item decide the axis). Equal centres still split: by position in the array.
    const int axis = longestAxis(centers_box.extents());
    mid = begin + count / 2;
    std::nth_element(items_.begin() + begin, items_.begin() + mid, items_.begin() + end,
                     [&](std::int32_t x, std::int32_t y) { return centers[x][axis] < centers[y][axis]; });
  }
  const auto left = static_cast<std::int32_t>(nodes_.size());
  nodes_.emplace_back();
  nodes_.emplace_back();
  nodes_[node].first = left;
  nodes_[node].count = 0;
  build(left, begin, mid, depth + 1, boxes, centers, options);
  build(left + 1, mid, end, depth + 1, boxes, centers, options);
}

void AabbTree::refit(const std::vector<Aabb>& item_boxes) {
  if (item_boxes.size() != items_.size())
    throw std::invalid_argument("AabbTree::refit: " + std::to_string(item_boxes.size()) + " boxes for " +
                                std::to_string(items_.size()) + " items");
  for (std::size_t i = 0; i < item_boxes.size(); ++i) checkItemBox(item_boxes[i], i);
  for (std::size_t s = 0; s < items_.size(); ++s) slot_boxes_[s] = item_boxes[items_[s]];
  refitNodes();
}

void AabbTree::refitNodes() noexcept {
  // Children follow their parent in the array, so a backward sweep sees both children before the parent.
  for (auto i = static_cast<std::int32_t>(nodes_.size()) - 1; i >= 0; --i) {
    Node& n = nodes_[i];
    Aabb box;
    if (n.isLeaf()) {
      for (std::int32_t s = n.first; s < n.first + n.count; ++s) box.merge(slot_boxes_[s]);
    } else {
      box = merged(nodes_[n.first].box, nodes_[n.first + 1].box);
    }
    n.box = box;
  }
}

}  // namespace clearway
