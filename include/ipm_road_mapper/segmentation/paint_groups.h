// Pieces of paint grouped the way paint is laid: collinear pieces into one line (the dashes
// of a dashed line, the fragments of a solid one broken by a missed stretch), parallel
// strokes side by side into a stack (the stripes of a hatched area or of a crossing).
#pragma once

#include <vector>

#include "ipm_road_mapper/segmentation/paint_pieces.h"

namespace ipm_road_mapper {
namespace segmentation {

// How pieces group (config section `groups`).
struct GroupOptions {
  double max_stroke_width_m = 0.7;  // wider pieces are blobs, not strokes
  double min_stroke_elongation = 2.5;
  double min_stroke_length_m = 0.5;
  double chain_max_gap_m = 15.0;  // longest gap between two pieces of one line
  double chain_max_turn_deg = 25.0;
  double chain_max_offset_m = 0.35;  // lateral offset of a piece from the line through the other
  double stack_max_turn_deg = 15.0;
  double stack_min_spacing_m = 0.35;  // side-by-side strokes this far apart (center lines)...
  double stack_max_spacing_m = 2.2;   // ... up to this: the stripes of one area (lanes are wider)
  double stack_min_overlap = 0.3;     // overlap along the stripes, of the shorter one
};

// Whether a piece is a stroke (long and thin) under the options.
bool IsStroke(const PaintPiece& piece, const GroupOptions& options);

// Chains of collinear strokes: each chain is piece indices ordered along the line. A stroke
// links at each end to at most one other (the best match first), so a chain never branches.
// Pieces that are not strokes, or are in `excluded`, are in no chain; every other stroke
// is in exactly one chain (alone when nothing continues it).
std::vector<std::vector<int>> ChainStrokes(const std::vector<PaintPiece>& pieces,
                                           const std::vector<bool>& excluded,
                                           const GroupOptions& options);

// Stacks of parallel strokes side by side (two or more): each stack is piece indices.
std::vector<std::vector<int>> StackStrokes(const std::vector<PaintPiece>& pieces,
                                           const GroupOptions& options);

// A direction sign-aligned with `reference` (directions of pieces have no sign).
Eigen::Vector2d Aligned(const Eigen::Vector2d& direction, const Eigen::Vector2d& reference);

}  // namespace segmentation
}  // namespace ipm_road_mapper
