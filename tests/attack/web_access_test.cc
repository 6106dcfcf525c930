// The attack suite, snapthread-web's door (docs/security.md, "The edges"): who gets the
// page and its WebSocket. Raw HTTP over TCP against the real binary, so every header is
// the test's to choose (a browser would not let a test forge Host or Origin):
//   * beyond loopback (--bind 0.0.0.0, the token from --token-file): nothing without the
//     token or with a wrong one (401), the token moves from ?token= into an HttpOnly,
//     SameSite=Strict cookie with a redirect to the clean URL, and with the cookie every
//     file of the page loads (before, app.js and the style sheets got 401: a blank page);
//   * a Host that is not the bridge's address or a --host-name (a foreign site, a DNS
//     rebinding name that resolves here, a wrong port) gets 403 even with the token;
//   * a WebSocket whose Origin is not the page's own (another site, none) gets 403;
//   * every response carries the Content-Security-Policy and its companions;
//   * --max-pages: the page past the limit gets 503 and is counted;
//   * the token is printed once, and a token file others may read is refused.
#include <sys/socket.h>
#include <sys/stat.h>
#include <unistd.h>

#include <fstream>
#include <map>
#include <memory>
#include <regex>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "loopback_socket.h"
#include "test_support.h"

namespace snapthread::attack_test {
namespace {

using test_support::ChildProcess;
using test_support::OneLog;

struct Response {
  int status = -1;
  std::map<std::string, std::string> headers;  // names lowercase
  std::string body;
  std::string raw;
};

// A connected socket to 127.0.0.1:port (-1 on failure), with a 10 s receive timeout.
int Connect(int port) { return test_support::ConnectLoopback(port, 10); }

Response Parse(const std::string& raw) {
  Response r;
  r.raw = raw;
  const size_t end = raw.find("\r\n\r\n");
  const std::string head = raw.substr(0, end);
  if (end != std::string::npos) r.body = raw.substr(end + 4);
  std::smatch m;
  if (std::regex_search(head, m, std::regex(R"(^HTTP/1\.1 (\d{3}))"))) r.status = std::stoi(m[1]);
  size_t at = head.find("\r\n");
  while (at != std::string::npos) {
    const size_t next = head.find("\r\n", at + 2);
    const std::string line = head.substr(at + 2, next == std::string::npos ? std::string::npos : next - at - 2);
    const size_t colon = line.find(':');
    if (colon != std::string::npos) {
      std::string name = line.substr(0, colon);
      for (char& c : name) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
      r.headers[name] = line.substr(line.find_first_not_of(' ', colon + 1));
    }
    at = next;
  }
  return r;
}

// Sends `request` and reads the response head (and, without an upgrade, up to the
// connection's close; requests say Connection: close).
Response Exchange(int fd, const std::string& request, bool head_only) {
  ::send(fd, request.data(), request.size(), MSG_NOSIGNAL);
  std::string raw;
  char buffer[4096];
  while (true) {
    const ssize_t n = ::recv(fd, buffer, sizeof buffer, 0);
    if (n <= 0) break;
    raw.append(buffer, static_cast<size_t>(n));
    if (head_only && raw.find("\r\n\r\n") != std::string::npos) break;
  }
  return Parse(raw);
}

struct Request {
  Request(std::string target_ = "/", std::string host_ = "", std::string cookie_ = "", std::string origin_ = "",
          bool upgrade_ = false)
      : target(std::move(target_)), host(std::move(host_)), cookie(std::move(cookie_)),
        origin(std::move(origin_)), upgrade(upgrade_) {}
  std::string target;
  std::string host;     // "" = no Host header
  std::string cookie;   // "" = none
  std::string origin;   // "" = none
  bool upgrade;
};

std::string Header(const Response& r, const std::string& name) {
  const auto it = r.headers.find(name);
  return it == r.headers.end() ? "" : it->second;
}

Response Send(int port, const Request& q) {
  const int fd = Connect(port);
  if (fd < 0) return {};
  std::string text = "GET " + q.target + " HTTP/1.1\r\n";
  if (!q.host.empty()) text += "Host: " + q.host + "\r\n";
  if (!q.cookie.empty()) text += "Cookie: " + q.cookie + "\r\n";
  if (!q.origin.empty()) text += "Origin: " + q.origin + "\r\n";
  if (q.upgrade) {
    text += "Connection: Upgrade\r\nUpgrade: websocket\r\nSec-WebSocket-Version: 13\r\n"
            "Sec-WebSocket-Key: dGhlIHNhbXBsZSBub25jZQ==\r\n";
  } else {
    text += "Connection: close\r\n";
  }
  text += "\r\n";
  Response r = Exchange(fd, text, q.upgrade);
  ::close(fd);
  return r;
}

class WebAccessTest : public ::testing::Test {
 protected:
  // Starts snapthread-web with `args` (live view of a session nobody runs: the page and
  // its WebSocket are what is tested); sets port_ and the printed URL.
  std::unique_ptr<ChildProcess> StartWeb(std::vector<std::string> args, const std::string& tag) {
    args.insert(args.begin(), {test_support::BinDir() + "/snapthread-web", "--port", "0", "--session",
                               session_, "--lcm-url", test_support::kLoopbackLcmUrl});
    auto web = std::make_unique<ChildProcess>(args, OneLog(dir_.path() + "/web_" + tag + ".txt", true));
    EXPECT_TRUE(web->WaitForOutput(" at http://", 30)) << web->Out();
    std::smatch m;
    const std::string out = web->Out();
    if (std::regex_search(out, m, std::regex(R"(at (http://[^:/]+:(\d+)/\S*))"))) {
      url_ = m[1];
      port_ = std::stoi(m[2]);
    }
    return web;
  }

  std::string Host() const { return "127.0.0.1:" + std::to_string(port_); }

  std::string WriteTokenFile(const std::string& token, mode_t mode) {
    const std::string path = dir_.path() + "/token";
    std::ofstream(path) << token << "\n";
    ::chmod(path.c_str(), mode);
    return path;
  }

  // The headers every response must carry.
  static void ExpectHardened(const Response& r, const std::string& what) {
    SCOPED_TRACE(what + ": " + r.raw.substr(0, 600));
    ASSERT_TRUE(r.headers.count("content-security-policy"));
    const std::string& csp = r.headers.at("content-security-policy");
    EXPECT_NE(csp.find("default-src 'self'"), std::string::npos);
    EXPECT_NE(csp.find("script-src 'self';"), std::string::npos);
    EXPECT_NE(csp.find("frame-ancestors 'none'"), std::string::npos);
    EXPECT_EQ(csp.find("unsafe-inline"), std::string::npos);
    EXPECT_EQ(csp.find("unsafe-eval"), std::string::npos);
    EXPECT_EQ(Header(r, "x-content-type-options"), "nosniff");
    EXPECT_EQ(Header(r, "referrer-policy"), "no-referrer");
  }

  const std::string token_ = "Observer-token_0123456789.abcdef~";
  std::string session_ = test_support::UniqueSession("WEBACCESS");
  std::string url_;
  int port_ = 0;
  test_support::SessionKeyFile key_;
  test_support::ScopedTempDir dir_{"web-access"};
};

TEST_F(WebAccessTest, BeyondLoopbackTheTokenOpensThePageAndEveryFileAndNothingElseDoes) {
  auto web = StartWeb({"--bind", "0.0.0.0", "--token-file", WriteTokenFile(token_, 0600)}, "token");
  ASSERT_GT(port_, 0) << web->Out();
  EXPECT_EQ(url_, "http://0.0.0.0:" + std::to_string(port_) + "/?token=" + token_);
  const std::string host = Host();
  const std::string cookie = "snapthread_token_" + std::to_string(port_) + "=" + token_;
  const std::string wrong_cookie = "snapthread_token_" + std::to_string(port_) + "=" + std::string(token_.size(), 'x');

  // Without the token, with a wrong one (query or cookie), with another port's cookie.
  for (const auto& [what, q] : std::vector<std::pair<std::string, Request>>{
           {"page without", {"/", host}},
           {"script without", {"/app.js", host}},
           {"style without", {"/style.css", host}},
           {"page wrong query", {"/?token=" + std::string(token_.size(), '0'), host}},
           {"page short query", {"/?token=" + token_.substr(0, 10), host}},
           {"page wrong cookie", {"/", host, wrong_cookie}},
           {"page other port's cookie", {"/", host, "snapthread_token_1=" + token_}},
           {"ws without", {"/ws", host, "", "http://" + host, true}},
           {"ws wrong cookie", {"/ws", host, wrong_cookie, "http://" + host, true}}}) {
    const Response r = Send(port_, q);
    EXPECT_EQ(r.status, 401) << what << ": " << r.raw;
    EXPECT_EQ(r.body.find("<"), std::string::npos) << what << ": a refusal serves no page";
    ExpectHardened(r, what);
  }

  // The right ?token=: a redirect to the clean URL that sets the cookie.
  for (const std::string& path : {std::string("/"), std::string("/index.html"), std::string("//evil.example/")}) {
    const Response r = Send(port_, {path + "?token=" + token_, host});
    SCOPED_TRACE(r.raw);
    EXPECT_EQ(r.status, 303);
    EXPECT_EQ(Header(r, "location"), path == "//evil.example/" ? "/" : path)
        << "the redirect stays on this bridge, without the token";
    EXPECT_EQ(Header(r, "set-cookie"), cookie + "; Path=/; HttpOnly; SameSite=Strict");
    ExpectHardened(r, "redirect");
  }

  // With the cookie: the page and every file it loads (app.js, style.css, uplot.css).
  for (const char* file : {"/", "/app.js", "/style.css", "/uplot.css"}) {
    const Response r = Send(port_, {file, host, cookie});
    EXPECT_EQ(r.status, 200) << file << ": " << r.raw.substr(0, 400);
    EXPECT_GT(r.body.size(), 100u) << file;
    ExpectHardened(r, file);
  }
  // The page's own HTML runs no inline script: only the bundle, by file.
  const Response page = Send(port_, {"/", host, cookie});
  EXPECT_EQ(std::regex_search(page.body, std::regex(R"(<script(?![^>]*\bsrc=))")), false) << page.body;
  EXPECT_FALSE(std::regex_search(page.body, std::regex(R"(\son[a-z]+\s*=)"))) << "no handler attributes: " << page.body;
  EXPECT_NE(Header(page, "content-security-policy").find("connect-src 'self' ws://" + host), std::string::npos);

  // The WebSocket: the cookie (or ?token=) and the page's own Origin.
  EXPECT_EQ(Send(port_, {"/ws", host, cookie, "http://" + host, true}).status, 101);
  EXPECT_EQ(Send(port_, {"/ws?token=" + token_, host, "", "http://" + host, true}).status, 101);
  EXPECT_EQ(Send(port_, {"/ws", host, cookie, "http://evil.example", true}).status, 403);
  EXPECT_EQ(Send(port_, {"/ws", host, cookie, "http://evil.example:" + std::to_string(port_), true}).status, 403);
  EXPECT_EQ(Send(port_, {"/ws", host, cookie, "null", true}).status, 403);
  EXPECT_EQ(Send(port_, {"/ws", host, cookie, "", true}).status, 403) << "no Origin: not the page";

  // Host: a foreign site, a DNS-rebinding name (resolves to this address, names its own
  // host), another port, none: refused even with the token.
  for (const std::string& bad : {std::string("evil.example"), "evil.example:" + std::to_string(port_),
                                 "rebind.attacker.example:" + std::to_string(port_),
                                 "127.0.0.1:" + std::to_string(port_ + 1), std::string("127.0.0.1"),
                                 std::string("")}) {
    const Response r = Send(port_, {"/", bad, cookie});
    EXPECT_EQ(r.status, 403) << "Host '" << bad << "': " << r.raw.substr(0, 300);
    ExpectHardened(r, "host " + bad);
    EXPECT_EQ(Send(port_, {"/ws", bad, cookie, "http://" + bad, true}).status, 403) << bad;
  }
  // "localhost" names this bridge on a loopback connection.
  EXPECT_EQ(Send(port_, {"/", "localhost:" + std::to_string(port_), cookie}).status, 200);

  // The token appears once in the output: in the URL for the operator.
  web->Signal(SIGTERM);
  EXPECT_TRUE(web->WaitOrKill(10));
  const std::string out = web->Out();
  size_t count = 0;
  for (size_t at = out.find(token_); at != std::string::npos; at = out.find(token_, at + 1)) count++;
  EXPECT_EQ(count, 1u) << out;
}

TEST_F(WebAccessTest, OnLoopbackHostAndOriginAreCheckedAndHostNamesAreAccepted) {
  auto web = StartWeb({"--host-name", "labpc", "--host-name", "LabPC.lab.example"}, "loopback");
  ASSERT_GT(port_, 0) << web->Out();
  const std::string p = std::to_string(port_);
  EXPECT_EQ(url_, "http://labpc:" + p + "/") << "the URL names the first --host-name, no token on loopback";
  for (const std::string& host : {Host(), "localhost:" + p, "labpc:" + p, "labpc.lab.example:" + p}) {
    EXPECT_EQ(Send(port_, {"/", host}).status, 200) << host;
    EXPECT_EQ(Send(port_, {"/ws", host, "", "http://" + host, true}).status, 101) << host;
    EXPECT_EQ(Send(port_, {"/ws", host, "", "https://evil.example", true}).status, 403) << host;
  }
  // DNS rebinding against a loopback bridge: the attacker's name resolving to 127.0.0.1.
  EXPECT_EQ(Send(port_, {"/", "rebind.attacker.example:" + p}).status, 403);
  EXPECT_EQ(Send(port_, {"/ws", "rebind.attacker.example:" + p, "", "http://rebind.attacker.example:" + p, true}).status,
            403);
  EXPECT_EQ(Send(port_, {"/", "labpc.evil.example:" + p}).status, 403);
}

TEST_F(WebAccessTest, PagesBeyondMaxPagesAreRefusedAndCounted) {
  auto web = StartWeb({"--max-pages", "2"}, "max");
  ASSERT_GT(port_, 0) << web->Out();
  const std::string host = Host();
  std::vector<int> open;
  for (int i = 0; i < 2; ++i) {
    const int fd = Connect(port_);
    ASSERT_GE(fd, 0);
    const Response r = Exchange(fd,
                                "GET /ws HTTP/1.1\r\nHost: " + host + "\r\nOrigin: http://" + host +
                                    "\r\nConnection: Upgrade\r\nUpgrade: websocket\r\nSec-WebSocket-Version: 13\r\n"
                                    "Sec-WebSocket-Key: dGhlIHNhbXBsZSBub25jZQ==\r\n\r\n",
                                true);
    EXPECT_EQ(r.status, 101) << r.raw;
    open.push_back(fd);
  }
  const Response third = Send(port_, {"/ws", host, "", "http://" + host, true});
  EXPECT_EQ(third.status, 503) << third.raw;
  ExpectHardened(third, "503");
  // The bridge counts it; its counters reach the open pages once a second (a text frame
  // of JSON; the test reads the raw bytes of the first page's stream for it).
  std::string stream;
  char buffer[4096];
  const auto start = std::chrono::steady_clock::now();
  while (stream.find("\"pages_refused\":1") == std::string::npos &&
         std::chrono::steady_clock::now() - start < std::chrono::seconds(10)) {
    const ssize_t n = ::recv(open[0], buffer, sizeof buffer, 0);
    if (n <= 0) break;
    stream.append(buffer, static_cast<size_t>(n));
  }
  EXPECT_NE(stream.find("\"pages_refused\":1"), std::string::npos) << stream.substr(0, 2000);
  for (int fd : open) ::close(fd);
  // A page closed frees its place.
  EXPECT_TRUE(test_support::WaitUntil(
      [&] { return Send(port_, {"/ws", host, "", "http://" + host, true}).status == 101; }, 10.0, 0.2));
}

TEST_F(WebAccessTest, ATokenFileOthersMayReadOrABadTokenIsRefusedAtStart) {
  const std::string bin = test_support::BinDir() + "/snapthread-web";
  auto run = [&](std::vector<std::string> args) {
    args.insert(args.begin(), {bin, "--port", "0", "--bind", "0.0.0.0", "--session", session_, "--lcm-url",
                               test_support::kLoopbackLcmUrl, "--duration-s", "5"});
    ChildProcess p(args, OneLog(dir_.path() + "/refused.txt", true));
    return p.Finish(20);
  };
  const test_support::ProcessResult open_file = run({"--token-file", WriteTokenFile(token_, 0644)});
  EXPECT_EQ(open_file.exit_code, 1);
  EXPECT_NE(open_file.out.find("chmod 600"), std::string::npos) << open_file.out;
  EXPECT_EQ(open_file.out.find(token_), std::string::npos) << "the refusal does not print the token";
  const test_support::ProcessResult short_file = run({"--token-file", WriteTokenFile("short", 0600)});
  EXPECT_EQ(short_file.exit_code, 1) << short_file.out;
  const test_support::ProcessResult cookie_breaker = run({"--token", "abcdefghijklmnop; Path=/x"});
  EXPECT_EQ(cookie_breaker.exit_code, 1) << cookie_breaker.out;
  const test_support::ProcessResult both = run({"--token", token_, "--token-file", WriteTokenFile(token_, 0600)});
  EXPECT_NE(both.exit_code, 0) << "--token and --token-file exclude each other: " << both.out;
  const test_support::ProcessResult bad_name = run({"--host-name", "evil.example; script-src *"});
  EXPECT_EQ(bad_name.exit_code, 2) << bad_name.out;
}

}  // namespace
}  // namespace snapthread::attack_test
