// A Foxglove WebSocket server (the protocol of foxglove_bridge: subprotocols foxglove.sdk.v1 and
// foxglove.websocket.v1, JSON-encoded channels, the `time` and, with control on, `clientPublish`
// capabilities) and the HTTP server of the project's own page, on one thread of their own.
//
// Safe by default: it binds 127.0.0.1; any other address needs a token (generated and printed when
// none is given), and so does control. A browser's Origin must be the page's own or an allowed one;
// the HTTP side serves the page's compiled-in files and nothing else; client messages are limited in
// size and count; a client that does not read loses messages (counted), then its connection, and a
// publisher never waits for any client.
#pragma once

#include <cstdint>
#include <functional>
#include <map>
#include <memory>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "mbot/viewer/foxglove_encoder.hpp"

namespace mbot::viewer {

struct ServerOptions {
  std::string address = "127.0.0.1";
  int port = 8765;                           // the WebSocket port; 0 picks a free one (tests)
  int http_port = 8080;                      // the page; 0 picks a free one, -1 serves no page
  std::string token;                         // required of every client when set
  bool control = false;                      // clients may publish a goal and teleop (needs a token)
  std::vector<std::string> allowed_origins;  // besides the page's own and Foxglove's web app
  int max_clients = 16;
  size_t max_client_message_bytes = 64 * 1024;
  size_t max_client_backlog_bytes = 8u << 20;  // unsent bytes past which a client's messages drop
  double stalled_client_timeout_s = 10.0;      // dropping that long: the connection is closed
  std::string name = "mbot_nav";
  std::map<std::string, std::string> metadata;  // serverInfo's metadata (what the page may offer)
};

struct ServerStats {
  int clients = 0;                                // connected now
  long long connections = 0, refused = 0;         // accepted and refused handshakes, in all
  long long closed_slow = 0, closed_abusive = 0;  // connections the server closed, and why
  long long client_messages = 0, client_errors = 0;
  long long dropped_slow = 0;  // messages not sent to a client that did not read
  std::map<std::string, long long> messages_by_topic, bytes_by_topic;  // what was sent, all clients
};

class FoxgloveServer {
 public:
  FoxgloveServer(ServerOptions options, std::vector<ChannelSpec> channels);
  ~FoxgloveServer();
  FoxgloveServer(const FoxgloveServer&) = delete;
  FoxgloveServer& operator=(const FoxgloveServer&) = delete;

  // Binds both ports and starts the thread; throws std::runtime_error naming the address and port
  // that could not be bound, or an unsafe option (a non-loopback address or control without token).
  void Start();
  // Closes every connection and joins the thread. Safe to call twice.
  void Stop();

  int port() const;
  int http_port() const;
  const ServerOptions& options() const;

  // Thread-safe, never blocks: the message goes to every client subscribed to the topic.
  void Publish(const std::string& topic, int64_t t_us, std::string payload);
  // The data's clock (`time` capability), to every client.
  void PublishTime(int64_t t_us);
  // A message a client published on a channel it advertised (control on): the topic it named,
  // the schema name, the parsed JSON. Called on the server's thread; keep it short.
  using ClientMessageHandler =
      std::function<void(const std::string& topic, const std::string& schema_name, const nlohmann::json& message)>;
  void OnClientMessage(ClientMessageHandler handler);

  ServerStats Stats() const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

// True for 127.0.0.0/8, ::1 and "localhost".
bool IsLoopback(const std::string& address);
// 32 random hex digits.
std::string NewToken();

}  // namespace mbot::viewer
