#include "headless_chromium.h"

#include <openssl/evp.h>
#include <sys/socket.h>

#include <boost/asio/connect.hpp>
#include <boost/asio/ip/tcp.hpp>
#include <boost/beast/core.hpp>
#include <boost/beast/websocket.hpp>
#include <fstream>
#include <nlohmann/json.hpp>
#include <sstream>

#include "http_client.h"

namespace optique::testing {

namespace asio = boost::asio;
namespace websocket = boost::beast::websocket;
using namespace std::chrono_literals;

struct HeadlessChromium::Connection {
  asio::io_context io;
  websocket::stream<asio::ip::tcp::socket> socket{io};
};

HeadlessChromium::HeadlessChromium(const std::string& url, const std::string& dir, int width, int height) {
  const std::string profile = dir + "/chromium-profile";
  browser_ = std::make_unique<Process>(
      std::vector<std::string>{"/usr/bin/chromium", "--headless", "--no-sandbox", "--disable-gpu", "--hide-scrollbars",
                               "--no-first-run", "--user-data-dir=" + profile, "--remote-debugging-port=0",
                               "--window-size=" + std::to_string(width) + "," + std::to_string(height), url},
      dir + "/chromium.log");
  // Chromium writes the port it chose, and its browser's path, here.
  const std::string active_port = profile + "/DevToolsActivePort";
  if (!wait_for_file(active_port, 30s)) {
    error_ = "Chromium did not open its DevTools port within 30 s:\n" + browser_->output();
    return;
  }
  const int port = std::atoi(read_file(active_port).c_str());
  // The page's own endpoint.
  std::string target;
  const bool listed = poll_until(
      [&] {
        const HttpReply list = http_request(port, "GET", "/json/list");
        if (list.status != 200) return false;
        for (const auto& entry : nlohmann::json::parse(list.body, nullptr, false)) {
          if (entry.value("type", "") == "page") target = entry.value("webSocketDebuggerUrl", "");
        }
        return !target.empty();
      },
      10s);
  if (!listed) {
    error_ = "Chromium lists no page on port " + std::to_string(port);
    return;
  }
  const std::string path = target.substr(target.find('/', std::string("ws://").size()));
  connection_ = std::make_unique<Connection>();
  boost::system::error_code ec;
  auto& socket = connection_->socket.next_layer();
  socket.connect({asio::ip::make_address("127.0.0.1"), static_cast<std::uint16_t>(port)}, ec);
  if (!ec) {
    // Never a read that waits forever: the socket's own timeout.
    const timeval timeout{10, 0};
    ::setsockopt(socket.native_handle(), SOL_SOCKET, SO_RCVTIMEO, &timeout, sizeof timeout);
    connection_->socket.handshake("127.0.0.1:" + std::to_string(port), path, ec);
  }
  if (ec) error_ = "cannot reach Chromium's page at " + target + ": " + ec.message();
}

HeadlessChromium::~HeadlessChromium() {
  if (connection_) {
    boost::system::error_code ignored;
    connection_->socket.next_layer().close(ignored);
  }
}

std::optional<std::string> HeadlessChromium::call(const std::string& method, const std::string& params_json,
                                                  const std::string& result_field) {
  if (!error_.empty() || !connection_) return std::nullopt;
  const int id = next_id_++;
  const std::string request =
      "{\"id\":" + std::to_string(id) + ",\"method\":\"" + method + "\",\"params\":" + params_json + "}";
  boost::system::error_code ec;
  connection_->socket.write(asio::buffer(request), ec);
  // Events come too; the answer is the message with our id.
  for (int messages = 0; !ec && messages < 10000; ++messages) {
    boost::beast::flat_buffer buffer;
    connection_->socket.read(buffer, ec);
    if (ec) break;
    const auto reply = nlohmann::json::parse(boost::beast::buffers_to_string(buffer.data()), nullptr, false);
    if (!reply.is_object() || reply.value("id", 0) != id) continue;
    if (reply.contains("error")) {
      error_ = method + ": " + reply["error"].dump();
      return std::nullopt;
    }
    const nlohmann::json* value = &reply["result"];
    std::istringstream fields(result_field);
    for (std::string field; std::getline(fields, field, '.');) value = &(*value)[field];
    return value->is_string() ? value->get<std::string>() : value->dump();
  }
  error_ = method + ": no answer from Chromium (" + ec.message() + ")";
  return std::nullopt;
}

std::optional<std::string> HeadlessChromium::evaluate(const std::string& expression) {
  const nlohmann::json params = {{"expression", expression}, {"returnByValue", true}};
  return call("Runtime.evaluate", params.dump(), "result.value");
}

bool HeadlessChromium::screenshot(const std::string& png_path) {
  const auto base64 = call("Page.captureScreenshot", R"({"format":"png"})", "data");
  if (!base64) return false;
  std::string png(base64->size() / 4 * 3 + 3, '\0');
  const int decoded =
      EVP_DecodeBlock(reinterpret_cast<unsigned char*>(png.data()),
                      reinterpret_cast<const unsigned char*>(base64->data()), static_cast<int>(base64->size()));
  if (decoded < 0) {
    error_ = "the screenshot is not base64";
    return false;
  }
  // EVP_DecodeBlock counts the padding's bytes too.
  std::size_t size = static_cast<std::size_t>(decoded);
  for (auto it = base64->rbegin(); it != base64->rend() && *it == '='; ++it) --size;
  png.resize(size);
  std::ofstream(png_path, std::ios::binary) << png;
  return true;
}

}  // namespace optique::testing
