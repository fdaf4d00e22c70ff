// How the renderer turns a pixel polygon into pixels (renderer.h FillPixelPolygon), chosen
// per scenario for the mask (segmentation.mask_rasterizer).
#pragma once

namespace ipm_road_mapper {
namespace sim {

enum class FillRule {
  // cv::fillPoly at 1/16 px: it also labels the pixels an edge only touches, up to half a
  // pixel outside the polygon, so every shape comes out half a pixel too large on each side
  // (docs/synthetic_drives.md, "Rendering"). The benchmark drives' masks, for continuity.
  kOpenCvFillPoly,
  // Every pixel whose center lies inside the polygon (even-odd rule): the 50 %-coverage rule
  // of a segmentation network, which the mapper's sub-pixel outline assumes.
  kPixelCenters,
};

}  // namespace sim
}  // namespace ipm_road_mapper
