#include "http_server.h"

#include <chrono>
#include <optional>
#include <stdexcept>

#include <boost/beast/core.hpp>
#include <boost/beast/http.hpp>
#include <boost/beast/websocket.hpp>

#include "observer_token.h"
#include "ws_client.h"

namespace snapthread::web {

namespace beast = boost::beast;
namespace http = beast::http;
using tcp = boost::asio::ip::tcp;

namespace {

constexpr auto kRequestTimeout = std::chrono::seconds(30);
constexpr size_t kMaxBodyBytes = 1024;  // the page only GETs

// One HTTP connection: reads requests until the client closes it or upgrades it.
class HttpSession : public std::enable_shared_from_this<HttpSession> {
 public:
  HttpSession(tcp::socket&& socket, std::shared_ptr<const ServeConfig> config)
      : stream_(std::move(socket)), config_(std::move(config)) {}

  void Read() {
    parser_.emplace();
    parser_->body_limit(kMaxBodyBytes);
    stream_.expires_after(kRequestTimeout);
    http::async_read(stream_, buffer_, *parser_,
                     [self = shared_from_this()](const beast::error_code& ec, size_t) {
                       if (!ec) self->Handle(self->parser_->release());
                     });
  }

 private:
  void Handle(http::request<http::string_body> request) {
    const std::string target(request.target());
    if (!config_->token.empty() &&
        !TokenMatches(QueryParameter(target, "token"), config_->token)) {
      return Respond(request, http::status::unauthorized,
                     "401: this page needs the observer token: open the URL snapthread-web printed "
                     "(it ends in ?token=...)\n",
                     "text/plain; charset=utf-8");
    }
    const std::string path(TargetPath(target));
    if (beast::websocket::is_upgrade(request)) {
      if (path != "/ws") {
        return Respond(request, http::status::not_found, "no WebSocket here\n", "text/plain");
      }
      stream_.expires_never();
      std::make_shared<WsClient>(stream_.release_socket(), config_->hub, config_->max_rate_hz)
          ->Accept(std::move(request));
      return;
    }
    if (request.method() != http::verb::get && request.method() != http::verb::head) {
      return Respond(request, http::status::method_not_allowed, "GET only\n", "text/plain");
    }
    const PageFile* file = config_->files->Find(path);
    if (file == nullptr) return Respond(request, http::status::not_found, "not found\n", "text/plain");
    Respond(request, http::status::ok, file->content, file->content_type);
  }

  void Respond(const http::request<http::string_body>& request, http::status status,
               const std::string& body, const std::string& content_type) {
    auto response = std::make_shared<http::response<http::string_body>>(status, request.version());
    response->set(http::field::server, "snapthread-web");
    response->set(http::field::content_type, content_type);
    response->set(http::field::cache_control, "no-store");
    response->keep_alive(request.keep_alive());
    if (request.method() != http::verb::head) response->body() = body;
    response->content_length(body.size());
    http::async_write(stream_, *response,
                      [self = shared_from_this(), response](const beast::error_code& ec, size_t) {
                        if (ec) return;
                        if (!response->keep_alive()) {
                          beast::error_code ignored;
                          self->stream_.socket().shutdown(tcp::socket::shutdown_send, ignored);
                          return;
                        }
                        self->Read();
                      });
  }

  beast::tcp_stream stream_;
  beast::flat_buffer buffer_;
  std::optional<http::request_parser<http::string_body>> parser_;
  std::shared_ptr<const ServeConfig> config_;
};

}  // namespace

HttpServer::HttpServer(boost::asio::io_context& io, const tcp::endpoint& endpoint, ServeConfig config)
    : io_(io), acceptor_(io), config_(std::make_shared<const ServeConfig>(std::move(config))) {
  beast::error_code ec;
  const std::string where = endpoint.address().to_string() + ":" + std::to_string(endpoint.port());
  acceptor_.open(endpoint.protocol(), ec);
  if (!ec) acceptor_.set_option(boost::asio::socket_base::reuse_address(true), ec);
  if (!ec) acceptor_.bind(endpoint, ec);
  if (!ec) acceptor_.listen(boost::asio::socket_base::max_listen_connections, ec);
  if (ec) throw std::runtime_error("cannot listen on " + where + ": " + ec.message());
}

unsigned short HttpServer::port() const { return acceptor_.local_endpoint().port(); }

void HttpServer::Start() { Accept(); }

void HttpServer::Stop() {
  beast::error_code ignored;
  acceptor_.close(ignored);
}

void HttpServer::Accept() {
  acceptor_.async_accept(io_,  // one io thread: the hub and every page on it
                         [this](const beast::error_code& ec, tcp::socket socket) {
                           if (ec == boost::asio::error::operation_aborted) return;
                           if (!ec) std::make_shared<HttpSession>(std::move(socket), config_)->Read();
                           Accept();
                         });
}

}  // namespace snapthread::web
