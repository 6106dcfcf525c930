// The attack suite, the page as a target: whoever holds a session's root key (or a
// device's credential, for its status) chooses every string the page shows, live or in a
// log handed to an observer. This test writes such a log, signed as the server and the
// device sign, with LCM's own log writer (lcm::LogFile): markup in
// the session name (its channels' prefix), the scene, the method, the model, the knot and
// the device id, each payload an <img> whose src is a marker URL on the bridge and whose
// onerror sets a marker global, a <script> and an <svg onload>; plus bytes that are not
// UTF-8 in the second half. snapthread-web replays it into headless Chromium (web_injection_check.mjs), and
// the test asserts: no marker global, no request for a marker URL, no element made from
// the text, every payload shown literally as text, the thread drawn, and no
// Content-Security-Policy violation (nothing even tried to run).
// On the code before this suite (innerHTML, no CSP) the page ran the payloads: see
// docs/security.md.
#include <algorithm>
#include <cmath>
#include <regex>
#include <string>
#include <type_traits>
#include <vector>

#include <gtest/gtest.h>
#include <lcm/lcm-cpp.hpp>

#include "auth/key_set.h"
#include "auth/message_mac.h"
#include "auth/session_epoch.h"
#include "sample_messages.h"
#include "session_key_file.h"
#include "test_support.h"

namespace snapthread::attack_test {
namespace {

using test_support::ChildProcess;
using test_support::OneLog;

// What a field carries: markup that runs script (or fetches a marker URL) when parsed as
// HTML, tagged with the field's name so a failure says which field went through.
std::string Payload(const std::string& field) {
  return "<img src=/pwned-img-" + field + " onerror=\"window.__pwned='" + field + "'\">" +
         "<script>window.__pwned='" + field + "-script'</script>" +
         "<svg onload=\"window.__pwned='" + field + "-svg'\"></svg>";
}

// A number field of a flat JSON text (the first "key": value), NaN when absent.
double Field(const std::string& json, const std::string& key) {
  const size_t at = json.find("\"" + key + "\":");
  if (at == std::string::npos) return std::nan("");
  return std::strtod(json.c_str() + at + key.size() + 3, nullptr);
}

// The hostile log: 8 s of a session at 30 shapes/s, statuses at 3 Hz, every message
// tagged by a holder of `root` (the server's signature; the device's for its status).
void WriteHostileLog(const std::string& path, const std::string& session, const auth::SessionKey& root) {
  lcm::LogFile log(path, "w");
  ASSERT_TRUE(log.good()) << path;
  const auth::KeySet server = auth::KeySet::ForRole(root, auth::Role::kServer);
  const auth::KeySet hand = auth::KeySet::ForRole(root, auth::Role::kDevice, "hand");
  int64_t event = 0;
  auth::AuthSequence auth_seq;
  auto write = [&](const std::string& channel, auto msg, int64_t t_us) {
    const bool device = std::is_same_v<decltype(msg), device_status_t>;
    if constexpr (std::is_same_v<decltype(msg), device_status_t>) {
      std::copy(hand.device_public_key()->begin(), hand.device_public_key()->end(), msg.device_public_key);
      std::copy(hand.device_certificate()->begin(), hand.device_certificate()->end(), msg.device_certificate);
    }
    ASSERT_TRUE(auth::Sign(&msg, channel, 7, auth_seq.Next(), device ? *hand.device_status_tagger() : server.tagger()));
    std::vector<uint8_t> bytes = test_support::Encode(msg);
    lcm::LogEvent e{};
    e.eventnum = event++;
    e.timestamp = 1700000000000000 + t_us;
    e.channel = channel;
    e.datalen = static_cast<int32_t>(bytes.size());
    e.data = bytes.data();
    ASSERT_EQ(log.writeEvent(&e), 0);
  };
  for (int i = 0; i < 240; ++i) {
    const int64_t t = i * 33333;
    thread_shape_t shape = test_support::SampleShape(12);
    shape.seq = i;
    shape.utime = t;
    shape.status = force_model_t::STATUS_REGULAR;
    shape.scene = Payload("shape-scene");
    shape.model = Payload("model");
    shape.knot = Payload("knot");
    // The second half adds bytes that are not UTF-8 (a browser drops a WebSocket whose
    // text is not UTF-8: the page must still get to the log's end).
    if (i >= 120) shape.knot += "\xff\xfe\xc0\xaf";
    write(session + "_SHAPE", shape, t);
    force_model_t model = test_support::Sample<force_model_t>();
    model.seq = i;
    write(session + "_FORCE_MODEL", model, t + 1);
    if (i % 10 == 0) {
      solver_status_t status = test_support::Sample<solver_status_t>();
      status.seq = i;
      status.scene = Payload("scene");
      status.method = Payload("method");
      status.knot = Payload("solver-knot");
      write(session + "_SOLVER_STATUS", status, t + 2);
      device_status_t device = test_support::Sample<device_status_t>();
      device.seq = i;
      device.device_id = Payload("device");
      write(session + "_DEVICE_STATUS", device, t + 3);
    }
  }
}

TEST(WebInjection, MarkupInEveryLoggedStringIsShownAsTextAndRunsNothing) {
  test_support::ScopedTempDir dir("web-injection");
  const std::string log = dir.path() + "/hostile.lcmlog";
  const std::string session = Payload("session");
  const test_support::SessionKeyFile root;  // the observer's side: the bridge verifies with it
  WriteHostileLog(log, session, root.key());
  if (HasFatalFailure()) return;

  ChildProcess web({test_support::BinDir() + "/snapthread-web", "--port", "0", "--log", log, "--key", root.path()},
                   OneLog(dir.path() + "/web.txt", true));
  ASSERT_TRUE(web.WaitForOutput(" at http://", 30)) << web.Out();
  std::smatch m;
  const std::string out = web.Out();
  ASSERT_TRUE(std::regex_search(out, m, std::regex(R"(at (http://\S+))"))) << out;
  const std::string url = m[1];
  EXPECT_EQ(out.find("<img"), std::string::npos) << "the log's session is printed escaped: " << out;

  ChildProcess node({SNAPTHREAD_NODE, SNAPTHREAD_WEB_INJECTION_CHECK, SNAPTHREAD_WEB_NODE_MODULES, url,
                     dir.path()},
                    test_support::OutputFiles(dir.path() + "/check.json", dir.path() + "/check.err"));
  const test_support::ProcessResult r = node.Finish(240);
  ASSERT_TRUE(r.exited) << "web_injection_check timed out: " << r.err;
  ASSERT_EQ(r.exit_code, 0) << r.out << r.err;
  const std::string& result = r.out;
  std::printf("web_injection_test: %s\n", result.c_str());
  SCOPED_TRACE(result);

  EXPECT_NE(result.find("\"pwned\":null"), std::string::npos) << "a payload ran script";
  EXPECT_EQ(Field(result, "marker_requests"), 0) << "the page fetched a payload's marker URL";
  EXPECT_EQ(Field(result, "elements_from_text"), 0) << "the status panel holds img/script/svg elements";
  EXPECT_EQ(Field(result, "csp_violations"), 0);
  EXPECT_GT(Field(result, "shapes"), 10);
  EXPECT_EQ(Field(result, "last_seq"), 239) << "the page shows the log's last shape";
  EXPECT_GT(Field(result, "frames"), 0);
  EXPECT_NE(result.find("\"csp\":\"default-src 'self'"), std::string::npos) << "the page was sent the CSP";
  // Each field's payload, literally, in the panel's text.
  for (const std::string field : {"session", "scene", "method", "model", "knot", "device"}) {
    EXPECT_NE(result.find("\"literal_" + field + "\":true"), std::string::npos) << field << " not shown as text";
  }
  web.Signal(SIGTERM);
  EXPECT_TRUE(web.WaitOrKill(10));
}

}  // namespace
}  // namespace snapthread::attack_test
