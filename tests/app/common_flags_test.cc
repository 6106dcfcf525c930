// The common flags (common/app): defaults, parsing, the session check with its exit code
// and message, the LCM URL and the key file rules.
#include <cstdlib>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "app/command_line.h"
#include "app/common_flags.h"
#include "app/exit_codes.h"
#include "test_support.h"

namespace snapthread::app {
namespace {

// argv for CLI11 from a list of arguments (the program name first).
struct Argv {
  explicit Argv(std::vector<std::string> args) : strings(std::move(args)) {
    strings.insert(strings.begin(), "program");
    for (auto& s : strings) pointers.push_back(s.data());
  }
  int argc() const { return static_cast<int>(pointers.size()); }
  char** argv() { return pointers.data(); }
  std::vector<std::string> strings;
  std::vector<char*> pointers;
};

CommonFlagSet WithLogLevel() {
  CommonFlagSet set;
  set.log_level = true;
  return set;
}

std::optional<int> Parse(CLI::App& app, std::vector<std::string> args, int usage_exit = kExitUsage) {
  Argv a(std::move(args));
  return ParseCommandLine(app, a.argc(), a.argv(), usage_exit);
}

TEST(CommonFlagsTest, DefaultsWithoutFlags) {
  CLI::App app;
  CommonFlags flags;
  AddCommonFlags(&app, &flags, WithLogLevel());
  EXPECT_EQ(Parse(app, {}), std::nullopt);
  EXPECT_EQ(flags.session, "SNAPTHREAD");
  EXPECT_EQ(flags.lcm_url, "");
  EXPECT_EQ(flags.key_path, "");
  EXPECT_EQ(flags.log_level, "info");
  EXPECT_EQ(CheckCommonFlags(flags, "program", kExitUsage), std::nullopt);
}

TEST(CommonFlagsTest, ParsesEveryFlag) {
  CLI::App app;
  CommonFlags flags;
  AddCommonFlags(&app, &flags, WithLogLevel());
  EXPECT_EQ(Parse(app, {"--session", "LAB_2", "--lcm-url", "memq://", "--key", "/k/session.key",
                        "--log-level", "debug"}),
            std::nullopt);
  EXPECT_EQ(flags.session, "LAB_2");
  EXPECT_EQ(flags.lcm_url, "memq://");
  EXPECT_EQ(flags.key_path, "/k/session.key");
  EXPECT_EQ(flags.log_level, "debug");
  EXPECT_EQ(LcmUrl(flags), "memq://");  // not udpm: no receive buffer added
}

TEST(CommonFlagsTest, OnlyTheRequestedFlagsExist) {
  CLI::App app;
  CommonFlags flags;
  CommonFlagSet url_only;  // as snapthread-logger
  url_only.session = false;
  url_only.key = false;
  url_only.lcm_url_names = "-l,--lcm-url";
  AddCommonFlags(&app, &flags, url_only);
  EXPECT_EQ(Parse(app, {"-l", "memq://"}), std::nullopt);
  EXPECT_EQ(flags.lcm_url, "memq://");
  testing::internal::CaptureStderr();
  EXPECT_EQ(Parse(app, {"--session", "A"}, 7), 7);
  EXPECT_NE(testing::internal::GetCapturedStderr().find("--session"), std::string::npos);
}

TEST(CommonFlagsTest, BadSessionIsAUsageErrorNamingTheFlag) {
  for (const std::string& bad : std::vector<std::string>{"bad-name", "", "a b", std::string(50, 'A')}) {
    CLI::App app;
    CommonFlags flags;
    AddCommonFlags(&app, &flags);
    ASSERT_EQ(Parse(app, {"--session", bad}), std::nullopt) << bad;
    testing::internal::CaptureStderr();
    EXPECT_EQ(CheckCommonFlags(flags, "snapthread-x", kExitUsage), kExitUsage) << bad;
    const std::string err = testing::internal::GetCapturedStderr();
    EXPECT_NE(err.find("snapthread-x: bad --session"), std::string::npos) << err;
    EXPECT_NE(err.find("[A-Za-z0-9_]"), std::string::npos) << err;
  }
  // The longest name the channels carry is accepted.
  CommonFlags longest;
  longest.session = std::string(messages::kMaxSessionNameLength, 'A');
  EXPECT_EQ(CheckCommonFlags(longest, "snapthread-x", kExitUsage), std::nullopt);
}

TEST(CommonFlagsTest, HostileSessionIsShownEscaped) {
  const std::string problem = SessionNameProblem("a\x1b[2Jb");
  EXPECT_EQ(problem.find('\x1b'), std::string::npos) << problem;
  EXPECT_NE(problem.find("bad --session"), std::string::npos);
}

TEST(CommonFlagsTest, BadLogLevelAndUnknownFlagAreUsageErrors) {
  CLI::App app;
  CommonFlags flags;
  AddCommonFlags(&app, &flags, WithLogLevel());
  testing::internal::CaptureStderr();
  EXPECT_EQ(Parse(app, {"--log-level", "loud"}), kExitUsage);
  EXPECT_NE(testing::internal::GetCapturedStderr().find("--log-level"), std::string::npos);
  CLI::App other;
  AddCommonFlags(&other, &flags);
  testing::internal::CaptureStderr();
  EXPECT_EQ(Parse(other, {"--lcm-url"}), kExitUsage);
  EXPECT_NE(testing::internal::GetCapturedStderr().find("--lcm-url"), std::string::npos);
}

TEST(CommonFlagsTest, HelpExitsZero) {
  CLI::App app;
  CommonFlags flags;
  AddCommonFlags(&app, &flags);
  testing::internal::CaptureStdout();
  EXPECT_EQ(Parse(app, {"--help"}), kExitOk);
  const std::string help = testing::internal::GetCapturedStdout();
  for (const char* flag : {"--session", "--lcm-url", "--key"}) EXPECT_NE(help.find(flag), std::string::npos) << flag;
  EXPECT_EQ(help.find("--log-level"), std::string::npos);
}

TEST(CommonFlagsTest, SessionFromTheEnvironmentOnlyWhereAsked) {
  ::setenv("SNAPTHREAD_SESSION", "FROM_ENV", 1);
  CommonFlags plain, observer;
  CLI::App a, b;
  AddCommonFlags(&a, &plain);
  CommonFlagSet from_environment;
  from_environment.session_from_environment = true;
  AddCommonFlags(&b, &observer, from_environment);
  ::unsetenv("SNAPTHREAD_SESSION");
  EXPECT_EQ(plain.session, "SNAPTHREAD");
  EXPECT_FALSE(plain.session_from_environment);
  EXPECT_EQ(observer.session, "FROM_ENV");
  EXPECT_TRUE(observer.session_from_environment);
  EXPECT_EQ(Parse(b, {"--session", "GIVEN"}), std::nullopt);
  EXPECT_EQ(observer.session, "GIVEN");  // the flag wins
}

TEST(CommonFlagsTest, LcmUrlFromTheEnvironmentThenTheDefault) {
  CommonFlags flags;
  ::setenv("LCM_DEFAULT_URL", "memq://", 1);
  EXPECT_EQ(LcmUrl(flags), "memq://");
  ::unsetenv("LCM_DEFAULT_URL");
  const std::string url = LcmUrl(flags, 4096);
  EXPECT_EQ(url.rfind(messages::kDefaultLcmUrl, 0), 0u) << url;
  EXPECT_NE(url.find("recv_buf_size="), std::string::npos) << url;
}

TEST(CommonFlagsTest, FiniteNumberRefusesNan) {
  double value = 1.0;
  for (const char* bad : {"nan", "inf", "-inf", "abc"}) {
    CLI::App app;
    app.add_option("--duration-s", value)->check(CLI::NonNegativeNumber)->check(FiniteNumber());
    testing::internal::CaptureStderr();
    EXPECT_EQ(Parse(app, {"--duration-s", bad}), kExitUsage) << bad;
    EXPECT_NE(testing::internal::GetCapturedStderr().find("--duration-s"), std::string::npos) << bad;
  }
  CLI::App app;
  app.add_option("--duration-s", value)->check(FiniteNumber());
  EXPECT_EQ(Parse(app, {"--duration-s", "2.5"}), std::nullopt);
  EXPECT_EQ(value, 2.5);
}

TEST(CommonFlagsTest, KeyFileRules) {
  test_support::SessionKeyFile file;  // a usable key, via $SNAPTHREAD_KEY_FILE
  CommonFlags flags;
  auth::KeyLocation where;
  const auto keys = LoadKeySet(flags, auth::Role::kServer, "program", &where);
  ASSERT_TRUE(keys.has_value());
  EXPECT_EQ(where.path, file.path());
  ASSERT_NE(keys->root(), nullptr);
  EXPECT_EQ(keys->root()->Id(), file.key().Id());

  flags.key_path = file.path() + ".missing";
  testing::internal::CaptureStderr();
  EXPECT_FALSE(LoadKeySet(flags, auth::Role::kObserver, "snapthread-x").has_value());
  const std::string err = testing::internal::GetCapturedStderr();
  EXPECT_NE(err.find("snapthread-x: --key: "), std::string::npos) << err;
  EXPECT_NE(err.find(flags.key_path), std::string::npos) << err;
}

}  // namespace
}  // namespace snapthread::app
