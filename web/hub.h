// Fans the session's messages out to every connected page. Publish() may be called from
// any thread (the LCM feed, the replay player): it posts to the io thread, where the hub
// keeps the latest message of each kind (a page that connects gets them at once) and offers
// each to every client's pacer (latest wins per client). Everything else runs on the io
// thread. PublishStats() (the app calls it once a second) sends the bridge's own counters
// ("bridge"). Pages hold the hub (shared_ptr), so it outlives every client, also while
// the io_context destroys the handlers left at shutdown.
#pragma once

#include <array>
#include <functional>
#include <memory>
#include <string>
#include <unordered_set>

#include <boost/asio/io_context.hpp>

#include "client_pacer.h"
#include "feed_kind.h"
#include "live_feed.h"

namespace snapthread::web {

class WsClient;

class Hub : public std::enable_shared_from_this<Hub> {
 public:
  using CommandFn = std::function<bool(const std::string&)>;
  using CountsFn = std::function<FeedCounts()>;

  // `mode` "live" or "replay", for the page; `counts` reads the feed's counters.
  Hub(boost::asio::io_context& io, std::string mode, std::string session, CountsFn counts);

  void Publish(FeedKind kind, Text text);  // any thread
  // Replay commands from pages go here (none in live mode: refused).
  void SetCommandHandler(CommandFn handler) { command_ = std::move(handler); }
  void PublishStats();  // io thread

  // io thread:
  void Join(WsClient* client);
  void Leave(WsClient* client);
  // A text message from a page: "ack" acknowledges a paced message (ClientPacer), "ping T"
  // is answered to that page alone ("pong"), the
  // rest goes to the command handler. Unknown commands are counted and ignored.
  void OnClientMessage(WsClient* client, const std::string& text);
  size_t clients() const { return clients_.size(); }

  // The HTTP side's connections and refusals (io thread), sent with the bridge counters.
  struct AccessCounts {
    int open_connections = 0;          // HTTP connections not (yet) upgraded
    int open_pages = 0;                // WebSockets
    int64_t refused_connections = 0;  // over the connection limit: closed at accept
    int64_t refused_pages = 0;        // WebSockets over --max-pages: 503
    int64_t refused_unauthorized = 0;  // no or a wrong token: 401
    int64_t refused_forbidden = 0;     // a foreign Host or Origin: 403
  };
  AccessCounts& access() { return access_; }

 private:
  boost::asio::io_context& io_;
  std::string mode_;
  std::string session_;
  CountsFn counts_;
  CommandFn command_;
  std::array<Text, kFeedKinds> latest_{};
  std::unordered_set<WsClient*> clients_;
  int64_t connections_ = 0;
  int64_t bad_commands_ = 0;
  int64_t shapes_dropped_ = 0;  // by the pacers of pages gone
  AccessCounts access_;
};

}  // namespace snapthread::web
