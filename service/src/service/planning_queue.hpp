// A pool of planning threads fed with per-vehicle jobs.
//
// At most one job per vehicle runs at a time and at most one waits: a newer job of the same
// vehicle replaces the waiting one (only the latest request of a vehicle matters). Vehicles are
// served in the order their jobs became ready, so one busy vehicle cannot starve the others.
#pragma once

#include <atomic>
#include <chrono>
#include <condition_variable>
#include <cstdint>
#include <deque>
#include <functional>
#include <memory>
#include <mutex>
#include <string>
#include <thread>
#include <unordered_map>
#include <unordered_set>
#include <vector>

#include "pullout/model/types.hpp"
#include "pullout/pipeline/start_planner.hpp"

namespace pullout::service {

struct PlanningJob {
  PullOutRequest request;
  // The vehicle's acceptance number (VehicleRegistry): a result is published only if no newer
  // request of the vehicle was accepted meanwhile.
  std::uint64_t sequence{0};
  // Set when a newer request of the vehicle arrives or the service stops; the search's
  // StopCondition watches it.
  std::shared_ptr<std::atomic<bool>> cancel;
  std::chrono::steady_clock::time_point accepted_at;
  // The vehicle's previous world (SearchOrder::previous_world): StartPlanner::plan reuses its lane
  // world when the lanes are identical.
  std::shared_ptr<const PlannedWorld> previous_world;
  // Its `planning` status is held back (VehicleRegistry::on_request hold_planning): the planning
  // thread tries a quick answer first and writes the status (release_planning) when it runs out.
  bool planning_held{false};
};

class PlanningQueue {
 public:
  // Runs one job on a worker thread. Must not throw (exceptions are caught and logged anyway).
  using Runner = std::function<void(PlanningJob&)>;

  PlanningQueue(int worker_threads, Runner runner);
  ~PlanningQueue();
  PlanningQueue(const PlanningQueue&) = delete;
  PlanningQueue& operator=(const PlanningQueue&) = delete;

  // Queues a job for its vehicle. Returns true when it replaced a job of that vehicle that had not
  // started yet. Ignored after stop().
  bool push(PlanningJob job);

  // Jobs waiting for a worker (not the running ones).
  std::size_t depth() const;

  // Drops the waiting jobs and joins the workers once their running jobs return (cancel those
  // first to make this quick). Idempotent.
  void stop();

 private:
  void worker_loop();

  Runner runner_;
  mutable std::mutex mutex_;
  std::condition_variable wake_;
  std::unordered_map<std::string, PlanningJob> waiting_;  // vehicle -> its next job
  std::deque<std::string> ready_;                         // vehicles with a waiting job and none running
  std::unordered_set<std::string> running_;
  bool stopping_{false};
  std::vector<std::thread> workers_;
};

}  // namespace pullout::service
