// Shapes of the synthetic markings, as convex components in normalized coordinates
// (a along the heading, 0 = rear; b across, 0 = right side). See world.h.
#include <algorithm>
#include <string>
#include <vector>

#include "ipm_road_mapper/sim/world.h"

namespace ipm_road_mapper {
namespace sim {
namespace {

using Polygon = std::vector<Eigen::Vector2d>;

Polygon Rect(double a0, double a1, double b0, double b1) {
  return {{a0, b0}, {a1, b0}, {a1, b1}, {a0, b1}};
}

Polygon Triangle(Eigen::Vector2d p0, Eigen::Vector2d p1, Eigen::Vector2d p2) {
  return {p0, p1, p2};
}

// Straight arrow: a stem and a head whose base spans the full width, tip at the front.
std::vector<Polygon> StraightArrow() {
  return {Rect(0.0, 0.62, 0.36, 0.64), Triangle({0.62, 0.0}, {1.0, 0.5}, {0.62, 1.0})};
}

// Left-turn arrow: a stem on the right side, an elbow bar to the left and a head pointing
// left whose tip touches the left side and whose base reaches the front.
std::vector<Polygon> LeftArrow() {
  return {Rect(0.0, 0.74, 0.0, 0.3), Rect(0.54, 0.74, 0.0, 0.55),
          Triangle({0.28, 0.55}, {1.0, 0.55}, {0.64, 1.0})};
}

// Straight-and-left arrow: a straight arrow on the right half plus a left branch.
std::vector<Polygon> StraightLeftArrow() {
  return {Rect(0.0, 0.68, 0.14, 0.36), Triangle({0.68, 0.0}, {1.0, 0.25}, {0.68, 0.5}),
          Rect(0.38, 0.52, 0.36, 0.72), Triangle({0.22, 0.72}, {0.68, 0.72}, {0.45, 1.0})};
}

std::vector<Polygon> MirrorAcross(std::vector<Polygon> shape) {
  for (auto& polygon : shape) {
    for (auto& p : polygon) p.y() = 1.0 - p.y();
    std::reverse(polygon.begin(), polygon.end());  // keep counter-clockwise
  }
  return shape;
}

// Seven-segment digits laid out across the road, read left to right by the driver (the
// first digit on the left, b near 1), their tops at the front (a = 1).
std::vector<Polygon> Digits(const std::string& text) {
  // Segments a..g as bits 0..6 for digits 0..9.
  static const int kSegments[10] = {0x3F, 0x06, 0x5B, 0x4F, 0x66, 0x6D, 0x7D, 0x07, 0x7F, 0x6F};
  const int n = static_cast<int>(text.size());
  const double gap = 0.3;  // between glyphs, in glyph widths
  const double glyph_w = 1.0 / (n + (n - 1) * gap);
  const double tx = 0.2, ty = 0.09;  // stroke thickness (glyph width / height)
  std::vector<Polygon> shape;
  for (int i = 0; i < n; ++i) {
    const int bits = kSegments[text[i] - '0'];
    // Glyph-local x in [0, 1] from its left to its right, y in [0, 1] from bottom to top.
    auto add = [&](double x0, double x1, double y0, double y1) {
      const double left = 1.0 - i * (1.0 + gap) * glyph_w;  // b of the glyph's left edge
      shape.push_back(Rect(y0, y1, left - x1 * glyph_w, left - x0 * glyph_w));
    };
    if (bits & 0x01) add(0.0, 1.0, 1.0 - ty, 1.0);               // a: top
    if (bits & 0x02) add(1.0 - tx, 1.0, 0.5, 1.0);               // b: top right
    if (bits & 0x04) add(1.0 - tx, 1.0, 0.0, 0.5);               // c: bottom right
    if (bits & 0x08) add(0.0, 1.0, 0.0, ty);                     // d: bottom
    if (bits & 0x10) add(0.0, tx, 0.0, 0.5);                     // e: bottom left
    if (bits & 0x20) add(0.0, tx, 0.5, 1.0);                     // f: top left
    if (bits & 0x40) add(0.0, 1.0, 0.5 - ty / 2, 0.5 + ty / 2);  // g: middle
  }
  return shape;
}

}  // namespace

std::vector<Polygon> MarkingShape(const std::string& class_name, const std::string& text) {
  if (class_name == "arrow_straight") return StraightArrow();
  if (class_name == "arrow_left") return LeftArrow();
  if (class_name == "arrow_right") return MirrorAcross(LeftArrow());
  if (class_name == "arrow_straight_left") return StraightLeftArrow();
  if (class_name == "arrow_straight_right") return MirrorAcross(StraightLeftArrow());
  if (class_name == "speed_limit") return Digits(text);
  if (class_name == "diamond") return {{{0.0, 0.5}, {0.5, 0.0}, {1.0, 0.5}, {0.5, 1.0}}};
  return {Rect(0.0, 1.0, 0.0, 1.0)};  // stripes, stop lines and any other class
}

}  // namespace sim
}  // namespace ipm_road_mapper
