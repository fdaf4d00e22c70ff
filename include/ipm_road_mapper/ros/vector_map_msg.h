// The generated message ipm_road_mapper/VectorMap (msg/VectorMap.msg) has the same C++ name
// as the core's ipm_road_mapper::VectorMap (core/vector_map.h), in the same namespace. This
// header is the one place that includes the generated header, renaming only its typedef:
// the message type is ipm_road_mapper::VectorMapMsg in C++ (the template VectorMap_<>, its
// traits, md5 and ROS type name "ipm_road_mapper/VectorMap" are untouched; Python and the
// wire see ipm_road_mapper/VectorMap). Include this, never "ipm_road_mapper/VectorMap.h".
#pragma once

#define VectorMap VectorMapMsg
#include "ipm_road_mapper/VectorMap.h"
#undef VectorMap
