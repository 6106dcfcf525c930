#include <chrono>
#include <csignal>
#include <cstdio>
#include <exception>
#include <memory>
#include <optional>

#include <boost/asio/io_context.hpp>
#include <boost/asio/ip/address.hpp>
#include <boost/asio/signal_set.hpp>
#include <boost/asio/steady_timer.hpp>

#include "access_policy.h"
#include "app/common_flags.h"
#include "auth/key_set.h"
#include "http_server.h"
#include "hub.h"
#include "live_feed.h"
#include "messages/channels.h"
#include "observer_token.h"
#include "replay_feed.h"
#include "web_options.h"

namespace snapthread::web {
namespace {

namespace asio = boost::asio;

// The once-a-second "bridge" counters, on the io thread.
void ScheduleStats(asio::steady_timer* timer, Hub* hub) {
  timer->expires_after(std::chrono::seconds(1));
  timer->async_wait([timer, hub](const boost::system::error_code& ec) {
    if (ec) return;
    hub->PublishStats();
    ScheduleStats(timer, hub);
  });
}

// The observer token: --token-file's, checked, or a new one beyond loopback. False after
// saying why it cannot be used.
bool ResolveToken(const asio::ip::address& address, WebOptions* o) {
  // Beyond loopback the page is for the observers holding the token only (observer_token.h).
  try {
    if (!o->token_file.empty()) o->token = LoadTokenFile(o->token_file);
  } catch (const std::exception& e) {
    std::fprintf(stderr, "snapthread-web: %s\n", e.what());
    return false;
  }
  if (!o->token.empty()) {
    if (const std::string problem = TokenProblem(o->token); !problem.empty()) {
      std::fprintf(stderr, "snapthread-web: bad --token: %s\n", problem.c_str());
      return false;
    }
  }
  if (!address.is_loopback() && o->token.empty()) o->token = GenerateObserverToken();
  return true;
}

// The hub and the feed that publishes to it: a replay of --log, or the live session. The
// feed's callbacks hold this object's address: it stays where it is while they run.
struct Feeds {
  std::unique_ptr<LiveFeed> live;
  std::unique_ptr<ReplayFeed> replay;
  std::optional<auth::KeySet> keys;  // the observer credential (or the root key)
  std::shared_ptr<Hub> hub;
  const std::string& session(const WebOptions& o) const { return replay ? replay->session() : o.common.session; }
};

// Opens the feed of `o` into `f` with the keys in `f`; throws with the reason when it cannot.
void OpenFeeds(asio::io_context& io, const WebOptions& o, Feeds* f) {
  auto publish = [f](FeedKind k, Text t) { f->hub->Publish(k, std::move(t)); };
  const auth::PublicKey& server_key = f->keys->server_public_key();
  if (!o.log_path.empty()) {
    // The hub is set below, once it exists: the feed publishes to it.
    f->replay = std::make_unique<ReplayFeed>(o.log_path, o.common.session, server_key,
                                             &f->keys->read_key(), publish);
    f->hub = std::make_shared<Hub>(io, "replay", f->replay->session(), [f] { return f->replay->counts(); });
    f->hub->SetCommandHandler([f](const std::string& c) { return f->replay->Command(c); });
    const ReplayPosition p = f->replay->position();
    // The log's session name is the log's text: shown escaped.
    std::printf("snapthread-web: replaying %s: session %s, %lld shapes over %.1f s (last seq %lld)\n",
                o.log_path.c_str(), messages::EscapeForDisplay(f->replay->session()).c_str(),
                static_cast<long long>(p.shape_count), p.duration_s, static_cast<long long>(p.last_seq));
  } else {
    f->hub = std::make_shared<Hub>(io, "live", o.common.session, [f] { return f->live->counts(); });
    f->live = std::make_unique<LiveFeed>(o.lcm_url, o.common.session, server_key, publish);
  }
}

// The one place the token is printed: in the URL for the operator to open (the page then
// moves it into a cookie and out of the address bar). With --host-name, the URL names
// the first, as browsers on other machines reach the bridge by it.
void PrintPageUrl(const WebOptions& o, const asio::ip::address& address, const Feeds& feeds, unsigned port) {
  const std::string host = !o.host_names.empty() ? o.host_names.front()
                           : address.is_v6()     ? "[" + o.bind + "]"
                                                 : o.bind;
  std::printf("snapthread-web: serving %s of session %s at http://%s:%u/%s\n",
              feeds.replay ? "a replay" : "the live view", messages::EscapeForDisplay(feeds.session(o)).c_str(),
              host.c_str(), port, o.token.empty() ? "" : ("?token=" + o.token).c_str());
  std::fflush(stdout);
}

// Serves until SIGINT / SIGTERM or --duration-s, then stops the feeds.
void Serve(asio::io_context& io, const WebOptions& o, HttpServer* server, Feeds* feeds) {
  asio::signal_set signals(io, SIGINT, SIGTERM);
  asio::steady_timer stats(io);
  asio::steady_timer deadline(io);
  auto stop = [&] {
    server->Stop();
    io.stop();
  };
  signals.async_wait([&](const boost::system::error_code&, int) { stop(); });
  if (o.duration_s > 0) {
    deadline.expires_after(std::chrono::duration_cast<std::chrono::steady_clock::duration>(
        std::chrono::duration<double>(o.duration_s)));
    deadline.async_wait([&](const boost::system::error_code& e) {
      if (!e) stop();
    });
  }
  ScheduleStats(&stats, feeds->hub.get());
  server->Start();
  if (feeds->live) feeds->live->Start();
  if (feeds->replay) feeds->replay->Start();
  io.run();
  // The feeds stop before the hub and the io_context go (they post to both).
  if (feeds->live) feeds->live->Stop();
  if (feeds->replay) feeds->replay->Stop();
}

}  // namespace

int RunWeb(WebOptions o) {
  asio::io_context io;
  boost::system::error_code ec;
  const asio::ip::address address = asio::ip::make_address(o.bind, ec);
  if (ec) {
    std::fprintf(stderr, "snapthread-web: --bind '%s' is not an IP address\n", o.bind.c_str());
    return app::kExitUsage;
  }
  if (!ResolveToken(address, &o)) return 1;
  Feeds feeds;
  // An observer credential (or the root key): a device's or an operator's is refused,
  // naming the observer role.
  feeds.keys = app::LoadKeySet(o.common, auth::Role::kObserver, "snapthread-web");
  if (!feeds.keys) return 1;
  std::shared_ptr<const PageFiles> files;
  std::optional<HttpServer> server;
  try {
    files = std::make_shared<const PageFiles>(o.page_dir);
    OpenFeeds(io, o, &feeds);
  } catch (const std::exception& e) {
    std::fprintf(stderr, "snapthread-web: %s\n", e.what());
    return 1;
  }
  try {
    server.emplace(io, asio::ip::tcp::endpoint(address, static_cast<unsigned short>(o.port)),
                   ServeConfig{feeds.hub, files, AccessConfig{o.token, o.host_names, 0}, o.max_rate_hz,
                               o.max_pages});
  } catch (const std::exception& e) {
    std::fprintf(stderr, "snapthread-web: %s\n", e.what());
    return 1;
  }
  PrintPageUrl(o, address, feeds, server->port());
  Serve(io, o, &*server, &feeds);
  std::printf("snapthread-web: stopped\n");
  return 0;
}

}  // namespace snapthread::web
