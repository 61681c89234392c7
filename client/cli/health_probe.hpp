// `pullout health URL`: one HTTP/1.0 GET, for container HEALTHCHECKs and scripts (the runtime image
// has no curl). Only plain http:// with a numeric or resolvable host is supported; no redirects,
// no TLS, no proxy.
//
// Exit codes: 0 the server answered 200; 1 it answered with any other status; 2 the URL is not
// one this probe understands; 3 no answer (cannot resolve, connect refused, timeout, malformed
// reply).
#pragma once

#include <ostream>
#include <string>

namespace pullout::cli {

inline constexpr int kExitHealthy = 0;
inline constexpr int kExitUnhealthy = 1;

struct HttpUrl {
  std::string host;
  std::string port{"80"};
  std::string path{"/"};
};

// Parses "http://host[:port][/path]"; returns false (with `error` set) for anything else.
bool parse_http_url(const std::string& url, HttpUrl& parsed, std::string& error);

struct HealthOptions {
  std::string url;
  double timeout_s{2.0};  // connect, send and receive together
  bool quiet{false};      // no status line on stdout
};

int run_health(const HealthOptions& options, std::ostream& out, std::ostream& err);

}  // namespace pullout::cli
