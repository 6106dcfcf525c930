// snapthread-viewer: watches a session (thread shape + solver status) over LCM.
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <utility>

#include <CLI/CLI.hpp>

#include "messages/channels.h"
#include "messages/lcm_url.h"
#include "stop_signals.h"
#include "viewer_app.h"

int main(int argc, char** argv) {
  snapthread::viewer::ViewerOptions o;
  if (const char* s = std::getenv("SNAPTHREAD_SESSION"); s != nullptr && *s != '\0') {
    o.session = s;
  }
  CLI::App app{
      "snapthread-viewer: draws a snapthread session (thread, grasp, force, solver state) "
      "from <SESSION>_SHAPE and <SESSION>_SOLVER_STATUS. Never publishes forces.\n"
      "Mouse: left drag orbits, wheel zooms, F refits, Q/Esc quits."};
  app.add_option("--session", o.session, "session name (channel prefix; env SNAPTHREAD_SESSION)")
      ->capture_default_str();
  app.add_option("--lcm-url", o.lcm_url,
                 "LCM URL (default: env LCM_DEFAULT_URL, else udpm://239.255.76.67:7667?ttl=0)");
  app.add_option("--width", o.width, "window width, pixels")->capture_default_str()
      ->check(CLI::Range(64, 8192));
  app.add_option("--height", o.height, "window height, pixels")->capture_default_str()
      ->check(CLI::Range(64, 8192));
  app.add_option("--screenshot", o.screenshot_path,
                 "headless: write a PNG after --after-shapes shapes and exit");
  app.add_option("--after-shapes", o.after_shapes, "shapes to receive before the screenshot")
      ->capture_default_str()->check(CLI::Range(1, 1000000));
  app.add_option("--timeout-s", o.timeout_s,
                 "screenshot: fail (exit 2) if the shapes have not arrived by then")
      ->capture_default_str()->check(CLI::NonNegativeNumber);
  app.add_option("--key", o.key_path,
                 "session key file (default: $SNAPTHREAD_KEY_FILE, else "
                 "$XDG_CONFIG_HOME/snapthread/session.key)");
  app.add_flag("--print-rates", o.print_rates,
               "print live rates of every <SESSION>_* channel once per second (no window)");
  app.add_option("--duration-s", o.duration_s, "exit after this many seconds (0 = never)")
      ->capture_default_str()->check(CLI::NonNegativeNumber);
  app.add_option("--max-fps", o.max_fps, "render at most this many frames per second")
      ->capture_default_str()->check(CLI::Range(1.0, 1000.0));
  app.add_flag("--grasp-mode", o.grasp_mode,
               "drag the grasp with the mouse: publishes device_state_t on <SESSION>_DEVICE_STATE");
  app.add_option("--scene", o.scene_path, "scene YAML (its device mapping; needed by --grasp-mode)")
      ->check(CLI::ExistingFile);
  CLI11_PARSE(app, argc, argv);
  // CLI11's range checks let "nan" through (every comparison with NaN is false).
  for (const auto& [flag, value] : {std::pair<const char*, double>{"--timeout-s", o.timeout_s},
                                    {"--duration-s", o.duration_s}, {"--max-fps", o.max_fps}}) {
    if (!std::isfinite(value)) {
      std::fprintf(stderr, "snapthread-viewer: %s: expected a finite number\n", flag);
      return snapthread::viewer::kExitSetupFailed;
    }
  }
  // A receiver: a kernel buffer that rides out seconds off the CPU (lcm_url.h).
  o.lcm_url = snapthread::messages::WithReceiveBuffer(snapthread::messages::ResolveLcmUrl(o.lcm_url));
  if (!snapthread::messages::IsValidSessionName(o.session)) {
    std::fprintf(stderr, "snapthread-viewer: bad --session %s (expected [A-Za-z0-9_]+)\n",
                 snapthread::messages::EscapeForDisplay(o.session).c_str());
    return snapthread::viewer::kExitSetupFailed;
  }
  if (o.grasp_mode && o.scene_path.empty()) {
    std::fprintf(stderr, "snapthread-viewer: --grasp-mode needs --scene FILE\n");
    return snapthread::viewer::kExitSetupFailed;
  }
  snapthread::viewer::InstallStopSignals();
  if (o.print_rates) return snapthread::viewer::RunPrintRates(o);
  return snapthread::viewer::RunViewer(o);
}
