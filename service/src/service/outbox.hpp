// Where the service's replies go: the DDS writers in production, a recorder in tests.
#pragma once

#include <string>

#include "pullout/model/types.hpp"

namespace pullout::service {

class Outbox {
 public:
  virtual ~Outbox() = default;
  // Each returns false when the sample could not be written (already logged). Thread-safe.
  virtual bool publish_path(const PullOutPath& path) = 0;
  virtual bool publish_status(const PullOutStatus& status) = 0;
  // The vehicle is no longer served: frees what the transport holds for it (the DDS edge
  // unregisters its path and status instances). Returns false when that failed (already logged).
  virtual bool forget_vehicle(const std::string& vehicle_id) = 0;
};

}  // namespace pullout::service
