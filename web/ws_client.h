// One page's WebSocket (Boost.Beast): the upgrade, a read loop for the page's commands
// (small text messages) and a write loop that sends what the client's pacer gives, one
// message at a time. A page that reads slowly keeps a write pending; meanwhile new
// messages only replace the pacer's slots (latest wins), so memory stays bounded.
// Lives on the io thread; held by its pending operations (shared_from_this).
#pragma once

#include <memory>
#include <string>
#include <utility>
#include <vector>

#include <boost/asio/ip/tcp.hpp>
#include <boost/asio/steady_timer.hpp>
#include <boost/beast/core.hpp>
#include <boost/beast/http.hpp>
#include <boost/beast/websocket.hpp>

#include "client_pacer.h"

namespace snapthread::web {

class Hub;

class WsClient : public std::enable_shared_from_this<WsClient> {
 public:
  static constexpr size_t kMaxCommandBytes = 1024;

  WsClient(boost::asio::ip::tcp::socket&& socket, std::shared_ptr<Hub> hub, double max_rate_hz);
  ~WsClient();

  // Completes the upgrade of `request` (already checked: access_policy.h), its 101 response
  // carrying `headers` (security_headers.h), then joins the hub.
  void Accept(boost::beast::http::request<boost::beast::http::string_body> request,
              std::vector<std::pair<std::string, std::string>> headers);
  void Offer(FeedKind kind, Text text);
  void Acked();  // the page handled a shape or force model
  const ClientPacer& pacer() const { return pacer_; }

 private:
  void OnAccept(const boost::beast::error_code& ec);
  void Read();
  void Pump();
  void Close();

  boost::beast::websocket::stream<boost::beast::tcp_stream> ws_;
  std::shared_ptr<Hub> hub_;
  ClientPacer pacer_;
  boost::beast::flat_buffer read_buffer_;
  boost::asio::steady_timer timer_;
  Text writing_;  // the message being written (null: none)
  bool timer_armed_ = false;
  bool open_ = false;
};

}  // namespace snapthread::web
