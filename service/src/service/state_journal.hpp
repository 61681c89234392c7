// Restart without loss: every vehicle's latest request, path and status on disk, read back when
// the service starts again (README, Restart without loss).
//
// One file per vehicle, <dir>/<16 hex digits of a hash of the vehicle id>.state, holding the
// vehicle id and three CDR blobs (the same encoding as on the wire: the generated type support
// serialises them): the request that the status answers, the path last published, the status
// last published, and a checksum of all of it. A file is written to <name>.tmp and renamed over
// the old one, so a reader sees the old state or the new one, never half of one: a process killed
// in the middle (SIGKILL) leaves a whole file. No fsync: a killed process loses nothing the kernel
// has, a power cut may lose the last changes (the vehicle then re-requests).
//
// The request is kept in memory when it arrives and written with the first status that answers
// it (same request id): the file always pairs a path with the request it was planned for, whose
// lanes and objects the restored safety check needs. A request newer than the last status is not
// on disk; the vehicle's client sends an unanswered request again.
//
// Writes are serialised by one lock (the registry already orders the samples of one vehicle).
#pragma once

#include <cstdint>
#include <map>
#include <mutex>
#include <optional>
#include <string>
#include <vector>

#include "pullout/model/types.hpp"
#include "pullout/session/vehicle_session.hpp"
#include "service/outbox.hpp"

namespace pullout::msg {
class PullOutRequest;
}  // namespace pullout::msg

namespace pullout::service {

// What load() found in one file.
struct JournalEntry {
  std::string file;
  // The request as received (decoded again by the caller, with its own checks), and the vehicle's
  // last path and status.
  std::string vehicle_id;
  std::optional<PullOutRequest> request;
  std::vector<RequestIssue> request_issues;  // from decoding the request
  std::optional<PullOutPath> path;
  PullOutStatus status;
};

struct JournalLoad {
  std::vector<JournalEntry> entries;
  // One line per file that was not used: which file and why (unreadable, truncated, a checksum
  // that does not match, an unknown format, older than the caller's limit).
  std::vector<std::string> problems;
};

// Journals what passes through it to `next` (the DDS edge). Thread-safe.
class StateJournal final : public Outbox {
 public:
  // Creates `dir` if missing. Throws std::runtime_error (naming the directory) when it cannot be
  // created or written.
  StateJournal(std::string dir, Outbox& next);

  // Every valid state file; files whose status is older than `max_age_s` (by its stamp, 0: no
  // limit) are reported and left out. Leftover .tmp files are removed. What is loaded is also
  // kept as the vehicles' records (their next writes keep the request).
  JournalLoad load(double max_age_s);

  // A request as received (before anything else of it): remembered until a status answers it.
  void on_request(const msg::PullOutRequest& sample);

  bool publish_path(const PullOutPath& path) override;
  bool publish_status(const PullOutStatus& status) override;
  // Removes the vehicle's file (an evicted vehicle is not restored).
  bool forget_vehicle(const std::string& vehicle_id) override;

  // The file of a vehicle (for tests).
  std::string file_of(const std::string& vehicle_id) const;

 private:
  struct Record {
    std::string pending_request;  // CDR of the latest request, until a status answers it
    std::uint64_t pending_request_id{0};
    std::string request;  // CDR of the request the status answers
    std::string path;     // CDR
    std::string status;   // CDR
  };
  // Writes the vehicle's file (caller holds mutex_). Logs and returns false on failure.
  bool write(const std::string& vehicle_id, const Record& record);

  std::string dir_;
  Outbox& next_;
  std::mutex mutex_;
  std::map<std::string, Record> records_;
};

}  // namespace pullout::service
