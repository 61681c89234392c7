// Where the service's replies go: the DDS writers in production, a recorder in tests.
#pragma once

#include "pullout/model/types.hpp"

namespace pullout::service {

class Outbox {
 public:
  virtual ~Outbox() = default;
  // Each returns false when the sample could not be written (already logged). Thread-safe.
  virtual bool publish_path(const PullOutPath& path) = 0;
  virtual bool publish_status(const PullOutStatus& status) = 0;
};

}  // namespace pullout::service
