#include "hub.h"

#include <cmath>
#include <cstdlib>

#include <boost/asio/post.hpp>

#include "json_writer.h"
#include "ws_client.h"

namespace snapthread::web {

Hub::Hub(boost::asio::io_context& io, std::string mode, std::string session, CountsFn counts)
    : io_(io), mode_(std::move(mode)), session_(std::move(session)), counts_(std::move(counts)) {}

void Hub::Publish(FeedKind kind, Text text) {
  boost::asio::post(io_, [this, kind, text = std::move(text)]() {
    latest_[Index(kind)] = text;
    for (WsClient* c : clients_) c->Offer(kind, text);
  });
}

void Hub::Join(WsClient* client) {
  clients_.insert(client);
  connections_++;
  for (int k = 0; k < kFeedKinds; ++k) {
    if (latest_[k] && k != Index(FeedKind::kPong)) client->Offer(static_cast<FeedKind>(k), latest_[k]);
  }
}

void Hub::Leave(WsClient* client) {
  if (clients_.erase(client) > 0) shapes_dropped_ += client->pacer().dropped(FeedKind::kShape);
}

void Hub::OnClientMessage(WsClient* client, const std::string& text) {
  if (text == "ack") {
    client->Acked();
    return;
  }
  if (text.rfind("ping ", 0) == 0) {
    char* end = nullptr;
    const double t = std::strtod(text.c_str() + 5, &end);
    if (end != text.c_str() + 5 && std::isfinite(t)) {
      JsonWriter w;
      w.BeginObject().String("type", "pong").Number("t", t).EndObject();
      client->Offer(FeedKind::kPong, std::make_shared<const std::string>(w.Take()));
      return;
    }
  }
  if (!command_ || !command_(text)) bad_commands_++;
}

void Hub::PublishStats() {
  const FeedCounts c = counts_();
  int64_t dropped = shapes_dropped_;
  for (WsClient* client : clients_) dropped += client->pacer().dropped(FeedKind::kShape);
  JsonWriter w;
  w.BeginObject().String("type", "bridge").String("mode", mode_).String("session", session_);
  w.Int("clients", static_cast<int64_t>(clients_.size())).Int("connections", connections_);
  w.Int("shapes", c.received[0]).Int("force_models", c.received[1]);
  w.Int("solver_statuses", c.received[2]).Int("device_statuses", c.received[3]);
  w.Int("malformed", c.malformed).Int("auth_rejected", c.auth_rejected);
  w.Int("shapes_dropped", dropped).Int("bad_commands", bad_commands_);
  w.Int("pages_refused", access_.refused_pages).Int("connections_refused", access_.refused_connections);
  w.Int("unauthorized", access_.refused_unauthorized).Int("forbidden", access_.refused_forbidden);
  w.EndObject();
  auto text = std::make_shared<const std::string>(w.Take());
  latest_[Index(FeedKind::kBridge)] = text;
  for (WsClient* client : clients_) client->Offer(FeedKind::kBridge, text);
}

}  // namespace snapthread::web
