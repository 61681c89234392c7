// PulloutService::stop() from several threads at once (a signal thread and the destructor do
// this at shut-down): exactly one joins the dispatcher, the others wait for the shut-down to
// finish, nobody joins a thread twice. The real service object on a leased loopback domain.
#include <gtest/gtest.h>

#include <string>
#include <thread>
#include <vector>

#include "pullout/config/config.hpp"
#include "service/pullout_service.hpp"
#include "service_process.hpp"

namespace pullout::service {
namespace {

TEST(PulloutServiceStop, ConcurrentCallersShutDownOnce) {
  integration::DomainLease lease;
  Config config = load_config(std::string(PULLOUT_SOURCE_DIR) + "/config/pullout.yaml");
  config.dds.domain_id = lease.domain();
  for (int round = 0; round < 10; ++round) {
    PulloutService service(config);
    service.start();
    std::vector<std::thread> stoppers;
    for (int i = 0; i < 4; ++i) stoppers.emplace_back([&service] { service.stop(); });
    for (std::thread& t : stoppers) t.join();
    // After every caller returned the service is stopped; stopping again is a no-op, and the
    // destructor (one more stop) follows.
    service.stop();
  }
}

}  // namespace
}  // namespace pullout::service
