// A service that dies (SIGKILL) under its clients, with the real pullout_service processes:
//   - a request outstanding when the service is killed is answered by the next service, without
//     the caller sending it again (the client re-sends it, the topic being volatile);
//   - a killed service is noticed within its participant lease (config/dds/loopback.xml: 2 s),
//     and a wait that nothing can answer any more returns at once instead of at its timeout.
// Each test leases a DDS domain and runs its services itself (the ServiceTest fixture expects a
// clean exit, which a killed service cannot give).
#include <signal.h>
#include <sys/types.h>

#include <chrono>
#include <filesystem>
#include <fstream>
#include <memory>
#include <optional>
#include <string>
#include <thread>

#include <gtest/gtest.h>

#include "integration_support.hpp"
#include "pullout/client/client.hpp"

namespace pullout::integration {
namespace {

using namespace std::chrono_literals;
using SteadyClock = std::chrono::steady_clock;

ServiceOptions service_options(int domain) {
  ServiceOptions o;
  o.executable = PULLOUT_SERVICE_EXE;
  o.config_path = default_config_path();
  o.domain = domain;
  return o;
}

// Whether every thread of `pid` is stopped (SIGSTOP delivered: state T in /proc/PID/task/*/stat).
bool all_threads_stopped(pid_t pid) {
  const std::string tasks = "/proc/" + std::to_string(pid) + "/task";
  std::error_code ec;
  int count = 0;
  for (const auto& entry : std::filesystem::directory_iterator(tasks, ec)) {
    std::ifstream in(entry.path() / "stat");
    std::string text((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
    const auto close = text.rfind(')');
    if (close == std::string::npos || close + 2 >= text.size()) return false;
    const char state = text[close + 2];
    if (state != 'T' && state != 't') return false;
    ++count;
  }
  return !ec && count > 0;
}

// Stops the process (SIGSTOP) and waits until none of its threads runs: from then on, nothing it
// receives is processed. Then SIGKILL.
void freeze_then_kill(pid_t pid) {
  ASSERT_EQ(::kill(pid, SIGSTOP), 0);
  const auto deadline = SteadyClock::now() + 5s;
  while (!all_threads_stopped(pid) && SteadyClock::now() < deadline) std::this_thread::sleep_for(1ms);
  ASSERT_TRUE(all_threads_stopped(pid)) << "the service did not stop on SIGSTOP";
}

TEST(ServiceRestart, ARequestOutstandingWhenTheServiceIsKilledIsAnsweredByTheNextService) {
  DomainLease lease;
  const Scenario scenario = load_test_scenario("straight_shoulder");
  ClientOptions o;
  o.vehicle_id = "restart-car";
  o.domain_id = lease.domain();
  o.resend_window = std::chrono::milliseconds(60000);  // generous: the machine may be busy
  Client client(o);

  std::optional<ServiceProcess> first;
  first.emplace(service_options(lease.domain()));
  ASSERT_TRUE(client.wait_for_service(kMatchTimeout));

  // Frozen, the service still holds its matches but processes nothing: the request reaches its
  // socket and dies with it.
  freeze_then_kill(first->pid());
  const std::uint64_t id = client.send(scenario.request);
  ASSERT_EQ(::kill(first->pid(), SIGKILL), 0);
  first.reset();  // reaps it

  ServiceProcess second(service_options(lease.domain()));
  // No second send(): the client re-sends the same request to the new service.
  const auto path = client.wait_for_path(id, 30s);
  ASSERT_TRUE(path.has_value()) << "request " << id << " was never answered\n" << second.stderr_tail();
  EXPECT_EQ(path->request_id, id);
  expect_found_path_invariants(*path);
  const auto status = client.wait_for_status(
      id, [](const PullOutStatus& s) { return s.state == ExecutionState::kWaitingApproval; }, kReplyTimeout);
  ASSERT_TRUE(status.has_value()) << second.stderr_tail();
  EXPECT_EQ(client.current_request_id(), id);
  EXPECT_EQ(client.service_state(), ServiceState::kConnected);
  EXPECT_TRUE(second.stop().clean()) << second.stderr_tail();
}

TEST(ServiceRestart, AKilledServiceIsNoticedWithinItsLeaseAndAWaitReturnsAtOnce) {
  DomainLease lease;
  const Scenario scenario = load_test_scenario("straight_shoulder");
  ClientOptions o;
  o.vehicle_id = "lost-car";
  o.domain_id = lease.domain();
  Client client(o);
  ServiceProcess service(service_options(lease.domain()));
  ASSERT_TRUE(client.wait_for_service(kMatchTimeout));
  const std::uint64_t id = client.send(scenario.request);
  ASSERT_TRUE(client.wait_for_path(id, kReplyTimeout).has_value()) << service.stderr_tail();
  ASSERT_TRUE(client.wait_for_status(
      id, [](const PullOutStatus& s) { return s.state == ExecutionState::kWaitingApproval; }, kReplyTimeout));

  // Answered, so nothing will be re-sent: once the service is gone, a wait for execution can
  // only end by the service being noticed lost (or by its timeout, 30 s).
  const auto killed_at = SteadyClock::now();
  ASSERT_EQ(::kill(service.pid(), SIGKILL), 0);
  const auto executing = client.wait_for_status(
      id, [](const PullOutStatus& s) { return s.state == ExecutionState::kExecuting; }, 30s);
  const auto noticed_after = SteadyClock::now() - killed_at;
  EXPECT_FALSE(executing.has_value());
  EXPECT_EQ(client.service_state(), ServiceState::kLost);
  // The lease is 2 s (config/dds/loopback.xml); generous for a busy machine.
  EXPECT_LT(noticed_after, 5s) << std::chrono::duration<double>(noticed_after).count() << " s";
  // What was received before stays: the found path is still the vehicle's latest.
  ASSERT_TRUE(client.latest_path().has_value());
  EXPECT_EQ(client.latest_path()->request_id, id);
}

}  // namespace
}  // namespace pullout::integration
