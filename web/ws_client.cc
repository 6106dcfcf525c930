#include "ws_client.h"

#include "hub.h"

namespace snapthread::web {

namespace beast = boost::beast;
namespace websocket = beast::websocket;

WsClient::WsClient(boost::asio::ip::tcp::socket&& socket, std::shared_ptr<Hub> hub,
                   double max_rate_hz)
    : ws_(std::move(socket)), hub_(std::move(hub)), pacer_(max_rate_hz), timer_(ws_.get_executor()) {
  hub_->access().open_pages++;
}

WsClient::~WsClient() {
  hub_->Leave(this);
  hub_->access().open_pages--;
}

void WsClient::Accept(beast::http::request<beast::http::string_body> request,
                      std::vector<std::pair<std::string, std::string>> headers) {
  ws_.set_option(websocket::stream_base::decorator(
      [headers = std::move(headers)](websocket::response_type& response) {
        response.set(beast::http::field::server, "snapthread-web");
        for (const auto& [name, value] : headers) response.set(name, value);
      }));
  // Beast's suggested server timeouts: the handshake must finish, and a page that stops
  // answering pings is dropped.
  beast::get_lowest_layer(ws_).expires_never();
  ws_.set_option(websocket::stream_base::timeout::suggested(beast::role_type::server));
  ws_.read_message_max(kMaxCommandBytes);
  ws_.async_accept(request, [self = shared_from_this()](const beast::error_code& ec) {
    self->OnAccept(ec);
  });
}

void WsClient::OnAccept(const beast::error_code& ec) {
  if (ec) return;
  open_ = true;
  ws_.text(true);
  hub_->Join(this);
  Read();
  Pump();
}

void WsClient::Read() {
  ws_.async_read(read_buffer_, [self = shared_from_this()](const beast::error_code& ec, size_t) {
    if (ec) {
      self->Close();
      return;
    }
    const std::string text = beast::buffers_to_string(self->read_buffer_.data());
    self->read_buffer_.consume(self->read_buffer_.size());
    self->hub_->OnClientMessage(self.get(), text);
    self->Read();
  });
}

void WsClient::Close() {
  open_ = false;
  hub_->Leave(this);
  timer_.cancel();
}

void WsClient::Offer(FeedKind kind, Text text) {
  if (!open_) return;
  pacer_.Offer(kind, std::move(text));
  Pump();
}

void WsClient::Acked() {
  pacer_.Ack();
  Pump();
}

void WsClient::Pump() {
  if (!open_ || writing_) return;
  ClientPacer::Next next = pacer_.Take(Clock::now());
  if (!next.text) {
    // Paced kinds pending: ask again when the first may go (one timer at a time; the
    // intervals are equal, so an armed timer is never later than needed).
    if (next.wait && !timer_armed_) {
      timer_armed_ = true;
      timer_.expires_at(next.at);
      timer_.async_wait([self = shared_from_this()](const beast::error_code&) {
        self->timer_armed_ = false;
        self->Pump();
      });
    }
    return;
  }
  writing_ = std::move(next.text);
  ws_.async_write(boost::asio::buffer(*writing_),
                  [self = shared_from_this()](const beast::error_code& ec, size_t) {
                    self->writing_.reset();
                    if (ec) {
                      self->Close();
                      return;
                    }
                    self->Pump();
                  });
}

}  // namespace snapthread::web
