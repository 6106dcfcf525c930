// snapthread-scene-shape: runs a scene along its grasp.path with the scene's tracker (as
// snapthread-sweep does) up to one row, builds the server's thread_shape_t of that
// equilibrium (server::BuildShape: nodes, the rod's material frames and twist, contacts)
// and publishes it, signed with the session key, with a signed solver status before each
// shape, until --duration ends. It feeds snapthread-viewer --screenshot for the docs'
// pictures of states a device cannot reach yet (a rolled rod: tools/rod/viewer_shot.sh).
#include <chrono>
#include <cstdio>
#include <string>
#include <thread>
#include <vector>

#include <CLI/CLI.hpp>
#include <lcm/lcm-cpp.hpp>

#include "../sweep.h"
#include "../tool_main.h"
#include "auth/key_file.h"
#include "auth/key_set.h"
#include "auth/message_mac.h"
#include "auth/session_epoch.h"
#include "messages/channels.h"
#include "messages/lcm_url.h"
#include "realtime/clock.h"
#include "scene/scene.h"
#include "server_messages.h"

int main(int argc, char** argv) {
  using namespace snapthread;
  CLI::App app{"snapthread-scene-shape: publishes the thread shape of a scene at one row of "
               "its grasp.path (for viewer screenshots)"};
  std::string scene_file, session = "SNAPTHREAD", lcm_url, key_path;
  std::vector<std::string> sets;
  int steps = 100, row = -1;
  double duration_s = 20.0, rate_hz = 30.0;
  app.add_option("--scene", scene_file, "scene YAML with a grasp.path")->required()->check(CLI::ExistingFile);
  app.add_option("--set", sets, "override a scene key, e.g. --set params.n=20 (repeatable)");
  app.add_option("--steps", steps, "steps per leg of the path")->capture_default_str();
  app.add_option("--row", row, "the path row to show (-1: the last)")->capture_default_str();
  app.add_option("--session", session, "session name (channel prefix)")->capture_default_str();
  app.add_option("--lcm-url", lcm_url, "LCM URL (default: env LCM_DEFAULT_URL, else udpm loopback)");
  app.add_option("--key", key_path, "the root key file (default: $SNAPTHREAD_KEY_FILE, else XDG)");
  app.add_option("--duration", duration_s, "publish for this many seconds")->capture_default_str();
  app.add_option("--rate-hz", rate_hz, "shapes per second")->capture_default_str()
      ->check(CLI::Range(1.0, 200.0));
  return RunTool("snapthread-scene-shape", app, argc, argv, [&]() -> int {
    messages::Channels{session};  // refuses a --session outside [A-Za-z0-9_] before the sweep
    std::vector<SceneOverride> overrides;
    for (const auto& s : sets) overrides.push_back(ParseOverride(s));
    const Scene scene = LoadScene(scene_file, overrides);
    if (steps < 1) throw std::invalid_argument("--steps: expected an integer >= 1");
    std::vector<Vec> controls = PathControls(scene, steps);
    if (row >= static_cast<int>(controls.size()) || row < -1) {
      throw std::invalid_argument("--row: expected -1 or 0.." + std::to_string(controls.size() - 1));
    }
    if (row >= 0) controls.resize(static_cast<size_t>(row) + 1);
    auto tracker = MakeTracker(scene);
    const std::vector<SweepRow> rows = RunSweep(tracker.get(), controls);
    const SweepRow& last = rows.back();
    std::printf("row %d: probe %.4g, negative pivots %d, roll %.1f deg\n", last.step, last.probe,
                last.negative_pivots, last.u.size() >= 6 ? last.u[3] * 180.0 / 3.14159265358979 : 0.0);
    std::fflush(stdout);

    // Published as the server would: signed with the root key's server signer.
    const auth::KeySet keys = auth::KeySet::FromRoot(auth::LoadKey(auth::ResolveKeyPath(key_path)));
    lcm::LCM lcm(messages::ResolveLcmUrl(lcm_url));
    if (!lcm.good()) throw std::runtime_error("cannot open LCM");
    const messages::Channels channels(session);
    const int64_t epoch = auth::NewEpoch();
    auth::AuthSequence auth_seq;
    server::ShapeInputs in;
    in.scene = scene.name;
    in.mapping = &scene.device;
    in.model = &tracker->model();
    in.x = tracker->state();
    in.u = tracker->control();
    in.force_model_units = last.force;
    for (int i = 0; i < 3 && i < last.force.size(); ++i) {
      in.force_newtons[i] = scene.device.newtons_per_model_force * last.force[i];
    }
    in.snaps = 0;
    const auto start = std::chrono::steady_clock::now();
    for (int64_t seq = 0;; ++seq) {
      if (std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count() > duration_s) break;
      solver_status_t st{};
      st.utime = realtime::RealtimeMicros();
      st.seq = seq;
      st.scene = scene.name;
      st.method = scene.solver.method;
      st.iterations = last.iterations;  // of the row's update
      st.residual = last.residual;
      st.lambda_min = last.lambda_min;
      st.negative_pivots = last.negative_pivots;
      if (auth::Sign(&st, channels.solver_status, epoch, auth_seq.Next(), keys.tagger())) {
        lcm.publish(channels.solver_status, &st);
      }
      in.seq = seq;
      in.utime = realtime::RealtimeMicros();
      thread_shape_t shape = server::BuildShape(in);
      if (auth::Sign(&shape, channels.shape, epoch, auth_seq.Next(), keys.tagger())) {
        lcm.publish(channels.shape, &shape);
      }
      std::this_thread::sleep_for(std::chrono::duration<double>(1.0 / rate_hz));
    }
    return 0;
  }, ToolExitCodes{.scene_error_is_bad_input = true});
}
