// snapthread-ctl: the operator's console (docs/lab-setup.md, "Commands during a session").
//   snapthread-ctl [--key K] [--session S] [--lcm-url U] [--timeout-s T] SUBCOMMAND
//     load-scene NAME   a scene of the server's --scene-dir (e.g. zeeman)
//     set-method NAME   newton | newton-ls | higher-order (within the server's --allow-methods)
//     reset             back to the scene's start state
//     status            the server's scene, method, state, rates and refusals
// Each waits for the server's authenticated answer and prints it.
// --key: an operator credential, or the root key (acting as operator "operator"); any other
// credential refuses to start (exit 1), naming the operator role.
// Exit codes: 0 applied (status: printed); 1 the server refused (its reason on standard
// error), or LCM / the key file failed; 2 bad arguments; 3 (app::kExitNoReply) no
// authenticated answer within --timeout-s: no server on this session, another key, or a
// command the server dropped (a full command queue).
#include <chrono>
#include <cstdio>
#include <optional>
#include <string>

#include <CLI/CLI.hpp>
#include <lcm/lcm-cpp.hpp>

#include "app/command_line.h"
#include "app/common_flags.h"
#include "app/exit_codes.h"
#include "command_client.h"
#include "messages/channels.h"
#include "messages/lcm_url.h"
#include "messages/validate.h"
#include "snapthread/command_t.hpp"
#include "status_text.h"

namespace {

using namespace snapthread;
constexpr const char* kProgram = "snapthread-ctl";
// The operator the server host's root key acts as.
constexpr const char* kRootOperatorName = "operator";

// What a timeout means, with the likeliest cause.
std::string NoAnswer(const ctl::CommandClient& client, const std::string& what, double timeout_s) {
  char seconds[32];
  std::snprintf(seconds, sizeof seconds, "%g", timeout_s);
  std::string text = "no " + what + " within " + seconds + " s";
  if (client.refused_statuses() + client.refused_replies() > 0) {
    text += " (" + std::to_string(client.refused_statuses() + client.refused_replies()) +
            " messages from the session failed authentication: was --key issued by this session's root key?)";
  } else {
    text += " (is a server running on this --session and --lcm-url?)";
  }
  return text;
}

int Report(const ctl::CommandClient& client, const ctl::CommandOutcome& out, double timeout_s) {
  using Kind = ctl::CommandOutcome::Kind;
  const std::string shown = ctl::TerminalText(out.message, messages::kMaxCommandReplyBytes);
  switch (out.kind) {
    case Kind::kApplied:
      std::printf("%s\n", shown.c_str());
      return app::kExitOk;
    case Kind::kRefused:
      return app::Fail(kProgram, app::kExitFailure, "refused by the server: " + shown);
    case Kind::kNotSent:
      return app::Fail(kProgram, app::kExitFailure, "the command could not be signed or sent");
    case Kind::kNoServer:
      return app::Fail(kProgram, app::kExitNoReply,
                       NoAnswer(client, "authenticated SOLVER_STATUS", timeout_s) +
                           "; nothing was sent");
    case Kind::kNoReply:
      return app::Fail(kProgram, app::kExitNoReply,
                       NoAnswer(client, "authenticated reply", timeout_s) +
                           "; the command may or may not have been applied");
  }
  return app::kExitFailure;
}

}  // namespace

int main(int argc, char** argv) {
  CLI::App cli{"snapthread-ctl: send a command to a running snapthread-server and print its answer"};
  cli.fallthrough();  // the common flags may follow the subcommand too
  app::CommonFlags common;
  app::CommonFlagSet flag_set;
  flag_set.encrypt = true;
  app::AddCommonFlags(&cli, &common, flag_set);
  double timeout_s = 10.0;
  cli.add_option("--timeout-s", timeout_s, "seconds to wait for the server's answer (LOAD_SCENE may take seconds)")
      ->capture_default_str()->check(CLI::PositiveNumber)->check(app::FiniteNumber());
  std::string scene, method;
  CLI::App* load = cli.add_subcommand("load-scene", "load a scene of the server's --scene-dir");
  load->add_option("NAME", scene, "scene name, e.g. zeeman")->required();
  CLI::App* set = cli.add_subcommand("set-method", "switch the solver method");
  set->add_option("NAME", method, "newton | newton-ls | higher-order")->required();
  CLI::App* reset = cli.add_subcommand("reset", "back to the scene's start state");
  CLI::App* status = cli.add_subcommand("status", "print the server's scene, method, state, rates and refusals");
  cli.require_subcommand(1);
  if (auto code = app::ParseCommandLine(cli, argc, argv, app::kExitUsage)) return *code;
  if (auto code = app::CheckCommonFlags(common, kProgram, app::kExitUsage)) return *code;

  // The operator's credential, or the root key (the server host), acting as operator
  // "operator"; any other credential is refused here, naming the operator role.
  std::optional<auth::KeySet> keys = app::LoadKeySet(common, auth::Role::kOperator, kProgram);
  if (!keys) return app::kExitFailure;
  if (keys->role() == auth::Role::kServer) {
    keys = auth::KeySet::ForRole(*keys->root(), auth::Role::kOperator, kRootOperatorName);
  }
  const std::string url = app::LcmUrl(common);
  lcm::LCM lcm(url);
  if (!lcm.good()) {
    return app::Fail(kProgram, app::kExitFailure,
                     "LCM failed to start on " + url + ": " + messages::LcmStartHint(url));
  }
  const messages::Channels channels(common.session);
  ctl::CommandClient client(&lcm, channels, *keys);
  const auto deadline = ctl::Clock::now() + std::chrono::duration_cast<ctl::Clock::duration>(
                                                std::chrono::duration<double>(timeout_s));
  if (*status) {
    solver_status_t s;
    if (!client.WaitForStatus(deadline, &s)) {
      return app::Fail(kProgram, app::kExitNoReply,
                       NoAnswer(client, "authenticated SOLVER_STATUS", timeout_s));
    }
    std::printf("%s", ctl::StatusText(s).c_str());
    return app::kExitOk;
  }
  ctl::CommandOutcome out;
  if (*load) out = client.Send(command_t::LOAD_SCENE, scene, deadline);
  if (*set) out = client.Send(command_t::SET_METHOD, method, deadline);
  if (*reset) out = client.Send(command_t::RESET, "", deadline);
  return Report(client, out, timeout_s);
}
