// Internal to instance extraction: the partial view of a marking. A marking cut by the image
// border, an occluder (pixels of another instance next to its outline) or the IPM's range
// keeps what is real in the view: its outline is clipped to where the IPM maps, each outline
// edge is labeled real or cut, and each side of the fitted rectangle is labeled measured
// (the marking's own boundary was seen there) or cut (docs/backend.md, "Partial views").
// Not installed; include only from src/core.
#pragma once

#include <Eigen/Core>
#include <array>
#include <cstdint>
#include <opencv2/core.hpp>
#include <vector>

#include "ipm_road_mapper/core/frontend/class_table.h"
#include "ipm_road_mapper/core/frontend/observations.h"
#include "ipm_road_mapper/core/geometry/ipm.h"

namespace ipm_road_mapper {
namespace extraction {

// Labels which edges of *outline_uv (a convex sub-pixel outline) are no boundary of the
// instance `value` of `mask`: edges along the image border (both ends within margin_px + 0.5
// of one border line) and edges with pixels of another foreground value just outside them
// (an occluder or a neighbour; lane lines, paint that hides nothing, excepted). A vertex alone on
// the border (the marking's corner leaves the image there) is doubled into a zero-length cut edge.
// One flag per edge i -> i + 1.
std::vector<std::uint8_t> CutEdges(std::vector<Eigen::Vector2d>* outline_uv, const cv::Mat& mask,
                                   int value, const ClassTable& classes, int margin_px);

// Clips the outline to where the IPM maps (edges sampled every few pixels; where samples
// fail, the mapped part is closed by a chord, a cut edge). Writes the kept outline (image
// and ground, x-y in base_link) and its edge flags; the unclipped outline is returned as is.
// False when fewer than three points map.
bool ClipOutlineToGround(const Ipm& ipm, const std::vector<Eigen::Vector2d>& outline_uv,
                         const std::vector<std::uint8_t>& edge_cut,
                         std::vector<Eigen::Vector2d>* kept_uv,
                         std::vector<Eigen::Vector2d>* kept_base,
                         std::vector<std::uint8_t>* kept_cut);

// Labels the sides of marking->corners_base (side i from corner i to i + 1) from its outline
// and edge flags and fills side_uv with the observed boundary pixels of each measured side.
// A side is measured when every outline vertex on it (within a ground tolerance) is either
// between two real edges or joins a cut edge to a real edge running along the side (the
// marking's straight boundary continues beyond the cut on the side's line).
void LabelSides(MarkingObservation* marking);

}  // namespace extraction
}  // namespace ipm_road_mapper
