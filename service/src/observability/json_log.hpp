// Log lines as JSON (observability.log_format: json, or pullout_service --log-format json): every
// line the service writes to stderr is one JSON object
//
//   {"time":"2026-12-02T04:30:00.123Z","level":"info","logger":"pullout_service",
//    "message":"vehicle 'car-1' request 7: shift path, ...","vehicle_id":"car-1","request_id":7}
//
// time is UTC with milliseconds; level is spdlog's name; the fields vehicle_id and request_id are
// added when the message names them in the service's usual form ("vehicle '<id>'", "request <n>").
// Text that is not valid UTF-8 (a vehicle id is whatever a client sent) is replaced, never dropped.
// Fast DDS's own log entries are routed through the logger "fastdds" in this mode, so that they
// are JSON lines too.
#pragma once

#include <memory>

#include <spdlog/formatter.h>

namespace pullout::service {

class JsonLogFormatter final : public spdlog::formatter {
 public:
  void format(const spdlog::details::log_msg& msg, spdlog::memory_buf_t& dest) override;
  std::unique_ptr<spdlog::formatter> clone() const override;
};

// Sets the JSON formatter on every spdlog logger (present and future) and routes Fast DDS's log
// (warnings and errors) into spdlog's "fastdds" logger, on the same sink as the default logger.
void use_json_logs();

}  // namespace pullout::service
