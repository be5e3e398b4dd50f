#include "mbot/viewer/server.hpp"

#include <atomic>
#include <chrono>
#include <cstring>
#include <mutex>
#include <random>
#include <set>
#include <stdexcept>
#include <thread>

#include <websocketpp/config/asio_no_tls.hpp>
#include <websocketpp/server.hpp>

#include "mbot/common/log.hpp"
#include "viewer_assets.hpp"

namespace mbot::viewer {

namespace {

using WsServer = websocketpp::server<websocketpp::config::asio>;
using Hdl = websocketpp::connection_hdl;
using nlohmann::json;
namespace asio = websocketpp::lib::asio;

constexpr const char* kSubprotocols[] = {"foxglove.sdk.v1", "foxglove.websocket.v1"};
constexpr int kMaxBadMessages = 20;  // a client that sends this much garbage is closed

double Now() { return std::chrono::duration<double>(std::chrono::steady_clock::now().time_since_epoch()).count(); }

// The query parameter `key` of a request target ("/?token=abc&x=1"), or "".
std::string QueryParam(const std::string& resource, const std::string& key) {
  const size_t q = resource.find('?');
  if (q == std::string::npos) return "";
  size_t pos = q + 1;
  while (pos <= resource.size()) {
    size_t amp = resource.find('&', pos);
    if (amp == std::string::npos) amp = resource.size();
    const std::string pair = resource.substr(pos, amp - pos);
    const size_t eq = pair.find('=');
    if (eq != std::string::npos && pair.substr(0, eq) == key) return pair.substr(eq + 1);
    pos = amp + 1;
  }
  return "";
}

bool ConstantTimeEqual(const std::string& a, const std::string& b) {
  if (a.size() != b.size()) return false;
  unsigned char diff = 0;
  for (size_t i = 0; i < a.size(); ++i) diff |= static_cast<unsigned char>(a[i] ^ b[i]);
  return diff == 0;
}

void PutLe(std::string* out, uint64_t v, int bytes) {
  for (int i = 0; i < bytes; ++i) out->push_back(static_cast<char>((v >> (8 * i)) & 0xff));
}

uint64_t GetLe(const std::string& s, size_t at, int bytes) {
  uint64_t v = 0;
  for (int i = 0; i < bytes; ++i) v |= uint64_t(static_cast<unsigned char>(s[at + i])) << (8 * i);
  return v;
}

}  // namespace

bool IsLoopback(const std::string& address) {
  return address == "localhost" || address == "::1" || address.rfind("127.", 0) == 0;
}

std::string NewToken() {
  std::random_device rd;
  std::string token;
  static const char* kHex = "0123456789abcdef";
  for (int i = 0; i < 32; ++i) token += kHex[rd() % 16];
  return token;
}

struct FoxgloveServer::Impl {
  struct Client {
    std::map<uint32_t, uint32_t> subscriptions;  // subscription id → channel index
    struct Advertised {
      std::string topic, schema_name;
    };
    std::map<uint32_t, Advertised> advertised;  // client channel id → what it publishes
    int bad_messages = 0;
    double stalled_since = 0;  // when its backlog first passed the limit; 0 when it reads
    std::string peer;
  };

  ServerOptions options;
  std::vector<ChannelSpec> channels;
  std::map<std::string, uint32_t> channel_by_topic;
  asio::io_service ioc;
  WsServer ws, http;
  std::thread thread;
  std::atomic<bool> running{false};
  std::atomic<size_t> pending_bytes{0};                 // posted to the server's thread, not yet delivered
  std::map<Hdl, Client, std::owner_less<Hdl>> clients;  // on the server's thread only
  std::set<std::string> origins;
  int bound_port = 0, bound_http_port = -1;

  mutable std::mutex stats_mutex;
  ServerStats stats;
  std::mutex handler_mutex;
  ClientMessageHandler handler;

  Impl(ServerOptions o, std::vector<ChannelSpec> c) : options(std::move(o)), channels(std::move(c)) {
    for (uint32_t i = 0; i < channels.size(); ++i) channel_by_topic[channels[i].topic] = i;
  }

  template <typename F>
  void Count(F f) {
    std::lock_guard<std::mutex> lock(stats_mutex);
    f(stats);
  }

  void SendText(Hdl hdl, const json& j) {
    websocketpp::lib::error_code ec;
    ws.send(hdl, j.dump(), websocketpp::frame::opcode::text, ec);
  }

  void Status(Hdl hdl, int level, const std::string& message) {
    SendText(hdl, {{"op", "status"}, {"level", level}, {"message", message}});
  }

  void Close(Hdl hdl, websocketpp::close::status::value code, const std::string& why) {
    websocketpp::lib::error_code ec;
    ws.close(hdl, code, why, ec);
    if (ec) {
      WsServer::connection_ptr con = ws.get_con_from_hdl(hdl, ec);
      if (con) con->terminate(ec);
    }
  }

  // Refuses a handshake with an HTTP status and says why in the log.
  bool Refuse(WsServer::connection_ptr con, websocketpp::http::status_code::value code, const std::string& why) {
    con->set_status(code);
    con->set_body(why + "\n");
    Count([](ServerStats& s) { ++s.refused; });
    log::Warn("viewer: refused " + con->get_remote_endpoint() + ": " + why);
    return false;
  }

  bool Validate(Hdl hdl) {
    WsServer::connection_ptr con = ws.get_con_from_hdl(hdl);
    if (static_cast<int>(clients.size()) >= options.max_clients) {
      return Refuse(con, websocketpp::http::status_code::service_unavailable,
                    "too many viewers (viewer.max_clients = " + std::to_string(options.max_clients) + ")");
    }
    const std::string origin = con->get_request_header("Origin");
    if (!origin.empty() && !origins.count(origin)) {
      return Refuse(con, websocketpp::http::status_code::forbidden,
                    "origin '" + origin + "' is not allowed (viewer.allowed_origins)");
    }
    if (!options.token.empty() && !ConstantTimeEqual(QueryParam(con->get_resource(), "token"), options.token)) {
      return Refuse(con, websocketpp::http::status_code::unauthorized,
                    "no valid token (connect to ws://host:port/?token=<the token mbot_nav printed>)");
    }
    for (const char* wanted : kSubprotocols) {
      for (const std::string& offered : con->get_requested_subprotocols()) {
        if (offered == wanted) {
          con->select_subprotocol(offered);
          return true;
        }
      }
    }
    return Refuse(con, websocketpp::http::status_code::bad_request,
                  "no supported subprotocol (foxglove.sdk.v1 or foxglove.websocket.v1)");
  }

  void OnOpen(Hdl hdl) {
    WsServer::connection_ptr con = ws.get_con_from_hdl(hdl);
    Client& c = clients[hdl];
    c.peer = con->get_remote_endpoint();
    Count([&](ServerStats& s) {
      ++s.connections;
      s.clients = static_cast<int>(clients.size());
    });
    json capabilities = json::array({"time"});
    json metadata = {{"subprotocol", con->get_subprotocol()}};
    for (const auto& [key, value] : options.metadata) metadata[key] = value;
    json info = {{"op", "serverInfo"},
                 {"name", options.name},
                 {"capabilities", capabilities},
                 {"metadata", std::move(metadata)},
                 {"sessionId", std::to_string(static_cast<long long>(Now() * 1000))}};
    if (options.control) {
      info["capabilities"].push_back("clientPublish");
      info["supportedEncodings"] = json::array({"json"});
    }
    SendText(hdl, info);
    json advertise = {{"op", "advertise"}, {"channels", json::array()}};
    for (uint32_t i = 0; i < channels.size(); ++i) {
      advertise["channels"].push_back({{"id", i + 1},
                                       {"topic", channels[i].topic},
                                       {"encoding", "json"},
                                       {"schemaName", channels[i].schema_name},
                                       {"schema", channels[i].schema},
                                       {"schemaEncoding", "jsonschema"}});
    }
    SendText(hdl, advertise);
  }

  void OnClose(Hdl hdl) {
    clients.erase(hdl);
    Count([&](ServerStats& s) { s.clients = static_cast<int>(clients.size()); });
  }

  // One bad message: a status back, and after too many the connection closes.
  void Bad(Hdl hdl, Client& c, const std::string& why) {
    Count([](ServerStats& s) { ++s.client_errors; });
    Status(hdl, 2, why);
    if (++c.bad_messages >= kMaxBadMessages) {
      Count([](ServerStats& s) { ++s.closed_abusive; });
      log::Warn("viewer: closing " + c.peer + " after " + std::to_string(kMaxBadMessages) + " bad messages (" + why +
                ")");
      Close(hdl, websocketpp::close::status::policy_violation, "too many bad messages");
    }
  }

  void OnMessage(Hdl hdl, WsServer::message_ptr msg) {
    auto it = clients.find(hdl);
    if (it == clients.end()) return;
    Client& c = it->second;
    Count([](ServerStats& s) { ++s.client_messages; });
    const std::string& data = msg->get_payload();
    if (msg->get_opcode() == websocketpp::frame::opcode::binary) {
      OnBinary(hdl, c, data);
      return;
    }
    json j = json::parse(data, nullptr, false);
    if (j.is_discarded() || !j.is_object() || !j.contains("op") || !j["op"].is_string()) {
      Bad(hdl, c, "a text message must be a JSON object with an 'op'");
      return;
    }
    const std::string op = j["op"];
    try {
      if (op == "subscribe") {
        for (const json& s : j.at("subscriptions")) {
          const uint32_t id = s.at("id").get<uint32_t>(), channel = s.at("channelId").get<uint32_t>();
          if (channel < 1 || channel > channels.size()) {
            Bad(hdl, c, "subscribe: no channel " + std::to_string(channel));
          } else if (c.subscriptions.count(id)) {
            Bad(hdl, c, "subscribe: subscription id " + std::to_string(id) + " is in use");
          } else {
            c.subscriptions[id] = channel - 1;
          }
        }
      } else if (op == "unsubscribe") {
        for (const json& id : j.at("subscriptionIds")) c.subscriptions.erase(id.get<uint32_t>());
      } else if (op == "advertise") {
        if (!options.control) {
          Bad(hdl, c, "client publishing is off (viewer.control = false)");
          return;
        }
        for (const json& ch : j.at("channels")) {
          if (ch.at("encoding").get<std::string>() != "json") {
            Bad(hdl, c, "advertise: only the json encoding is supported");
            continue;
          }
          c.advertised[ch.at("id").get<uint32_t>()] = {ch.at("topic").get<std::string>(),
                                                       ch.value("schemaName", std::string())};
        }
      } else if (op == "unadvertise") {
        for (const json& id : j.at("channelIds")) c.advertised.erase(id.get<uint32_t>());
      } else {
        Bad(hdl, c, "unsupported op '" + op + "'");
      }
    } catch (const json::exception& e) {
      Bad(hdl, c, op + ": " + e.what());
    }
  }

  void OnBinary(Hdl hdl, Client& c, const std::string& data) {
    if (data.size() < 5 || data[0] != 0x01) {
      Bad(hdl, c, "unsupported binary message (only client message data, opcode 0x01)");
      return;
    }
    const uint32_t channel = static_cast<uint32_t>(GetLe(data, 1, 4));
    auto ad = c.advertised.find(channel);
    if (ad == c.advertised.end()) {
      Bad(hdl, c, "client message data on channel " + std::to_string(channel) + ", which it did not advertise");
      return;
    }
    json message = json::parse(data.begin() + 5, data.end(), nullptr, false);
    if (message.is_discarded()) {
      Bad(hdl, c, "client message on '" + ad->second.topic + "' is not JSON");
      return;
    }
    std::lock_guard<std::mutex> lock(handler_mutex);
    if (!handler) return;
    try {
      handler(ad->second.topic, ad->second.schema_name, message);
    } catch (const std::exception& e) {
      Bad(hdl, c, "client message on '" + ad->second.topic + "': " + e.what());
    }
  }

  // On the server's thread: one message to every subscriber, unless a client has stopped reading.
  void Deliver(uint32_t channel, int64_t t_us, const std::string& payload) {
    const double now = Now();
    std::vector<Hdl> stalled;
    long long sent = 0, dropped = 0;
    for (auto& [hdl, c] : clients) {
      for (const auto& [sub, ch] : c.subscriptions) {
        if (ch != channel) continue;
        websocketpp::lib::error_code ec;
        WsServer::connection_ptr con = ws.get_con_from_hdl(hdl, ec);
        if (!con) break;
        if (con->get_buffered_amount() > options.max_client_backlog_bytes) {
          ++dropped;
          if (c.stalled_since == 0) c.stalled_since = now;
          if (now - c.stalled_since > options.stalled_client_timeout_s) stalled.push_back(hdl);
          break;
        }
        c.stalled_since = 0;
        std::string frame;
        frame.reserve(13 + payload.size());
        frame.push_back(0x01);
        PutLe(&frame, sub, 4);
        PutLe(&frame, static_cast<uint64_t>(std::max<int64_t>(t_us, 0)) * 1000, 8);
        frame += payload;
        con->send(frame, websocketpp::frame::opcode::binary);
        ++sent;
      }
    }
    const std::string& topic = channels[channel].topic;
    Count([&](ServerStats& s) {
      s.messages_by_topic[topic] += sent;
      s.bytes_by_topic[topic] += sent * static_cast<long long>(payload.size() + 13);
      s.dropped_slow += dropped;
      s.closed_slow += static_cast<long long>(stalled.size());
    });
    for (Hdl h : stalled) {
      log::Warn("viewer: closing " + clients[h].peer + ": it read nothing for " +
                std::to_string(options.stalled_client_timeout_s) + " s");
      websocketpp::lib::error_code ec;
      WsServer::connection_ptr con = ws.get_con_from_hdl(h, ec);
      if (con) con->terminate(ec);  // a close handshake would queue behind what it does not read
    }
  }

  void ServePage(Hdl hdl) {
    WsServer::connection_ptr con = http.get_con_from_hdl(hdl);
    std::string path = con->get_resource();
    path = path.substr(0, path.find('?'));
    con->append_header("Cache-Control", "no-store");
    con->append_header("X-Content-Type-Options", "nosniff");
    if (con->get_request().get_method() != "GET") {
      con->set_status(websocketpp::http::status_code::method_not_allowed);
      con->set_body("only GET\n");
      return;
    }
    if (path == "/config.json") {
      con->append_header("Content-Type", "application/json");
      con->set_body(
          json{{"ws_port", bound_port}, {"token_required", !options.token.empty()}, {"control", options.control}}
              .dump());
      con->set_status(websocketpp::http::status_code::ok);
      return;
    }
    // Only the page's own files: a fixed table, so no request reaches the file system.
    const Asset* asset = FindAsset(path == "/" ? "web/index.html" : "web" + path);
    if (!asset || path.find("..") != std::string::npos) {
      con->set_status(websocketpp::http::status_code::not_found);
      con->set_body("not found\n");
      return;
    }
    con->append_header("Content-Type", asset->mime);
    con->set_body(std::string(asset->data, asset->size));
    con->set_status(websocketpp::http::status_code::ok);
  }
};

FoxgloveServer::FoxgloveServer(ServerOptions options, std::vector<ChannelSpec> channels)
    : impl_(std::make_unique<Impl>(std::move(options), std::move(channels))) {}

FoxgloveServer::~FoxgloveServer() { Stop(); }

void FoxgloveServer::Start() {
  Impl& m = *impl_;
  ServerOptions& o = m.options;
  if (!IsLoopback(o.address) && o.token.empty()) {
    throw std::runtime_error("viewer: address " + o.address + " is not loopback: a token is required");
  }
  if (o.control && o.token.empty()) throw std::runtime_error("viewer: control needs a token");
  for (WsServer* s : {&m.ws, &m.http}) {
    s->clear_access_channels(websocketpp::log::alevel::all);
    s->clear_error_channels(websocketpp::log::elevel::all);
    s->init_asio(&m.ioc);
    s->set_reuse_addr(true);
    s->set_open_handshake_timeout(5000);
    s->set_close_handshake_timeout(2000);
    s->set_max_http_body_size(4096);
  }
  m.ws.set_max_message_size(o.max_client_message_bytes);
  // The kernel holds at most this much for a client too, so one that stops reading is seen (its
  // backlog grows here, where it is counted) instead of hidden in megabytes of socket buffer; no
  // Nagle delay on the small messages.
  m.ws.set_tcp_post_init_handler([&m](Hdl h) {
    websocketpp::lib::error_code wec;
    WsServer::connection_ptr con = m.ws.get_con_from_hdl(h, wec);
    if (!con) return;
    asio::ip::tcp::socket& socket = con->get_raw_socket();
    asio::error_code ec;
    socket.set_option(asio::socket_base::send_buffer_size(256 * 1024), ec);
    socket.set_option(asio::ip::tcp::no_delay(true), ec);
  });
  m.ws.set_validate_handler([&m](Hdl h) { return m.Validate(h); });
  m.ws.set_open_handler([&m](Hdl h) { m.OnOpen(h); });
  m.ws.set_close_handler([&m](Hdl h) { m.OnClose(h); });
  m.ws.set_fail_handler([&m](Hdl h) { m.OnClose(h); });
  m.ws.set_message_handler([&m](Hdl h, WsServer::message_ptr msg) { m.OnMessage(h, msg); });
  m.ws.set_http_handler([&m](Hdl h) {
    WsServer::connection_ptr con = m.ws.get_con_from_hdl(h);
    con->set_status(websocketpp::http::status_code::upgrade_required);
    con->set_body("a Foxglove WebSocket server: connect with Foxglove, or open the page\n");
  });
  const auto bind = [&](WsServer& s, int port, const char* key) {
    websocketpp::lib::error_code ec;
    s.listen(o.address, std::to_string(port), ec);
    if (ec) {
      throw std::runtime_error("viewer: cannot listen on " + o.address + ":" + std::to_string(port) + " (viewer." +
                               key + "): " + ec.message());
    }
    s.start_accept(ec);
    asio::error_code aec;
    return static_cast<int>(s.get_local_endpoint(aec).port());
  };
  m.bound_port = bind(m.ws, o.port, "port");
  if (o.http_port >= 0) {
    m.http.set_validate_handler([](Hdl) { return false; });  // the page's port serves files only
    m.http.set_http_handler([&m](Hdl h) { m.ServePage(h); });
    m.bound_http_port = bind(m.http, o.http_port, "http_port");
  }
  for (const std::string& host : {std::string("localhost"), std::string("127.0.0.1"), o.address}) {
    if (m.bound_http_port > 0) m.origins.insert("http://" + host + ":" + std::to_string(m.bound_http_port));
  }
  m.origins.insert("https://app.foxglove.dev");
  for (const std::string& a : o.allowed_origins) m.origins.insert(a);
  m.running = true;
  m.thread = std::thread([&m] {
    while (m.running) {
      try {
        m.ioc.run();
        break;
      } catch (const std::exception& e) {
        log::Warn(std::string("viewer: ") + e.what());
      }
    }
  });
}

void FoxgloveServer::Stop() {
  Impl& m = *impl_;
  if (!m.running.exchange(false)) return;
  asio::post(m.ioc, [&m] {
    websocketpp::lib::error_code ec;
    m.ws.stop_listening(ec);
    if (m.bound_http_port >= 0) m.http.stop_listening(ec);
    for (auto& [hdl, c] : m.clients) m.Close(hdl, websocketpp::close::status::going_away, "mbot_nav is stopping");
  });
  // The close handshakes get a moment; then whatever is left is cut.
  std::this_thread::sleep_for(std::chrono::milliseconds(100));
  m.ioc.stop();
  if (m.thread.joinable()) m.thread.join();
}

int FoxgloveServer::port() const { return impl_->bound_port; }
int FoxgloveServer::http_port() const { return impl_->bound_http_port; }
const ServerOptions& FoxgloveServer::options() const { return impl_->options; }

void FoxgloveServer::Publish(const std::string& topic, int64_t t_us, std::string payload) {
  Impl& m = *impl_;
  auto it = m.channel_by_topic.find(topic);
  if (it == m.channel_by_topic.end() || !m.running) return;
  const uint32_t channel = it->second;
  // The server's thread is behind (a burst, a machine that is busy): the newest message waits, the
  // publisher never does, and what does not fit is dropped and counted.
  const size_t size = payload.size();
  if (m.pending_bytes.load() + size > 4 * m.options.max_client_backlog_bytes) {
    m.Count([](ServerStats& s) { ++s.dropped_slow; });
    return;
  }
  m.pending_bytes += size;
  asio::post(m.ioc, [&m, channel, t_us, size, p = std::move(payload)] {
    m.Deliver(channel, t_us, p);
    m.pending_bytes -= size;
  });
}

void FoxgloveServer::PublishTime(int64_t t_us) {
  Impl& m = *impl_;
  if (!m.running) return;
  asio::post(m.ioc, [&m, t_us] {
    std::string frame(1, 0x02);
    PutLe(&frame, static_cast<uint64_t>(std::max<int64_t>(t_us, 0)) * 1000, 8);
    for (auto& [hdl, c] : m.clients) {
      websocketpp::lib::error_code ec;
      WsServer::connection_ptr con = m.ws.get_con_from_hdl(hdl, ec);
      if (con && con->get_buffered_amount() <= m.options.max_client_backlog_bytes) {
        con->send(frame, websocketpp::frame::opcode::binary);
      }
    }
  });
}

void FoxgloveServer::OnClientMessage(ClientMessageHandler handler) {
  std::lock_guard<std::mutex> lock(impl_->handler_mutex);
  impl_->handler = std::move(handler);
}

ServerStats FoxgloveServer::Stats() const {
  std::lock_guard<std::mutex> lock(impl_->stats_mutex);
  return impl_->stats;
}

}  // namespace mbot::viewer
