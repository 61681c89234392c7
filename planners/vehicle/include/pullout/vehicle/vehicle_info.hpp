// Vehicle dimensions and steering limit: VehicleInfo lives in the data model (a request may carry
// its own vehicle), this header stays the core's name for it.
#pragma once

#include "pullout/model/types.hpp"
