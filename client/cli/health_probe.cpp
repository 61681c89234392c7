#include "health_probe.hpp"

#include <fcntl.h>
#include <netdb.h>
#include <poll.h>
#include <sys/socket.h>
#include <unistd.h>

#include <cerrno>
#include <chrono>
#include <cstring>
#include <memory>

#include "commands.hpp"

namespace pullout::cli {
namespace {

using Clock = std::chrono::steady_clock;

// Enough for any status line and headers a health endpoint sends; the body is not needed.
constexpr std::size_t kMaxReplyBytes = 16 * 1024;

class Fd {
 public:
  explicit Fd(int fd) : fd_(fd) {}
  ~Fd() {
    if (fd_ >= 0) ::close(fd_);
  }
  Fd(const Fd&) = delete;
  Fd& operator=(const Fd&) = delete;
  int get() const { return fd_; }

 private:
  int fd_;
};

int remaining_ms(Clock::time_point deadline) {
  const auto left = std::chrono::duration_cast<std::chrono::milliseconds>(deadline - Clock::now()).count();
  return left > 0 ? static_cast<int>(left) : 0;
}

// Waits until `fd` is ready for `events`; false on timeout or error.
bool wait_ready(int fd, short events, Clock::time_point deadline) {
  while (true) {
    pollfd p{fd, events, 0};
    const int ms = remaining_ms(deadline);
    if (ms == 0) return false;
    const int n = ::poll(&p, 1, ms);
    if (n > 0) return true;
    if (n == 0) return false;
    if (errno != EINTR) return false;
  }
}

// A connected non-blocking socket to one of the addresses, or -1 (`error` set).
int connect_any(const addrinfo* list, Clock::time_point deadline, std::string& error) {
  error = "no address";
  for (const addrinfo* ai = list; ai != nullptr; ai = ai->ai_next) {
    const int fd = ::socket(ai->ai_family, ai->ai_socktype | SOCK_NONBLOCK | SOCK_CLOEXEC, ai->ai_protocol);
    if (fd < 0) {
      error = std::strerror(errno);
      continue;
    }
    if (::connect(fd, ai->ai_addr, ai->ai_addrlen) == 0) return fd;
    if (errno == EINPROGRESS && wait_ready(fd, POLLOUT, deadline)) {
      int so_error = 0;
      socklen_t len = sizeof so_error;
      if (::getsockopt(fd, SOL_SOCKET, SO_ERROR, &so_error, &len) == 0 && so_error == 0) return fd;
      error = std::strerror(so_error != 0 ? so_error : errno);
    } else {
      error = errno == EINPROGRESS ? "connect timed out" : std::strerror(errno);
    }
    ::close(fd);
  }
  return -1;
}

bool send_all(int fd, const std::string& data, Clock::time_point deadline) {
  std::size_t sent = 0;
  while (sent < data.size()) {
    const ssize_t n = ::send(fd, data.data() + sent, data.size() - sent, MSG_NOSIGNAL);
    if (n > 0) {
      sent += static_cast<std::size_t>(n);
    } else if (n < 0 && (errno == EAGAIN || errno == EINTR)) {
      if (!wait_ready(fd, POLLOUT, deadline)) return false;
    } else {
      return false;
    }
  }
  return true;
}

// Reads until the status line is complete, the peer closes, or the deadline.
std::string read_status_line(int fd, Clock::time_point deadline) {
  std::string reply;
  char buf[1024];
  while (reply.size() < kMaxReplyBytes && reply.find("\r\n") == std::string::npos) {
    const ssize_t n = ::recv(fd, buf, sizeof buf, 0);
    if (n > 0) {
      reply.append(buf, static_cast<std::size_t>(n));
    } else if (n == 0) {
      break;
    } else if (errno == EAGAIN || errno == EINTR) {
      if (!wait_ready(fd, POLLIN, deadline)) break;
    } else {
      break;
    }
  }
  const auto eol = reply.find("\r\n");
  return eol == std::string::npos ? std::string() : reply.substr(0, eol);
}

}  // namespace

bool parse_http_url(const std::string& url, HttpUrl& parsed, std::string& error) {
  constexpr const char* kScheme = "http://";
  if (url.compare(0, std::strlen(kScheme), kScheme) != 0) {
    error = "only http:// URLs are supported";
    return false;
  }
  const std::string rest = url.substr(std::strlen(kScheme));
  const auto slash = rest.find('/');
  const std::string authority = rest.substr(0, slash);
  parsed.path = slash == std::string::npos ? "/" : rest.substr(slash);
  std::string host = authority;
  if (!authority.empty() && authority.front() == '[') {  // [IPv6]:port
    const auto close = authority.find(']');
    if (close == std::string::npos) {
      error = "unterminated [ in host";
      return false;
    }
    host = authority.substr(1, close - 1);
    const std::string after = authority.substr(close + 1);
    if (!after.empty()) {
      if (after.front() != ':') {
        error = "unexpected text after ]";
        return false;
      }
      parsed.port = after.substr(1);
    }
  } else if (const auto colon = authority.rfind(':'); colon != std::string::npos) {
    host = authority.substr(0, colon);
    parsed.port = authority.substr(colon + 1);
  }
  if (host.empty()) {
    error = "no host";
    return false;
  }
  if (authority.find('@') != std::string::npos) {
    error = "user information is not supported";
    return false;
  }
  if (parsed.port.empty() || parsed.port.size() > 5 ||
      parsed.port.find_first_not_of("0123456789") != std::string::npos || std::stoi(parsed.port) < 1 ||
      std::stoi(parsed.port) > 65535) {
    error = "port must be a number in [1, 65535]";
    return false;
  }
  for (const char c : parsed.path) {
    if (c == ' ' || c == '\r' || c == '\n' || c == '#') {
      error = "the path contains a space, a line break or a fragment";
      return false;
    }
  }
  parsed.host = host;
  return true;
}

int run_health(const HealthOptions& options, std::ostream& out, std::ostream& err) {
  HttpUrl url;
  std::string error;
  if (!parse_http_url(options.url, url, error)) {
    err << "pullout health: " << options.url << ": " << error << '\n';
    return kExitBadInput;
  }
  const auto deadline =
      Clock::now() + std::chrono::duration_cast<Clock::duration>(std::chrono::duration<double>(options.timeout_s));

  addrinfo hints{};
  hints.ai_family = AF_UNSPEC;
  hints.ai_socktype = SOCK_STREAM;
  addrinfo* found = nullptr;
  if (const int rc = ::getaddrinfo(url.host.c_str(), url.port.c_str(), &hints, &found); rc != 0) {
    err << "pullout health: cannot resolve " << url.host << ": " << ::gai_strerror(rc) << '\n';
    return kExitCommunication;
  }
  const std::unique_ptr<addrinfo, void (*)(addrinfo*)> addresses(found, ::freeaddrinfo);
  Fd fd(connect_any(addresses.get(), deadline, error));
  if (fd.get() < 0) {
    err << "pullout health: cannot connect to " << url.host << ':' << url.port << ": " << error << '\n';
    return kExitCommunication;
  }
  const std::string host_header = url.host.find(':') != std::string::npos ? "[" + url.host + "]" : url.host;
  const std::string request = "GET " + url.path + " HTTP/1.0\r\nHost: " + host_header + ':' + url.port +
                              "\r\nUser-Agent: pullout-health\r\nConnection: close\r\n\r\n";
  if (!send_all(fd.get(), request, deadline)) {
    err << "pullout health: cannot send the request to " << options.url << '\n';
    return kExitCommunication;
  }
  const std::string status_line = read_status_line(fd.get(), deadline);
  // "HTTP/1.x NNN reason"
  if (status_line.compare(0, 5, "HTTP/") != 0 || status_line.find(' ') == std::string::npos) {
    err << "pullout health: no HTTP status line from " << options.url
        << (remaining_ms(deadline) == 0 ? " (timed out)" : "") << '\n';
    return kExitCommunication;
  }
  const std::string code = status_line.substr(status_line.find(' ') + 1, 3);
  if (!options.quiet) out << options.url << ": " << status_line << '\n';
  return code == "200" ? kExitHealthy : kExitUnhealthy;
}

}  // namespace pullout::cli
