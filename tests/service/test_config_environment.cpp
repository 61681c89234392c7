// The environment variables that override config keys (PULLOUT_DOMAIN_ID, PULLOUT_DDS_PROFILE,
// PULLOUT_DDS_SECURITY_DIR; config.hpp), a config without dds.profiles_file (the built-in
// loopback profiles), and the real pullout_service process configured by its environment.
#include <chrono>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <map>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "pullout/client/client.hpp"
#include "pullout/config/config.hpp"
#include "service_process.hpp"

namespace pullout {
namespace {

namespace fs = std::filesystem;
using integration::ChildProcess;
using integration::DomainLease;
using integration::TempDir;

const std::string kSourceDir = PULLOUT_SOURCE_DIR;

// A fake environment: only the variables in the map are set.
Environment fake(std::map<std::string, std::string> vars) {
  auto shared = std::make_shared<std::map<std::string, std::string>>(std::move(vars));
  return [shared](const char* name) -> const char* {
    const auto it = shared->find(name);
    return it == shared->end() ? nullptr : it->second.c_str();
  };
}

// A config file in a fresh directory with the shipped dds/ profiles copied beside it.
struct ConfigDir {
  TempDir dir;
  std::string config;
  explicit ConfigDir(const std::string& text, bool with_profiles = true) {
    if (with_profiles) {
      fs::create_directories(fs::path(dir.path()) / "dds");
      for (const char* name : kDdsProfileNames) {
        fs::copy_file(kSourceDir + "/config/dds/" + name + ".xml",
                      fs::path(dir.path()) / "dds" / (std::string(name) + ".xml"));
      }
    }
    config = dir.write_file("pullout.yaml", text);
  }
};

std::vector<std::string> problems_of(const std::string& path, const Environment& env) {
  try {
    load_config(path, env);
  } catch (const ConfigError& e) {
    return e.problems();
  }
  return {};
}

std::string dump(const std::vector<std::string>& lines) {
  std::string s;
  for (const auto& l : lines) s += l + "\n";
  return s;
}

TEST(ConfigProfiles, AConfigWithoutProfilesFileUsesTheBuiltInProfiles) {
  // Every key is optional: a config with no dds section and no profiles file beside it loads
  // (it used to fail with "dds.profiles_file: file not found: <dir>/dds/loopback.xml").
  ConfigDir file("service: {worker_threads: 1}\n", /*with_profiles=*/false);
  const Config c = load_config(file.config);
  EXPECT_TRUE(c.dds.profiles_file.empty()) << c.dds.profiles_file;
  EXPECT_EQ(describe_profiles(c.dds), "the built-in loopback profiles");
  EXPECT_EQ(c.service.worker_threads, 1);
}

TEST(ConfigProfiles, TheEmptyDocumentLoadsWithoutAnyFileBesideIt) {
  ConfigDir file("", /*with_profiles=*/false);
  EXPECT_TRUE(load_config(file.config).dds.profiles_file.empty());
}

TEST(ConfigEnvironment, DomainIdOverridesTheFile) {
  ConfigDir file("dds: {domain_id: 3}\n");
  EXPECT_EQ(load_config(file.config, fake({})).dds.domain_id, 3);
  EXPECT_EQ(load_config(file.config, fake({{"PULLOUT_DOMAIN_ID", "42"}})).dds.domain_id, 42);
  EXPECT_EQ(load_config(file.config, fake({{"PULLOUT_DOMAIN_ID", "0"}})).dds.domain_id, 0);
  EXPECT_EQ(load_config(file.config, fake({{"PULLOUT_DOMAIN_ID", "232"}})).dds.domain_id, 232);
  // Empty counts as unset.
  EXPECT_EQ(load_config(file.config, fake({{"PULLOUT_DOMAIN_ID", ""}})).dds.domain_id, 3);
}

TEST(ConfigEnvironment, BadDomainIdNamesTheVariable) {
  ConfigDir file("");
  for (const char* bad : {"233", "-1", "abc", "7 ", "1e2", "99999999999"}) {
    const auto p = problems_of(file.config, fake({{"PULLOUT_DOMAIN_ID", bad}}));
    ASSERT_EQ(p.size(), 1u) << bad << "\n" << dump(p);
    EXPECT_EQ(p[0],
              std::string("PULLOUT_DOMAIN_ID: must be an integer in [0, 232] (it overrides dds.domain_id), got '") +
                  bad + "'");
  }
}

TEST(ConfigEnvironment, ProfileByNameIsTheFileBesideTheConfig) {
  ConfigDir file("dds: {profiles_file: dds/loopback.xml}\n");
  const fs::path dir(file.dir.path());
  EXPECT_EQ(load_config(file.config, fake({{"PULLOUT_DDS_PROFILE", "network"}})).dds.profiles_file,
            (dir / "dds" / "network.xml").string());
  EXPECT_EQ(load_config(file.config, fake({{"PULLOUT_DDS_PROFILE", "loopback"}})).dds.profiles_file,
            (dir / "dds" / "loopback.xml").string());
  EXPECT_EQ(load_config(file.config,
                        fake({{"PULLOUT_DDS_PROFILE", "discovery_client"}, {"ROS_DISCOVERY_SERVER", "10.0.0.1:11811"}}))
                .dds.profiles_file,
            (dir / "dds" / "discovery_client.xml").string());
}

TEST(ConfigEnvironment, ProfileByPath) {
  ConfigDir file("");
  const std::string custom = file.dir.write_file("custom.xml", "<dds/>\n");
  EXPECT_EQ(load_config(file.config, fake({{"PULLOUT_DDS_PROFILE", custom}})).dds.profiles_file, custom);
  // Relative to the config file, like the key.
  EXPECT_EQ(load_config(file.config, fake({{"PULLOUT_DDS_PROFILE", "custom.xml"}})).dds.profiles_file, custom);
}

TEST(ConfigEnvironment, BadProfileNamesTheVariable) {
  ConfigDir file("");
  auto p = problems_of(file.config, fake({{"PULLOUT_DDS_PROFILE", "multicast"}}));
  ASSERT_EQ(p.size(), 1u) << dump(p);
  EXPECT_EQ(p[0],
            "PULLOUT_DDS_PROFILE: unknown profile 'multicast': one of loopback, network, discovery_client, or the "
            "path of a Fast DDS XML profiles file");

  p = problems_of(file.config, fake({{"PULLOUT_DDS_PROFILE", "/nowhere/profiles.xml"}}));
  ASSERT_EQ(p.size(), 1u) << dump(p);
  EXPECT_EQ(p[0], "PULLOUT_DDS_PROFILE: file not found: /nowhere/profiles.xml");

  // A named profile that is not beside the config file.
  ConfigDir bare("", /*with_profiles=*/false);
  p = problems_of(bare.config, fake({{"PULLOUT_DDS_PROFILE", "network"}}));
  ASSERT_EQ(p.size(), 1u) << dump(p);
  EXPECT_EQ(p[0].rfind("PULLOUT_DDS_PROFILE=network: file not found: ", 0), 0u) << p[0];
}

TEST(ConfigEnvironment, DiscoveryClientNeedsTheServerAddress) {
  ConfigDir file("");
  const auto p = problems_of(file.config, fake({{"PULLOUT_DDS_PROFILE", "discovery_client"}}));
  ASSERT_EQ(p.size(), 1u) << dump(p);
  EXPECT_EQ(p[0].rfind("PULLOUT_DDS_PROFILE: discovery_client needs ROS_DISCOVERY_SERVER", 0), 0u) << p[0];
}

TEST(ConfigEnvironment, SecurityDirIsCheckedUnderTheVariablesName) {
  ConfigDir file("");
  const auto p = problems_of(file.config, fake({{"PULLOUT_DDS_SECURITY_DIR", "/nowhere/pki"}}));
  ASSERT_EQ(p.size(), 1u) << dump(p);
  EXPECT_EQ(p[0], "PULLOUT_DDS_SECURITY_DIR: directory not found: /nowhere/pki");
}

TEST(ConfigEnvironment, MetricsEndpoint) {
  ConfigDir file("");
  const Config c =
      load_config(file.config, fake({{"PULLOUT_METRICS_ENABLED", "true"}, {"PULLOUT_METRICS_ADDRESS", "0.0.0.0"}}));
  EXPECT_TRUE(c.observability.metrics.enabled);
  EXPECT_EQ(c.observability.metrics.address, "0.0.0.0");
  EXPECT_FALSE(load_config(file.config, fake({{"PULLOUT_METRICS_ENABLED", "false"}})).observability.metrics.enabled);
  EXPECT_FALSE(load_config(file.config, fake({})).observability.metrics.enabled);

  auto p = problems_of(file.config, fake({{"PULLOUT_METRICS_ENABLED", "yes"}}));
  ASSERT_EQ(p.size(), 1u) << dump(p);
  EXPECT_EQ(p[0].rfind("PULLOUT_METRICS_ENABLED: must be true or false", 0), 0u) << p[0];
  p = problems_of(file.config, fake({{"PULLOUT_METRICS_ADDRESS", "localhost"}}));
  ASSERT_EQ(p.size(), 1u) << dump(p);
  EXPECT_EQ(p[0].rfind("PULLOUT_METRICS_ADDRESS: must be an IPv4 address", 0), 0u) << p[0];
}

TEST(ConfigEnvironment, EveryBadVariableIsReportedWithTheFilesProblems) {
  ConfigDir file("service: {worker_threads: 0}\n");
  const auto p = problems_of(file.config, fake({{"PULLOUT_DOMAIN_ID", "x"}, {"PULLOUT_DDS_PROFILE", "nope"}}));
  EXPECT_EQ(p.size(), 3u) << dump(p);
}

// --- the real process ---

using Vars = std::map<std::string, std::string>;

// Sets environment variables for the children started while it lives.
class ScopedEnv {
 public:
  explicit ScopedEnv(std::map<std::string, std::string> vars) : vars_(std::move(vars)) {
    for (const auto& [k, v] : vars_) ::setenv(k.c_str(), v.c_str(), 1);
  }
  ~ScopedEnv() {
    for (const auto& [k, v] : vars_) ::unsetenv(k.c_str());
  }
  ScopedEnv(const ScopedEnv&) = delete;
  ScopedEnv& operator=(const ScopedEnv&) = delete;

 private:
  std::map<std::string, std::string> vars_;
};

TEST(ServiceEnvironment, TheServiceRunsOnTheDomainAndProfileOfItsEnvironment) {
  // A config with no dds section: domain and profile come from the environment only. A client
  // on that domain finds the service; the service exits cleanly on SIGTERM.
  DomainLease lease;
  ConfigDir file("service: {worker_threads: 1, log_level: warn}\n");
  std::optional<ChildProcess> service;
  {
    ScopedEnv env(Vars{{"PULLOUT_DOMAIN_ID", std::to_string(lease.domain())}, {"PULLOUT_DDS_PROFILE", "loopback"}});
    service.emplace(std::vector<std::string>{PULLOUT_SERVICE_EXE, "--config", file.config},
                    file.dir.path() + "/out.txt", file.dir.path() + "/err.txt");
  }
  ClientOptions options;
  options.vehicle_id = "env-probe";
  options.domain_id = lease.domain();
  Client client(options);
  EXPECT_TRUE(client.wait_for_service(std::chrono::seconds(15)))
      << integration::read_file_tail(file.dir.path() + "/err.txt", 2000);
  const auto exit = service->stop();
  EXPECT_TRUE(exit.clean()) << exit.describe();
}

TEST(ServiceEnvironment, ABadVariableStopsTheServiceNamingIt) {
  ConfigDir file("");
  std::optional<ChildProcess> service;
  {
    ScopedEnv env(Vars{{"PULLOUT_DOMAIN_ID", "300"}});
    service.emplace(std::vector<std::string>{PULLOUT_SERVICE_EXE, "--config", file.config},
                    file.dir.path() + "/out.txt", file.dir.path() + "/err.txt");
  }
  const auto exit = service->wait_exit(std::chrono::seconds(10));
  ASSERT_TRUE(exit.has_value()) << "still running";
  EXPECT_TRUE(exit->exited);
  EXPECT_EQ(exit->exit_code, 1);
  const std::string err = integration::read_file_tail(file.dir.path() + "/err.txt", 2000);
  EXPECT_NE(err.find("PULLOUT_DOMAIN_ID: must be an integer in [0, 232]"), std::string::npos) << err;
}

}  // namespace
}  // namespace pullout
