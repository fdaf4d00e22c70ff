// Lanelet2 export of the vector map: the OSM XML that lanelet2_io loads (format of the
// Lanelet2 docs, "Reading and Writing to OSM" and "Tagging Linestrings").
//
// - Points are OSM nodes: lat / lon on WGS84 (map_geodesy.h) and the tag `ele` (altitude
//   above the ellipsoid, as Lanelet2 reads it), plus `local_x` / `local_y` (the map frame's
//   x, y in m, as Autoware's maps carry them).
// - A lane line is a way (line string) sampled every kLaneSampleSpacing_m along its spline,
//   oriented along the drive, tagged `type=line_thin` with `subtype=solid` or `dashed` where
//   the class's style is known, and cut into pieces where lanelets begin and end
//   (lanelet_pairing.h); the pieces of one line share their cut nodes.
// - A lanelet is a relation `type=lanelet`, `subtype=road` with members `left` and `right`
//   (the two bound pieces, both running in the drive's direction). It is `one_way=yes` where
//   the drive went along it (its direction is known), else `one_way=no`: a lane across a
//   center line may carry the other direction's traffic, which the drive cannot tell.
// - A marking is a closed way through its 4 corners (counter-clockwise from above), except a
//   stop line, which is a two-point way along its center (`type=stop_line`, the way Lanelet2
//   regulatory elements refer to it). Arrows are `type=arrow` with the direction as subtype
//   (`straight`, `left`, `right`, `straight_left`, `straight_right`), every other marking
//   `type=road_marking` with its class name as subtype (Lanelet2 lets maps invent types).
// - Every element carries `irm:id` (its map.json id) and `irm:class`; a marking whose extent
//   was never closed (`complete: false` in map.json) carries `irm:complete=no`.
// Ids are positive (Lanelet2's advice: editors treat negative ids as new), nodes first.
// Load it with lanelet2_projection's LocalCartesianProjector at the map's geo_origin to get
// the map frame's metres back; a UTM projector gives UTM coordinates instead (scale and
// grid convergence differ from the local frame by up to 0.1 % and a few degrees).
#pragma once

#include <cstddef>
#include <string>

#include "ipm_road_mapper/core/map/vector_map.h"

namespace ipm_road_mapper {

// What an export wrote, for the summary and tests.
struct Lanelet2ExportStats {
  std::size_t nodes = 0, ways = 0, lanelets = 0;
  std::size_t lanes_left_out = 0;  // lanes found whose bounds' pieces did not correspond
};

// The map as Lanelet2 OSM XML (see the file comment).
std::string VectorMapToLanelet2Osm(const VectorMap& map, const GeoOrigin& origin,
                                   Lanelet2ExportStats* stats = nullptr);

// Writes VectorMapToLanelet2Osm atomically (temporary file + rename, fsynced). Throws
// std::runtime_error when the file cannot be written.
void SaveLanelet2Osm(const VectorMap& map, const GeoOrigin& origin, const std::string& path,
                     Lanelet2ExportStats* stats = nullptr);

}  // namespace ipm_road_mapper
