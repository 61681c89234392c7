#include "service/replicas.hpp"

#include <algorithm>

namespace pullout::service {
namespace {

std::uint64_t score(const std::string& vehicle_id, const ParticipantId& replica) {
  std::uint64_t h = 14695981039346656037ULL;  // FNV-1a over the id, then the prefix
  const auto mix = [&h](unsigned char c) {
    h ^= c;
    h *= 1099511628211ULL;
  };
  for (const unsigned char c : vehicle_id) mix(c);
  for (const auto c : replica.value) mix(static_cast<unsigned char>(c));
  // A final avalanche so that prefixes differing in one byte spread well.
  h ^= h >> 33;
  h *= 0xff51afd7ed558ccdULL;
  h ^= h >> 33;
  return h;
}

}  // namespace

ParticipantId rendezvous_winner(const std::string& vehicle_id, const std::vector<ParticipantId>& live) {
  ParticipantId best = live.front();
  std::uint64_t best_score = score(vehicle_id, best);
  for (const ParticipantId& r : live) {
    const std::uint64_t s = score(vehicle_id, r);
    if (s > best_score || (s == best_score && best < r)) {
      best = r;
      best_score = s;
    }
  }
  return best;
}

bool ReplicaShadows::serves(const std::string& vehicle_id, const ParticipantId& self,
                            const std::vector<ParticipantId>& others) const {
  const auto it = shadows_.find(vehicle_id);
  if (it != shadows_.end() && it->second.owner) {
    const ParticipantId& owner = *it->second.owner;
    if (owner == self) return true;
    if (std::find(others.begin(), others.end(), owner) != others.end()) return false;
  }
  std::vector<ParticipantId> live = others;
  live.push_back(self);
  return rendezvous_winner(vehicle_id, live) == self;
}

bool ReplicaShadows::owner_left(const std::string& vehicle_id, const ParticipantId& self,
                                const std::vector<ParticipantId>& others) const {
  const auto it = shadows_.find(vehicle_id);
  if (it == shadows_.end() || !it->second.owner) return false;
  const ParticipantId& owner = *it->second.owner;
  return owner != self && std::find(others.begin(), others.end(), owner) == others.end();
}

ReplicaShadows::Shadow* ReplicaShadows::at(const std::string& vehicle_id) {
  const auto it = shadows_.find(vehicle_id);
  if (it != shadows_.end()) return &it->second;
  if (shadows_.size() >= max_vehicles_) return nullptr;
  return &shadows_[vehicle_id];
}

void ReplicaShadows::keep_request(const PullOutRequest& request) {
  Shadow* s = at(request.vehicle_id);
  if (s == nullptr) return;
  s->requests[request.request_id] = request;
  // Keep the newest, and the one the status answers.
  while (s->requests.size() > kKeptRequests) {
    auto oldest = s->requests.begin();
    if (s->status && oldest->first == s->status->request_id) ++oldest;
    if (oldest == s->requests.end()) break;
    s->requests.erase(oldest);
  }
}

std::vector<std::string> ReplicaShadows::owned_by(const ParticipantId& departed) const {
  std::vector<std::string> out;
  for (const auto& [id, s] : shadows_) {
    if (s.owner && *s.owner == departed) out.push_back(id);
  }
  return out;
}

std::optional<SessionSnapshot> ReplicaShadows::snapshot(const std::string& vehicle_id, bool& request_known) const {
  request_known = false;
  const auto it = shadows_.find(vehicle_id);
  if (it == shadows_.end() || !it->second.status) return std::nullopt;
  const Shadow& s = it->second;
  SessionSnapshot snap;
  snap.status = *s.status;
  snap.path = s.path;
  const auto r = s.requests.find(s.status->request_id);
  if (r != s.requests.end()) {
    snap.request = r->second;
    request_known = true;
  } else if (!s.requests.empty()) {
    // The owner left before its answer to the vehicle's latest request reached this replica:
    // that request (the newest kept) gives the world, and is handled again after the restore.
    const auto newest = std::max_element(s.requests.begin(), s.requests.end(), [](const auto& a, const auto& b) {
      return a.second.stamp_ns < b.second.stamp_ns;
    });
    snap.request = newest->second;
    snap.request_is_later = true;
    request_known = true;
  }
  return snap;
}

}  // namespace pullout::service
