// Whether one marking element's views saw another element: a test in the image, free of the
// flat-ground assumption that puts a marking beyond a crest meters short in the map.
#pragma once

#include <vector>

#include "ipm_road_mapper/core/geometry/ipm.h"
#include "ipm_road_mapper/core/geometry/ipm_uncertainty.h"
#include "ipm_road_mapper/core/map/road_map.h"

namespace ipm_road_mapper {

// The newest whole views of `viewed` this many at most are compared (PixelsAgree).
constexpr std::size_t kMaxAgreementViews = 10;

// Whether `viewed`'s newest whole views (at most kMaxAgreementViews) saw `model`: the median,
// over those views, of the distance between the view's center pixel (mean of its corner
// pixels) and model's corners projected from that frame (the frames' current poses, the
// ipm's extrinsic) is within gate_sigmas of the pixel sigma of Omega_p's error model (the
// segmentation error and the pitch error in pixels, fy * sigma_theta, in quadrature). False
// without a whole view that projects.
bool PixelsAgree(const Ipm& ipm, const IpmErrorModel& error_model, double gate_sigmas,
                 const std::vector<FrameRecord>& frames, const MarkingElement& model,
                 const MarkingElement& viewed);

}  // namespace ipm_road_mapper
