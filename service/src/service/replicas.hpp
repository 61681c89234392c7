// Replica mode (service.replica.enabled): which replica serves which vehicle, and what the others
// keep to take a vehicle over.
//
// Every replica reads every request, and the path and status topics (TRANSIENT_LOCAL: a replica
// that starts late gets every vehicle's latest). A vehicle is served by
//   - its owner, the replica whose writers published its latest status, while that replica is
//     alive (sticky: a replica joining never takes a vehicle from a live one);
//   - otherwise the winner of rendezvous hashing of (vehicle id, replica GUID prefix) over the live
//     replicas: every replica computes the same winner from the same set, so a new vehicle, or a
//     vehicle whose owner died, gets exactly one replica, and the vehicles of a dead replica are
//     spread over the others.
// A replica that does not serve a vehicle keeps its shadow: the owner, the latest path and status,
// and the requests it saw (the one the status answers, for the safety check's lanes and objects).
// When the owner leaves (its DDS participant lease expires), the winner rebuilds the session from
// the shadow (VehicleSession::restore). Liveliness is the participant's: the path and status
// writers keep an infinite liveliness lease, since Fast DDS 2.9 turns writer-side filtering off for
// a finite one.
//
// Dispatcher thread only.
#pragma once

#include <cstdint>
#include <map>
#include <optional>
#include <string>
#include <vector>

#include "pullout/model/types.hpp"
#include "pullout/session/vehicle_session.hpp"
#include "service/dds_edge.hpp"

namespace pullout::service {

// The replica among `live` (not empty) that serves `vehicle_id` when it has no live owner.
ParticipantId rendezvous_winner(const std::string& vehicle_id, const std::vector<ParticipantId>& live);

class ReplicaShadows {
 public:
  struct Shadow {
    std::optional<ParticipantId> owner;
    std::optional<PullOutPath> path;
    std::optional<PullOutStatus> status;
    // The latest requests seen, by id (at most kKeptRequests).
    std::map<std::uint64_t, PullOutRequest> requests;
  };
  static constexpr std::size_t kKeptRequests = 2;

  // At most `max_vehicles` shadows (further vehicles are not shadowed; logged by the caller).
  explicit ReplicaShadows(std::size_t max_vehicles) : max_vehicles_(max_vehicles) {}

  // Whether this replica (`self`, with the other live replicas `others`) serves the vehicle now.
  bool serves(const std::string& vehicle_id, const ParticipantId& self, const std::vector<ParticipantId>& others) const;

  // Whether the vehicle's owner has left (not `self`, not among `others`) and its vehicles are
  // not taken over yet: its requests are kept for the takeover, not served as new ones.
  bool owner_left(const std::string& vehicle_id, const ParticipantId& self,
                  const std::vector<ParticipantId>& others) const;

  // Null when full.
  Shadow* at(const std::string& vehicle_id);
  void keep_request(const PullOutRequest& request);
  void erase(const std::string& vehicle_id) { shadows_.erase(vehicle_id); }
  // The vehicles whose owner is `departed`.
  std::vector<std::string> owned_by(const ParticipantId& departed) const;
  // The snapshot to restore from: the request the status answers when seen, else the newest kept
  // request (request_is_later), else no request (request_known false).
  std::optional<SessionSnapshot> snapshot(const std::string& vehicle_id, bool& request_known) const;
  std::size_t size() const { return shadows_.size(); }

 private:
  std::size_t max_vehicles_;
  std::map<std::string, Shadow> shadows_;
};

}  // namespace pullout::service
