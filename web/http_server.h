// The bridge's HTTP side (Boost.Beast): accepts connections on the bind address, serves
// the page's files (GET/HEAD) and hands WebSocket upgrades of /ws to a WsClient. When a
// token is required, every request without ?token=<token> gets 401 before anything else.
#pragma once

#include <memory>
#include <string>

#include <boost/asio/io_context.hpp>
#include <boost/asio/ip/tcp.hpp>

#include "hub.h"
#include "page_files.h"

namespace snapthread::web {

struct ServeConfig {
  std::shared_ptr<Hub> hub;
  std::shared_ptr<const PageFiles> files;
  std::string token;       // "" = no token required
  double max_rate_hz = 60.0;
};

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
