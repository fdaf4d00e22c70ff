// Hashes of what a map element's published form depends on, so that publishers send an
// element again only when it changed (MarkerBuilder, VectorMapDeltaBuilder). Equal
// elements give equal fingerprints; a change of any hashed field almost surely changes it.
#pragma once

#include <Eigen/Core>
#include <cstddef>
#include <vector>

#include "ipm_road_mapper/core/map/vector_map.h"

namespace ipm_road_mapper {

// Mixes `value` into `seed` (boost::hash_combine's recipe, 64-bit constant).
void HashCombine(std::size_t* seed, std::size_t value);

// Mixes the 3 coordinates of `p` into `seed`.
void HashPoint(std::size_t* seed, const Eigen::Vector3d& p);

// Class and corners: what a marking's rviz markers show.
std::size_t GeometryFingerprint(const MapMarking& marking);

// Class and control points [first, last) of a lane: what one chunk of its markers shows.
std::size_t GeometryFingerprint(const MapLane& lane, std::size_t first, std::size_t last);

// Every field of the message form (geometry, class, observations, stamps).
std::size_t MessageFingerprint(const MapMarking& marking);
std::size_t MessageFingerprint(const MapLane& lane);

// A lane's message fields other than its control points (class, style, observations, stamps,
// predecessor and successor ids).
std::size_t FieldsFingerprint(const MapLane& lane);

}  // namespace ipm_road_mapper
