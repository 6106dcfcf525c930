// snapthread-web's parts without a server: the JSON the page reads, the per-page pacing
// (latest wins, at most 60 Hz), the observer token, the page's files, and the replay of
// a log written here.
#include <chrono>
#include <cmath>
#include <fstream>
#include <mutex>
#include <set>
#include <string>
#include <thread>
#include <vector>

#include <gtest/gtest.h>
#include <lcm/lcm-cpp.hpp>

#include "auth/credential.h"
#include "auth/key_set.h"
#include "auth/message_mac.h"
#include "auth/sealed_message.h"
#include "client_pacer.h"
#include "json_writer.h"
#include "message_json.h"
#include "observer_token.h"
#include "page_files.h"
#include "replay_feed.h"
#include "sample_messages.h"
#include "temp_dir.h"
#include "environment.h"

namespace snapthread::web {
namespace {

using namespace std::chrono_literals;

TEST(JsonWriter, EscapesStringsAndWritesNonFiniteNumbersAsNull) {
  JsonWriter w;
  w.BeginObject().String("s", "a\"b\\c\n\x01").Number("nan", std::nan("")).Number("x", 0.25);
  w.BeginArray("v").Element(1).Element(2).EndArray().EndObject();
  EXPECT_EQ(w.text(), R"({"s":"a\"b\\c\n\u0001","nan":null,"x":0.25,"v":[1,2]})");
}

TEST(MessageJson, ShapeCarriesWhatThePageDraws) {
  const thread_shape_t shape = test_support::SampleShape(3);
  const std::string json = ShapeJson(shape, true);
  EXPECT_NE(json.find(R"("type":"shape")"), std::string::npos) << json;
  EXPECT_NE(json.find(R"("positions":[0,0,0,1,0.5,0,2,1,0])"), std::string::npos) << json;
  EXPECT_NE(json.find(R"("smooth":true)"), std::string::npos) << json;
  EXPECT_NE(json.find(R"("status":2)"), std::string::npos) << json;
  EXPECT_NE(json.find(R"("force":[0,2,0])"), std::string::npos) << json;
  EXPECT_TRUE(DrawsSmooth("curve2d"));
  EXPECT_FALSE(DrawsSmooth("zeeman"));
  EXPECT_FALSE(DrawsSmooth("no such model"));
}

TEST(MessageJson, ForceModelCarriesTheChartedValues) {
  const std::string json = ForceModelJson(test_support::Sample<force_model_t>());
  EXPECT_NE(json.find(R"("solve_us":250)"), std::string::npos) << json;
  EXPECT_NE(json.find(R"("residual":1e-09)"), std::string::npos) << json;
  EXPECT_NE(json.find(R"("f_n":1.8708286933869707)"), std::string::npos) << json;  // |(-0.5,-1,-1.5)|
  EXPECT_NE(json.find(R"("force_error_n":0.00025)"), std::string::npos) << json;
  force_model_t none = test_support::Sample<force_model_t>();
  none.force_error_n = -1.0;  // no estimate: the page shows "none"
  const std::string without = ForceModelJson(none);
  EXPECT_NE(without.find(R"("force_error_n":-1)"), std::string::npos) << without;
  const std::string device = DeviceStatusJson(test_support::Sample<device_status_t>());
  EXPECT_NE(device.find(R"("round_trip_us_p99":1200)"), std::string::npos) << device;
  const std::string solver = SolverStatusJson(test_support::Sample<solver_status_t>());
  EXPECT_NE(solver.find(R"("method":"higher-order")"), std::string::npos) << solver;
}

Text T(const std::string& s) { return std::make_shared<const std::string>(s); }

TEST(ClientPacer, AOneKilohertzStreamReachesAPageAtMostSixtyTimesASecondLatestFirst) {
  ClientPacer pacer(60.0);
  const Clock::time_point t0 = Clock::now();
  int sent = 0;
  std::string last;
  // One second of shapes at 1 kHz; the page reads whenever the pacer allows, and
  // acknowledges each shape at once.
  for (int i = 0; i < 1000; ++i) {
    const Clock::time_point now = t0 + std::chrono::milliseconds(i);
    pacer.Offer(FeedKind::kShape, T(std::to_string(i)));
    const ClientPacer::Next next = pacer.Take(now);
    if (next.text) {
      pacer.Ack();
      sent++;
      last = *next.text;
      EXPECT_EQ(last, std::to_string(i)) << "the newest shape goes, not an old one";
    } else {
      EXPECT_TRUE(next.wait);
      EXPECT_GT(next.at, now);
    }
  }
  EXPECT_LE(sent, 61);
  EXPECT_GE(sent, 55);
  // The last shape is still waiting for its turn, and goes when it comes.
  const ClientPacer::Next last_one = pacer.Take(t0 + 1100ms);
  ASSERT_TRUE(last_one.text);
  EXPECT_EQ(*last_one.text, "999");
  EXPECT_EQ(pacer.sent(FeedKind::kShape), sent + 1);
  EXPECT_EQ(pacer.dropped(FeedKind::kShape) + sent + 1, 1000);
}

TEST(ClientPacer, AStalledPageHoldsOneMessagePerKindAndStatusesGoFirst) {
  ClientPacer pacer(60.0);
  for (int i = 0; i < 10000; ++i) pacer.Offer(FeedKind::kShape, T("shape" + std::to_string(i)));
  pacer.Offer(FeedKind::kSolverStatus, T("status"));
  const Clock::time_point now = Clock::now();
  ClientPacer::Next first = pacer.Take(now);
  ASSERT_TRUE(first.text);
  EXPECT_EQ(*first.text, "status");
  ClientPacer::Next second = pacer.Take(now);
  ASSERT_TRUE(second.text);
  EXPECT_EQ(*second.text, "shape9999");
  const ClientPacer::Next third = pacer.Take(now);
  EXPECT_FALSE(third.text);
  EXPECT_FALSE(third.wait) << "nothing is left once the latest went";
  EXPECT_EQ(pacer.dropped(FeedKind::kShape), 9999);
}

TEST(ClientPacer, APageThatDoesNotAcknowledgeGetsNoMoreThanTheWindow) {
  ClientPacer pacer(60.0);
  Clock::time_point now = Clock::now();
  int sent = 0;
  for (int i = 0; i < 100; ++i, now += 20ms) {  // 50 Hz: each shape may go at once
    pacer.Offer(FeedKind::kShape, T(std::to_string(i)));
    sent += pacer.Take(now).text != nullptr;
  }
  EXPECT_EQ(sent, ClientPacer::kWindow) << "no acknowledgement, no more shapes";
  EXPECT_EQ(pacer.in_flight(), ClientPacer::kWindow);
  pacer.Offer(FeedKind::kDeviceStatus, T("status"));
  const ClientPacer::Next status = pacer.Take(now);
  ASSERT_TRUE(status.text) << "unpaced kinds are not held by the window";
  EXPECT_EQ(*status.text, "status");
  EXPECT_FALSE(pacer.Take(now).text);
  pacer.Ack();
  const ClientPacer::Next latest = pacer.Take(now);
  ASSERT_TRUE(latest.text);
  EXPECT_EQ(*latest.text, "99") << "after the acknowledgement the latest shape goes";
}

TEST(ObserverToken, ComesFromTheQueryAndComparesExactly) {
  const std::string a = GenerateObserverToken(), b = GenerateObserverToken();
  EXPECT_EQ(a.size(), 32u);
  EXPECT_NE(a, b);
  EXPECT_EQ(QueryParameter("/ws?x=1&token=abc&y", "token"), "abc");
  EXPECT_EQ(QueryParameter("/?token=", "token"), "");
  EXPECT_EQ(QueryParameter("/index.html", "token"), "");
  EXPECT_EQ(TargetPath("/ws?token=abc"), "/ws");
  EXPECT_TRUE(TokenMatches(a, a));
  EXPECT_FALSE(TokenMatches(a.substr(0, 31), a));
  EXPECT_FALSE(TokenMatches(b, a));
  EXPECT_FALSE(TokenMatches("", "")) << "an empty expected token never matches";
}

TEST(PageFiles, ServesOnlyTheFilesOfTheFolder) {
  test_support::ScopedTempDir dir("web-page");
  std::ofstream(dir.path() + "/index.html") << "<html></html>";
  std::ofstream(dir.path() + "/app.js") << "let x;";
  const PageFiles files(dir.path());
  ASSERT_NE(files.Find("/"), nullptr);
  EXPECT_EQ(files.Find("/")->content, "<html></html>");
  EXPECT_EQ(files.Find("/app.js")->content_type, "text/javascript; charset=utf-8");
  EXPECT_EQ(files.Find("/../app.js"), nullptr);
  EXPECT_EQ(files.Find("/sub/app.js"), nullptr);
  EXPECT_EQ(files.Find("app.js"), nullptr);
  EXPECT_EQ(files.Find("/missing.js"), nullptr);
  test_support::ScopedTempDir empty("web-empty");
  EXPECT_THROW(PageFiles{empty.path()}, std::runtime_error);
}

// The keys of a logged session: its server (root key) and the observer credential that
// reviews the log, and another session's server.
struct LogKeys {
  auth::SessionKey root = auth::SessionKey::Generate();
  auth::KeySet server = auth::KeySet::FromRoot(auth::SessionKey::FromBytes(root.data(), auth::SessionKey::kBytes));
  auth::KeySet observer =
      auth::KeySet::FromCredential(auth::IssueCredential(root, auth::Role::kObserver, "", auth::kNeverExpires));
  auth::KeySet other_server = auth::KeySet::FromRoot(auth::SessionKey::Generate());
};

// msg signed by `server` for `channel` (sequence `seq`), encoded.
template <class Msg>
std::vector<uint8_t> Signed(Msg msg, const std::string& channel, int64_t seq, const auth::KeySet& server) {
  EXPECT_TRUE(auth::Sign(&msg, channel, 77, seq, server.tagger()));
  return test_support::Encode(msg);
}

// A log of `shapes` shapes of session S 10 ms apart signed by keys.server, with a status,
// a shape of another session, a malformed shape, a shape signed by another session's
// server and a force model the server did not sign mixed in. `sealed`: every message as
// the sealed_t envelope a session run with --encrypt publishes (and the logger records).
std::string WriteLog(const std::string& dir, int shapes, const LogKeys& keys, bool sealed = false) {
  const std::string path = dir + "/session.lcmlog";
  lcm::LogFile log(path, "w");
  if (sealed) auth::SetSealing(keys.server.read_key(), nullptr, true);
  auto write = [&](const std::string& channel, const std::vector<uint8_t>& bytes, int64_t t_us) {
    const auth::ByteView out = auth::SealForChannel(auth::ByteView{bytes.data(), bytes.size()}, channel);
    lcm::LogEvent e;
    e.eventnum = 0;
    e.timestamp = 1'000'000 + t_us;
    e.channel = channel;
    e.datalen = static_cast<int32_t>(out.size);
    e.data = const_cast<uint8_t*>(out.data);
    log.writeEvent(&e);
  };
  write("S_SOLVER_STATUS", Signed(test_support::Sample<solver_status_t>(), "S_SOLVER_STATUS", 1, keys.server), 0);
  for (int i = 0; i < shapes; ++i) {
    thread_shape_t s = test_support::SampleShape(4);
    s.seq = 100 + i;
    write("S_SHAPE", Signed(s, "S_SHAPE", 2 + i, keys.server), 10'000 * i);
    if (i == 2) write("OTHER_SHAPE", Signed(s, "OTHER_SHAPE", 2 + i, keys.server), 10'000 * i + 1);
    if (i == 3) write("S_SHAPE", {1, 2, 3}, 10'000 * i + 2);
    if (i == 4) {
      s.seq = 999;
      write("S_SHAPE", Signed(s, "S_SHAPE", 1000, keys.other_server), 10'000 * i + 3);
      write("S_FORCE_MODEL", test_support::Encode(test_support::Sample<force_model_t>()), 10'000 * i + 4);
    }
  }
  auth::ClearSealing();
  return path;
}

struct Received {
  std::mutex mutex;
  std::vector<std::pair<FeedKind, std::string>> messages;
  void Add(FeedKind k, Text t) {
    std::lock_guard<std::mutex> lock(mutex);
    messages.emplace_back(k, *t);
  }
  std::string LastShape() {
    std::lock_guard<std::mutex> lock(mutex);
    for (auto it = messages.rbegin(); it != messages.rend(); ++it) {
      if (it->first == FeedKind::kShape) return it->second;
    }
    return "";
  }
};

// Reviewed with an observer credential: the server's signed messages play; the shape signed
// by another session's server is refused and counted, the unsigned force model skipped.
TEST(ReplayFeed, PlaysTheSessionToItsLastShapeAndSeeksBack) {
  test_support::ScopedTempDir dir("web-replay");
  const LogKeys keys;
  const std::string path = WriteLog(dir.path(), 20, keys);
  Received received;
  ReplayFeed replay(path, "", keys.observer.server_public_key(), &keys.observer.read_key(),
                    [&](FeedKind k, Text t) { received.Add(k, std::move(t)); });
  EXPECT_EQ(replay.session(), "S");
  EXPECT_EQ(replay.counts().malformed, 1);
  EXPECT_EQ(replay.counts().auth_rejected, 1) << "the shape signed by another server";
  EXPECT_EQ(replay.counts().received[Index(FeedKind::kForceModel)], 0) << "the unsigned force model";
  EXPECT_EQ(replay.counts().received[Index(FeedKind::kShape)], 20) << "OTHER_SHAPE is not S's";
  EXPECT_EQ(replay.counts().received[Index(FeedKind::kSolverStatus)], 1)
      << "the status before the first shape is the session's too";
  ReplayPosition p = replay.position();
  EXPECT_EQ(p.shape_count, 20);
  EXPECT_EQ(p.last_seq, 119);
  EXPECT_NEAR(p.duration_s, 0.19, 1e-9);

  EXPECT_TRUE(replay.Command("speed 4"));
  EXPECT_FALSE(replay.Command("speed -1"));
  EXPECT_FALSE(replay.Command("seek nan"));
  EXPECT_FALSE(replay.Command("rm -rf"));
  replay.Start();
  ASSERT_TRUE(test_support::WaitUntil([&] { return replay.position().at_end; }, 10.0));
  p = replay.position();
  EXPECT_EQ(p.shape_index, 20);
  EXPECT_TRUE(p.paused) << "the replay stays on its last frame";
  EXPECT_NE(received.LastShape().find(R"("seq":119)"), std::string::npos);

  EXPECT_TRUE(replay.Command("seek 0.055"));  // between shapes 5 (50 ms) and 6 (60 ms)
  p = replay.position();
  EXPECT_EQ(p.shape_index, 6);
  EXPECT_FALSE(p.at_end);
  EXPECT_NE(received.LastShape().find(R"("seq":105)"), std::string::npos) << received.LastShape();
  replay.Stop();
}

TEST(ReplayFeed, RefusesALogWithoutShapes) {
  test_support::ScopedTempDir dir("web-replay-empty");
  const LogKeys keys;
  const auth::PublicKey& server = keys.observer.server_public_key();
  const std::string path = WriteLog(dir.path(), 0, keys);
  EXPECT_THROW(ReplayFeed(path, "", server, nullptr, [](FeedKind, Text) {}), std::runtime_error);
  EXPECT_THROW(ReplayFeed(dir.path() + "/missing.lcmlog", "", server, nullptr, [](FeedKind, Text) {}),
               std::runtime_error);
}

// An observer credential of another session finds no genuine shape in the log: refused,
// saying how many messages its key refused.
TEST(ReplayFeed, RefusesALogOfAnotherSessionsServer) {
  test_support::ScopedTempDir dir("web-replay-foreign");
  const LogKeys keys;
  const LogKeys other;
  const std::string path = WriteLog(dir.path(), 5, keys);
  try {
    ReplayFeed replay(path, "", other.observer.server_public_key(), &other.observer.read_key(),
                      [](FeedKind, Text) {});
    ADD_FAILURE() << "a log of another server was replayed";
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find("refused"), std::string::npos) << e.what();
  }
}

// A log of a session run with --encrypt (sealed_t envelopes) reviewed with an observer
// credential: opened with its read key, checked and played as a clear one; without the
// read key nothing opens.
TEST(ReplayFeed, OpensASealedLogWithTheObserversReadKey) {
  test_support::ScopedTempDir dir("web-replay-sealed");
  const LogKeys keys;
  const std::string path = WriteLog(dir.path(), 10, keys, /*sealed=*/true);
  {
    lcm::LogFile log(path, "r");
    const lcm::LogEvent* first = log.readNextEvent();
    ASSERT_NE(first, nullptr);
    EXPECT_TRUE(auth::IsSealed(first->data, static_cast<std::size_t>(first->datalen))) << "the log is sealed";
  }
  ReplayFeed replay(path, "", keys.observer.server_public_key(), &keys.observer.read_key(), [](FeedKind, Text) {});
  EXPECT_EQ(replay.session(), "S");
  EXPECT_EQ(replay.counts().received[Index(FeedKind::kShape)], 10);
  EXPECT_EQ(replay.counts().received[Index(FeedKind::kSolverStatus)], 1);
  EXPECT_EQ(replay.counts().auth_rejected, 1) << "the shape signed by another server";
  EXPECT_EQ(replay.position().last_seq, 109);
  EXPECT_THROW(ReplayFeed(path, "", keys.observer.server_public_key(), nullptr, [](FeedKind, Text) {}),
               std::runtime_error);
}

}  // namespace
}  // namespace snapthread::web
