#include "clients/cpp/session.h"

#include <poll.h>

#include <cerrno>
#include <cstring>

#include <algorithm>
#include <array>
#include <boost/asio.hpp>
#include <vector>

#include "net/auth.h"
#include "net/envelope.h"
#include "net/framing.h"
#include "net/hello_proof.h"
#include "net/session_seal.h"

namespace optique::client {
namespace {

namespace asio = boost::asio;

// A whole scene of 100,000 instances is about 15 MB.
constexpr std::uint32_t kMaxReplyBytes = 256u << 20;

}  // namespace

// The socket, the framing, and (with the secret) the seal both ways.
struct Session::Link {
  asio::io_context io;
  asio::ip::tcp::socket socket{io};
  net::FrameReader reader{kMaxReplyBytes};
  std::optional<net::Sealer> sealer;
  std::optional<net::Opener> opener;
  std::uint64_t sequence = 0;

  Result<void> send(wire::Envelope message) {
    message.set_protocol_version(net::kProtocolVersion);
    message.set_sequence(++sequence);
    std::vector<std::uint8_t> payload(message.ByteSizeLong());
    message.SerializeToArray(payload.data(), static_cast<int>(payload.size()));
    if (sealer) payload = sealer->seal(payload);
    std::vector<std::uint8_t> bytes;
    net::append_frame(bytes, payload);
    boost::system::error_code ec;
    asio::write(socket, asio::buffer(bytes), ec);
    if (ec) return Error{"cannot send to the master: " + ec.message()};
    return {};
  }

  // Replies wait at most `timeout`; receive() then fails, with timed_out set.
  // (A socket's SO_RCVTIMEO would not do: Asio's blocking read waits again,
  // for ever, when the kernel's read times out.)
  void set_timeout(std::chrono::milliseconds timeout) {
    wait_at_most = std::max(timeout, std::chrono::milliseconds(0));
  }
  std::chrono::milliseconds wait_at_most{10000};
  bool timed_out = false;  // the last receive() failed for want of an answer in time

  // Whether bytes came before `deadline`; an error other than none says why not.
  Result<bool> readable_by(std::chrono::steady_clock::time_point deadline) {
    for (;;) {
      const auto left = std::chrono::ceil<std::chrono::milliseconds>(deadline - std::chrono::steady_clock::now());
      pollfd polled{socket.native_handle(), POLLIN, 0};
      const int ready = ::poll(&polled, 1, static_cast<int>(std::clamp<std::int64_t>(left.count(), 0, 1 << 30)));
      if (ready > 0) return true;
      if (ready == 0) return false;
      if (errno != EINTR) return Error{std::string("cannot wait for the master: ") + std::strerror(errno)};
    }
  }

  Result<wire::Envelope> receive() {
    timed_out = false;
    const auto deadline = std::chrono::steady_clock::now() + wait_at_most;
    for (;;) {
      net::DecodedFrame frame = reader.next();
      if (frame.status == net::DecodeStatus::bad) return Error{"the master sent a bad frame: " + frame.error};
      if (frame.status == net::DecodeStatus::good) {
        std::vector<std::uint8_t> payload(frame.payload.begin(), frame.payload.end());
        if (opener) {
          auto opened = opener->open(payload);
          if (!opened) {
            // A refusal of the hello comes before the sealing starts: in the clear.
            auto plain = net::parse_envelope(payload);
            if (plain && plain.value().has_refuse()) return refused(plain.value());
            return Error{opened.error()};
          }
          payload = std::move(opened).value();
        }
        auto envelope = net::parse_envelope(payload);
        if (!envelope) return Error{"the master sent what is not a message: " + envelope.error()};
        if (envelope.value().has_refuse()) return refused(envelope.value());
        if (envelope.value().has_goodbye()) {
          return Error{"the master said goodbye: " + envelope.value().goodbye().reason()};
        }
        return envelope;
      }
      auto readable = readable_by(deadline);
      if (!readable) return Error{readable.error()};
      if (!readable.value()) {
        timed_out = true;
        return Error{"no answer from the master in time"};
      }
      std::array<std::uint8_t, 65536> chunk{};
      boost::system::error_code ec;
      const std::size_t got = socket.read_some(asio::buffer(chunk), ec);
      if (ec == asio::error::eof) return Error{"the master closed the session"};
      if (ec) return Error{"no answer from the master: " + ec.message()};
      reader.append(std::span(chunk.data(), got));
    }
  }

  static Error refused(const wire::Envelope& refusal) {
    return Error{"the master refused the session: " + refusal.refuse().reason()};
  }
};

Session::Session(std::unique_ptr<Link> link) : link_(std::move(link)) {}

Session::~Session() { close(); }

Result<std::unique_ptr<Session>> Session::connect(const Options& options) {
  auto link = std::make_unique<Link>();
  boost::system::error_code ec;
  const auto address = asio::ip::make_address(options.host, ec);
  if (ec) return Error{"'" + options.host + "' is not an IP address"};
  link->socket.connect({address, options.port}, ec);
  if (ec) return Error{"cannot connect to " + options.host + ":" + std::to_string(options.port) + ": " + ec.message()};
  link->socket.set_option(asio::ip::tcp::no_delay(true));
  // A master that does not answer is an error after the timeout, not a hang.
  link->set_timeout(options.timeout);

  auto challenge = link->receive();
  if (!challenge) return Error{challenge.error()};
  if (!challenge.value().has_challenge()) return Error{"the master did not begin with a challenge"};
  wire::Envelope hello;
  hello.mutable_hello()->set_node_id(options.name);
  hello.mutable_hello()->add_capabilities("scene-session");
  std::optional<net::SessionKeys> keys;
  if (challenge.value().challenge().secret_required()) {
    if (options.secret_file.empty()) {
      return Error{"this master requires the installation's shared secret: set Options::secret_file"};
    }
    auto secret = net::load_secret_file(options.secret_file);
    if (!secret) return Error{secret.error()};
    const std::string& theirs = challenge.value().challenge().nonce();
    keys =
        net::prove_hello(secret.value(), std::span(reinterpret_cast<const std::uint8_t*>(theirs.data()), theirs.size()),
                         net::random_nonce(), net::kProtocolVersion, *hello.mutable_hello());
  }
  if (auto sent = link->send(hello); !sent) return Error{sent.error()};
  if (keys) {
    link->sealer.emplace(keys->to_master);
    link->opener.emplace(keys->to_node);
  }
  std::unique_ptr<Session> session(new Session(std::move(link)));
  session->timeout_ = options.timeout;
  // The master answers a hello only to refuse it: the first reply opens the session.
  auto scene = session->read_scene();
  if (!scene) return Error{scene.error()};
  session->scene_ = std::move(scene).value();
  return session;
}

Result<session::Reply> Session::ask(session::Request request) {
  if (!link_) return Error{"the session is closed"};
  const std::uint64_t id = next_request_++;
  request.set_id(id);
  wire::Envelope envelope;
  *envelope.mutable_session_request() = std::move(request);
  if (auto sent = link_->send(std::move(envelope)); !sent) return Error{sent.error()};
  for (;;) {
    auto got = link_->receive();
    if (!got) return Error{got.error()};
    if (got.value().has_session_event()) {
      events_.push_back(std::move(*got.value().mutable_session_event()));
    } else if (got.value().has_session_reply() &&
               (got.value().session_reply().id() == id ||
                (got.value().session_reply().id() == 0 && got.value().session_reply().has_refused()))) {
      // Id 0: the master could not read the request (too large, or not one);
      // one request is out at a time, so it is this one.
      return std::move(*got.value().mutable_session_reply());
    }
  }
}

Result<Outcome> Session::outcome_of(session::Request request, std::chrono::milliseconds timeout) {
  const bool transaction = request.has_transaction();
  const std::chrono::milliseconds usual = timeout_;
  timeout_ = std::max(timeout_, timeout);
  auto reply = ask(std::move(request));
  timeout_ = usual;
  if (!reply) return Error{reply.error()};
  Outcome outcome;
  if (reply.value().has_refused()) {
    outcome.refused = reply.value().refused();
  } else if (reply.value().has_applied()) {
    outcome.frame = reply.value().applied().frame();
  } else {
    return Error{std::string("the master answered ") + (transaction ? "a transaction" : "LoadAsset") +
                 " with something else"};
  }
  return outcome;
}

Result<Outcome> Session::apply(const Transaction& transaction) {
  session::Request request;
  *request.mutable_transaction() = transaction.message();
  return outcome_of(std::move(request), timeout_);
}

Result<Outcome> Session::load_asset(const std::string& asset, const std::string& path,
                                    std::chrono::milliseconds timeout) {
  session::Request request;
  request.mutable_load_asset()->set_asset(asset);
  request.mutable_load_asset()->set_path(path);
  return outcome_of(std::move(request), timeout);
}

Result<Outcome> Session::upload_asset(const std::string& asset, std::string glb, std::chrono::milliseconds timeout) {
  session::Request request;
  request.mutable_load_asset()->set_asset(asset);
  request.mutable_load_asset()->set_glb(std::move(glb));
  return outcome_of(std::move(request), timeout);
}

Result<session::SceneContents> Session::read_scene() {
  session::Request request;
  request.mutable_read_scene();
  auto reply = ask(std::move(request));
  if (!reply) return Error{reply.error()};
  if (!reply.value().has_scene()) return Error{"the master answered ReadScene with something else"};
  return std::move(*reply.value().mutable_scene());
}

Result<void> Session::subscribe(const session::Subscribe& kinds) {
  session::Request request;
  *request.mutable_subscribe() = kinds;
  auto reply = ask(std::move(request));
  if (!reply) return Error{reply.error()};
  if (!reply.value().has_subscribed()) return Error{"the master answered Subscribe with something else"};
  return {};
}

Result<std::optional<session::Event>> Session::next_event(std::chrono::milliseconds timeout) {
  if (!events_.empty()) {
    session::Event event = std::move(events_.front());
    events_.pop_front();
    return std::optional<session::Event>(std::move(event));
  }
  if (!link_) return Error{"the session is closed"};
  link_->set_timeout(timeout);
  for (;;) {
    auto got = link_->receive();
    if (!got && link_->timed_out) {
      link_->set_timeout(timeout_);
      return std::optional<session::Event>();
    }
    if (!got) return Error{got.error()};
    if (got.value().has_session_event()) {
      link_->set_timeout(timeout_);
      return std::optional<session::Event>(std::move(*got.value().mutable_session_event()));
    }
  }
}

void Session::close() {
  if (!link_) return;
  wire::Envelope goodbye;
  goodbye.mutable_goodbye()->set_reason("the application is done");
  (void)link_->send(std::move(goodbye));
  boost::system::error_code ignored;
  link_->socket.shutdown(asio::ip::tcp::socket::shutdown_both, ignored);
  link_.reset();
}

}  // namespace optique::client
