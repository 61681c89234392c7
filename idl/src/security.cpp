#include "pullout/idl/security.hpp"

#include <filesystem>
#include <fstream>
#include <stdexcept>

#include <fastdds/dds/domain/qos/DomainParticipantQos.hpp>

namespace pullout::idl {

namespace {

std::string file_uri(const std::string& dir, const char* name) {
  const std::filesystem::path path = std::filesystem::absolute(std::filesystem::path(dir) / name);
  std::error_code ec;
  if (!std::filesystem::is_regular_file(path, ec) || !std::ifstream(path).good()) {
    throw std::invalid_argument("DDS security credentials: " + path.string() + " is missing or unreadable");
  }
  // Fast DDS 2.9 takes "file://" followed by the path (absolute here: file:///...).
  return "file://" + path.string();
}

}  // namespace

void add_security_properties(const std::string& dir, eprosima::fastdds::dds::DomainParticipantQos& qos) {
  if (dir.empty()) throw std::invalid_argument("DDS security credentials: no directory given");
  const std::string ca = file_uri(dir, kSecurityFiles[0]);
  const std::string certificate = file_uri(dir, kSecurityFiles[1]);
  const std::string key = file_uri(dir, kSecurityFiles[2]);
  const std::string governance = file_uri(dir, kSecurityFiles[3]);
  const std::string permissions = file_uri(dir, kSecurityFiles[4]);
  auto& properties = qos.properties().properties();
  const auto set = [&properties](const std::string& name, const std::string& value) {
    for (auto& p : properties) {
      if (p.name() == name) {
        p.value() = value;
        return;
      }
    }
    properties.emplace_back(name, value);
  };
  set("dds.sec.auth.plugin", "builtin.PKI-DH");
  set("dds.sec.auth.builtin.PKI-DH.identity_ca", ca);
  set("dds.sec.auth.builtin.PKI-DH.identity_certificate", certificate);
  set("dds.sec.auth.builtin.PKI-DH.private_key", key);
  set("dds.sec.access.plugin", "builtin.Access-Permissions");
  set("dds.sec.access.builtin.Access-Permissions.permissions_ca", ca);
  set("dds.sec.access.builtin.Access-Permissions.governance", governance);
  set("dds.sec.access.builtin.Access-Permissions.permissions", permissions);
  set("dds.sec.crypto.plugin", "builtin.AES-GCM-GMAC");
}

bool is_literal_partition_name(const std::string& vehicle_id) {
  return !vehicle_id.empty() && vehicle_id.find_first_of("*?[]\\") == std::string::npos;
}

}  // namespace pullout::idl
