#include "http_server.h"

#include <chrono>
#include <optional>
#include <stdexcept>
#include <utility>
#include <vector>

#include <boost/beast/core.hpp>
#include <boost/beast/http.hpp>
#include <boost/beast/websocket.hpp>

#include "observer_token.h"
#include "security_headers.h"
#include "ws_client.h"

namespace snapthread::web {

namespace beast = boost::beast;
namespace http = beast::http;
using tcp = boost::asio::ip::tcp;

namespace {

constexpr auto kRequestTimeout = std::chrono::seconds(30);
constexpr size_t kMaxBodyBytes = 1024;  // the page only GETs

// Where the connection arrived, as a Host header names it ("10.1.2.3", "[fe80::1]").
void LocalAddress(const tcp::socket& socket, std::string* text, bool* loopback) {
  beast::error_code ec;
  boost::asio::ip::address a = socket.local_endpoint(ec).address();
  if (ec) return;
  if (a.is_v6() && a.to_v6().is_v4_mapped()) {
    a = boost::asio::ip::make_address_v4(boost::asio::ip::v4_mapped, a.to_v6());
  }
  *loopback = a.is_loopback();
  *text = a.is_v6() ? "[" + a.to_string() + "]" : a.to_string();
}

// One HTTP connection: reads requests until the client closes it or upgrades it.
class HttpSession : public std::enable_shared_from_this<HttpSession> {
 public:
  HttpSession(tcp::socket&& socket, std::shared_ptr<const ServeConfig> config)
      : stream_(std::move(socket)), config_(std::move(config)) {
    config_->hub->access().open_connections++;
  }
  ~HttpSession() { config_->hub->access().open_connections--; }

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
    Hub::AccessCounts& counts = config_->hub->access();
    RequestFacts facts;
    const auto view = [](beast::string_view v) { return std::string_view(v.data(), v.size()); };
    facts.target = view(request.target());
    facts.host = view(request[http::field::host]);
    facts.origin = view(request[http::field::origin]);
    facts.cookie = view(request[http::field::cookie]);
    facts.upgrade = beast::websocket::is_upgrade(request);
    LocalAddress(stream_.socket(), &facts.local_address, &facts.local_is_loopback);
    const PageFiles& files = *config_->files;
    const AccessVerdict verdict = DecideAccess(config_->access, facts, [&files](std::string_view p) {
      return !p.empty() && p.front() == '/' && files.Find(std::string(p)) != nullptr;
    });
    host_ = verdict.host;
    if (verdict.kind == AccessVerdict::Kind::kRefuse) {
      (verdict.status == 401 ? counts.refused_unauthorized : counts.refused_forbidden)++;
      return Respond(request, static_cast<http::status>(verdict.status), verdict.why,
                     "text/plain; charset=utf-8");
    }
    if (verdict.kind == AccessVerdict::Kind::kRedirect) {
      return Respond(request, http::status::see_other, "", "text/plain; charset=utf-8",
                     {{"Location", verdict.location}, {"Set-Cookie", verdict.set_cookie}});
    }
    const std::string path(TargetPath(facts.target));
    if (facts.upgrade) {
      if (path != "/ws") {
        return Respond(request, http::status::not_found, "no WebSocket here\n", "text/plain");
      }
      if (counts.open_pages >= config_->max_pages) {
        counts.refused_pages++;
        return Respond(request, http::status::service_unavailable,
                       "503: this bridge serves at most " + std::to_string(config_->max_pages) +
                           " pages at once (--max-pages)\n",
                       "text/plain; charset=utf-8");
      }
      stream_.expires_never();
      std::make_shared<WsClient>(stream_.release_socket(), config_->hub, config_->max_rate_hz)
          ->Accept(std::move(request), SecurityHeaders(host_));
      return;
    }
    if (request.method() != http::verb::get && request.method() != http::verb::head) {
      return Respond(request, http::status::method_not_allowed, "GET only\n", "text/plain");
    }
    const PageFile* file = files.Find(path);
    if (file == nullptr) return Respond(request, http::status::not_found, "not found\n", "text/plain");
    Respond(request, http::status::ok, file->content, file->content_type);
  }

  void Respond(const http::request<http::string_body>& request, http::status status,
               const std::string& body, const std::string& content_type,
               const std::vector<std::pair<std::string, std::string>>& extra = {}) {
    auto response = std::make_shared<http::response<http::string_body>>(status, request.version());
    response->set(http::field::server, "snapthread-web");
    response->set(http::field::content_type, content_type);
    response->set(http::field::cache_control, "no-store");
    for (const auto& [name, value] : SecurityHeaders(host_)) response->set(name, value);
    for (const auto& [name, value] : extra) response->set(name, value);
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
  std::string host_;  // the accepted Host of the request being answered ("" if refused)
};

}  // namespace

HttpServer::HttpServer(boost::asio::io_context& io, const tcp::endpoint& endpoint, ServeConfig config)
    : io_(io), acceptor_(io) {
  beast::error_code ec;
  const std::string where = endpoint.address().to_string() + ":" + std::to_string(endpoint.port());
  acceptor_.open(endpoint.protocol(), ec);
  if (!ec) acceptor_.set_option(boost::asio::socket_base::reuse_address(true), ec);
  if (!ec) acceptor_.bind(endpoint, ec);
  if (!ec) acceptor_.listen(boost::asio::socket_base::max_listen_connections, ec);
  if (ec) throw std::runtime_error("cannot listen on " + where + ": " + ec.message());
  config.access.port = acceptor_.local_endpoint().port();
  config_ = std::make_shared<const ServeConfig>(std::move(config));
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
                           if (!ec) {
                             Hub::AccessCounts& counts = config_->hub->access();
                             if (counts.open_connections >= kConnectionsPerPage * config_->max_pages) {
                               counts.refused_connections++;  // the socket closes here
                             } else {
                               std::make_shared<HttpSession>(std::move(socket), config_)->Read();
                             }
                           }
                           Accept();
                         });
}

}  // namespace snapthread::web
