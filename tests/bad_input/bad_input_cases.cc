// The bad-input table (issue 12 item 6). Scene files go to every binary that reads one;
// command lines try bad numbers ("abc", "-5", "1e999", "nan"), missing files,
// directories, FIFOs, /dev/zero, unknown flags and missing values on each binary.
#include <string>
#include <utility>
#include <vector>

#include "bad_input.h"

namespace snapthread::bad_input {
namespace {

Input Text(std::string text) { return {InputKind::kText, std::move(text), ""}; }
Input Kind(InputKind kind) { return {kind, "", ""}; }

const char kGoodHead[] = "model: curve2d\nparams: {n: 10}\n";

// A bad scene and the text that names what is wrong with it.
struct BadScene {
  Input input;
  std::string expect;
};

std::vector<BadScene> BadScenes() {
  std::string binary;
  for (int i = 0; i < 512; ++i) binary += static_cast<char>((i * 37 + 11) % 256);
  std::string deep_block;
  for (int i = 0; i < 5000; ++i) deep_block += "- ";
  const std::string g = "grasp: {start: [9, 0]}\n";
  return {
      {Text(""), "expected a YAML mapping"},
      {Text(binary), "not valid YAML"},
      {Kind(InputKind::kHuge), "over the 1 MiB limit"},
      {Text("model: " + std::string(100000, '[') + std::string(100000, ']') + "\n"), "nested deeper than 64"},
      {Text("model:\n" + deep_block + "1\n"), "nested deeper than"},
      {Text("model: curve2d\nparams: {n: 10, bending: .nan}\n" + g), "params.bending"},
      {Text("model: curve2d\nparams: {n: 10, stretching: .inf}\n" + g), "params.stretching"},
      {Text("model: curve2d\nparams: {n: -5}\n" + g), "params.n"},
      {Text("model: curve2d\nparams: {n: 1000000000}\n" + g), "params.n"},
      {Text("model: curve2d\nparams: {n: 1e999}\n" + g), "params.n"},
      {Text("model: curve2d\nparams: {n: ten}\n" + g), "params.n"},
      {Text(kGoodHead + g + "colour: red\n"), "colour: unknown key"},
      {Text("model: curve2d\nparams: {n: 10, colour: red}\n" + g), "params.colour: unknown key"},
      {Text(std::string(kGoodHead) + "grasp: 5\n"), "grasp: expected a mapping"},
      {Text("params: {n: 10}\n" + g), "model: missing"},
      {Text(kGoodHead), "grasp: missing"},
      {Text("model: rope\n" + g), "model: expected one of"},
      {Text(std::string(kGoodHead) + "model: cusp\n" + g), "model: duplicated key"},
      {Text("model: curve2d\nparams: {n: 10, n: 12}\n" + g), "params.n: duplicated key"},
      {Text(std::string(kGoodHead) + "grasp: {start: [9, 0], path: [[1, 2], [.nan, 3]]}\n"), "grasp.path[1]"},
      {Text(std::string(kGoodHead) + "grasp: {start: [9, 0], path: [[1, 2, 3]]}\n"), "grasp.path[0]"},
      {Text(std::string(kGoodHead) + "grasp: {start: [9, 0, 1]}\n"), "grasp.start"},
      {Text(kGoodHead + g + "device: {max_force_n: -1}\n"), "device.max_force_n"},
      {Text(kGoodHead + g + "solver: {cutoff: .nan}\n"), "solver.cutoff"},
      {Text(kGoodHead + g + "solver: {method: [newton]}\n"), "solver.method"},
      {Text(kGoodHead + g + "[1, 2]: 3\n"), "expected plain names"},
      {Text("model: curve2d\nparams: &p {n: *p}\n" + g), "params.n"},
      {Kind(InputKind::kFifo), "a FIFO"},
      {Kind(InputKind::kDirectory), "directory"},
      {Kind(InputKind::kDevZero), "character device"},
      {Kind(InputKind::kMissing), "{in}"},
  };
}

}  // namespace

std::vector<Case> SceneFileCases() {
  const std::vector<std::pair<std::string, std::vector<std::string>>> readers = {
      {"snapthread-sweep", {"--scene", "{in}", "--from", "0,0", "--to", "1,1", "--steps", "2"}},
      {"snapthread-server", {"--scene", "{in}", "--session", "{session}", "--lcm-url", "{url}"}},
      {"snapthread-device", {"--backend", "sim-path", "--scene", "{in}", "--session", "{session}",
                             "--lcm-url", "{url}", "--duration", "1", "--no-rt"}},
      {"snapthread-viewer", {"--grasp-mode", "--scene", "{in}", "--session", "{session}", "--lcm-url", "{url}"}},
      {"snapthread-bench", {"--advise", "{in}", "--quick", "--no-plot", "--out", "{dir}/out"}},
  };
  std::vector<Case> cases;
  for (const auto& [binary, args] : readers) {
    for (const BadScene& s : BadScenes()) cases.push_back({binary, args, s.input, s.expect});
  }
  // The stability suite reads its scenes from a folder.
  const std::vector<std::string> stability = {"--scenes", "{in}", "--sweeps", "zeeman_folds", "--no-plot",
                                              "--out", "{dir}/out"};
  cases.push_back({"snapthread-stability", stability, {InputKind::kSceneDir, "model: [", "zeeman.yaml"},
                   "not valid YAML"});
  cases.push_back({"snapthread-stability", stability,
                   {InputKind::kSceneDir, "model: zeeman\nparams: {n: 3}\ngrasp: {start: [0, 3]}\n", "zeeman.yaml"},
                   "no parameters"});
  cases.push_back({"snapthread-stability", stability, {InputKind::kSceneDirFifo, "", "zeeman.yaml"}, "a FIFO"});
  cases.push_back({"snapthread-stability", stability, {InputKind::kSceneDirFifo, "", "thread3d_loop.yaml"},
                   "a FIFO"});
  return cases;
}

std::vector<Case> CommandLineCases() {
  const Input none;
  const std::vector<std::string> sweep = {"--scene", "{scenes}/curve2d_snap.yaml"};
  auto with = [](std::vector<std::string> base, const std::vector<std::string>& more) {
    base.insert(base.end(), more.begin(), more.end());
    return base;
  };
  const std::vector<std::string> sweep_ft = with(sweep, {"--from", "9,-4", "--to", "9,4"});
  const std::vector<std::string> server = {"--scene", "{scenes}/zeeman.yaml", "--session", "{session}",
                                           "--lcm-url", "{url}"};
  const std::vector<std::string> device = {"--backend", "sim-path", "--scene", "{scenes}/zeeman.yaml",
                                           "--session", "{session}", "--lcm-url", "{url}", "--no-rt"};
  const std::vector<std::string> viewer = {"--session", "{session}", "--lcm-url", "{url}", "--print-rates"};
  const std::vector<std::string> bench = {"--quick", "--no-plot", "--out", "{dir}/out"};
  const std::vector<std::string> advise = with(bench, {"--advise", "{scenes}/curve2d_snap.yaml"});
  const std::vector<std::string> stability = {"--no-plot", "--out", "{dir}/out"};
  const std::vector<std::string> report = {"--no-plots", "--out", "{dir}/report"};
  const std::string run_session = "deploy/run_session.sh";
  return {
      // snapthread-sweep
      {"snapthread-sweep", with(sweep_ft, {"--steps", "abc"}), none, "--steps"},
      {"snapthread-sweep", with(sweep_ft, {"--steps", "-5"}), none, "--steps"},
      {"snapthread-sweep", with(sweep_ft, {"--steps", "1e999"}), none, "--steps"},
      {"snapthread-sweep", with(sweep_ft, {"--steps", "1000000000000"}), none, "--steps"},
      {"snapthread-sweep", with(sweep, {"--from", "9,nan", "--to", "9,4"}), none, "--from"},
      {"snapthread-sweep", with(sweep, {"--from", "9,-4", "--to", "9,1e999"}), none, "--to"},
      {"snapthread-sweep", with(sweep_ft, {"--cutoff", "nan"}), none, "--cutoff"},
      {"snapthread-sweep", with(sweep_ft, {"--cutoff", "-5"}), none, "--cutoff"},
      {"snapthread-sweep", with(sweep_ft, {"--max-iterations", "-5"}), none, "--max-iterations"},
      {"snapthread-sweep", with(sweep_ft, {"--method", "magic"}), none, "--method"},
      {"snapthread-sweep", with(sweep_ft, {"--set", "params.n"}), none, "--set"},
      {"snapthread-sweep", with(sweep_ft, {"--set", "params.n=1e999"}), none, "params.n"},
      {"snapthread-sweep", with(sweep_ft, {"--set", "params.n=1000000000"}), none, "params.n"},
      {"snapthread-sweep", with(sweep_ft, {"--out", "{dir}/no/such/dir/out.csv"}), none, "--out"},
      {"snapthread-sweep", with(sweep_ft, {"--bogus"}), none, "--bogus"},
      {"snapthread-sweep", with(sweep_ft, {"--steps"}), none, "--steps"},
      {"snapthread-sweep", {"--from", "0,0", "--to", "1,1"}, none, "--scene"},
      // snapthread-server
      {"snapthread-server", with(server, {"--shape-rate-hz", "nan"}), none, "--shape-rate-hz"},
      {"snapthread-server", with(server, {"--status-rate-hz", "-5"}), none, "--status-rate-hz"},
      {"snapthread-server", with(server, {"--duration", "1e999"}), none, "--duration"},
      {"snapthread-server", with(server, {"--load-timeout", "abc"}), none, "--load-timeout"},
      {"snapthread-server", with(server, {"--method", "magic"}), none, "--method"},
      {"snapthread-server", with(server, {"--allow-methods", "newton,magic"}), none, "--allow-methods"},
      {"snapthread-server", with(server, {"--log-level", "loud"}), none, "--log-level"},
      {"snapthread-server", {"--scene", "{scenes}/zeeman.yaml", "--session", "bad-name"}, none, "--session"},
      {"snapthread-server", with(server, {"--scene-dir", "{in}"}), Kind(InputKind::kMissing), "--scene-dir"},
      {"snapthread-server", with(server, {"--scene-dir", "{in}"}), Kind(InputKind::kFifo), "--scene-dir"},
      {"snapthread-server", with(server, {"--key", "{in}"}), Kind(InputKind::kDirectory), "--key"},
      {"snapthread-server", with(server, {"--key", "{in}"}), Kind(InputKind::kDevZero), "--key"},
      {"snapthread-server", with(server, {"--key", "{in}"}), Kind(InputKind::kFifo), "--key"},
      {"snapthread-server", with(server, {"--key", "{in}"}), Kind(InputKind::kKeyMode0644), "mode"},
      {"snapthread-server", with(server, {"--bogus"}), none, "--bogus"},
      {"snapthread-server", with(server, {"--summary"}), none, "--summary"},
      {"snapthread-server", {"--session", "{session}"}, none, "--scene"},
      // snapthread-device
      {"snapthread-device", with(device, {"--rate-hz", "nan"}), none, "--rate-hz"},
      {"snapthread-device", with(device, {"--rate-hz", "-5"}), none, "--rate-hz"},
      {"snapthread-device", with(device, {"--duration", "1e999"}), none, "--duration"},
      {"snapthread-device", with(device, {"--duration", "nan"}), none, "--duration"},
      {"snapthread-device", with(device, {"--publish-divisor", "abc"}), none, "--publish-divisor"},
      {"snapthread-device", with(device, {"--fade-ms", "nan"}), none, "--fade-ms"},
      {"snapthread-device", with(device, {"--model-timeout-ms", "nan"}), none, "--model-timeout-ms"},
      {"snapthread-device", with(device, {"--speed-m-per-s", "nan"}), none, "--speed-m-per-s"},
      {"snapthread-device", with(device, {"--backend", "magic"}), none, "--backend"},
      {"snapthread-device", with(device, {"--path-csv", "{in}"}), Kind(InputKind::kFifo), "a FIFO"},
      {"snapthread-device", with(device, {"--path-csv", "{in}"}), Kind(InputKind::kDevZero), "character device"},
      {"snapthread-device", with(device, {"--path-csv", "{in}"}), Kind(InputKind::kHuge), "limit"},
      {"snapthread-device", with(device, {"--path-csv", "{in}"}), Text("x,y\n0.01,abc\n"), ":2"},
      {"snapthread-device", with(device, {"--path-csv", "{in}"}), Text("0.01,nan\n"), "non-finite"},
      {"snapthread-device", with(device, {"--path-csv", "{in}"}), Text(""), "no positions"},
      {"snapthread-device", with(device, {"--session", "bad-name"}), none, "--session"},
      {"snapthread-device", with(device, {"--key", "{in}"}), Kind(InputKind::kKeyShort), "bytes"},
      {"snapthread-device", with(device, {"--key", "{in}"}), Kind(InputKind::kFifo), "--key"},
      {"snapthread-device", with(device, {"--bogus"}), none, "--bogus"},
      {"snapthread-device", with(device, {"--trace-divisor"}), none, "--trace-divisor"},
      // snapthread-viewer
      {"snapthread-viewer", with(viewer, {"--width", "abc"}), none, "--width"},
      {"snapthread-viewer", with(viewer, {"--width", "-5"}), none, "--width"},
      {"snapthread-viewer", with(viewer, {"--timeout-s", "nan"}), none, "--timeout-s"},
      {"snapthread-viewer", with(viewer, {"--duration-s", "nan"}), none, "--duration-s"},
      {"snapthread-viewer", with(viewer, {"--duration-s", "-5"}), none, "--duration-s"},
      {"snapthread-viewer", with(viewer, {"--max-fps", "nan"}), none, "--max-fps"},
      {"snapthread-viewer", with(viewer, {"--after-shapes", "1e999"}), none, "--after-shapes"},
      {"snapthread-viewer", {"--session", "bad-name", "--print-rates"}, none, "--session"},
      {"snapthread-viewer", {"--session", "{session}", "--grasp-mode"}, none, "--scene"},
      {"snapthread-viewer", with(viewer, {"--key", "{in}"}), Kind(InputKind::kDevZero), "--key"},
      {"snapthread-viewer", with(viewer, {"--bogus"}), none, "--bogus"},
      {"snapthread-viewer", with(viewer, {"--width"}), none, "--width"},
      // snapthread-bench
      {"snapthread-bench", with(bench, {"--repetitions", "0"}), none, "--repetitions"},
      {"snapthread-bench", with(bench, {"--repetitions", "abc"}), none, "--repetitions"},
      {"snapthread-bench", with(bench, {"--only", "magic"}), none, "--only"},
      {"snapthread-bench", with(bench, {"--only", "scaling", "--ns", "1"}), none, "--ns"},
      {"snapthread-bench", with(bench, {"--only", "scaling", "--ns", "1000000000"}), none, "--ns"},
      {"snapthread-bench", with(bench, {"--only", "accuracy", "--methods", "magic"}), none, "--methods"},
      {"snapthread-bench", with(bench, {"--only", "accuracy", "--cutoffs", "nan"}), none, "--cutoffs"},
      {"snapthread-bench", with(bench, {"--only", "accuracy", "--budgets", "-5"}), none, "--budgets"},
      {"snapthread-bench", with(bench, {"--service-duration", "nan"}), none, "--service-duration"},
      {"snapthread-bench", with(advise, {"--target-force-error", "nan"}), none, "--target-force-error"},
      {"snapthread-bench", with(advise, {"--ladder", "1"}), none, "--ladder"},
      {"snapthread-bench", with(advise, {"--reference-n", "1000000000"}), none, "--reference-n"},
      {"snapthread-bench", with(bench, {"--bogus"}), none, "--bogus"},
      {"snapthread-bench", with(bench, {"--advise"}), none, "--advise"},
      // snapthread-stability
      {"snapthread-stability", with(stability, {"--budgets", "abc"}), none, "--budgets"},
      {"snapthread-stability", with(stability, {"--budgets", "-5"}), none, "--budgets"},
      {"snapthread-stability", with(stability, {"--sweeps", "magic"}), none, "--sweeps"},
      {"snapthread-stability", with(stability, {"--substeps", "0"}), none, "--substeps"},
      {"snapthread-stability", with(stability, {"--plot-budget", "abc"}), none, "--plot-budget"},
      {"snapthread-stability", with(stability, {"--scenes", "{in}"}), Kind(InputKind::kMissing), "{in}"},
      {"snapthread-stability", with(stability, {"--bogus"}), none, "--bogus"},
      {"snapthread-stability", with(stability, {"--budgets"}), none, "--budgets"},
      // snapthread-report
      {"snapthread-report", with(report, {"{in}"}), Kind(InputKind::kMissing), "{in}"},
      {"snapthread-report", with(report, {"{in}"}), Kind(InputKind::kDirectory), "directory"},
      {"snapthread-report", with(report, {"{in}"}), Kind(InputKind::kFifo), "not a regular file"},
      {"snapthread-report", with(report, {"{in}"}), Kind(InputKind::kDevZero), "not a regular file"},
      {"snapthread-report", with(report, {"{in}"}), Text(""), "no readable events"},
      {"snapthread-report", with(report, {"{in}"}), Text(std::string(4096, '\x5a')), "no readable events"},
      {"snapthread-report", with(report, {"{in}"}), Kind(InputKind::kHuge), "no readable events"},
      {"snapthread-report", with(report, {"{in}", "--session"}), Kind(InputKind::kMissing), "--session"},
      {"snapthread-report", with(report, {"{in}", "--bogus"}), Kind(InputKind::kMissing), "--bogus"},
      {"snapthread-report", report, none, "LOGFILE"},
      // snapthread-keygen
      {"snapthread-keygen", {"--key", "{in}"}, Kind(InputKind::kDirectory), "directory"},
      {"snapthread-keygen", {"--key", "{in}", "--id"}, Kind(InputKind::kDevZero), "{in}"},
      {"snapthread-keygen", {"--key", "{in}", "--id"}, Kind(InputKind::kFifo), "{in}"},
      {"snapthread-keygen", {"--key", "{in}", "--id"}, Kind(InputKind::kMissing), "{in}"},
      {"snapthread-keygen", {"--key", "{in}", "--id"}, Kind(InputKind::kKeyMode0644), "mode"},
      {"snapthread-keygen", {"--key", "{in}", "--id"}, Kind(InputKind::kKeyShort), "bytes"},
      {"snapthread-keygen", {"--key", "{in}"}, Kind(InputKind::kKeyShort), "--force"},
      {"snapthread-keygen", {"--key", "/proc/snapthread/session.key"}, none, "/proc/snapthread"},
      {"snapthread-keygen", {"--bogus"}, none, "--bogus"},
      {"snapthread-keygen", {"--key"}, none, "--key"},
      // snapthread-linear-bench
      {"snapthread-linear-bench", {"--sizes", "abc"}, none, "--sizes"},
      {"snapthread-linear-bench", {"--sizes", "-5"}, none, "--sizes"},
      {"snapthread-linear-bench", {"--sizes", "0"}, none, "--sizes"},
      {"snapthread-linear-bench", {"--sizes", "1e999"}, none, "--sizes"},
      {"snapthread-linear-bench", {"--sizes", "1000000000"}, none, "--sizes"},
      {"snapthread-linear-bench", {"--thread3d", "--sizes", "1"}, none, "--sizes"},
      {"snapthread-linear-bench", {"--bandwidth", "-1"}, none, "--bandwidth"},
      {"snapthread-linear-bench", {"--budget-s", "nan"}, none, "--budget-s"},
      {"snapthread-linear-bench", {"--min-sample-us", "-1"}, none, "--min-sample-us"},
      {"snapthread-linear-bench", {"--dense-max", "abc"}, none, "--dense-max"},
      {"snapthread-linear-bench", {"--ring", "--thread3d"}, none, "--ring"},
      {"snapthread-linear-bench", {"--bogus"}, none, "--bogus"},
      {"snapthread-linear-bench", {"--sizes"}, none, "--sizes"},
      // snapthread-logger
      {"snapthread-logger", {"-l", "{url}", "-f", "{in}"}, Kind(InputKind::kFifo), "not a regular file"},
      {"snapthread-logger", {"-l", "{url}", "-f", "{in}"}, Kind(InputKind::kDevZero), "not a regular file"},
      {"snapthread-logger", {"-l", "{url}", "-f", "{in}"}, Kind(InputKind::kDirectory), "directory"},
      {"snapthread-logger", {"-l", "{url}", "{in}"}, Text("a log"), "--force"},
      {"snapthread-logger", {"-l", "{url}", "{dir}/no/such/dir/x.lcmlog"}, none, "cannot write"},
      {"snapthread-logger", {"-l", "{url}", "--duration-s", "nan", "{dir}/x.lcmlog"}, none, "--duration-s"},
      {"snapthread-logger", {"-l", "{url}", "--duration-s", "-5", "{dir}/x.lcmlog"}, none, "--duration-s"},
      {"snapthread-logger", {"-l", "{url}", "--flush-interval", "abc", "{dir}/x.lcmlog"}, none, "--flush-interval"},
      {"snapthread-logger", {"-l", "{url}", "--flush-interval", "0", "{dir}/x.lcmlog"}, none, "--flush-interval"},
      {"snapthread-logger", {"-l", "bogus://nowhere", "{dir}/x.lcmlog"}, none, "bogus://nowhere"},
      {"snapthread-logger", {"-l", "{url}", "-s", ""}, none, "--strftime"},
      {"snapthread-logger", {"-l", "{url}", "--bogus", "{dir}/x.lcmlog"}, none, "--bogus"},
      {"snapthread-logger", {"-l", "{url}", "-c"}, none, "--channel"},
      {"snapthread-logger", {"-l", "{url}"}, none, "file"},
      // deploy/run_session.sh: the session wrapper around the logger and the binaries
      {run_session, {"--duration", "abc"}, none, "--duration"},
      {run_session, {"--duration", "-5"}, none, "--duration"},
      {run_session, {"--duration", "1e999"}, none, "--duration"},
      {run_session, {"--scene", "{in}"}, Kind(InputKind::kDevZero), "--scene"},
      {run_session, {"--scene", "{in}"}, Kind(InputKind::kDirectory), "--scene"},
      {run_session, {"--scene", "{in}"}, Kind(InputKind::kFifo), "--scene"},
      {run_session, {"--session", "bad-name"}, none, "--session"},
      {run_session, {"--bogus"}, none, "--bogus"},
      {run_session, {"--duration"}, none, "--duration"},
  };
}

}  // namespace snapthread::bad_input
