#include "http/server.h"

#include <boost/asio/post.hpp>
#include <boost/asio/write.hpp>
#include <boost/beast/core.hpp>
#include <boost/beast/http.hpp>
#include <boost/beast/http/span_body.hpp>
#include <boost/beast/websocket.hpp>

#include <algorithm>
#include <array>
#include <atomic>
#include <deque>
#include <optional>

#include "http/listen.h"

namespace optique::http {
namespace {

namespace beast = boost::beast;
namespace bhttp = boost::beast::http;
namespace websocket = boost::beast::websocket;

// A close frame's reason holds at most 123 bytes; cut at a character's start.
std::string close_frame_reason(const std::string& reason) {
  constexpr std::size_t kMax = 123;
  if (reason.size() <= kMax) return reason;
  std::size_t end = kMax;
  while (end > 0 && (static_cast<unsigned char>(reason[end]) & 0xC0) == 0x80) --end;
  return reason.substr(0, end);
}

Method method_of(bhttp::verb verb) {
  switch (verb) {
    case bhttp::verb::get:
      return Method::get;
    case bhttp::verb::head:
      return Method::head;
    case bhttp::verb::post:
      return Method::post;
    default:
      return Method::other;
  }
}

}  // namespace

class Server::Peer : public WebSocketPeer {
 public:
  Peer(asio::io_context& io, const std::shared_ptr<Session>& session, std::shared_ptr<std::atomic<std::size_t>> queued)
      : io_(io), session_(session), queued_(std::move(queued)) {}

  void send(std::string text) override;
  void close(std::string reason) override;
  void reset(std::string reason) override;
  [[nodiscard]] std::size_t queued_bytes() const override { return *queued_; }

 private:
  asio::io_context& io_;
  std::weak_ptr<Session> session_;
  std::shared_ptr<std::atomic<std::size_t>> queued_;
};

class Server::Session : public std::enable_shared_from_this<Session> {
 public:
  Session(Server& server, std::uint64_t id, asio::ip::tcp::socket socket)
      : server_(server), counters_(server.counters_), id_(id), stream_(std::move(socket)) {
    boost::system::error_code ec;
    const auto peer = stream_.socket().remote_endpoint(ec);
    if (!ec) {
      peer_ = peer.address().to_string() + ":" + std::to_string(peer.port());
      peer_is_loopback_ = peer.address().is_loopback();
    }
    counters_->open += 1;
  }
  ~Session() {
    counters_->open -= 1;
    if (streaming_) counters_->streams -= 1;
    if (endpoint_) counters_->websockets -= 1;
  }

  void start() { read_request(); }

  // Over a connection limit: told so, and closed.
  void refuse(std::string why) {
    Response busy = text_response(503, std::move(why));
    busy.headers.emplace_back("Retry-After", "1");
    refusing_ = true;  // closed once written: lingering is for the clients let in
    write_response(std::move(busy), 11, false);
  }

  void push(const std::shared_ptr<const std::string>& event) {
    if (!streaming_ || closed_) return;
    if (events_.size() >= server_.limits_.max_queued_events) {
      counters_->streams_behind += 1;
      server_.log_.debug("status: closing the event stream to {}: {} events behind", peer_, events_.size());
      reset();
      return;
    }
    events_.push_back(event);
    if (!writing_) write_next_event();
  }

  // Closed without a goodbye: what the kernel still holds for the client is
  // dropped now, not kept (for minutes) for a client that does not read.
  void reset() {
    beast::error_code ignored;
    tcp().socket().set_option(asio::socket_base::linger(true, 0), ignored);
    close();
  }

  void close() {
    if (closed_) return;
    closed_ = true;
    if (opened_) {
      endpoint_->closed(close_reason_.empty() ? "the status server closed it" : close_reason_);
    }
    beast::error_code ignored;
    tcp().socket().shutdown(asio::ip::tcp::socket::shutdown_both, ignored);
    tcp().close();
    server_.on_closed(id_);
  }

  // From the endpoint's owner, on the server's thread (Server::Peer).
  void websocket_send(std::string text, const std::shared_ptr<std::atomic<std::size_t>>& queued) {
    if (closed_ || closing_) {
      *queued -= text.size();
      return;
    }
    if (*queued > endpoint_->max_queued_bytes) {
      counters_->streams_behind += 1;
      close_reason_ = "it stopped reading: " + std::to_string(queued->load()) + " bytes waited for it";
      server_.log_.debug("status: closing the WebSocket of {}: {}", peer_, close_reason_);
      reset();
      return;
    }
    outbox_.push_back(std::move(text));
    if (!writing_) write_next_message();
  }
  void websocket_reset(std::string reason) {
    if (closed_) return;
    close_reason_ = std::move(reason);
    reset();
  }
  void websocket_close(std::string reason, websocket::close_code code = websocket::close_code::normal) {
    if (closed_ || closing_) return;
    closing_ = true;
    close_reason_ = std::move(reason);
    close_code_ = code;
    if (!writing_) write_next_message();
  }

 private:
  void read_request() {
    parser_.emplace();
    parser_->header_limit(server_.limits_.max_header_bytes);
    parser_->body_limit(server_.limits_.max_body_bytes);
    header_bytes_ = 0;
    stream_.expires_after(server_.limits_.request_timeout);
    read_header();
  }

  // Beast's header_limit bounds what is buffered past the part it has parsed,
  // not the header: a header of many small fields passed an 8 KiB limit twice
  // over. So the header is fed to the parser here, never read past the limit,
  // and counted from the request line to the blank line; Beast reads the body.
  void read_header() {
    const std::size_t limit = server_.limits_.max_header_bytes;
    if (buffer_.size() > 0) {
      beast::error_code error;
      const std::size_t used = parser_->put(buffer_.data(), error);
      buffer_.consume(used);
      header_bytes_ += used;
      if (parser_->is_header_done()) {
        if (header_bytes_ > limit) {
          on_request(bhttp::error::header_limit);
          return;
        }
        bhttp::async_read(stream_, buffer_, *parser_,
                          [self = shared_from_this()](beast::error_code e, std::size_t) { self->on_request(e); });
        return;
      }
      if (error && error != bhttp::error::need_more) {
        on_request(error);
        return;
      }
    }
    if (header_bytes_ + buffer_.size() >= limit) {
      on_request(bhttp::error::header_limit);
      return;
    }
    const std::size_t room = limit - header_bytes_ - buffer_.size();
    stream_.async_read_some(buffer_.prepare(std::min<std::size_t>(room, 4096)),
                            [self = shared_from_this()](beast::error_code error, std::size_t n) {
                              self->buffer_.commit(n);
                              if (error == asio::error::eof) {
                                const bool nothing = self->header_bytes_ + self->buffer_.size() == 0;
                                error = nothing ? bhttp::error::end_of_stream : bhttp::error::partial_message;
                              }
                              if (error) {
                                self->on_request(error);
                                return;
                              }
                              self->read_header();
                            });
  }

  void on_request(beast::error_code error) {
    if (closed_) return;
    if (error == bhttp::error::header_limit || error == bhttp::error::body_limit) {
      counters_->too_large += 1;
      const bool header = error == bhttp::error::header_limit;
      write_response(
          text_response(header ? 431 : 413, header ? "request header too large (the limit is " +
                                                         std::to_string(server_.limits_.max_header_bytes) + " bytes)"
                                                   : "request body too large (the limit is " +
                                                         std::to_string(server_.limits_.max_body_bytes) + " bytes)"),
          11, false);
      return;
    }
    if (error == beast::error::timeout) {
      counters_->timed_out += 1;
      server_.log_.debug("status: closed {}: no whole request within {} ms", peer_,
                         server_.limits_.request_timeout.count());
      close();
      return;
    }
    if (error && error.category() == bhttp::make_error_code(bhttp::error::end_of_stream).category() &&
        error != bhttp::error::end_of_stream && error != bhttp::error::partial_message) {
      counters_->bad_requests += 1;
      write_response(text_response(400, "not an HTTP request: " + error.message()), 11, false);
      return;
    }
    if (error) {  // the client went away (end_of_stream, reset)
      close();
      return;
    }
    counters_->requests += 1;
    const auto& message = parser_->get();
    Request request;
    request.method = method_of(message.method());
    request.method_text = std::string(message.method_string());
    const std::string_view target(message.target().data(), message.target().size());
    const auto question = target.find('?');
    request.path = std::string(target.substr(0, question));
    if (question != std::string_view::npos) request.query = std::string(target.substr(question + 1));
    if (const auto found = message.find(bhttp::field::authorization); found != message.end()) {
      request.authorization = std::string(found->value());
    }
    if (const auto found = message.find(bhttp::field::host); found != message.end()) {
      request.host = std::string(found->value());
    }
    if (const auto found = message.find(bhttp::field::origin); found != message.end()) {
      request.origin = std::string(found->value());
    }
    request.peer = peer_;
    request.peer_is_loopback = peer_is_loopback_;
    request.websocket_upgrade = websocket::is_upgrade(message);
    Response response = server_.handler_(request);
    if (response.websocket && response.status == 101 && request.websocket_upgrade) {
      start_websocket(std::move(response.websocket));
      return;
    }
    if (response.status == 101) response = text_response(500, "the status server cannot upgrade this request");
    if (response.event_stream && response.status == 200 && request.method != Method::head) {
      start_stream();
      return;
    }
    const bool head = request.method == Method::head;
    write_response(std::move(response), message.version(), message.keep_alive(), head);
  }

  void write_response(Response response, unsigned version, bool keep_alive, bool head = false) {
    body_ = std::move(response.body);
    response_.emplace();
    response_->version(version);
    response_->result(response.status);
    response_->set(bhttp::field::server, "optique");
    response_->set(bhttp::field::content_type, response.content_type);
    response_->set(bhttp::field::cache_control, "no-store");
    response_->set("X-Content-Type-Options", "nosniff");
    response_->set("X-Frame-Options", "DENY");
    for (const auto& [name, value] : response.headers) response_->set(name, value);
    response_->body() = boost::beast::span<const char>(body_->data(), body_->size());
    response_->prepare_payload();
    response_->keep_alive(keep_alive);
    if (head) response_->body() = {};  // the length of what a GET would get, no body
    stream_.expires_after(server_.limits_.write_timeout);
    bhttp::async_write(stream_, *response_,
                       [self = shared_from_this(), keep_alive](beast::error_code error, std::size_t) {
                         self->on_written(error, keep_alive);
                       });
  }

  void on_written(beast::error_code error, bool keep_alive) {
    if (closed_) return;
    if (error == beast::error::timeout) counters_->timed_out += 1;
    if (error || refusing_) {
      close();
      return;
    }
    if (!keep_alive) {
      linger();
      return;
    }
    read_request();
  }

  // The answer is out; what the client still sends (the rest of a body too
  // large) is read and dropped for a moment before closing, or the kernel would
  // answer it with a reset that can overtake the answer.
  void linger() {
    beast::error_code ignored;
    stream_.socket().shutdown(asio::ip::tcp::socket::shutdown_send, ignored);
    stream_.expires_after(std::chrono::seconds(1));  // for every read from here on
    drop_what_comes();
  }
  void drop_what_comes() {
    stream_.async_read_some(asio::buffer(discard_), [self = shared_from_this()](beast::error_code error, std::size_t) {
      if (self->closed_) return;
      if (error) {
        self->close();  // the client closed too, or a second passed
        return;
      }
      self->drop_what_comes();
    });
  }

  // No length and no chunks: the stream ends when the connection does.
  void start_stream() {
    streaming_ = true;
    counters_->streams += 1;
    server_.streams_[id_] = shared_from_this();  // between events nothing else holds it
    beast::error_code ignored;
    stream_.socket().set_option(asio::socket_base::send_buffer_size(server_.limits_.stream_send_buffer), ignored);
    events_.push_back(std::make_shared<const std::string>(
        "HTTP/1.1 200 OK\r\nServer: optique\r\nContent-Type: text/event-stream\r\nCache-Control: no-store\r\n"
        "X-Content-Type-Options: nosniff\r\nX-Frame-Options: DENY\r\nConnection: close\r\n\r\n"));
    write_next_event();
  }

  void write_next_event() {
    if (events_.empty() || closed_) {
      writing_ = false;
      return;
    }
    writing_ = true;
    const std::shared_ptr<const std::string> next = events_.front();
    stream_.expires_after(server_.limits_.write_timeout);
    asio::async_write(stream_, asio::buffer(*next),
                      [self = shared_from_this(), next](beast::error_code error, std::size_t) {
                        if (self->closed_) return;
                        if (error) {
                          if (error == beast::error::timeout) self->counters_->timed_out += 1;
                          self->reset();
                          return;
                        }
                        self->events_.pop_front();
                        self->write_next_event();
                      });
  }

  // The connection as TCP, under the WebSocket once it is one.
  beast::tcp_stream& tcp() { return ws_ ? ws_->next_layer() : stream_; }

  void start_websocket(std::shared_ptr<WebSocketEndpoint> endpoint) {
    endpoint_ = std::move(endpoint);
    counters_->websockets += 1;
    stream_.expires_never();  // the WebSocket keeps its own time
    ws_.emplace(std::move(stream_));
    websocket::stream_base::timeout timeouts;
    timeouts.handshake_timeout = server_.limits_.write_timeout;  // the upgrade's answer, and closing
    timeouts.idle_timeout = server_.limits_.websocket_idle;
    timeouts.keep_alive_pings = true;
    ws_->set_option(timeouts);
    ws_->set_option(websocket::stream_base::decorator(
        [](websocket::response_type& response) { response.set(bhttp::field::server, "optique"); }));
    ws_->read_message_max(endpoint_->max_message_bytes);
    beast::error_code ignored;
    tcp().socket().set_option(asio::socket_base::send_buffer_size(server_.limits_.stream_send_buffer), ignored);
    ws_->async_accept(parser_->get(), [self = shared_from_this()](beast::error_code error) {
      if (self->closed_) return;
      if (error) {
        self->close_reason_ = "its upgrade failed: " + error.message();
        self->close();
        return;
      }
      self->opened_ = true;
      self->endpoint_->opened(std::make_shared<Peer>(self->server_.io_, self, self->queued_));
      self->read_message();
    });
  }

  void read_message() {
    ws_->async_read(inbox_, [self = shared_from_this()](beast::error_code error, std::size_t) {
      if (self->closed_) return;
      if (error) {
        self->websocket_ended(error);
        return;
      }
      if (!self->ws_->got_text()) {
        self->inbox_.clear();
        self->websocket_close("this WebSocket takes text messages only", websocket::close_code::unknown_data);
        self->read_message();  // until the client answers the close
        return;
      }
      std::string text = beast::buffers_to_string(self->inbox_.data());
      self->inbox_.clear();
      if (!self->closing_) self->endpoint_->received(std::move(text));
      self->read_message();
    });
  }

  // The read ended: the client closed, went silent, broke a rule, or the close
  // this side began is done.
  void websocket_ended(beast::error_code error) {
    if (close_reason_.empty()) {
      if (error == websocket::error::closed) {
        close_reason_ = "the client closed the WebSocket (code " + std::to_string(ws_->reason().code) + ")";
      } else if (error == websocket::error::message_too_big) {
        close_reason_ = "a message over " + std::to_string(endpoint_->max_message_bytes) + " bytes";
      } else if (error == beast::error::timeout) {
        counters_->timed_out += 1;
        close_reason_ = "it answered nothing, not even a ping, for " +
                        std::to_string(server_.limits_.websocket_idle.count()) + " ms";
      } else {
        close_reason_ = "the WebSocket broke: " + error.message();
      }
    }
    close();
  }

  void write_next_message() {
    if (closed_) return;
    if (outbox_.empty()) {
      writing_ = false;
      if (closing_) {
        writing_ = true;  // the close frame is the last write
        ws_->async_close(websocket::close_reason(close_code_, close_frame_reason(close_reason_)),
                         [self = shared_from_this()](beast::error_code error) {
                           // Done: the read sees the client's answer and ends.
                           if (error && !self->closed_) self->close();
                         });
      }
      return;
    }
    writing_ = true;
    ws_->text(true);
    ws_->async_write(asio::buffer(outbox_.front()), [self = shared_from_this()](beast::error_code error, std::size_t) {
      if (self->closed_) return;
      *self->queued_ -= self->outbox_.front().size();
      self->outbox_.pop_front();
      if (error) {
        if (error == beast::error::timeout) self->counters_->timed_out += 1;
        self->close_reason_ = "writing to it failed: " + error.message();
        self->reset();
        return;
      }
      self->write_next_message();
    });
  }

  Server& server_;
  std::shared_ptr<Counters> counters_;
  std::uint64_t id_;
  beast::tcp_stream stream_;
  beast::flat_buffer buffer_;
  std::size_t header_bytes_ = 0;  // of the request being read, parsed so far
  std::string peer_;
  bool peer_is_loopback_ = false;
  std::optional<bhttp::request_parser<bhttp::string_body>> parser_;
  std::optional<bhttp::response<bhttp::span_body<const char>>> response_;
  std::shared_ptr<const std::string> body_;  // what response_ points into, while it is written
  std::deque<std::shared_ptr<const std::string>> events_;
  bool streaming_ = false;
  bool writing_ = false;
  bool closed_ = false;
  bool refusing_ = false;
  std::array<char, 4096> discard_{};
  // As a WebSocket: its endpoint, what waits to be written (the count shared
  // with its Peer, which adds as it is asked), and how it closes.
  std::optional<websocket::stream<beast::tcp_stream>> ws_;
  std::shared_ptr<WebSocketEndpoint> endpoint_;
  beast::flat_buffer inbox_;
  std::deque<std::string> outbox_;
  std::shared_ptr<std::atomic<std::size_t>> queued_ = std::make_shared<std::atomic<std::size_t>>(0);
  bool opened_ = false;  // told its endpoint; it is then told when it closes
  bool closing_ = false;
  websocket::close_code close_code_ = websocket::close_code::normal;
  std::string close_reason_;
};

void Server::Peer::send(std::string text) {
  *queued_ += text.size();  // now, so that a caller on another thread sees it at once
  asio::post(io_, [session = session_, queued = queued_, text = std::move(text)]() mutable {
    if (auto open = session.lock()) open->websocket_send(std::move(text), queued);
  });
}

void Server::Peer::reset(std::string reason) {
  asio::post(io_, [session = session_, reason = std::move(reason)]() mutable {
    if (auto open = session.lock()) open->websocket_reset(std::move(reason));
  });
}

void Server::Peer::close(std::string reason) {
  asio::post(io_, [session = session_, reason = std::move(reason)]() mutable {
    if (auto open = session.lock()) open->websocket_close(std::move(reason));
  });
}

Server::Server(asio::io_context& io, ServerLimits limits, Handler handler, spdlog::logger& log)
    : io_(io),
      limits_(limits),
      handler_(std::move(handler)),
      log_(log),
      acceptor_(io),
      accept_retry_(io),
      budget_(limits.max_connections, limits.max_per_address, limits.loopback_reserved) {}

Server::~Server() = default;

Result<std::uint16_t> Server::listen(const std::string& address, std::uint16_t port) {
  auto bound = listen_on(acceptor_, address, port);
  if (bound) accept_next();
  return bound;
}

void Server::accept_next() {
  acceptor_.async_accept([this](const boost::system::error_code& error, asio::ip::tcp::socket socket) {
    if (stopped_ || error == asio::error::operation_aborted) return;
    if (!error) {
      accept_failing_ = false;
      counters_->accepted += 1;
      const std::uint64_t id = next_id_++;
      boost::system::error_code ec;
      const asio::ip::address peer = socket.remote_endpoint(ec).address();
      auto session = std::make_shared<Session>(*this, id, std::move(socket));
      // One refused is not counted among the sessions: it only says so.
      switch (ec ? Admission::busy : budget_.admit(peer)) {
        case Admission::admitted:
          sessions_[id] = {session, peer};
          session->start();
          break;
        case Admission::busy:
          counters_->refused_busy += 1;
          session->refuse("too many connections to this status server; try again shortly");
          break;
        case Admission::too_many_from_address:
          counters_->refused_address += 1;
          session->refuse("too many connections to this status server from your address (" +
                          std::to_string(limits_.max_per_address) + "); try again shortly");
          break;
      }
    } else {
      // Out of file descriptors and the like: again in a moment, not in a spin.
      if (!accept_failing_) log_.warn("status: accept failed: {}; trying again every 100 ms", error.message());
      accept_failing_ = true;
      accept_retry_.expires_after(std::chrono::milliseconds(100));
      accept_retry_.async_wait([this](const boost::system::error_code& e) {
        if (!e && !stopped_) accept_next();
      });
      return;
    }
    accept_next();
  });
}

void Server::on_closed(std::uint64_t id) {
  if (const auto found = sessions_.find(id); found != sessions_.end()) {
    budget_.release(found->second.peer);
    sessions_.erase(found);
  }
  streams_.erase(id);  // may be the last hold on the session: its caller holds another
}

void Server::publish(std::shared_ptr<const std::string> data) {
  asio::post(io_, [this, data = std::move(data)] {
    if (stopped_) return;
    const auto event = std::make_shared<const std::string>("data: " + *data + "\n\n");
    for (auto it = sessions_.begin(); it != sessions_.end();) {
      const auto session = it->second.session.lock();
      ++it;  // push() may close the session, which erases it
      if (session) session->push(event);
    }
  });
}

void Server::stop() {
  asio::post(io_, [this] {
    if (stopped_) return;
    stopped_ = true;
    boost::system::error_code ignored;
    acceptor_.close(ignored);
    accept_retry_.cancel();
    std::vector<std::shared_ptr<Session>> open;
    for (auto& [id, entry] : sessions_) {
      if (auto session = entry.session.lock()) open.push_back(std::move(session));
    }
    for (auto& session : open) session->close();
    sessions_.clear();
    streams_.clear();
  });
}

ServerCounts Server::counts() const {
  ServerCounts c;
  c.accepted = counters_->accepted;
  c.requests = counters_->requests;
  c.refused_busy = counters_->refused_busy;
  c.refused_address = counters_->refused_address;
  c.timed_out = counters_->timed_out;
  c.too_large = counters_->too_large;
  c.bad_requests = counters_->bad_requests;
  c.streams_behind = counters_->streams_behind;
  c.open = counters_->open;
  c.streams = counters_->streams;
  c.websockets = counters_->websockets;
  return c;
}

}  // namespace optique::http
