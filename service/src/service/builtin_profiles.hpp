// The service's built-in Fast DDS XML profiles (dds.profiles_file empty): config/dds/loopback.xml,
// compiled in at build time (service/CMakeLists.txt), so a config file needs no profiles file.
#pragma once

namespace pullout::service {

// The XML text of config/dds/loopback.xml.
extern const char* const kBuiltinProfilesXml;

}  // namespace pullout::service
