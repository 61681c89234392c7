#include "observability/json_log.hpp"

#include <cctype>
#include <chrono>
#include <cstdio>
#include <cstring>
#include <ctime>
#include <string>

#include <spdlog/spdlog.h>
#include <fastdds/dds/log/Log.hpp>
#include <nlohmann/json.hpp>

namespace pullout::service {
namespace {

std::string utc_time(spdlog::log_clock::time_point t) {
  const auto since_epoch = t.time_since_epoch();
  const std::time_t secs = std::chrono::duration_cast<std::chrono::seconds>(since_epoch).count();
  const auto ms = std::chrono::duration_cast<std::chrono::milliseconds>(since_epoch).count() % 1000;
  std::tm tm{};
  gmtime_r(&secs, &tm);
  char buf[32];
  const std::size_t n = std::strftime(buf, sizeof buf, "%Y-%m-%dT%H:%M:%S", &tm);
  char out[48];
  std::snprintf(out, sizeof out, "%.*s.%03dZ", static_cast<int>(n), buf, static_cast<int>(ms));
  return out;
}

// "vehicle '<id>'": the id up to the closing quote (ids are bounded by the service).
void add_vehicle_id(const std::string& text, nlohmann::ordered_json& line) {
  constexpr const char* kPrefix = "vehicle '";
  const auto start = text.find(kPrefix);
  if (start == std::string::npos) return;
  const auto begin = start + std::strlen(kPrefix);
  const auto end = text.find('\'', begin);
  if (end == std::string::npos) return;
  line["vehicle_id"] = text.substr(begin, end - begin);
}

// "request <digits>"
void add_request_id(const std::string& text, nlohmann::ordered_json& line) {
  constexpr const char* kPrefix = "request ";
  for (auto at = text.find(kPrefix); at != std::string::npos; at = text.find(kPrefix, at + 1)) {
    std::size_t i = at + std::strlen(kPrefix);
    std::size_t j = i;
    while (j < text.size() && std::isdigit(static_cast<unsigned char>(text[j])) != 0) ++j;
    if (j > i && j - i <= 20) {
      try {
        line["request_id"] = std::stoull(text.substr(i, j - i));
        return;
      } catch (const std::exception&) {
        return;  // beyond 64 bits: not one of ours
      }
    }
  }
}

class FastDdsToSpdlog final : public eprosima::fastdds::dds::LogConsumer {
 public:
  explicit FastDdsToSpdlog(std::shared_ptr<spdlog::logger> logger) : logger_(std::move(logger)) {}
  void Consume(const eprosima::fastdds::dds::Log::Entry& entry) override {
    using Log = eprosima::fastdds::dds::Log;
    const auto level = entry.kind == Log::Kind::Error     ? spdlog::level::err
                       : entry.kind == Log::Kind::Warning ? spdlog::level::warn
                                                          : spdlog::level::info;
    const char* category = entry.context.category != nullptr ? entry.context.category : "";
    logger_->log(level, "[{}] {}", category, entry.message);
  }

 private:
  std::shared_ptr<spdlog::logger> logger_;
};

}  // namespace

void JsonLogFormatter::format(const spdlog::details::log_msg& msg, spdlog::memory_buf_t& dest) {
  const std::string text(msg.payload.data(), msg.payload.size());
  nlohmann::ordered_json line;  // keys in the order written: time, level, logger, message, fields
  line["time"] = utc_time(msg.time);
  const auto level = spdlog::level::to_string_view(msg.level);
  line["level"] = std::string(level.data(), level.size());
  line["logger"] = std::string(msg.logger_name.data(), msg.logger_name.size());
  line["message"] = text;
  add_vehicle_id(text, line);
  add_request_id(text, line);
  const std::string out = line.dump(-1, ' ', false, nlohmann::ordered_json::error_handler_t::replace);
  dest.append(out.data(), out.data() + out.size());
  dest.push_back('\n');
}

std::unique_ptr<spdlog::formatter> JsonLogFormatter::clone() const { return std::make_unique<JsonLogFormatter>(); }

void use_json_logs() {
  spdlog::set_formatter(std::make_unique<JsonLogFormatter>());
  auto main_logger = spdlog::default_logger();
  auto dds_logger =
      std::make_shared<spdlog::logger>("fastdds", main_logger->sinks().begin(), main_logger->sinks().end());
  dds_logger->set_formatter(std::make_unique<JsonLogFormatter>());
  dds_logger->set_level(spdlog::level::trace);  // Fast DDS's own verbosity decides what comes
  eprosima::fastdds::dds::Log::ClearConsumers();
  eprosima::fastdds::dds::Log::RegisterConsumer(std::make_unique<FastDdsToSpdlog>(dds_logger));
}

}  // namespace pullout::service
