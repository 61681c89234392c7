// Test and benchmark harness: the real pullout_service (or any helper executable) as a child
// process, owned by its PID.
//
//   ChildProcess   fork/exec with stdout/stderr redirected to files; stop() sends SIGTERM, waits,
//                  then SIGKILL after a timeout; the destructor always stops and reaps the child.
//   DomainLease    an exclusive DDS domain id for this process, so that test binaries run in
//                  parallel by ctest (and benchmarks) never share a domain.
//   ServiceProcess pullout_service on a leased domain: started, then ready when a probe
//                  pullout::Client matches its endpoints (Client::wait_for_service); stop()
//                  reports the exit status and any /dev/shm file the service left behind.
//
// Every wait is bounded. Nothing here reads the service's log to decide anything; the stderr
// file is only shown in failure messages (and checked by the bad-config test, whose contract is
// the error text on stderr).
#pragma once

#include <sys/types.h>

#include <chrono>
#include <optional>
#include <set>
#include <string>
#include <vector>

namespace pullout::integration {

using Millis = std::chrono::milliseconds;

// The exit status of a process that a sanitizer stopped (ASAN_OPTIONS and UBSAN_OPTIONS exitcode,
// set by scripts/test-sanitize): no pullout program exits with it, so a report is never taken for
// an expected failure (a bad config exits with 1, as do the sanitizers by default).
constexpr int kSanitizerExitCode = 66;

// How a child ended.
struct ExitResult {
  bool exited{false};  // normal exit: exit_code is valid
  int exit_code{-1};
  int signal{0};             // killed by this signal (exited == false)
  bool force_killed{false};  // did not stop within the timeout and was sent SIGKILL

  bool clean() const { return exited && exit_code == 0 && !force_killed; }
  std::string describe() const;
};

class ChildProcess {
 public:
  // Starts argv[0] (a path, not looked up in PATH) with argv. stdout and stderr go to the given
  // files (truncated). The child gets SIGTERM if the thread that started it dies first
  // (PR_SET_PDEATHSIG), so a crashed or timed-out test does not leave it running: start children
  // from a thread that outlives them (the main thread). Throws std::runtime_error.
  ChildProcess(const std::vector<std::string>& argv, const std::string& stdout_path, const std::string& stderr_path);
  ~ChildProcess();  // stop(kDefaultStopTimeout) if still running; never throws
  ChildProcess(const ChildProcess&) = delete;
  ChildProcess& operator=(const ChildProcess&) = delete;

  static constexpr Millis kDefaultStopTimeout{10000};

  pid_t pid() const { return pid_; }
  // True while the child has not exited (reaps it if it has).
  bool running();
  // Waits up to `timeout` for the child to exit on its own.
  std::optional<ExitResult> wait_exit(Millis timeout);
  // SIGTERM, wait up to `timeout`, then SIGKILL and reap. Idempotent: returns the first result.
  ExitResult stop(Millis timeout = kDefaultStopTimeout);

 private:
  bool try_reap();
  pid_t pid_{-1};
  std::optional<ExitResult> result_;
};

// An exclusive DDS domain: a lock file per domain under /tmp, held (flock) for the lease's
// lifetime and released by the kernel if the process dies. The search starts at an offset taken
// from the PID. Throws std::runtime_error when every domain in [first, last] is taken.
class DomainLease {
 public:
  // The default range stays away from domain 0 (a developer's service) and from the domains the
  // unit tests pick without a lease (tests/service: 100..199, tests/client: 150..229).
  static constexpr int kFirstDomain = 1;
  static constexpr int kLastDomain = 99;

  explicit DomainLease(int first = kFirstDomain, int last = kLastDomain);
  ~DomainLease();
  DomainLease(const DomainLease&) = delete;
  DomainLease& operator=(const DomainLease&) = delete;

  int domain() const { return domain_; }

 private:
  int domain_{-1};
  int fd_{-1};
};

// A scratch directory (mkdtemp under /tmp), removed with everything in it on destruction.
class TempDir {
 public:
  TempDir();
  ~TempDir();
  TempDir(const TempDir&) = delete;
  TempDir& operator=(const TempDir&) = delete;

  const std::string& path() const { return path_; }
  // Writes `text` to path()/name and returns the full path. Throws std::runtime_error.
  std::string write_file(const std::string& name, const std::string& text) const;

 private:
  std::string path_;
};

struct ServiceOptions {
  std::string executable;   // the pullout_service binary
  std::string config_path;  // --config
  int domain{-1};           // --domain; -1: lease one
  std::string log_level{"warn"};
  Millis ready_timeout{20000};
  Millis stop_timeout{10000};
  // A secure service (dds.security_dir in the config) is probed by a vehicle with credentials:
  // its credentials directory and its vehicle id (empty: a plain probe with a made-up id).
  std::string probe_security_dir;
  std::string probe_vehicle_id;
};

struct StopReport {
  ExitResult exit;
  std::vector<std::string> leaked_shm_files;  // new in /dev/shm and held by no live process

  bool clean() const { return exit.clean() && leaked_shm_files.empty(); }
  std::string describe() const;
};

class ServiceProcess {
 public:
  // Starts the service and waits until a probe client matches it. Throws std::runtime_error
  // (with the service's exit status and the end of its stderr) when it exits or does not become
  // ready within options.ready_timeout.
  explicit ServiceProcess(ServiceOptions options);
  ~ServiceProcess();  // stops the service if stop() was not called; never throws
  ServiceProcess(const ServiceProcess&) = delete;
  ServiceProcess& operator=(const ServiceProcess&) = delete;

  int domain() const { return domain_; }
  pid_t pid() const { return child_->pid(); }
  bool running() { return child_->running(); }

  // SIGTERM and wait (SIGKILL after options.stop_timeout); then the /dev/shm check. Idempotent.
  StopReport stop();

  // The service's stderr so far (for failure messages), at most the last `max_bytes`.
  std::string stderr_tail(std::size_t max_bytes = 4000) const;

 private:
  ServiceOptions options_;
  std::optional<DomainLease> lease_;
  int domain_{-1};
  TempDir dir_;
  std::set<std::string> shm_before_;
  std::optional<ChildProcess> child_;
  std::optional<StopReport> report_;
};

// Names of the files in /dev/shm.
std::set<std::string> list_dev_shm();
// Names of /dev/shm files some live process has open or mapped (scans /proc).
std::set<std::string> dev_shm_files_in_use();
// The last `max_bytes` of a file ("" if it cannot be read).
std::string read_file_tail(const std::string& path, std::size_t max_bytes);

}  // namespace pullout::integration
