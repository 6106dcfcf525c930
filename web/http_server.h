// The bridge's HTTP side (Boost.Beast): accepts connections on the bind address, serves
// the page's files (GET/HEAD) and hands WebSocket upgrades of /ws to a WsClient. Every
// request passes access_policy.h first (Host, the token, a WebSocket's Origin), and every
// response carries security_headers.h. At most `max_pages` WebSockets are open at once
// (more get 503) and at most kConnectionsPerPage times as many plain HTTP connections
// (more are closed at accept); each refusal is counted (Hub::AccessCounts).
#pragma once

#include <memory>
#include <string>

#include <boost/asio/io_context.hpp>
#include <boost/asio/ip/tcp.hpp>

#include "access_policy.h"
#include "hub.h"
#include "page_files.h"

namespace snapthread::web {

struct ServeConfig {
  std::shared_ptr<Hub> hub;
  std::shared_ptr<const PageFiles> files;
  AccessConfig access;     // token ("" = none required), host names; the port is set on bind
  double max_rate_hz = 60.0;
  int max_pages = 16;
};

// Plain HTTP connections allowed per page (a browser opens a few in parallel to load one).
inline constexpr int kConnectionsPerPage = 4;

class HttpServer {
 public:
  // Binds and listens; throws std::runtime_error (naming the address) when it cannot.
  HttpServer(boost::asio::io_context& io, const boost::asio::ip::tcp::endpoint& endpoint,
             ServeConfig config);
  void Start();
  void Stop();
  // The port actually bound (the one asked for, or the kernel's choice for 0).
  unsigned short port() const;

 private:
  void Accept();

  boost::asio::io_context& io_;
  boost::asio::ip::tcp::acceptor acceptor_;
  std::shared_ptr<const ServeConfig> config_;
};

}  // namespace snapthread::web
