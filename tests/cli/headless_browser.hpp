// Headless Chromium (Debian's `chromium`) driven over the DevTools protocol through a pipe
// (--remote-debugging-pipe: JSON messages ending in '\0' on file descriptors 3 and 4), so a test
// can load a page, evaluate JavaScript in it and take screenshots without a display, a WebSocket
// library or npm. Runs as root (--no-sandbox), with a profile in a scratch directory, shared
// memory in /tmp instead of /dev/shm (--disable-dev-shm-usage), no proxy.
//
// Processes: the browser is started in a process group of its own (its renderer, GPU and utility
// processes inherit it) and gets SIGKILL if the thread that started it dies
// (PR_SET_PDEATHSIG). close() asks it to quit (Browser.close), waits, then kills the group; the
// destructor calls close().
#pragma once

#include <sys/types.h>

#include <chrono>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

namespace pullout::integration {

class HeadlessBrowser {
 public:
  using Millis = std::chrono::milliseconds;

  // The chromium executable: $PULLOUT_CHROMIUM, else /usr/bin/chromium. Empty when neither exists.
  static std::string find_executable();

  // Starts the browser. `profile_dir` must be an empty scratch directory; the browser's stderr goes
  // to `log_file`. Throws std::runtime_error when it cannot start or does not answer.
  HeadlessBrowser(const std::string& executable, const std::string& profile_dir, const std::string& log_file);
  ~HeadlessBrowser();
  HeadlessBrowser(const HeadlessBrowser&) = delete;
  HeadlessBrowser& operator=(const HeadlessBrowser&) = delete;

  // Opens `url` in a new page of `width` x `height` px and attaches to it; later calls act on it.
  void open(const std::string& url, int width = 1200, int height = 900);
  // Evaluates `expression` in the page and returns its value (JSON-serialisable values only).
  // Throws std::runtime_error on a JavaScript exception.
  nlohmann::json evaluate(const std::string& expression);
  // Writes a PNG screenshot of the page to `file`.
  void screenshot(const std::string& file);

  // Browser.close, wait up to `timeout` for the browser to exit, then SIGKILL its process group.
  // Returns whether it exited on its own. Idempotent.
  bool close(Millis timeout = Millis(10000));
  pid_t pid() const { return pid_; }

  // One DevTools command (on the attached page when `on_page`); returns its result. Throws
  // std::runtime_error on an error answer or when no answer comes within `timeout`.
  nlohmann::json call(const std::string& method, const nlohmann::json& params, bool on_page,
                      Millis timeout = Millis(30000));

 private:
  void send(const nlohmann::json& message);
  // The next message; throws when none comes before `deadline`.
  nlohmann::json receive(std::chrono::steady_clock::time_point deadline);

  pid_t pid_{-1};
  int to_browser_{-1};    // our end of its fd 3
  int from_browser_{-1};  // our end of its fd 4
  std::string buffer_;
  int next_id_{1};
  std::string session_id_;
  bool closed_{false};
  bool exited_{false};
};

// Decodes standard base64 (the screenshot data). Throws std::invalid_argument on a bad character.
std::string base64_decode(const std::string& text);

}  // namespace pullout::integration
