#include "viewer_app.h"

#include <chrono>
#include <cmath>
#include <cstdio>
#include <memory>
#include <optional>
#include <thread>

#include <epoxy/gl.h>
// GLFW after epoxy: epoxy provides the GL declarations.
#include <GLFW/glfw3.h>
#include <lcm/lcm-cpp.hpp>

#include "app/common_flags.h"
#include "channel_rates.h"
#include "messages/channels.h"
#include "grasp_publisher.h"
#include "png_writer.h"
#include "renderer.h"
#include "session_receiver.h"
#include "scene/scene.h"
#include "models/registry.h"
#include "messages/lcm_url.h"

namespace snapthread::viewer {
namespace {

using Clock = std::chrono::steady_clock;
constexpr double kGraspPickPixels = 30.0;     // press this close to the grasp to drag it

std::string g_glfw_error;  // written only by the GLFW error callback on the main thread

void OnGlfwError(int code, const char* description) {
  g_glfw_error = "GLFW error " + std::to_string(code) + ": " + description;
}

double Seconds(Clock::time_point since) {
  return std::chrono::duration<double>(Clock::now() - since).count();
}

// Window state shared with the GLFW input callbacks through the user pointer.
struct InputState {
  OrbitCamera camera;
  bool fitted = false;
  bool request_fit = false;
  bool orbiting = false;
  bool dragging_grasp = false;
  double last_x = 0, last_y = 0;
  double scroll = 0;
  bool grasp_mode = false;
  std::optional<Eigen::Vector3d> grasp_model;  // last grasp seen in a shape
  bool planar = true;
};

void OnMouseButton(GLFWwindow* window, int button, int action, int) {
  auto* in = static_cast<InputState*>(glfwGetWindowUserPointer(window));
  if (button != GLFW_MOUSE_BUTTON_LEFT) return;
  if (action == GLFW_RELEASE) {
    in->orbiting = false;
    in->dragging_grasp = false;
    return;
  }
  glfwGetCursorPos(window, &in->last_x, &in->last_y);
  if (in->grasp_mode && in->grasp_model) {
    int w = 0, h = 0, ww = 0, wh = 0;
    glfwGetFramebufferSize(window, &w, &h);
    glfwGetWindowSize(window, &ww, &wh);
    const double sx = ww > 0 ? double(w) / ww : 1.0, sy = wh > 0 ? double(h) / wh : 1.0;
    const Eigen::Vector2d g = in->camera.ProjectToPixel(*in->grasp_model, w, h);
    if (std::hypot(g.x() - in->last_x * sx, g.y() - in->last_y * sy) < kGraspPickPixels) {
      in->dragging_grasp = true;
      return;
    }
  }
  in->orbiting = true;
}

void OnCursor(GLFWwindow* window, double x, double y) {
  auto* in = static_cast<InputState*>(glfwGetWindowUserPointer(window));
  if (in->orbiting) {
    in->camera.Orbit(-(x - in->last_x) * 0.01, (y - in->last_y) * 0.01);
  }
  in->last_x = x;
  in->last_y = y;
}

void OnScroll(GLFWwindow* window, double, double dy) {
  auto* in = static_cast<InputState*>(glfwGetWindowUserPointer(window));
  in->scroll += dy;
}

void OnKey(GLFWwindow* window, int key, int, int action, int) {
  auto* in = static_cast<InputState*>(glfwGetWindowUserPointer(window));
  if (action != GLFW_PRESS) return;
  if (key == GLFW_KEY_ESCAPE || key == GLFW_KEY_Q) glfwSetWindowShouldClose(window, 1);
  if (key == GLFW_KEY_F) in->request_fit = true;
}

// Fit the camera to the nodes (not the arrows), so a given shape always frames the same way.
void FitToShape(const thread_shape_t& shape, int width, int height, OrbitCamera* camera) {
  Eigen::Vector3d lo = Eigen::Vector3d::Constant(1e300), hi = -lo;
  for (const auto& p : shape.positions) {
    const Eigen::Vector3d q(p[0], p[1], p[2]);
    lo = lo.cwiseMin(q);
    hi = hi.cwiseMax(q);
  }
  camera->Fit(lo, hi, double(width) / height);
}

// A model whose grasp (with default parameters) lies in the plane; unknown names too.
bool IsPlanarModel(const std::string& model) {
  const ModelRegistration* reg = FindModel(model);
  return reg == nullptr || reg->capabilities.grasp_layout(ModelParams{.model = reg->name}).spatial_dimension == 2;
}

// Where the mouse ray meets the drag plane: z = 0 for planar models, else the plane through
// the current grasp facing the camera.
std::optional<Eigen::Vector3d> DragTarget(GLFWwindow* window, const InputState& in) {
  int w = 0, h = 0, ww = 0, wh = 0;
  glfwGetFramebufferSize(window, &w, &h);
  glfwGetWindowSize(window, &ww, &wh);
  double x = 0, y = 0;
  glfwGetCursorPos(window, &x, &y);
  if (ww > 0) x *= double(w) / ww;
  if (wh > 0) y *= double(h) / wh;
  Eigen::Vector3d o, d;
  in.camera.PixelRay(x, y, w, h, &o, &d);
  const Eigen::Vector3d anchor = in.grasp_model.value_or(Eigen::Vector3d::Zero());
  const Eigen::Vector3d n =
      in.planar ? Eigen::Vector3d::UnitZ() : Eigen::Vector3d(in.camera.Eye() - in.camera.Target()).normalized();
  const double denom = d.dot(n);
  if (std::abs(denom) < 1e-9) return std::nullopt;
  const double t = (anchor - o).dot(n) / denom;
  if (t <= 0) return std::nullopt;
  Eigen::Vector3d p = o + t * d;
  if (in.planar) p.z() = 0.0;
  return p;
}

bool SaveScreenshot(const std::string& path, int width, int height, std::string* error) {
  std::vector<uint8_t> pixels(size_t(width) * height * 3);
  glPixelStorei(GL_PACK_ALIGNMENT, 1);
  glReadBuffer(GL_BACK);
  glReadPixels(0, 0, width, height, GL_RGB, GL_UNSIGNED_BYTE, pixels.data());
  if (glGetError() != GL_NO_ERROR) {
    *error = "glReadPixels failed";
    return false;
  }
  std::vector<uint8_t> flipped(pixels.size());  // GL rows are bottom-up, PNG top-down
  const size_t row = size_t(width) * 3;
  for (int y = 0; y < height; ++y) {
    std::copy_n(&pixels[size_t(height - 1 - y) * row], row, &flipped[size_t(y) * row]);
  }
  return WritePngRgb(path, width, height, flipped, error);
}

constexpr const char* kProgram = "snapthread-viewer";

// Whether the LCM at --lcm-url opened; if not, says so and how to start it.
bool LcmOpened(const lcm::LCM& lcm, const ViewerOptions& options) {
  if (lcm.good()) return true;
  std::fprintf(stderr, "snapthread-viewer: cannot open LCM at %s. %s\n", options.lcm_url.c_str(),
               messages::LcmStartHint(options.lcm_url).c_str());
  return false;
}

// The scene of --grasp-mode (its device mapping), or nullopt after saying why not.
// The device the viewer drives as: the grasp it moves (the scene's only grasp's name, else
// "hand"), as the server names a pose that names no grasp.
std::string DrivenGraspName(const Scene& scene) {
  if (scene.grasps.size() == 1 && !scene.grasps.front().name.empty()) return scene.grasps.front().name;
  return "hand";
}

// What --key gives the viewer: an observer credential (or the root key, verified with its
// server key) to watch; a device credential (or the root key, acting as the driven grasp's
// device) to drive a grasp too. nullopt after saying why not, naming the role needed.
std::optional<auth::KeySet> LoadViewerKeys(const ViewerOptions& options, const Scene* driven) {
  const auth::Role role = driven != nullptr ? auth::Role::kDevice : auth::Role::kObserver;
  std::optional<auth::KeySet> keys = app::LoadKeySet(options.common, role, kProgram);
  if (driven == nullptr) return keys;
  if (!keys) {
    std::fprintf(stderr, "snapthread-viewer: --grasp-mode drives a grasp as its device: --key needs that "
                         "device's credential (or watch without --grasp-mode on an observer credential)\n");
    return keys;
  }
  const std::string grasp = DrivenGraspName(*driven);
  if (keys->root() != nullptr) {
    keys.emplace(auth::KeySet::ForRole(*keys->root(), auth::Role::kDevice, grasp));
  } else if (keys->name() != grasp) {
    std::fprintf(stderr, "snapthread-viewer: warning: the device credential is for '%s', the grasp driven is "
                         "'%s': the server will refuse these poses\n", keys->name().c_str(), grasp.c_str());
  }
  return keys;
}

std::optional<Scene> LoadGraspScene(const ViewerOptions& options) {
  try {
    return LoadScene(options.scene_path);
  } catch (const std::exception& e) {
    std::fprintf(stderr, "snapthread-viewer: --grasp-mode needs a scene: %s\n", e.what());
    return std::nullopt;
  }
}

// GLFW and an OpenGL 3.3 core window with its context current, or nullptr after saying
// why not (GLFW is terminated again then).
GLFWwindow* OpenWindow(const ViewerOptions& options) {
  glfwSetErrorCallback(&OnGlfwError);
  if (!glfwInit()) {
    std::fprintf(stderr, "snapthread-viewer: cannot initialise GLFW (no $DISPLAY? use xvfb-run): %s\n",
                 g_glfw_error.c_str());
    return nullptr;
  }
  glfwWindowHint(GLFW_CONTEXT_VERSION_MAJOR, 3);
  glfwWindowHint(GLFW_CONTEXT_VERSION_MINOR, 3);
  glfwWindowHint(GLFW_OPENGL_PROFILE, GLFW_OPENGL_CORE_PROFILE);
  glfwWindowHint(GLFW_OPENGL_FORWARD_COMPAT, GLFW_TRUE);
  glfwWindowHint(GLFW_SAMPLES, options.screenshot_path.empty() ? 4 : 0);
  const std::string title = "snapthread-viewer: " + options.common.session;
  GLFWwindow* window =
      glfwCreateWindow(options.width, options.height, title.c_str(), nullptr, nullptr);
  if (window == nullptr) {
    std::fprintf(stderr, "snapthread-viewer: cannot create an OpenGL 3.3 core window: %s\n",
                 g_glfw_error.c_str());
    glfwTerminate();
    return nullptr;
  }
  glfwMakeContextCurrent(window);
  glfwSwapInterval(1);
  std::fprintf(stderr, "snapthread-viewer: GL %s, %s; listening on %s_SHAPE at %s\n",
               reinterpret_cast<const char*>(glGetString(GL_VERSION)),
               reinterpret_cast<const char*>(glGetString(GL_RENDERER)), options.common.session.c_str(),
               options.lcm_url.c_str());
  return window;
}

// The mouse and keyboard callbacks, writing into `input`.
void ConnectInput(GLFWwindow* window, InputState* input) {
  glfwSetWindowUserPointer(window, input);
  glfwSetMouseButtonCallback(window, &OnMouseButton);
  glfwSetCursorPosCallback(window, &OnCursor);
  glfwSetScrollCallback(window, &OnScroll);
  glfwSetKeyCallback(window, &OnKey);
}

// Applies what a frame's snapshot and the input since the last frame ask of the camera
// and the grasp: fit to the first shape (or on F), zoom, drag the grasp.
void UpdateView(const SessionSnapshot& snap, int w, int h, GLFWwindow* window, GraspPublisher* grasp,
                InputState* input) {
  if (snap.has_shape) {
    if (!input->fitted || input->request_fit) {
      // Planar models face the camera as drawn in the seed; a 3-D thread starts from an
      // oblique view so its depth is visible.
      if (!input->fitted && !IsPlanarModel(snap.shape.model)) input->camera.SetAngles(0.5, 0.35);
      FitToShape(snap.shape, w, h, &input->camera);
      input->fitted = true;
      input->request_fit = false;
    }
    input->grasp_model = Eigen::Vector3d(snap.shape.grasp[0], snap.shape.grasp[1], snap.shape.grasp[2]);
    input->planar = IsPlanarModel(snap.shape.model);
  }
  if (input->scroll != 0) {
    input->camera.Zoom(std::pow(0.9, input->scroll));
    input->scroll = 0;
  }
  if (grasp != nullptr && input->dragging_grasp) {
    if (auto target = DragTarget(window, *input)) grasp->Publish(*target, true);
  }
}

// Writes the screenshot of the frame just drawn; returns the exit code.
int WriteScreenshot(const ViewerOptions& options, const SessionSnapshot& snap, int w, int h) {
  glFinish();
  std::string error;
  if (!SaveScreenshot(options.screenshot_path, w, h, &error)) {
    std::fprintf(stderr, "snapthread-viewer: screenshot failed: %s\n", error.c_str());
    return kExitSetupFailed;
  }
  std::printf("snapthread-viewer: wrote %s (%dx%d) after %lld shapes, %lld bad messages\n",
              options.screenshot_path.c_str(), w, h, static_cast<long long>(snap.shapes_received),
              static_cast<long long>(snap.bad_messages));
  return kExitOk;
}

// The screenshot's shapes did not arrive by --timeout-s: says what did and where.
int ReportScreenshotTimeout(const ViewerOptions& options, const SessionSnapshot& snap,
                            const SessionReceiver& receiver, double elapsed) {
  std::fprintf(stderr,
               "snapthread-viewer: timeout after %.1f s: received %lld of %d shapes on "
               "%s at %s (%lld bad messages%s%s). Is a server publishing with --session %s?\n",
               elapsed, static_cast<long long>(snap.shapes_received), options.after_shapes,
               receiver.shape_channel().c_str(), options.lcm_url.c_str(),
               static_cast<long long>(snap.bad_messages), receiver.last_error().empty() ? "" : ", last: ",
               receiver.last_error().c_str(), options.common.session.c_str());
  return kExitTimeout;
}

// What a window (not a screenshot) saw, against the server's shape numbering.
void PrintViewerTotals(const SessionReceiver& receiver) {
  std::printf("snapthread-viewer: %lld shapes, %lld bad messages\n",
              static_cast<long long>(receiver.shapes_received()),
              static_cast<long long>(receiver.bad_messages()));
  const ShapeSequence seq = receiver.shape_sequence();
  std::printf("snapthread-viewer: shape seq %lld..%lld: %lld received, %lld missed\n",
              static_cast<long long>(seq.first), static_cast<long long>(seq.highest),
              static_cast<long long>(seq.received), static_cast<long long>(seq.Missed()));
}

// What the frame loop needs besides the options.
struct FrameLoop {
  GLFWwindow* window;
  Renderer* renderer;
  SessionReceiver* receiver;
  GraspPublisher* grasp;  // null without --grasp-mode
  app::StopSignals* stop;
};

// Draws frames until the window closes, a stop signal, --duration-s, or the screenshot
// (written, or timed out); returns the exit code.
int RunFrames(const ViewerOptions& options, const FrameLoop& loop) {
  InputState input;
  input.grasp_mode = options.grasp_mode;
  ConnectInput(loop.window, &input);
  const auto start = Clock::now();
  const bool screenshot = !options.screenshot_path.empty();
  const double frame_period_s = 1.0 / options.max_fps;
  while (!glfwWindowShouldClose(loop.window) && !loop.stop->Requested()) {
    const auto frame_start = Clock::now();
    glfwPollEvents();
    int w = 0, h = 0;
    glfwGetFramebufferSize(loop.window, &w, &h);
    if (w <= 0 || h <= 0) {  // minimised
      std::this_thread::sleep_for(std::chrono::milliseconds(50));
      continue;
    }
    const SessionSnapshot snap = loop.receiver->Snapshot();
    UpdateView(snap, w, h, loop.window, loop.grasp, &input);
    const FrameInfo info{options.common.session, options.lcm_url, options.grasp_mode, input.dragging_grasp};
    loop.renderer->Draw(snap, input.camera, w, h, info);
    if (screenshot && snap.has_shape && snap.shapes_received >= options.after_shapes) {
      return WriteScreenshot(options, snap, w, h);
    }
    glfwSwapBuffers(loop.window);
    const double elapsed = Seconds(start);
    if (screenshot && options.timeout_s > 0 && elapsed > options.timeout_s) {
      return ReportScreenshotTimeout(options, snap, *loop.receiver, elapsed);
    }
    if (options.duration_s > 0 && elapsed > options.duration_s) break;
    const double spent = Seconds(frame_start);
    if (spent < frame_period_s) {
      std::this_thread::sleep_for(std::chrono::duration<double>(frame_period_s - spent));
    }
  }
  if (!screenshot) PrintViewerTotals(*loop.receiver);
  return kExitOk;
}

// The renderer in the window's context, then the frame loop; returns the exit code.
int RunWindow(const ViewerOptions& options, GLFWwindow* window, SessionReceiver* receiver,
              GraspPublisher* grasp, app::StopSignals* stop) {
  Renderer renderer;
  std::string error;
  if (!renderer.Init(&error)) {
    std::fprintf(stderr, "snapthread-viewer: %s\n", error.c_str());
    return kExitSetupFailed;
  }
  return RunFrames(options, FrameLoop{window, &renderer, receiver, grasp, stop});
}

}  // namespace

int RunPrintRates(const ViewerOptions& options, app::StopSignals* stop) {
  const std::optional<auth::KeySet> keys = LoadViewerKeys(options, nullptr);
  if (!keys) return kExitSetupFailed;
  lcm::LCM lcm(options.lcm_url);
  if (!LcmOpened(lcm, options)) return kExitSetupFailed;
  const std::string& session = options.common.session;
  ChannelRateMonitor monitor(&lcm, session + "_.*");
  // Checks shapes and statuses on the same LCM (handled by this loop) to count refusals.
  SessionReceiver checked(&lcm, session, &keys->server_public_key());
  const auto start = Clock::now();
  auto last_report = start;
  std::printf("channel rates of session %s on %s (once per second)\n", session.c_str(), options.lcm_url.c_str());
  std::fflush(stdout);
  while ((options.duration_s <= 0 || Seconds(start) < options.duration_s) && !stop->Requested()) {
    lcm.handleTimeout(50);
    const double since = Seconds(last_report);
    if (since >= 1.0) {
      last_report = Clock::now();
      std::printf("--- t=%.0f s\n%sauthentication refused %lld (shape/status)\n",
                  Seconds(start), monitor.RateReport(since).c_str(),
                  static_cast<long long>(checked.auth_rejected()));
      std::fflush(stdout);
    }
  }
  // Final totals in a fixed format that scripts (the two-host test) parse.
  for (const auto& [channel, count] : monitor.Totals()) {
    std::printf("TOTAL %s %lld\n", messages::EscapeForDisplay(channel).c_str(),
                static_cast<long long>(count.messages));
  }
  std::printf("REJECTED %lld\n", static_cast<long long>(checked.auth_rejected()));
  std::fflush(stdout);
  return kExitOk;
}

int RunViewer(const ViewerOptions& options, app::StopSignals* stop) {
  std::optional<Scene> scene;
  if (options.grasp_mode) {
    scene = LoadGraspScene(options);
    if (!scene) return kExitSetupFailed;
  }
  const std::optional<auth::KeySet> keys = LoadViewerKeys(options, scene ? &*scene : nullptr);
  if (!keys) return kExitSetupFailed;
  lcm::LCM lcm(options.lcm_url);
  if (!LcmOpened(lcm, options)) return kExitSetupFailed;
  SessionReceiver receiver(&lcm, options.common.session, &keys->server_public_key());
  // Receiving starts before the window: GL start-up takes seconds on a loaded machine, and
  // LCM drops what the shape queue cannot hold meanwhile.
  receiver.Start();
  std::unique_ptr<GraspPublisher> grasp;
  if (scene) {
    grasp = std::make_unique<GraspPublisher>(&lcm, options.common.session, scene->device, &keys->tagger(),
                                             [&receiver] { return receiver.epoch(); });
  }
  GLFWwindow* window = OpenWindow(options);
  if (window == nullptr) return kExitSetupFailed;
  const int exit_code = RunWindow(options, window, &receiver, grasp.get(), stop);
  receiver.Stop();
  glfwDestroyWindow(window);
  glfwTerminate();
  return exit_code;
}

}  // namespace snapthread::viewer
