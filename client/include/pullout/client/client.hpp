// pullout::Client: what vehicle software links to talk to the pullout service over DDS.
//
// One Client speaks for one vehicle (ClientOptions::vehicle_id). It publishes PullOutRequest and
// ExecutionProgress samples keyed by that id, and receives the PullOutPath and PullOutStatus
// replies of that vehicle only. Path and status are read through a DDS content filter on
// vehicle_id that the service evaluates at its writers, so other vehicles' replies are not even
// sent to this client (bench/fleet_bytes.cpp, bench/RESULTS.md); the client drops any other
// vehicle's sample that still arrives (a service without the filter, or a
// service writer past its number of reader filters). Path and status readers are
// transient-local, so a client started after the service replied still receives the vehicle's
// latest path and status.
//
// Re-sending and a lost service. A request is answered when its path, or a status for it in a
// state other than planning, has been received. Until then the client re-sends it, unchanged
// (same request id, same stamp), every ClientOptions::resend_period and at once when a service
// (re)appears, for at most ClientOptions::resend_window after send(); the service answers a
// re-sent request idempotently (no second search: it re-publishes what it has). So a request
// sent before the service was up, or outstanding when the service died, is answered by the next
// service without the caller re-sending. A newer send() replaces the request being re-sent.
// The client sees the service as connected while its request and progress writers and its path
// and status readers are each matched with a service endpoint (service_state()). A service that
// is killed is lost after its participant lease: the shipped profiles (config/dds/loopback.xml,
// network.xml) announce 2 s (loopback) and 4 s (network), so a dead service is noticed within
// about that (tests/integration/test_service_restart.cpp asserts < 5 s on loopback; Fast DDS's
// default lease was 20 s). A service that stops cleanly is lost at once. When the service is
// lost: a planning status it sent is stale (that search will never finish) and is never reported
// again (latest_status(), wait_for_status()), and waits for a request that will not be re-sent
// any more (answered, superseded, or past its resend window) return std::nullopt at once with
// service_state() == ServiceState::kLost as the reason, instead of running to their timeout.
// Paths and other statuses received before the loss are kept: a found path is still a valid path,
// but no one follows its execution or checks its safety until a service answers again.
//
// DDS setup: with an empty ClientOptions::profiles_file the participant and the topic QoS are
// built in code: loopback only (built-in transports off, one UDPv4 transport whitelisted to
// 127.0.0.1), and the QoS of DESIGN.md (request: reliable, volatile, keep last 1; path and status:
// reliable, transient local, keep last 1; progress: reliable, volatile, keep last 1). With a
// profiles file, the participant comes from the named participant profile (which must exist), and
// each reader/writer takes the QoS of its profile when the file has one:
//   pullout_request_writer, pullout_progress_writer, pullout_path_reader, pullout_status_reader
// else the built-in QoS above. FASTRTPS_DEFAULT_PROFILES_FILE is never consulted for defaults.
//
// Threading: every member function is thread-safe. Samples are taken from DDS and callbacks are
// invoked on one thread owned by the client (not a DDS listener thread), one at a time, in arrival
// order, with no internal lock held, so a callback may call any member function except the
// destructor, and may wait for another thread that uses the client, with one exception: on_path
// (on_status) called from another thread waits for a running path (status) callback to return, so
// a path callback must not wait for a thread that calls on_path (same for status). A slow
// callback delays later callbacks, not the blocking waits (state is updated before callbacks
// run). Callbacks must not throw; an exception escaping a callback is caught and reported through
// the Fast DDS log (category "PULLOUT_CLIENT"). A blocking wait called from a callback only sees
// what was received before that callback (the thread that would deliver newer samples is the one
// running the callback), so it times out rather than seeing new replies. Undecodable replies are
// dropped by the type support (they never reach a callback nor a wait).
//
// Lifetime: the destructor stops the client's thread (waiting for a running callback to return),
// then deletes every DDS entity. Do not destroy a Client from one of its callbacks, nor while
// another thread is inside one of its member functions.
//
// Many vehicles on one participant (a vehicle gateway, a fleet simulator). A ClientParticipant owns
// one DDS participant, the four topics and, by default (ClientParticipantOptions::
// shared_endpoints), one request writer, one progress writer and one path and one status reader
// for all the Clients constructed on it (Client(participant, options)). Each Client writes its
// own instance (keyed by its vehicle id) and gets its own vehicle's replies, handed over by
// vehicle id from the shared readers, whose content filter is the set of the participant's
// vehicles, evaluated at the service's writers: the service sees one reader per participant, not
// one per vehicle (one reader per vehicle made the reliability traffic grow as N^2 and stopped a
// fleet at about 200 vehicles on a 2-core machine; bench/RESULTS.md, "Load"). A Client on it has
// the same API, re-sending, service state, waits and callbacks as a single-vehicle Client, and its
// own delivery thread, with these differences:
//   - constructing or destroying a Client changes the set (the readers are announced again with
//     the new set; changes within 20 ms are applied together). A Client is connected
//     (wait_for_service) once its vehicle is in the set its readers announce. A reply the service
//     writes before it has the new set is not sent to this participant; the Client's re-send
//     (resend_period) repairs that;
//   - the shared readers are created with the first set, once no Client was added for 20 ms, and
//     the transient-local history (each vehicle's latest path and status from before) reaches
//     them when they match the service, filtered by the set they have then: the Clients
//     constructed together (in one go after the participant) get their vehicle's latest path and
//     status as single-vehicle Clients do; a Client added later gets only the replies to its own
//     requests;
//   - a request is answered when both its path and a status past planning were received (not
//     either): a Client that just joined the set can have one of the two filtered out at the
//     service (the two readers' new set reaches the service's two writers one after the other),
//     and the re-send has the service publish both again;
//   - destroying a Client unregisters its request and progress instances (the service sees the
//     vehicle go, as when a Client's own writers are deleted);
//   - the set holds at most about 25 KB of ids (pullout/idl/vehicle_filter.hpp: about 2,300 ids
//     of 8 bytes); a Client for which it has no room gets endpoints of its own, as below.
// With shared_endpoints false, each Client has its own request and progress writers and its own
// vehicle-filtered path and status readers on the shared participant (the service sees a reader
// per vehicle). Either way, discovery traffic, sockets and the participant's threads are paid
// once per participant instead of once per vehicle. On a shared participant, the domain, profiles
// file and participant profile are the participant's (the corresponding ClientOptions fields are
// ignored) and security_dir must be empty (DDS Security credentials belong to a participant, and a
// vehicle's permissions grant only its own id: a secure vehicle uses the single-vehicle
// constructor, with endpoints of its own in its vehicle's partition).
// At most one Client per vehicle id is alive on a participant at a time. Constructing and
// destroying Clients on one participant from several threads at once is allowed.
// Lifetime: a ClientParticipant must outlive the Clients constructed on it (a Client keeps the
// DDS participant alive anyway, so a violation leaks nothing: the DDS participant is deleted
// with the last of them). Destroying a Client deletes only its own endpoints (or its place in the
// shared ones); the other Clients on the participant are not disturbed.
//
// Units and frames are those of pullout/model/types.hpp. The public headers of this library
// include no DDS header.
#pragma once

#include <chrono>
#include <cstddef>
#include <cstdint>
#include <functional>
#include <memory>
#include <optional>
#include <stdexcept>
#include <string>

#include "pullout/client/export.hpp"
#include "pullout/model/types.hpp"

namespace pullout {

struct ClientOptions {
  // The vehicle this client speaks for: 1..255 bytes, no NUL character.
  std::string vehicle_id;
  // DDS domain, 0..232. The service must use the same domain.
  int domain_id{0};
  // Fast DDS XML profiles file. Empty: built-in loopback-only defaults (see above).
  std::string profiles_file;
  // Participant profile in profiles_file (ignored when profiles_file is empty).
  std::string participant_profile{"pullout_participant"};
  // DDS Security: a directory with this vehicle's credentials (ca.pem, cert.pem, key.pem,
  // governance.p7s, permissions.p7s; scripts/make-test-pki makes TEST ones). Empty: no security.
  // When set, the client authenticates, its samples are encrypted as the governance says, and its
  // endpoints live in the DDS partition named vehicle_id (which its permissions must grant), so
  // vehicle_id may not contain * ? [ ] or \. The service must run with security too
  // (dds.security_dir). README, "DDS Security".
  std::string security_dir;
  // An unanswered request is re-sent every resend_period (> 0), for at most resend_window after
  // send() (>= 0; zero: never re-sent). See "Re-sending and a lost service" above.
  std::chrono::milliseconds resend_period{1000};
  std::chrono::milliseconds resend_window{10000};
  // The vehicle this client plans for, put into every request that names none of its own
  // (PullOutRequest::vehicle_profile, ::vehicle): a profile of the service's config ("bus"), or
  // its own dimensions, or neither (the service's configured vehicle). The service checks them; a
  // bad one is rejected naming the field ("vehicle_profile: unknown profile ...").
  std::string vehicle_profile;
  std::optional<VehicleInfo> vehicle;
};

// A DDS participant shared by many Clients (see "Many vehicles on one participant" above).
struct ClientParticipantOptions {
  // DDS domain, 0..232. The service must use the same domain.
  int domain_id{0};
  // Fast DDS XML profiles file. Empty: built-in loopback-only defaults (see "DDS setup" above).
  std::string profiles_file;
  // Participant profile in profiles_file (ignored when profiles_file is empty).
  std::string participant_profile{"pullout_participant"};
  // true: the Clients share one request writer, one progress writer and one path and one status
  // reader (see "Many vehicles on one participant" above). false: each Client has endpoints of its
  // own, as before (the comparison in bench_load --endpoints-per-client).
  bool shared_endpoints{true};
};

namespace client_detail {
class SharedParticipant;
}  // namespace client_detail

// The client's view of the service (see "Re-sending and a lost service" above).
enum class ServiceState {
  kNotFound,   // never matched since the client was created
  kConnected,  // every endpoint matched with the service
  kLost,       // was connected, then an endpoint lost its match (lease expired, or service stopped)
};

// A DDS failure: the participant, a topic or an endpoint could not be created, a profiles file
// could not be loaded, or a sample could not be written.
class PULLOUT_CLIENT_EXPORT ClientError : public std::runtime_error {
 public:
  explicit ClientError(const std::string& what);
};

class PULLOUT_CLIENT_EXPORT ClientParticipant {
 public:
  // Creates the participant and the topics. Throws std::invalid_argument for a bad domain_id and
  // ClientError when DDS cannot be set up (the message names what failed).
  explicit ClientParticipant(ClientParticipantOptions options);
  ~ClientParticipant();

  ClientParticipant(const ClientParticipant&) = delete;
  ClientParticipant& operator=(const ClientParticipant&) = delete;
  ClientParticipant(ClientParticipant&&) = delete;
  ClientParticipant& operator=(ClientParticipant&&) = delete;

  int domain_id() const;
  // Clients alive on this participant.
  std::size_t client_count() const;

 private:
  friend class Client;
  std::shared_ptr<client_detail::SharedParticipant> shared_;
};

class PULLOUT_CLIENT_EXPORT Client {
 public:
  using PathCallback = std::function<void(const PullOutPath&)>;
  using StatusCallback = std::function<void(const PullOutStatus&)>;
  using StatusPredicate = std::function<bool(const PullOutStatus&)>;
  using Duration = std::chrono::nanoseconds;

  // Creates the participant, topics, readers and writers. Does not wait for the service (see
  // wait_for_service). Throws std::invalid_argument for a bad vehicle_id or domain_id or a
  // security_dir that lacks a credential, and ClientError when DDS cannot be set up (the message
  // names what failed).
  explicit Client(ClientOptions options);
  // A client on a shared participant (see "Many vehicles on one participant" above): creates this
  // vehicle's readers and writers on it. Throws as above, and std::invalid_argument when the
  // participant already has a Client for options.vehicle_id or options.security_dir is set.
  Client(ClientParticipant& participant, ClientOptions options);
  ~Client();

  Client(const Client&) = delete;
  Client& operator=(const Client&) = delete;
  Client(Client&&) = delete;
  Client& operator=(Client&&) = delete;

  // Publishes a request and makes it the current request. Overwrites request.vehicle_id with this
  // client's vehicle, request.request_id with a fresh id and request.stamp_ns with the system
  // clock. Ids are strictly increasing within a client and seeded from the system clock [ns], so
  // they stay unique (and increasing) across client restarts as long as the clock does not step
  // back. Returns the id. Does not wait for the service: the topic is volatile, so a request sent
  // before the service is matched reaches it only by being re-sent (within resend_window; call
  // wait_for_service first when resending is off). Throws ClientError when the sample cannot be
  // written (e.g. it exceeds the transport's maximum size); a failed re-send is only logged.
  std::uint64_t send(PullOutRequest request);

  // Publishes the vehicle's progress. Overwrites progress.vehicle_id; a request_id of 0 becomes
  // current_request_id(), a stamp_ns of 0 the system clock. Throws std::logic_error when
  // request_id is 0 and there is no current request, ClientError when the write fails.
  void report_progress(ExecutionProgress progress);

  // Registers the callback for paths (resp. statuses) of this vehicle, replacing the previous one;
  // an empty function unregisters. If a path (status) was already received, the new callback is
  // first invoked once with the latest one, then with every later one. Invoked on the client's
  // thread. When on_path returns (called from any other thread), the previous callback is not
  // running and will not be invoked again: on_path blocks while it runs (on_status only waits for
  // a status callback, on_path only for a path callback). Called from inside a callback, it does
  // not block and takes effect for the next delivery.
  void on_path(PathCallback callback);
  void on_status(StatusCallback callback);

  // Blocks until the path for request_id has been received or the timeout expires. Returns at
  // once if it is among the recently received paths (the last 16). std::nullopt on timeout, and
  // before it when the service is lost and request_id will not be re-sent (see above).
  std::optional<PullOutPath> wait_for_path(std::uint64_t request_id, Duration timeout) const;

  // Blocks until a status for request_id satisfies predicate (an empty predicate accepts any),
  // considering the latest status already received for that request, then each later one. The
  // predicate runs on the calling thread with an internal lock held: keep it a cheap, pure test.
  // std::nullopt on timeout, and before it when the service is lost and request_id will not be
  // re-sent; a planning status received before a loss is not considered. Note: the status reader
  // keeps the last status of the vehicle only,
  // so short-lived intermediate states may be skipped; wait for the state you need, not for a
  // transition.
  std::optional<PullOutStatus> wait_for_status(std::uint64_t request_id, const StatusPredicate& predicate,
                                               Duration timeout) const;

  // The latest path / status received for this vehicle (whatever request it answers).
  // latest_status() is std::nullopt (until the next status arrives) when the latest one says
  // planning and the service was lost after it came: that search will never finish.
  std::optional<PullOutPath> latest_path() const;
  std::optional<PullOutStatus> latest_status() const;

  // Whether the service is connected, lost, or was never found. Changes on the client's thread as
  // DDS reports matches (a killed service: after its participant lease, see above).
  ServiceState service_state() const;

  // The request this client follows: the id returned by the last send(), or, before the first
  // send(), the request of the latest path received (a restarted client adopts it). 0 when none.
  std::uint64_t current_request_id() const;

  // current_path_idx of the latest status for the current request, when that status says a path
  // is being executed or completed; std::nullopt otherwise (no status yet, planning, rejected, no
  // path).
  std::optional<std::uint32_t> current_segment() const;

  // Blocks until the request and progress writers and the path and status readers are each matched with a
  // service endpoint, or the timeout expires. Returns whether they are. Discovery on loopback
  // usually takes tens of milliseconds but can take a few seconds (lost announcements are repeated
  // periodically): allow several seconds.
  bool wait_for_service(Duration timeout) const;
  // As wait_for_service, and until at least `count` services (replicas) read this client's
  // requests (matched_services() >= count): a request sent before a replica has matched never
  // reaches it. Returns whether both hold. count 0 or 1 is wait_for_service.
  bool wait_for_services(std::size_t count, Duration timeout) const;
  // How many services (each replica counts) read this client's requests now: the request
  // writer's matched readers. A request sent while a replica is not among them never reaches
  // that replica (the request topic is volatile).
  std::size_t matched_services() const;

  const std::string& vehicle_id() const;
  int domain_id() const;

 private:
  class Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace pullout
