#include "pullout/collision/object_types.hpp"

namespace pullout {

bool ObjectTypesToCheck::includes(ObjectClass c) const {
  switch (c) {
    case ObjectClass::kCar:
      return check_car;
    case ObjectClass::kTruck:
      return check_truck;
    case ObjectClass::kBus:
      return check_bus;
    case ObjectClass::kTrailer:
      return check_trailer;
    case ObjectClass::kMotorcycle:
      return check_motorcycle;
    case ObjectClass::kBicycle:
      return check_bicycle;
    case ObjectClass::kPedestrian:
      return check_pedestrian;
    case ObjectClass::kUnknown:
      return check_unknown;
  }
  // An out-of-range class value is treated like an unknown object.
  return check_unknown;
}

}  // namespace pullout
