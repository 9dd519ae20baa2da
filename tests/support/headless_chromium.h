#pragma once
// Debian's Chromium, headless, driven over the DevTools protocol (a WebSocket):
// a page is opened and left to run in real time, then read (any JavaScript
// expression, the DOM included) and photographed. What a person would see
// after looking at the page for a while; --dump-dom cannot wait for a page that
// fills itself from a stream.

#include <memory>
#include <optional>
#include <string>

#include "process.h"

namespace optique::testing {

class HeadlessChromium {
 public:
  // Opens `url` in a fresh profile under `dir` (its log there too).
  HeadlessChromium(const std::string& url, const std::string& dir, int width = 1400, int height = 900);
  ~HeadlessChromium();
  HeadlessChromium(const HeadlessChromium&) = delete;
  HeadlessChromium& operator=(const HeadlessChromium&) = delete;

  // Empty when the browser is up and its page reachable; otherwise why not.
  [[nodiscard]] const std::string& error() const { return error_; }
  // The value of `expression` in the page, as a string (nullopt: it failed; see error()).
  [[nodiscard]] std::optional<std::string> evaluate(const std::string& expression);
  // The page as a PNG file.
  [[nodiscard]] bool screenshot(const std::string& png_path);

 private:
  struct Connection;
  [[nodiscard]] std::optional<std::string> call(const std::string& method, const std::string& params_json,
                                                const std::string& result_field);

  std::unique_ptr<Process> browser_;
  std::unique_ptr<Connection> connection_;
  std::string error_;
  int next_id_ = 1;
};

}  // namespace optique::testing
