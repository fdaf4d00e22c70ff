// The mapper as a nodelet. For now it loads and validates its parameters and logs them;
// the subscriptions, the core Mapper and the publications arrive with the front end.
#pragma once

#include <nodelet/nodelet.h>

#include "ipm_road_mapper/core/mapper_options.h"

namespace ipm_road_mapper {

class MapperNodelet : public nodelet::Nodelet {
 public:
  MapperNodelet() = default;
  ~MapperNodelet() override = default;

 private:
  void onInit() override;

  MapperOptions options_;
};

}  // namespace ipm_road_mapper
