#include "headless_browser.hpp"

#include <fcntl.h>
#include <poll.h>
#include <signal.h>
#include <sys/prctl.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cerrno>
#include <cstdlib>
#include <cstring>
#include <fstream>
#include <stdexcept>
#include <thread>

namespace pullout::integration {

namespace {

using Clock = std::chrono::steady_clock;

int base64_value(char c) {
  if (c >= 'A' && c <= 'Z') return c - 'A';
  if (c >= 'a' && c <= 'z') return c - 'a' + 26;
  if (c >= '0' && c <= '9') return c - '0' + 52;
  if (c == '+') return 62;
  if (c == '/') return 63;
  return -1;
}

}  // namespace

std::string base64_decode(const std::string& text) {
  std::string out;
  out.reserve(text.size() / 4 * 3);
  unsigned int bits = 0;
  int count = 0;
  for (char c : text) {
    if (c == '=') break;
    if (c == '\n' || c == '\r') continue;
    const int v = base64_value(c);
    if (v < 0) throw std::invalid_argument("base64: bad character");
    bits = (bits << 6) | static_cast<unsigned int>(v);
    count += 6;
    if (count >= 8) {
      count -= 8;
      out.push_back(static_cast<char>((bits >> count) & 0xFFu));
    }
  }
  return out;
}

std::string HeadlessBrowser::find_executable() {
  const char* env = std::getenv("PULLOUT_CHROMIUM");
  const std::string candidate = env != nullptr && *env != '\0' ? env : "/usr/bin/chromium";
  return ::access(candidate.c_str(), X_OK) == 0 ? candidate : "";
}

HeadlessBrowser::HeadlessBrowser(const std::string& executable, const std::string& profile_dir,
                                 const std::string& log_file) {
  int commands[2];  // parent writes [1], browser reads fd 3
  int answers[2];   // browser writes fd 4, parent reads [0]
  if (::pipe2(commands, O_CLOEXEC) != 0 || ::pipe2(answers, O_CLOEXEC) != 0) {
    throw std::runtime_error(std::string("pipe: ") + std::strerror(errno));
  }
  const std::vector<std::string> args{executable,
                                      "--headless",
                                      "--no-sandbox",  // root
                                      "--disable-gpu",
                                      "--disable-dev-shm-usage",
                                      "--no-first-run",
                                      "--no-default-browser-check",
                                      "--disable-extensions",
                                      "--disable-background-networking",
                                      "--no-proxy-server",
                                      "--remote-debugging-pipe",
                                      "--user-data-dir=" + profile_dir,
                                      "about:blank"};
  std::vector<char*> argv;
  for (const auto& a : args) argv.push_back(const_cast<char*>(a.c_str()));
  argv.push_back(nullptr);
  const pid_t parent = ::getpid();
  pid_ = ::fork();
  if (pid_ < 0) throw std::runtime_error(std::string("fork: ") + std::strerror(errno));
  if (pid_ == 0) {
    ::setpgid(0, 0);
    ::prctl(PR_SET_PDEATHSIG, SIGKILL);
    if (::getppid() != parent) ::_exit(127);
    const int log = ::open(log_file.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0644);
    const int null = ::open("/dev/null", O_RDWR);
    if (log < 0 || null < 0) ::_exit(127);
    // fds 3 and 4 are the DevTools pipe; move the pipe ends out of the way first.
    const int in = ::fcntl(commands[0], F_DUPFD, 10);
    const int out = ::fcntl(answers[1], F_DUPFD, 10);
    if (in < 0 || out < 0 || ::dup2(null, 0) < 0 || ::dup2(log, 1) < 0 || ::dup2(log, 2) < 0 || ::dup2(in, 3) < 0 ||
        ::dup2(out, 4) < 0) {
      ::_exit(127);
    }
    ::execv(argv[0], argv.data());
    ::_exit(127);
  }
  ::setpgid(pid_, pid_);  // also here: no race with the first kill(-pid)
  ::close(commands[0]);
  ::close(answers[1]);
  to_browser_ = commands[1];
  from_browser_ = answers[0];
  try {
    call("Browser.getVersion", nlohmann::json::object(), false, Millis(60000));
  } catch (...) {
    close(Millis(0));
    throw;
  }
}

HeadlessBrowser::~HeadlessBrowser() { close(); }

void HeadlessBrowser::send(const nlohmann::json& message) {
  std::string text = message.dump();
  text.push_back('\0');
  std::size_t done = 0;
  while (done < text.size()) {
    const ssize_t n = ::write(to_browser_, text.data() + done, text.size() - done);
    if (n < 0 && errno == EINTR) continue;
    if (n <= 0) throw std::runtime_error(std::string("DevTools pipe write: ") + std::strerror(errno));
    done += static_cast<std::size_t>(n);
  }
}

nlohmann::json HeadlessBrowser::receive(Clock::time_point deadline) {
  for (;;) {
    const std::size_t end = buffer_.find('\0');
    if (end != std::string::npos) {
      const std::string text = buffer_.substr(0, end);
      buffer_.erase(0, end + 1);
      return nlohmann::json::parse(text);
    }
    const auto left = std::chrono::duration_cast<Millis>(deadline - Clock::now()).count();
    if (left <= 0) throw std::runtime_error("no DevTools answer in time");
    pollfd p{from_browser_, POLLIN, 0};
    const int ready = ::poll(&p, 1, static_cast<int>(left));
    if (ready < 0 && errno == EINTR) continue;
    if (ready <= 0) continue;
    char chunk[65536];
    const ssize_t n = ::read(from_browser_, chunk, sizeof chunk);
    if (n < 0 && errno == EINTR) continue;
    if (n <= 0) throw std::runtime_error("the browser closed the DevTools pipe");
    buffer_.append(chunk, static_cast<std::size_t>(n));
  }
}

nlohmann::json HeadlessBrowser::call(const std::string& method, const nlohmann::json& params, bool on_page,
                                     Millis timeout) {
  if (closed_) throw std::runtime_error("the browser is closed");
  const int id = next_id_++;
  nlohmann::json message{{"id", id}, {"method", method}, {"params", params}};
  if (on_page) message["sessionId"] = session_id_;
  send(message);
  const auto deadline = Clock::now() + timeout;
  for (;;) {
    nlohmann::json answer = receive(deadline);
    if (!answer.contains("id") || answer["id"] != id) continue;  // an event, or an older answer
    if (answer.contains("error")) throw std::runtime_error(method + ": " + answer["error"].dump());
    return answer.value("result", nlohmann::json::object());
  }
}

void HeadlessBrowser::open(const std::string& url, int width, int height) {
  const auto target = call("Target.createTarget", {{"url", "about:blank"}}, false);
  const auto attached = call("Target.attachToTarget", {{"targetId", target.at("targetId")}, {"flatten", true}}, false);
  session_id_ = attached.at("sessionId").get<std::string>();
  call("Emulation.setDeviceMetricsOverride",
       {{"width", width}, {"height", height}, {"deviceScaleFactor", 1}, {"mobile", false}}, true);
  call("Page.enable", nlohmann::json::object(), true);
  call("Page.navigate", {{"url", url}}, true);
}

nlohmann::json HeadlessBrowser::evaluate(const std::string& expression) {
  const auto result = call("Runtime.evaluate", {{"expression", expression}, {"returnByValue", true}}, true);
  if (result.contains("exceptionDetails")) {
    throw std::runtime_error("JavaScript exception: " + result["exceptionDetails"].dump());
  }
  return result.at("result").value("value", nlohmann::json());
}

void HeadlessBrowser::screenshot(const std::string& file) {
  const auto result = call("Page.captureScreenshot", {{"format", "png"}}, true);
  std::ofstream out(file, std::ios::binary | std::ios::trunc);
  out << base64_decode(result.at("data").get<std::string>());
  if (!out) throw std::runtime_error("cannot write " + file);
}

bool HeadlessBrowser::close(Millis timeout) {
  if (closed_) return exited_;
  closed_ = true;
  if (pid_ <= 0) return exited_;
  try {
    if (timeout.count() > 0) {
      nlohmann::json message{{"id", next_id_++}, {"method", "Browser.close"}, {"params", nlohmann::json::object()}};
      send(message);
    }
  } catch (const std::exception&) {
    // The pipe is gone: the browser is exiting or dead; the wait below tells.
  }
  const auto deadline = Clock::now() + timeout;
  for (;;) {
    int status = 0;
    const pid_t r = ::waitpid(pid_, &status, WNOHANG);
    if (r == pid_ || (r < 0 && errno == ECHILD)) {
      exited_ = true;
      break;
    }
    if (Clock::now() >= deadline) break;
    std::this_thread::sleep_for(Millis(50));
  }
  // Whatever is left of the browser's process group (helpers outliving it, or all of it).
  ::kill(-pid_, SIGKILL);
  if (!exited_) ::waitpid(pid_, nullptr, 0);
  ::close(to_browser_);
  ::close(from_browser_);
  return exited_;
}

}  // namespace pullout::integration
