#include "service/state_journal.hpp"

#include <chrono>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <stdexcept>
#include <utility>

#include <fastdds/rtps/common/SerializedPayload.h>
#include <spdlog/spdlog.h>

#include "pullout/idl/convert.hpp"
#include "pullout/msg/pulloutPubSubTypes.h"

namespace pullout::service {
namespace {

// The format's name and version; a file of another version is reported, not read.
constexpr std::string_view kMagic = "pullout-state 1\n";

std::uint64_t fnv1a(std::string_view bytes) {
  std::uint64_t h = 14695981039346656037ULL;
  for (const unsigned char c : bytes) {
    h ^= c;
    h *= 1099511628211ULL;
  }
  return h;
}

template <typename PubSub, typename Msg>
std::string to_cdr(const Msg& sample) {
  PubSub type;
  eprosima::fastrtps::rtps::SerializedPayload_t payload(type.getSerializedSizeProvider(const_cast<Msg*>(&sample))());
  if (!type.serialize(const_cast<Msg*>(&sample), &payload)) throw std::runtime_error("CDR serialisation failed");
  return std::string(reinterpret_cast<const char*>(payload.data), payload.length);
}

template <typename PubSub, typename Msg>
bool from_cdr(const std::string& bytes, Msg& sample) {
  PubSub type;
  eprosima::fastrtps::rtps::SerializedPayload_t payload(static_cast<std::uint32_t>(bytes.size()));
  std::memcpy(payload.data, bytes.data(), bytes.size());
  payload.length = static_cast<std::uint32_t>(bytes.size());
  try {
    return type.deserialize(&payload, &sample);
  } catch (const std::exception&) {
    return false;
  }
}

void put_blob(std::string& out, const std::string& blob) {
  const auto n = static_cast<std::uint64_t>(blob.size());
  out.append(reinterpret_cast<const char*>(&n), sizeof n);
  out.append(blob);
}

// Reads one length-prefixed blob at `pos`; false when the file ends first.
bool get_blob(const std::string& in, std::size_t& pos, std::size_t end, std::string& blob) {
  std::uint64_t n = 0;
  if (end - pos < sizeof n) return false;
  std::memcpy(&n, in.data() + pos, sizeof n);
  pos += sizeof n;
  if (n > end - pos) return false;
  blob.assign(in, pos, n);
  pos += n;
  return true;
}

}  // namespace

StateJournal::StateJournal(std::string dir, Outbox& next) : dir_(std::move(dir)), next_(next) {
  std::error_code ec;
  std::filesystem::create_directories(dir_, ec);
  if (ec || !std::filesystem::is_directory(dir_)) {
    throw std::runtime_error("service.state_dir: cannot create directory " + dir_ + ": " + ec.message());
  }
  const std::string probe = dir_ + "/.write-probe";
  {
    std::ofstream out(probe);
    if (!out || !(out << "x") || !out.flush()) {
      throw std::runtime_error("service.state_dir: cannot write in " + dir_);
    }
  }
  std::filesystem::remove(probe, ec);
}

std::string StateJournal::file_of(const std::string& vehicle_id) const {
  char name[32];
  std::snprintf(name, sizeof name, "%016llx.state", static_cast<unsigned long long>(fnv1a(vehicle_id)));
  return dir_ + "/" + name;
}

void StateJournal::on_request(const msg::PullOutRequest& sample) {
  std::string cdr;
  try {
    cdr = to_cdr<msg::PullOutRequestPubSubType>(sample);
  } catch (const std::exception& e) {
    spdlog::error("state journal: vehicle '{}' request {}: {}", sample.vehicle_id(), sample.request_id(), e.what());
    return;
  }
  std::lock_guard<std::mutex> lock(mutex_);
  Record& r = records_[sample.vehicle_id()];
  r.pending_request = std::move(cdr);
  r.pending_request_id = sample.request_id();
}

// Write-ahead: the state is on disk before a vehicle can see it, so a process killed right after a
// publication never restarts behind what the vehicle was told (it failed as
// RestartWithoutLoss.AVehicleInMidManoeuvre... when the kill came between the two).
bool StateJournal::publish_path(const PullOutPath& path) {
  std::string cdr = to_cdr<msg::PullOutPathPubSubType>(idl::to_msg(path));
  {
    std::lock_guard<std::mutex> lock(mutex_);
    Record& r = records_[path.vehicle_id];
    r.path = std::move(cdr);
    // Written with the status that follows (a path is always followed by its status).
  }
  return next_.publish_path(path);
}

bool StateJournal::publish_status(const PullOutStatus& status) {
  std::string cdr = to_cdr<msg::PullOutStatusPubSubType>(idl::to_msg(status));
  {
    std::lock_guard<std::mutex> lock(mutex_);
    Record& r = records_[status.vehicle_id];
    r.status = std::move(cdr);
    if (!r.pending_request.empty() && r.pending_request_id == status.request_id) {
      r.request = std::move(r.pending_request);
      r.pending_request.clear();
      r.pending_request_id = 0;
    }
    write(status.vehicle_id, r);
  }
  return next_.publish_status(status);
}

bool StateJournal::forget_vehicle(const std::string& vehicle_id) {
  const bool ok = next_.forget_vehicle(vehicle_id);
  std::lock_guard<std::mutex> lock(mutex_);
  records_.erase(vehicle_id);
  std::error_code ec;
  std::filesystem::remove(file_of(vehicle_id), ec);
  return ok;
}

bool StateJournal::write(const std::string& vehicle_id, const Record& record) {
  std::string text(kMagic);
  put_blob(text, vehicle_id);
  put_blob(text, record.request);
  put_blob(text, record.path);
  put_blob(text, record.status);
  const std::uint64_t sum = fnv1a(text);
  text.append(reinterpret_cast<const char*>(&sum), sizeof sum);
  const std::string file = file_of(vehicle_id);
  const std::string tmp = file + ".tmp";
  {
    std::ofstream out(tmp, std::ios::binary | std::ios::trunc);
    if (!out || !out.write(text.data(), static_cast<std::streamsize>(text.size())) || !out.flush()) {
      spdlog::error("state journal: cannot write {} (vehicle '{}')", tmp, vehicle_id);
      return false;
    }
  }
  if (std::rename(tmp.c_str(), file.c_str()) != 0) {
    spdlog::error("state journal: cannot rename {} to {}: {}", tmp, file, std::strerror(errno));
    return false;
  }
  return true;
}

JournalLoad StateJournal::load(double max_age_s) {
  JournalLoad out;
  std::error_code ec;
  const auto now_ns =
      std::chrono::duration_cast<std::chrono::nanoseconds>(std::chrono::system_clock::now().time_since_epoch()).count();
  for (const auto& item : std::filesystem::directory_iterator(dir_, ec)) {
    const std::string file = item.path().string();
    if (item.path().extension() == ".tmp") {
      std::filesystem::remove(item.path(), ec);  // a write the process did not finish
      continue;
    }
    if (item.path().extension() != ".state") continue;
    const auto problem = [&](const std::string& why) { out.problems.push_back(file + ": " + why); };
    std::ifstream in(file, std::ios::binary);
    const std::string text((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
    if (!in.good() && !in.eof()) {
      problem("cannot be read");
      continue;
    }
    if (text.compare(0, kMagic.size(), kMagic) != 0) {
      problem("not a pullout state file of this version (expected '" + std::string(kMagic.substr(0, 15)) + "')");
      continue;
    }
    std::uint64_t sum = 0;
    if (text.size() < kMagic.size() + sizeof sum) {
      problem("truncated");
      continue;
    }
    const std::size_t end = text.size() - sizeof sum;
    std::memcpy(&sum, text.data() + end, sizeof sum);
    if (sum != fnv1a(std::string_view(text.data(), end))) {
      problem("checksum does not match (truncated or corrupt)");
      continue;
    }
    std::size_t pos = kMagic.size();
    std::string id;
    std::string request;
    std::string path;
    std::string status;
    if (!get_blob(text, pos, end, id) || !get_blob(text, pos, end, request) || !get_blob(text, pos, end, path) ||
        !get_blob(text, pos, end, status) || pos != end) {
      problem("truncated");
      continue;
    }
    JournalEntry e;
    e.file = file;
    e.vehicle_id = id;
    msg::PullOutStatus status_msg;
    if (status.empty() || !from_cdr<msg::PullOutStatusPubSubType>(status, status_msg)) {
      problem("status cannot be decoded");
      continue;
    }
    e.status = idl::from_msg(status_msg);
    if (e.status.vehicle_id != id) {
      problem("status of vehicle '" + e.status.vehicle_id + "' in the file of '" + id + "'");
      continue;
    }
    if (max_age_s > 0.0 && static_cast<double>(now_ns - e.status.stamp_ns) * 1e-9 > max_age_s) {
      problem("older than service.session_idle_timeout_s (vehicle '" + id + "'): not restored");
      continue;
    }
    if (!path.empty()) {
      msg::PullOutPath path_msg;
      if (!from_cdr<msg::PullOutPathPubSubType>(path, path_msg)) {
        problem("path cannot be decoded");
        continue;
      }
      e.path = idl::from_msg(path_msg);
    }
    if (!request.empty()) {
      msg::PullOutRequest request_msg;
      if (!from_cdr<msg::PullOutRequestPubSubType>(request, request_msg)) {
        problem("request cannot be decoded");
        continue;
      }
      e.request = idl::from_msg(request_msg, e.request_issues);
    }
    {
      std::lock_guard<std::mutex> lock(mutex_);
      Record& r = records_[id];
      r.request = std::move(request);
      r.path = std::move(path);
      r.status = std::move(status);
    }
    out.entries.push_back(std::move(e));
  }
  if (ec) out.problems.push_back(dir_ + ": " + ec.message());
  return out;
}

}  // namespace pullout::service
