// snapthread-web's door without a server: the Host, token and Origin decisions
// (access_policy.h), the token's comparison, format and file (observer_token.h), the
// security headers, and JSON text that stays UTF-8 whatever bytes a message holds.
#include <sys/stat.h>

#include <fstream>
#include <string>

#include <gtest/gtest.h>

#include "access_policy.h"
#include "json_writer.h"
#include "observer_token.h"
#include "security_headers.h"
#include "temp_dir.h"

namespace snapthread::web {
namespace {

const std::string kToken = "0123456789abcdef0123456789abcdef";

AccessConfig Config(std::string token = kToken) { return {std::move(token), {"LabPC", "labpc.lab.example"}, 7000}; }

RequestFacts Facts(std::string_view target, std::string_view host, std::string_view cookie = "",
                   std::string_view origin = "", bool upgrade = false) {
  return {.target = target, .host = host, .origin = origin, .cookie = cookie, .upgrade = upgrade,
          .local_address = "10.213.7.1", .local_is_loopback = false};
}

bool AnyPage(std::string_view path) { return path == "/" || path == "/app.js"; }

TEST(AccessPolicy, HostMustNameTheBoundAddressOrAConfiguredNameWithThePort) {
  const AccessConfig c = Config();
  EXPECT_TRUE(HostAllowed(c, "10.213.7.1:7000", "10.213.7.1", false));
  EXPECT_TRUE(HostAllowed(c, "labpc:7000", "10.213.7.1", false));
  EXPECT_TRUE(HostAllowed(c, "LABPC.lab.example:7000", "10.213.7.1", false)) << "names compare caseless";
  EXPECT_FALSE(HostAllowed(c, "10.213.7.1", "10.213.7.1", false)) << "port 7000 must be named";
  EXPECT_FALSE(HostAllowed(c, "10.213.7.1:7001", "10.213.7.1", false));
  EXPECT_FALSE(HostAllowed(c, "10.213.7.1:07000x", "10.213.7.1", false));
  EXPECT_FALSE(HostAllowed(c, "evil.example:7000", "10.213.7.1", false)) << "DNS rebinding";
  EXPECT_FALSE(HostAllowed(c, "labpc.evil.example:7000", "10.213.7.1", false));
  EXPECT_FALSE(HostAllowed(c, "localhost:7000", "10.213.7.1", false)) << "localhost only on loopback";
  EXPECT_TRUE(HostAllowed(c, "localhost:7000", "127.0.0.1", true));
  EXPECT_TRUE(HostAllowed(c, "[::1]:7000", "[::1]", true));
  EXPECT_FALSE(HostAllowed(c, "::1:7000", "[::1]", true));
  EXPECT_FALSE(HostAllowed(c, "", "10.213.7.1", false));
  EXPECT_FALSE(HostAllowed(c, ":7000", "10.213.7.1", false));
  const AccessConfig port80{"", {}, 80};
  EXPECT_TRUE(HostAllowed(port80, "10.213.7.1", "10.213.7.1", false)) << "a browser leaves out port 80";
}

TEST(AccessPolicy, OriginMustBeThePageItself) {
  EXPECT_TRUE(OriginMatches("http://labpc:7000", "labpc:7000"));
  EXPECT_TRUE(OriginMatches("https://LabPC:7000", "labpc:7000"));
  EXPECT_FALSE(OriginMatches("http://labpc:7001", "labpc:7000"));
  EXPECT_FALSE(OriginMatches("http://evil.example", "labpc:7000"));
  EXPECT_FALSE(OriginMatches("null", "labpc:7000"));
  EXPECT_FALSE(OriginMatches("", "labpc:7000"));
  EXPECT_FALSE(OriginMatches("http://", ""));
}

TEST(AccessPolicy, TheTokenMovesIntoACookieWithARedirectToThePageWithoutIt) {
  const AccessConfig c = Config();
  const std::string host = "10.213.7.1:7000";
  AccessVerdict v = DecideAccess(c, Facts("/?token=" + kToken, host), AnyPage);
  ASSERT_EQ(v.kind, AccessVerdict::Kind::kRedirect);
  EXPECT_EQ(v.location, "/");
  EXPECT_EQ(v.set_cookie, "snapthread_token_7000=" + kToken + "; Path=/; HttpOnly; SameSite=Strict");
  // The redirect never leaves the bridge's own files.
  EXPECT_EQ(DecideAccess(c, Facts("//evil.example/?token=" + kToken, host), AnyPage).location, "/");
  EXPECT_EQ(DecideAccess(c, Facts("/app.js?token=" + kToken, host), AnyPage).location, "/app.js");
  // With the cookie, every request is served; without, or wrong, 401.
  const std::string cookie = "other=1; snapthread_token_7000=" + kToken;
  EXPECT_EQ(DecideAccess(c, Facts("/app.js", host, cookie), AnyPage).kind, AccessVerdict::Kind::kServe);
  for (const std::string& bad : {std::string(""), "snapthread_token_7000=" + kToken.substr(1),
                                 "snapthread_token_7001=" + kToken, "snapthread_token_7000=" + kToken + "x"}) {
    v = DecideAccess(c, Facts("/app.js", host, bad), AnyPage);
    EXPECT_EQ(v.kind, AccessVerdict::Kind::kRefuse) << bad;
    EXPECT_EQ(v.status, 401) << bad;
  }
  v = DecideAccess(c, Facts("/?token=" + std::string(32, '0'), host, cookie), AnyPage);
  EXPECT_EQ(v.status, 401) << "a wrong ?token= is refused even next to a right cookie";
  // Host before the token: a foreign Host is 403 with the right token.
  v = DecideAccess(c, Facts("/", "evil.example:7000", cookie), AnyPage);
  EXPECT_EQ(v.status, 403);
  EXPECT_EQ(v.host, "") << "a refused Host never reaches the CSP";
  // No token configured (loopback): no cookie needed, ?token= ignored.
  EXPECT_EQ(DecideAccess(Config(""), Facts("/?token=x", host), AnyPage).kind, AccessVerdict::Kind::kServe);
}

TEST(AccessPolicy, AWebSocketNeedsTheTokenAndThePagesOrigin) {
  const AccessConfig c = Config();
  const std::string host = "labpc:7000";
  const std::string cookie = "snapthread_token_7000=" + kToken;
  EXPECT_EQ(DecideAccess(c, Facts("/ws", host, cookie, "http://labpc:7000", true), AnyPage).kind,
            AccessVerdict::Kind::kServe);
  EXPECT_EQ(DecideAccess(c, Facts("/ws?token=" + kToken, host, "", "http://labpc:7000", true), AnyPage).kind,
            AccessVerdict::Kind::kServe)
      << "a WebSocket with ?token= is served, not redirected";
  EXPECT_EQ(DecideAccess(c, Facts("/ws", host, cookie, "http://evil.example", true), AnyPage).status, 403);
  EXPECT_EQ(DecideAccess(c, Facts("/ws", host, cookie, "", true), AnyPage).status, 403);
  EXPECT_EQ(DecideAccess(c, Facts("/ws", host, "", "http://labpc:7000", true), AnyPage).status, 401);
  EXPECT_EQ(DecideAccess(Config(""), Facts("/ws", host, "", "http://evil.example", true), AnyPage).status, 403)
      << "on loopback too";
}

TEST(AccessPolicy, CookiesAndHostNamesParse) {
  EXPECT_EQ(CookieValue("a=1; snapthread_token_7000=abc ;b=2", "snapthread_token_7000"), "abc");
  EXPECT_EQ(CookieValue("xsnapthread_token_7000=abc", "snapthread_token_7000"), "");
  EXPECT_EQ(CookieValue("", "a"), "");
  EXPECT_TRUE(IsValidHostName("labpc"));
  EXPECT_TRUE(IsValidHostName("10.0.0.2"));
  EXPECT_TRUE(IsValidHostName("[fe80::1]"));
  EXPECT_FALSE(IsValidHostName("evil; script-src *"));
  EXPECT_FALSE(IsValidHostName("a b"));
  EXPECT_FALSE(IsValidHostName(""));
  EXPECT_FALSE(IsValidHostName("[fe80::1"));
}

TEST(ObserverToken, ComparesInConstantTimeOverHashesAndChecksItsForm) {
  EXPECT_TRUE(TokenMatches(kToken, kToken));
  EXPECT_FALSE(TokenMatches(kToken + "0", kToken)) << "a longer guess";
  EXPECT_FALSE(TokenMatches("", kToken));
  EXPECT_FALSE(TokenMatches("", ""));
  EXPECT_EQ(TokenProblem(kToken), "");
  EXPECT_EQ(TokenProblem(GenerateObserverToken()), "");
  EXPECT_NE(TokenProblem("short"), "");
  EXPECT_NE(TokenProblem(std::string(129, 'a')), "");
  EXPECT_NE(TokenProblem("abcdefghijklmnop; Path=/"), "") << "nothing that breaks the cookie";
  EXPECT_NE(TokenProblem("abcdefghijklmnop%41"), "");
}

TEST(ObserverToken, ATokenFileMustBePrivateAndHoldAToken) {
  test_support::ScopedTempDir dir("web-token");
  const std::string path = dir.path() + "/token";
  std::ofstream(path) << kToken << "\n";
  ::chmod(path.c_str(), 0600);
  EXPECT_EQ(LoadTokenFile(path), kToken);
  ::chmod(path.c_str(), 0640);
  try {
    LoadTokenFile(path);
    ADD_FAILURE() << "a group-readable token file was read";
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find("chmod 600"), std::string::npos) << e.what();
    EXPECT_EQ(std::string(e.what()).find(kToken), std::string::npos) << "the token is not in the message";
  }
  std::ofstream(path) << "not a token\n";
  ::chmod(path.c_str(), 0600);
  EXPECT_THROW(LoadTokenFile(path), std::runtime_error);
  EXPECT_THROW(LoadTokenFile(dir.path()), std::runtime_error) << "a directory";
  EXPECT_THROW(LoadTokenFile(dir.path() + "/missing"), std::runtime_error);
}

TEST(SecurityHeaders, EveryResponseForbidsInlineScriptFramingAndSniffing) {
  const std::string csp = ContentSecurityPolicy("labpc:7000");
  EXPECT_EQ(csp.find("default-src 'self'; script-src 'self';"), 0u) << csp;
  EXPECT_NE(csp.find("connect-src 'self' ws://labpc:7000 wss://labpc:7000;"), std::string::npos) << csp;
  EXPECT_NE(csp.find("frame-ancestors 'none'"), std::string::npos);
  EXPECT_EQ(csp.find("unsafe"), std::string::npos);
  EXPECT_EQ(ContentSecurityPolicy("").find("ws://"), std::string::npos);
  bool nosniff = false, referrer = false;
  for (const auto& [name, value] : SecurityHeaders("labpc:7000")) {
    nosniff |= name == "X-Content-Type-Options" && value == "nosniff";
    referrer |= name == "Referrer-Policy" && value == "no-referrer";
  }
  EXPECT_TRUE(nosniff);
  EXPECT_TRUE(referrer);
}

TEST(JsonWriter, BytesThatAreNotUtf8BecomeReplacementCharacters) {
  JsonWriter w;
  w.BeginObject().String("s", "ok \xc3\xa9 \xe2\x82\xac \xf0\x9f\x99\x82 <img> \xff \xc0\xaf \xed\xa0\x80 \xe2\x82").EndObject();
  EXPECT_EQ(w.text(),
            "{\"s\":\"ok \xc3\xa9 \xe2\x82\xac \xf0\x9f\x99\x82 <img> \\ufffd \\ufffd\\ufffd "
            "\\ufffd\\ufffd\\ufffd \\ufffd\\ufffd\"}");
}

}  // namespace
}  // namespace snapthread::web
