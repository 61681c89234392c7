// A filter on object classes, as Autoware's object_types_to_check.* parameter groups.
#pragma once

#include "pullout/model/types.hpp"

namespace pullout {

struct ObjectTypesToCheck {
  bool check_car{true};
  bool check_truck{true};
  bool check_bus{true};
  bool check_trailer{true};
  bool check_bicycle{true};
  bool check_motorcycle{true};
  bool check_pedestrian{true};
  bool check_unknown{true};

  bool includes(ObjectClass c) const;
};

}  // namespace pullout
