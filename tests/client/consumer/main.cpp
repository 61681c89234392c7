// Uses the installed pullout package: the model headers and pullout::Client (loopback defaults).
#include <chrono>
#include <iostream>

#include <pullout/client/client.hpp>
#include <pullout/model/names.hpp>
#include <pullout/model/types.hpp>

int main() {
  pullout::PullOutRequest request;
  request.goal_pose = {90.0, 0.0, 0.0};
  std::cout << "planner name: " << pullout::to_string(pullout::PlannerType::kShift) << '\n';

  try {
    pullout::ClientOptions options;
    options.vehicle_id = "package-consumer";
    options.domain_id = 231;  // nothing listens there: this only exercises the library
    pullout::Client client(options);
    const bool service = client.wait_for_service(std::chrono::milliseconds(50));
    std::cout << "client for " << client.vehicle_id() << " on domain " << client.domain_id()
              << ", service matched: " << (service ? "yes" : "no") << '\n';
  } catch (const pullout::ClientError& e) {
    std::cerr << "client error: " << e.what() << '\n';
    return 1;
  }
  try {
    pullout::ClientOptions bad;  // empty vehicle id
    pullout::Client client(bad);
    return 1;
  } catch (const std::invalid_argument&) {
    std::cout << "empty vehicle id rejected\n";
  }
  return 0;
}
