#include "service_process.hpp"

#include <dirent.h>
#include <fcntl.h>
#include <signal.h>
#include <sys/file.h>
#include <sys/prctl.h>
#include <sys/stat.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cerrno>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <stdexcept>
#include <thread>

#include "pullout/client/client.hpp"

namespace pullout::integration {

namespace {

constexpr Millis kPollPeriod{10};
constexpr Millis kProbePeriod{100};
constexpr const char* kShmDir = "/dev/shm";

std::runtime_error system_error(const std::string& what) {
  return std::runtime_error(what + ": " + std::strerror(errno));
}

std::string signal_name(int sig) {
  const char* name = ::strsignal(sig);
  return "signal " + std::to_string(sig) + (name != nullptr ? std::string(" (") + name + ")" : std::string());
}

}  // namespace

// ------------------------------------------------------------------------------------------------
// ExitResult

std::string ExitResult::describe() const {
  std::ostringstream os;
  if (exited) {
    os << "exited with status " << exit_code;
    if (exit_code == kSanitizerExitCode) os << " (a sanitizer report: see its stderr)";
  } else if (signal != 0) {
    os << "killed by " << signal_name(signal);
  } else {
    os << "not exited";
  }
  if (force_killed) os << " (did not stop within the timeout: SIGKILL sent)";
  return os.str();
}

// ------------------------------------------------------------------------------------------------
// ChildProcess

ChildProcess::ChildProcess(const std::vector<std::string>& argv, const std::string& stdout_path,
                           const std::string& stderr_path) {
  if (argv.empty()) throw std::invalid_argument("ChildProcess: empty argv");
  // Everything the child needs is prepared before fork(): between fork and exec a multi-threaded
  // process may only make async-signal-safe calls.
  std::vector<std::string> args = argv;
  std::vector<char*> c_argv;
  c_argv.reserve(args.size() + 1);
  for (auto& a : args) c_argv.push_back(a.data());
  c_argv.push_back(nullptr);
  const int out_fd = ::open(stdout_path.c_str(), O_WRONLY | O_CREAT | O_TRUNC | O_CLOEXEC, 0644);
  if (out_fd < 0) throw system_error("cannot open " + stdout_path);
  const int err_fd = ::open(stderr_path.c_str(), O_WRONLY | O_CREAT | O_TRUNC | O_CLOEXEC, 0644);
  if (err_fd < 0) {
    ::close(out_fd);
    throw system_error("cannot open " + stderr_path);
  }
  const pid_t parent = ::getpid();

  const pid_t pid = ::fork();
  if (pid == 0) {
    // Child. Dies with the parent (e.g. a test killed by the ctest timeout).
    ::prctl(PR_SET_PDEATHSIG, SIGTERM);
    if (::getppid() != parent) ::_exit(127);
    sigset_t none;
    sigemptyset(&none);
    ::sigprocmask(SIG_SETMASK, &none, nullptr);
    ::dup2(out_fd, STDOUT_FILENO);
    ::dup2(err_fd, STDERR_FILENO);
    const int null_fd = ::open("/dev/null", O_RDONLY);
    if (null_fd >= 0) ::dup2(null_fd, STDIN_FILENO);
    // Nothing else of the parent's (its DDS sockets above all) may live on in the child.
    ::close_range(3, ~0U, 0);
    ::execv(c_argv[0], c_argv.data());
    static const char kExecFailed[] = "ChildProcess: execv failed\n";
    (void)!::write(STDERR_FILENO, kExecFailed, sizeof(kExecFailed) - 1);
    ::_exit(127);
  }
  ::close(out_fd);
  ::close(err_fd);
  if (pid < 0) throw system_error("fork");
  pid_ = pid;
}

ChildProcess::~ChildProcess() {
  try {
    stop(kDefaultStopTimeout);
  } catch (...) {
    // Never throw from a destructor; stop() itself does not throw.
  }
}

bool ChildProcess::try_reap() {
  if (result_) return true;
  int status = 0;
  const pid_t r = ::waitpid(pid_, &status, WNOHANG);
  if (r == 0) return false;
  ExitResult res;
  if (r == pid_) {
    if (WIFEXITED(status)) {
      res.exited = true;
      res.exit_code = WEXITSTATUS(status);
    } else if (WIFSIGNALED(status)) {
      res.signal = WTERMSIG(status);
    }
  }
  // r < 0 (ECHILD): someone else reaped it; report "not exited" rather than block forever.
  result_ = res;
  return true;
}

bool ChildProcess::running() { return !try_reap(); }

std::optional<ExitResult> ChildProcess::wait_exit(Millis timeout) {
  const auto deadline = std::chrono::steady_clock::now() + timeout;
  while (!try_reap()) {
    if (std::chrono::steady_clock::now() >= deadline) return std::nullopt;
    std::this_thread::sleep_for(kPollPeriod);
  }
  return result_;
}

ExitResult ChildProcess::stop(Millis timeout) {
  if (try_reap()) return *result_;
  ::kill(pid_, SIGTERM);
  if (auto r = wait_exit(timeout)) return *r;
  ::kill(pid_, SIGKILL);
  int status = 0;
  ExitResult res;
  if (::waitpid(pid_, &status, 0) == pid_ && WIFSIGNALED(status)) res.signal = WTERMSIG(status);
  res.force_killed = true;
  result_ = res;
  return res;
}

// ------------------------------------------------------------------------------------------------
// DomainLease

DomainLease::DomainLease(int first, int last) {
  if (first < 0 || last > 232 || first > last) throw std::invalid_argument("DomainLease: bad domain range");
  const int count = last - first + 1;
  const int offset = static_cast<int>(::getpid() % count);
  for (int i = 0; i < count; ++i) {
    const int domain = first + (offset + i) % count;
    const std::string lock_path = "/tmp/pullout-dds-domain-" + std::to_string(domain) + ".lock";
    const int fd = ::open(lock_path.c_str(), O_RDWR | O_CREAT | O_CLOEXEC, 0666);
    if (fd < 0) continue;
    if (::flock(fd, LOCK_EX | LOCK_NB) == 0) {
      domain_ = domain;
      fd_ = fd;
      return;
    }
    ::close(fd);
  }
  throw std::runtime_error("DomainLease: every DDS domain in [" + std::to_string(first) + ", " + std::to_string(last) +
                           "] is in use");
}

DomainLease::~DomainLease() {
  // The lock file stays (removing it would race with another process locking it); closing the
  // descriptor releases the lock.
  if (fd_ >= 0) ::close(fd_);
}

// ------------------------------------------------------------------------------------------------
// TempDir

TempDir::TempDir() {
  std::string templ = "/tmp/pullout-test-XXXXXX";
  if (::mkdtemp(templ.data()) == nullptr) throw system_error("mkdtemp");
  path_ = templ;
}

TempDir::~TempDir() {
  std::error_code ec;
  std::filesystem::remove_all(path_, ec);
}

std::string TempDir::write_file(const std::string& name, const std::string& text) const {
  std::string file = path_ + "/" + name;
  std::ofstream out(file, std::ios::trunc);
  out << text;
  out.close();
  if (!out) throw std::runtime_error("cannot write " + file);
  return file;
}

// ------------------------------------------------------------------------------------------------
// /dev/shm

std::set<std::string> list_dev_shm() {
  std::set<std::string> names;
  std::error_code ec;
  for (const auto& entry : std::filesystem::directory_iterator(kShmDir, ec)) {
    names.insert(entry.path().filename().string());
  }
  return names;
}

std::set<std::string> dev_shm_files_in_use() {
  std::set<std::string> names;
  const std::string prefix = std::string(kShmDir) + "/";
  const auto note = [&](const std::string& target) {
    if (target.compare(0, prefix.size(), prefix) != 0) return;
    std::string name = target.substr(prefix.size());
    const auto deleted = name.find(" (deleted)");
    if (deleted != std::string::npos) name.erase(deleted);
    names.insert(name);
  };
  std::error_code ec;
  for (const auto& proc : std::filesystem::directory_iterator("/proc", ec)) {
    const std::string pid = proc.path().filename().string();
    if (pid.empty() || pid.find_first_not_of("0123456789") != std::string::npos) continue;
    std::error_code fd_ec;
    for (const auto& fd : std::filesystem::directory_iterator(proc.path() / "fd", fd_ec)) {
      std::error_code link_ec;
      const auto target = std::filesystem::read_symlink(fd.path(), link_ec);
      if (!link_ec) note(target.string());
    }
    std::ifstream maps(proc.path() / "maps");
    std::string line;
    while (std::getline(maps, line)) {
      const auto at = line.find(prefix);
      if (at != std::string::npos) note(line.substr(at));
    }
  }
  return names;
}

std::string read_file_tail(const std::string& path, std::size_t max_bytes) {
  std::ifstream in(path, std::ios::binary);
  if (!in) return "";
  std::ostringstream os;
  os << in.rdbuf();
  std::string text = os.str();
  if (text.size() > max_bytes) text = "..." + text.substr(text.size() - max_bytes);
  return text;
}

// ------------------------------------------------------------------------------------------------
// ServiceProcess

std::string StopReport::describe() const {
  std::ostringstream os;
  os << "service " << exit.describe();
  if (!leaked_shm_files.empty()) {
    os << "; left in /dev/shm:";
    for (const auto& f : leaked_shm_files) os << " " << f;
  }
  return os.str();
}

ServiceProcess::ServiceProcess(ServiceOptions options) : options_(std::move(options)) {
  if (options_.domain < 0) {
    lease_.emplace();
    domain_ = lease_->domain();
  } else {
    domain_ = options_.domain;
  }
  shm_before_ = list_dev_shm();
  child_.emplace(std::vector<std::string>{options_.executable, "--config", options_.config_path, "--domain",
                                          std::to_string(domain_), "--log-level", options_.log_level},
                 dir_.path() + "/service.stdout", dir_.path() + "/service.stderr");

  // Ready = a client on the same domain matches the service's request reader and its path and
  // status writers. Polled in short slices so that a service that exits is noticed at once.
  const auto fail = [&](const std::string& why) {
    const ExitResult exit = child_->stop(options_.stop_timeout);
    report_ = StopReport{exit, {}};
    return std::runtime_error("pullout_service (domain " + std::to_string(domain_) + ") " + why + "; " +
                              exit.describe() + "; stderr:\n" + stderr_tail());
  };
  const auto deadline = std::chrono::steady_clock::now() + options_.ready_timeout;
  try {
    ClientOptions probe_options;
    probe_options.vehicle_id =
        options_.probe_vehicle_id.empty() ? "readiness-probe-" + std::to_string(::getpid()) : options_.probe_vehicle_id;
    probe_options.domain_id = domain_;
    probe_options.security_dir = options_.probe_security_dir;
    Client probe(probe_options);
    while (!probe.wait_for_service(kProbePeriod)) {
      if (!child_->running()) throw fail("exited before it was ready");
      if (std::chrono::steady_clock::now() >= deadline) {
        throw fail("not ready after " + std::to_string(options_.ready_timeout.count()) + " ms");
      }
    }
  } catch (const ClientError& e) {
    throw fail(std::string("readiness probe failed: ") + e.what());
  }
}

ServiceProcess::~ServiceProcess() {
  try {
    stop();
  } catch (...) {
    // Never throw from a destructor.
  }
}

StopReport ServiceProcess::stop() {
  if (report_) return *report_;
  StopReport report;
  report.exit = child_->stop(options_.stop_timeout);
  // A file that appeared while the service ran and that no live process holds was left by it
  // (or by a process that crashed meanwhile, which the message would then show).
  const std::set<std::string> after = list_dev_shm();
  std::set<std::string> in_use;
  bool scanned = false;
  for (const auto& name : after) {
    if (shm_before_.count(name) != 0) continue;
    if (!scanned) {
      in_use = dev_shm_files_in_use();
      scanned = true;
    }
    if (in_use.count(name) == 0) report.leaked_shm_files.push_back(name);
  }
  report_ = report;
  return report;
}

std::string ServiceProcess::stderr_tail(std::size_t max_bytes) const {
  return read_file_tail(dir_.path() + "/service.stderr", max_bytes);
}

}  // namespace pullout::integration
