// snapthread-viewer: watches a session (thread shape + solver status) over LCM.
// Exit codes (common/app/exit_codes.h, docs/cli.md): 0 closed, stopped or screenshot
// written; 1 set-up failed (LCM, key, window); 2 bad arguments; 3 the screenshot's shapes
// did not arrive in time.
#include <CLI/CLI.hpp>

#include "app/command_line.h"
#include "app/common_flags.h"
#include "app/stop_signals.h"
#include "viewer_app.h"

namespace {

constexpr const char* kProgram = "snapthread-viewer";

void AddViewerFlags(CLI::App* app, snapthread::viewer::ViewerOptions* o) {
  using snapthread::app::FiniteNumber;
  snapthread::app::CommonFlagSet common;
  common.session_from_environment = true;
  common.key_note = "; an observer credential (snapthread-keygen --role observer) or the root key; "
                    "--grasp-mode needs a device credential";
  common.encrypt = true;  // what --grasp-mode publishes
  snapthread::app::AddCommonFlags(app, &o->common, common);
  app->add_option("--width", o->width, "window width, pixels")->capture_default_str()
      ->check(CLI::Range(64, 8192));
  app->add_option("--height", o->height, "window height, pixels")->capture_default_str()
      ->check(CLI::Range(64, 8192));
  app->add_option("--screenshot", o->screenshot_path,
                  "headless: write a PNG after --after-shapes shapes and exit");
  app->add_option("--after-shapes", o->after_shapes, "shapes to receive before the screenshot")
      ->capture_default_str()->check(CLI::Range(1, 1000000));
  app->add_option("--timeout-s", o->timeout_s,
                  "screenshot: fail (exit 3) if the shapes have not arrived by then")
      ->capture_default_str()->check(CLI::NonNegativeNumber)->check(FiniteNumber());
  app->add_flag("--print-rates", o->print_rates,
                "print live rates of every <SESSION>_* channel once per second (no window)");
  app->add_option("--duration-s", o->duration_s, "exit after this many seconds (0 = never)")
      ->capture_default_str()->check(CLI::NonNegativeNumber)->check(FiniteNumber());
  app->add_option("--max-fps", o->max_fps, "render at most this many frames per second")
      ->capture_default_str()->check(CLI::Range(1.0, 1000.0))->check(FiniteNumber());
  app->add_flag("--grasp-mode", o->grasp_mode,
                "drag the grasp with the mouse: publishes device_state_t on <SESSION>_DEVICE_STATE, "
                "as the device --key's device credential names (the root key: the scene's grasp)");
  app->add_option("--scene", o->scene_path, "scene YAML (its device mapping; needed by --grasp-mode)")
      ->check(CLI::ExistingFile);
}

}  // namespace

int main(int argc, char** argv) {
  namespace app = snapthread::app;
  namespace viewer = snapthread::viewer;
  viewer::ViewerOptions o;
  CLI::App cli{
      "snapthread-viewer: draws a snapthread session (thread, grasp, force, solver state) "
      "from <SESSION>_SHAPE and <SESSION>_SOLVER_STATUS. Never publishes forces.\n"
      "Mouse: left drag orbits, wheel zooms, F refits, Q/Esc quits."};
  AddViewerFlags(&cli, &o);
  if (auto code = app::ParseCommandLine(cli, argc, argv, viewer::kExitBadArguments)) return *code;
  if (auto code = app::CheckCommonFlags(o.common, kProgram, viewer::kExitBadArguments)) return *code;
  if (o.grasp_mode && o.scene_path.empty()) {
    return app::Fail(kProgram, viewer::kExitBadArguments, "--grasp-mode needs --scene FILE");
  }
  // A receiver: a kernel buffer that rides out seconds off the CPU (lcm_url.h).
  o.lcm_url = app::LcmUrl(o.common);
  app::StopSignals stop;  // before LCM, GLFW or the driver start a thread
  if (o.print_rates) return viewer::RunPrintRates(o, &stop);
  return viewer::RunViewer(o, &stop);
}
