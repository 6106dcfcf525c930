// Service chart: pose -> force-model round trip of a real server + device pair.
#include "bench_support.h"

#include <fcntl.h>
#include <signal.h>
#include <spawn.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <ctime>
#include <filesystem>
#include <fstream>
#include <iomanip>
#include <map>
#include <numbers>
#include <sstream>
#include <stdexcept>
#include <thread>

#include "auth/key_file.h"
#include "models/models.h"

extern char** environ;

namespace snapthread {

namespace fs = std::filesystem;

// ---------------------------------------------------------------- service

bool JsonNumber(const std::string& json, const std::string& key, double* value) {
  const std::string quoted = "\"" + key + "\"";
  size_t p = json.find(quoted);
  if (p == std::string::npos) return false;
  p = json.find(':', p + quoted.size());
  if (p == std::string::npos) return false;
  const char* begin = json.c_str() + p + 1;
  char* end = nullptr;
  const double v = std::strtod(begin, &end);
  if (end == begin || !std::isfinite(v)) return false;
  *value = v;
  return true;
}

std::string ReadFile(const std::string& path) {
  std::ifstream in(path);
  std::stringstream ss;
  ss << in.rdbuf();
  return ss.str();
}

pid_t Spawn(const std::vector<std::string>& args, const std::string& log) {
  posix_spawn_file_actions_t fa;
  posix_spawn_file_actions_init(&fa);
  posix_spawn_file_actions_addopen(&fa, STDOUT_FILENO, log.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0644);
  posix_spawn_file_actions_adddup2(&fa, STDOUT_FILENO, STDERR_FILENO);
  std::vector<char*> argv;
  for (const auto& a : args) argv.push_back(const_cast<char*>(a.c_str()));
  argv.push_back(nullptr);
  pid_t pid = -1;
  const int rc = posix_spawn(&pid, argv[0], &fa, nullptr, argv.data(), environ);
  posix_spawn_file_actions_destroy(&fa);
  return rc == 0 ? pid : -1;
}

int WaitFor(pid_t pid, double timeout_s) {
  const auto t0 = Clock::now();
  while (true) {
    int status = 0;
    const pid_t r = waitpid(pid, &status, WNOHANG);
    if (r == pid) return WIFEXITED(status) ? WEXITSTATUS(status) : 128 + (WIFSIGNALED(status) ? WTERMSIG(status) : 0);
    if (r < 0) return -1;
    if (Seconds(t0, Clock::now()) > timeout_s) {
      kill(pid, SIGKILL);
      waitpid(pid, &status, 0);
      return -1;
    }
    std::this_thread::sleep_for(std::chrono::milliseconds(20));
  }
}

bool PrepareServiceSession(const std::string& bin_dir, const std::string& scenes_dir, const std::string& scene,
                           const std::string& work_dir, ServiceSession* s, std::string* error) {
  s->server_bin = bin_dir + "/snapthread-server";
  s->device_bin = bin_dir + "/snapthread-device";
  for (const auto& b : {s->server_bin, s->device_bin})
    if (access(b.c_str(), X_OK) != 0) {
      *error = b + " missing (build snapthread-server and snapthread-device)";
      return false;
    }
  s->scene_file = scenes_dir + "/" + scene + ".yaml";
  fs::create_directories(work_dir);
  s->base = work_dir + "/" + s->session;
  return true;
}

bool WriteSessionKey(const std::string& path, std::string* error) {
  try {
    auth::WriteNewKey(auth::KeyLocation{path, "bench"}, /*overwrite=*/true);
  } catch (const std::exception& e) {
    *error = std::string("cannot make a session key: ") + e.what();
    return false;
  }
  return true;
}

namespace {
std::string NumberArg(double value) {
  char text[32];
  std::snprintf(text, sizeof text, "%g", value);
  return text;
}
}  // namespace

pid_t StartServer(const ServiceSession& s, std::string* error) {
  const pid_t server = Spawn({s.server_bin, "--key", s.key_path, "--scene", s.scene_file, "--session", s.session,
                              "--lcm-url", s.lcm_url, "--duration", NumberArg(s.duration_s + 60.0), "--log-level",
                              "info", "--summary", s.base + "_server.json"},
                             s.base + "_server.log");
  if (server < 0) {
    *error = "cannot start the server";
    return -1;
  }
  // The server logs its session line once it has loaded the scene and subscribed.
  for (int k = 0; k < 300; ++k) {
    if (ReadFile(s.base + "_server.log").find("server: session") != std::string::npos) return server;
    int status = 0;
    if (waitpid(server, &status, WNOHANG) == server) {
      *error = "the server exited at start (see " + s.base + "_server.log)";
      return -1;
    }
    std::this_thread::sleep_for(std::chrono::milliseconds(50));
  }
  kill(server, SIGTERM);
  WaitFor(server, 10);
  *error = "the server did not start within 15 s (see " + s.base + "_server.log)";
  return -1;
}

std::vector<std::string> DeviceArgs(const ServiceSession& s) {
  return {s.device_bin, "--key",  s.key_path, "--backend", "virtual-hand", "--scene", s.scene_file, "--session",
          s.session,    "--lcm-url", s.lcm_url, "--duration", NumberArg(s.duration_s), "--rate-hz", "1000",
          "--publish-divisor", "1", "--summary", s.base + "_device.json"};
}

std::string StopServer(pid_t server, int device_rc, const ServiceSession& s) {
  kill(server, SIGTERM);
  const int server_rc = WaitFor(server, 20.0);
  if (device_rc == 0 && server_rc == 0) return "";
  return "device exit " + std::to_string(device_rc) + ", server exit " + std::to_string(server_rc) + " (logs " +
         s.base + "_*.log)";
}

ServiceRun RunServiceOnce(const ServiceOptions& o, const std::string& scene, int index) {
  ServiceRun run;
  run.scene = scene;
  ServiceSession s;
  s.session = "BENCH_" + std::to_string(getpid()) + "_" + std::to_string(index);
  s.lcm_url = o.lcm_url;
  s.duration_s = o.duration_s;
  if (!PrepareServiceSession(o.bin_dir, o.scenes_dir, scene, o.work_dir, &s, &run.error)) return run;
  // The session key both binaries sign with: $SNAPTHREAD_KEY_FILE when set, else a new
  // one for this run (mode 0600) next to its logs.
  if (const char* env = std::getenv(auth::kKeyFileEnv); env != nullptr && *env != '\0') {
    s.key_path = env;
  } else {
    s.key_path = s.base + ".key";
    if (!WriteSessionKey(s.key_path, &run.error)) return run;
  }
  const pid_t server = StartServer(s, &run.error);
  if (server < 0) return run;
  std::vector<std::string> device_args = DeviceArgs(s);
  device_args.push_back("--no-rt");
  const pid_t device = Spawn(device_args, s.base + "_device.log");
  const int device_rc = device < 0 ? -1 : WaitFor(device, o.duration_s + 30.0);
  run.error = StopServer(server, device_rc, s);
  if (!run.error.empty()) return run;
  const std::string& base = s.base;
  const std::string dev = ReadFile(base + "_device.json");
  const std::string srv = ReadFile(base + "_server.json");
  const bool ok = JsonNumber(dev, "round_trip_us_p50", &run.round_trip_us_p50) &&
                  JsonNumber(dev, "round_trip_us_p99", &run.round_trip_us_p99) &&
                  JsonNumber(dev, "lateness_us_p50", &run.lateness_us_p50) &&
                  JsonNumber(dev, "lateness_us_p99", &run.lateness_us_p99) &&
                  JsonNumber(dev, "tick_rate_hz", &run.tick_rate_hz);
  if (!ok) {
    run.error = "the device summary lacks round_trip_us_* / lateness_us_* (" + base + "_device.json)";
    return run;
  }
  JsonNumber(srv, "update_rate_hz", &run.server_update_rate_hz);
  JsonNumber(srv, "solve_us_p50", &run.server_solve_us_p50);
  JsonNumber(srv, "solve_us_p99", &run.server_solve_us_p99);
  run.ok = true;
  return run;
}

std::vector<ServiceRun> RunServiceBench(const ServiceOptions& o, std::ostream* progress) {
  std::vector<ServiceRun> runs;
  int index = 0;
  for (const auto& scene : o.scenes)
    for (int rep = 0; rep < std::max(1, o.repetitions); ++rep) {
      if (progress)
        *progress << "bench service: " << scene << " run " << rep + 1 << "/" << o.repetitions << " (" << o.duration_s
                  << " s)\n"
                  << std::flush;
      runs.push_back(RunServiceOnce(o, scene, index++));
      if (progress && !runs.back().ok) *progress << "bench service: failed: " << runs.back().error << '\n';
    }
  return runs;
}

void WriteServiceCsv(const std::vector<ServiceRun>& runs, std::ostream& out) {
  out << "scene,ok,round_trip_us_p50,round_trip_us_p99,lateness_us_p50,lateness_us_p99,tick_rate_hz,"
         "server_update_rate_hz,server_solve_us_p50,server_solve_us_p99,error\n";
  for (const auto& r : runs)
    out << r.scene << ',' << (r.ok ? 1 : 0) << ',' << r.round_trip_us_p50 << ',' << r.round_trip_us_p99 << ','
        << r.lateness_us_p50 << ',' << r.lateness_us_p99 << ',' << r.tick_rate_hz << ',' << r.server_update_rate_hz
        << ',' << r.server_solve_us_p50 << ',' << r.server_solve_us_p99 << ",\"" << r.error << "\"\n";
}

void PrintServiceTable(const std::vector<ServiceRun>& runs, std::ostream& out) {
  std::map<std::string, std::vector<const ServiceRun*>> by;
  std::vector<std::string> order;
  for (const auto& r : runs) {
    if (!by.count(r.scene)) order.push_back(r.scene);
    by[r.scene].push_back(&r);
  }
  char buf[256];
  std::snprintf(buf, sizeof buf, "%-14s %5s %22s %22s %22s %22s %18s %18s %18s\n", "scene", "runs",
                "round trip p50 us", "round trip p99 us", "lateness p50 us", "lateness p99 us", "tick Hz",
                "server updates/s", "server solve p99 us");
  out << buf << "  (median [min..max] over the runs)\n";
  for (const auto& s : order) {
    std::vector<double> a, b, c, d, e, f, g;
    int ok = 0;
    for (const ServiceRun* r : by[s]) {
      if (!r->ok) continue;
      ++ok;
      a.push_back(r->round_trip_us_p50);
      b.push_back(r->round_trip_us_p99);
      c.push_back(r->lateness_us_p50);
      d.push_back(r->lateness_us_p99);
      e.push_back(r->tick_rate_hz);
      f.push_back(r->server_update_rate_hz);
      g.push_back(r->server_solve_us_p99);
    }
    auto cell = [](const std::vector<double>& v) {
      const Spread sp = Summarize(v);
      char t[64];
      std::snprintf(t, sizeof t, "%.0f [%.0f..%.0f]", sp.median, sp.min, sp.max);
      return std::string(t);
    };
    std::snprintf(buf, sizeof buf, "%-14s %2d/%-2zu %22s %22s %22s %22s %18s %18s %18s\n", s.c_str(), ok,
                  by[s].size(), cell(a).c_str(), cell(b).c_str(), cell(c).c_str(), cell(d).c_str(), cell(e).c_str(),
                  cell(f).c_str(), cell(g).c_str());
    out << buf;
  }
}


}  // namespace snapthread
