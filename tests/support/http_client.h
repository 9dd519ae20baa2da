#pragma once
// A plain HTTP/1.1 client on blocking POSIX sockets with deadlines, for tests
// of the master's status server: whole requests, raw bytes (slow, oversized or
// not HTTP at all), and event streams read as they come.

#include <chrono>
#include <map>
#include <string>

namespace optique::testing {

struct HttpReply {
  int status = 0;
  std::map<std::string, std::string> headers;  // names in lower case
  std::string body;
  std::string error;  // why there is no reply (connect failed, timed out…)
};

// Parses one reply from `raw` (a status line, headers, a body by Content-Length
// or up to the end); `error` set when it is not one.
[[nodiscard]] HttpReply parse_reply(const std::string& raw);

// How a RawClient connects: to which IPv4 address of this machine (another
// than loopback makes the server see a peer that is not on loopback), and with
// which receive buffer (SO_RCVBUF; 0: the kernel's, which grows as it likes).
struct ClientOptions {
  std::string address = "127.0.0.1";
  int receive_buffer = 0;
};

// An IPv4 address of this machine's that is not loopback (an interface that is
// up); empty when it has none.
[[nodiscard]] std::string non_loopback_address();

// A connection to `options.address`:`port`.
class RawClient {
 public:
  explicit RawClient(int port, const ClientOptions& options = {});
  ~RawClient();
  RawClient(const RawClient&) = delete;
  RawClient& operator=(const RawClient&) = delete;

  [[nodiscard]] bool connected() const { return fd_ >= 0; }
  bool send(const std::string& bytes);
  // What arrives until the peer closes or `timeout` passes, appended to what came before.
  std::string read_until_closed(std::chrono::milliseconds timeout);
  // What arrives until `needle` has come (true) or the timeout passes (false).
  bool read_until(const std::string& needle, std::chrono::milliseconds timeout);
  // Whether the peer closed (or reset) the connection within `timeout`.
  [[nodiscard]] bool closed_within(std::chrono::milliseconds timeout);
  // Reads and drops what arrives for `timeout`; whether the connection is still open.
  bool discard_for(std::chrono::milliseconds timeout);
  [[nodiscard]] const std::string& received() const { return received_; }
  // Reads one whole reply (by Content-Length) off a kept-alive connection.
  [[nodiscard]] HttpReply read_reply(std::chrono::milliseconds timeout);

 private:
  // One read of up to 64 KiB within `timeout`: bytes read, 0 closed, −1 timeout or error.
  long read_once(std::chrono::milliseconds timeout);

  int fd_ = -1;
  std::string received_;
  bool closed_ = false;
};

// One request ("Connection: close") with an optional bearer token; its reply.
[[nodiscard]] HttpReply http_request(int port, const std::string& method, const std::string& path,
                                     const std::string& token = "",
                                     std::chrono::milliseconds timeout = std::chrono::seconds(5));

}  // namespace optique::testing
