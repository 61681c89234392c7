#include "service/planning_queue.hpp"

#include <exception>
#include <utility>

#include <spdlog/spdlog.h>

namespace pullout::service {

PlanningQueue::PlanningQueue(int worker_threads, Runner runner) : runner_(std::move(runner)) {
  const int n = worker_threads < 1 ? 1 : worker_threads;
  workers_.reserve(static_cast<std::size_t>(n));
  for (int i = 0; i < n; ++i) workers_.emplace_back([this] { worker_loop(); });
}

PlanningQueue::~PlanningQueue() { stop(); }

bool PlanningQueue::push(PlanningJob job) {
  bool replaced = false;
  {
    std::lock_guard<std::mutex> lock(mutex_);
    if (stopping_) return false;
    const std::string vehicle = job.request.vehicle_id;
    auto it = waiting_.find(vehicle);
    if (it != waiting_.end()) {
      it->second = std::move(job);  // already in ready_ (or its vehicle is running)
      replaced = true;
    } else {
      waiting_.emplace(vehicle, std::move(job));
      if (running_.count(vehicle) == 0) ready_.push_back(vehicle);
    }
  }
  wake_.notify_one();
  return replaced;
}

std::size_t PlanningQueue::depth() const {
  std::lock_guard<std::mutex> lock(mutex_);
  return waiting_.size();
}

void PlanningQueue::stop() {
  {
    std::lock_guard<std::mutex> lock(mutex_);
    stopping_ = true;
    waiting_.clear();
    ready_.clear();
  }
  wake_.notify_all();
  for (auto& w : workers_) {
    if (w.joinable()) w.join();
  }
  workers_.clear();
}

void PlanningQueue::worker_loop() {
  std::unique_lock<std::mutex> lock(mutex_);
  while (true) {
    wake_.wait(lock, [this] { return stopping_ || !ready_.empty(); });
    if (stopping_) return;
    const std::string vehicle = std::move(ready_.front());
    ready_.pop_front();
    auto it = waiting_.find(vehicle);
    if (it == waiting_.end()) continue;  // cannot happen: ready_ and waiting_ change together
    PlanningJob job = std::move(it->second);
    waiting_.erase(it);
    running_.insert(vehicle);

    lock.unlock();
    try {
      runner_(job);
    } catch (const std::exception& e) {
      spdlog::error("planning job of vehicle '{}' failed: {}", vehicle, e.what());
    } catch (...) {
      spdlog::error("planning job of vehicle '{}' failed", vehicle);
    }
    lock.lock();

    running_.erase(vehicle);
    // A newer job of this vehicle arrived while it ran: it is its turn now.
    if (!stopping_ && waiting_.count(vehicle) != 0) ready_.push_back(vehicle);
  }
}

}  // namespace pullout::service
