// `pullout health URL`: URL parsing and the probe against small servers in the test (a status
// other than 200, a server that never answers, a refused connection). The probe against the real
// service is in tests/integration/test_observability.cpp.
#include <arpa/inet.h>
#include <netinet/in.h>
#include <sys/socket.h>
#include <unistd.h>

#include <chrono>
#include <sstream>
#include <string>
#include <thread>

#include <gtest/gtest.h>

#include "commands.hpp"
#include "health_probe.hpp"

namespace pullout::cli {
namespace {

TEST(ParseHttpUrl, HostPortPath) {
  HttpUrl u;
  std::string error;
  ASSERT_TRUE(parse_http_url("http://127.0.0.1:9464/readyz", u, error)) << error;
  EXPECT_EQ(u.host, "127.0.0.1");
  EXPECT_EQ(u.port, "9464");
  EXPECT_EQ(u.path, "/readyz");
  ASSERT_TRUE(parse_http_url("http://localhost", u, error)) << error;
  EXPECT_EQ(u.host, "localhost");
  EXPECT_EQ(u.port, "80");
  EXPECT_EQ(u.path, "/");
  ASSERT_TRUE(parse_http_url("http://[::1]:8080/healthz?x=1", u, error)) << error;
  EXPECT_EQ(u.host, "::1");
  EXPECT_EQ(u.port, "8080");
  EXPECT_EQ(u.path, "/healthz?x=1");
}

TEST(ParseHttpUrl, RefusesWhatItCannotDo) {
  HttpUrl u;
  std::string error;
  for (const char* bad : {"https://127.0.0.1/", "127.0.0.1:9464/readyz", "http://:80/", "http://h:0/",
                          "http://h:65536/", "http://h:12a/", "http://user@h/", "http://h/a b", "http://[::1/"}) {
    EXPECT_FALSE(parse_http_url(bad, u, error)) << bad;
    EXPECT_FALSE(error.empty()) << bad;
  }
}

// A listening socket on 127.0.0.1 (port chosen by the kernel).
class Listener {
 public:
  Listener() {
    fd_ = ::socket(AF_INET, SOCK_STREAM, 0);
    sockaddr_in addr{};
    addr.sin_family = AF_INET;
    addr.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
    socklen_t len = sizeof addr;
    if (fd_ < 0 || ::bind(fd_, reinterpret_cast<sockaddr*>(&addr), sizeof addr) != 0 || ::listen(fd_, 4) != 0 ||
        ::getsockname(fd_, reinterpret_cast<sockaddr*>(&addr), &len) != 0) {
      throw std::runtime_error("cannot listen on 127.0.0.1");
    }
    port_ = ntohs(addr.sin_port);
  }
  ~Listener() { ::close(fd_); }
  Listener(const Listener&) = delete;
  Listener& operator=(const Listener&) = delete;
  int fd() const { return fd_; }
  std::string url(const std::string& path) const { return "http://127.0.0.1:" + std::to_string(port_) + path; }

 private:
  int fd_{-1};
  int port_{0};
};

TEST(HealthProbe, AnswersOtherThan200AreUnhealthy) {
  Listener server;
  std::string received;
  std::thread serve([&] {
    const int conn = ::accept(server.fd(), nullptr, nullptr);
    char buf[1024];
    const ssize_t n = ::recv(conn, buf, sizeof buf, 0);
    if (n > 0) received.assign(buf, static_cast<std::size_t>(n));
    const std::string reply = "HTTP/1.1 503 Service Unavailable\r\nContent-Length: 10\r\n\r\nnot ready\n";
    ::send(conn, reply.data(), reply.size(), MSG_NOSIGNAL);
    ::close(conn);
  });
  std::ostringstream out, err;
  HealthOptions options;
  options.url = server.url("/readyz");
  EXPECT_EQ(run_health(options, out, err), kExitUnhealthy) << err.str();
  serve.join();
  EXPECT_EQ(received.rfind("GET /readyz HTTP/1.0\r\n", 0), 0u) << received;
  EXPECT_NE(out.str().find("503"), std::string::npos) << out.str();
}

TEST(HealthProbe, A200IsHealthy) {
  Listener server;
  std::thread serve([&] {
    const int conn = ::accept(server.fd(), nullptr, nullptr);
    char buf[1024];
    (void)::recv(conn, buf, sizeof buf, 0);
    const std::string reply = "HTTP/1.0 200 OK\r\n\r\nok\n";
    ::send(conn, reply.data(), reply.size(), MSG_NOSIGNAL);
    ::close(conn);
  });
  std::ostringstream out, err;
  HealthOptions options;
  options.url = server.url("/healthz");
  EXPECT_EQ(run_health(options, out, err), kExitHealthy) << err.str();
  serve.join();
}

TEST(HealthProbe, AServerThatNeverAnswersTimesOut) {
  Listener server;  // the kernel accepts the connection; nobody ever reads or writes
  std::ostringstream out, err;
  HealthOptions options;
  options.url = server.url("/readyz");
  options.timeout_s = 0.5;
  const auto t0 = std::chrono::steady_clock::now();
  EXPECT_EQ(run_health(options, out, err), kExitCommunication);
  const double s = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  EXPECT_LT(s, 5.0) << "the timeout did not bound the wait";
  EXPECT_NE(err.str().find("timed out"), std::string::npos) << err.str();
}

TEST(HealthProbe, ARefusedConnectionIsNoAnswer) {
  int port = 0;
  {
    Listener closed;  // bound, then closed: nothing listens there any more
    port = std::stoi(closed.url("").substr(std::string("http://127.0.0.1:").size()));
  }
  std::ostringstream out, err;
  HealthOptions options;
  options.url = "http://127.0.0.1:" + std::to_string(port) + "/readyz";
  EXPECT_EQ(run_health(options, out, err), kExitCommunication);
  EXPECT_NE(err.str().find("cannot connect"), std::string::npos) << err.str();
}

}  // namespace
}  // namespace pullout::cli
