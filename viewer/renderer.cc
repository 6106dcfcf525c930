#include "renderer.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstring>

#include <stb_easy_font.h>

#include "hud_layout.h"
#include "marker_colors.h"
#include "material_frames.h"
#include "messages/channels.h"
#include "spline.h"
#include "models/registry.h"

namespace snapthread::viewer {
namespace {

constexpr char kVertexShader[] = R"(#version 330 core
layout(location = 0) in vec3 a_position;
layout(location = 1) in vec3 a_normal;
layout(location = 2) in vec3 a_color;
uniform mat4 u_mvp;
out vec3 v_normal;
out vec3 v_color;
void main() {
  gl_Position = u_mvp * vec4(a_position, 1.0);
  v_normal = a_normal;
  v_color = a_color;
}
)";

// Headlight shading, two-sided; a zero normal marks flat (overlay) geometry.
constexpr char kFragmentShader[] = R"(#version 330 core
in vec3 v_normal;
in vec3 v_color;
uniform vec3 u_light_dir;
out vec4 frag_color;
void main() {
  float light = 1.0;
  if (dot(v_normal, v_normal) > 0.0) {
    light = 0.35 + 0.65 * abs(dot(normalize(v_normal), u_light_dir));
  }
  frag_color = vec4(v_color * light, 1.0);
}
)";

constexpr int kSplineSamplesPerSegment = 8;
constexpr int kTubeSides = 14;

// False with "<what> failed: <info log>" in *error when the object's status is not set;
// `get_iv` / `get_log` are the GL getters of the object's kind (shader or program).
template <typename GetIv, typename GetLog>
bool StatusOk(GLuint object, GLenum status, GetIv get_iv, GetLog get_log, const char* what, std::string* error) {
  GLint ok = 0;
  get_iv(object, status, &ok);
  if (ok) return true;
  char log[2048] = {0};
  get_log(object, sizeof log, nullptr, log);
  *error = std::string(what) + " failed: " + log;
  return false;
}

GLuint Compile(GLenum type, const char* source, std::string* error) {
  const GLuint shader = glCreateShader(type);
  glShaderSource(shader, 1, &source, nullptr);
  glCompileShader(shader);
  if (!StatusOk(shader, GL_COMPILE_STATUS, glGetShaderiv, glGetShaderInfoLog, "shader compile", error)) {
    glDeleteShader(shader);
    return 0;
  }
  return shader;
}

void ToFloat(const Eigen::Matrix4d& m, float out[16]) {  // column-major for OpenGL
  for (int c = 0; c < 4; ++c)
    for (int r = 0; r < 4; ++r) out[c * 4 + r] = static_cast<float>(m(r, c));
}

const char* StatusName(int status) {
  switch (status) {
    case 0: return "REGULAR";
    case 1: return "NEAR FOLD";
    case 2: return "SNAPPED";
    case 3: return "INVALID";
    case 4: return "SNAPPING";
    default: return "?";
  }
}

double Norm3(const double v[3]) { return std::sqrt(v[0] * v[0] + v[1] * v[1] + v[2] * v[2]); }

}  // namespace

Renderer::~Renderer() {
  if (vbo_ != 0) glDeleteBuffers(1, &vbo_);
  if (vao_ != 0) glDeleteVertexArrays(1, &vao_);
  if (program_ != 0) glDeleteProgram(program_);
}

bool Renderer::Init(std::string* error) {
  const GLuint vs = Compile(GL_VERTEX_SHADER, kVertexShader, error);
  if (vs == 0) return false;
  const GLuint fs = Compile(GL_FRAGMENT_SHADER, kFragmentShader, error);
  if (fs == 0) return false;
  program_ = glCreateProgram();
  glAttachShader(program_, vs);
  glAttachShader(program_, fs);
  glLinkProgram(program_);
  glDeleteShader(vs);
  glDeleteShader(fs);
  if (!StatusOk(program_, GL_LINK_STATUS, glGetProgramiv, glGetProgramInfoLog, "shader link", error)) return false;
  mvp_location_ = glGetUniformLocation(program_, "u_mvp");
  light_location_ = glGetUniformLocation(program_, "u_light_dir");
  glGenVertexArrays(1, &vao_);
  glGenBuffers(1, &vbo_);
  glBindVertexArray(vao_);
  glBindBuffer(GL_ARRAY_BUFFER, vbo_);
  glEnableVertexAttribArray(0);
  glVertexAttribPointer(0, 3, GL_FLOAT, GL_FALSE, sizeof(Vertex),
                        reinterpret_cast<void*>(offsetof(Vertex, position)));
  glEnableVertexAttribArray(1);
  glVertexAttribPointer(1, 3, GL_FLOAT, GL_FALSE, sizeof(Vertex),
                        reinterpret_cast<void*>(offsetof(Vertex, normal)));
  glEnableVertexAttribArray(2);
  glVertexAttribPointer(2, 3, GL_FLOAT, GL_FALSE, sizeof(Vertex),
                        reinterpret_cast<void*>(offsetof(Vertex, color)));
  glBindVertexArray(0);
  return glGetError() == GL_NO_ERROR || (*error = "GL error during set-up", false);
}

void Renderer::DrawVertices(const std::vector<Vertex>& v, GLenum mode, const float* mvp,
                            const float* light_dir) {
  if (v.empty()) return;
  glBindVertexArray(vao_);
  glBindBuffer(GL_ARRAY_BUFFER, vbo_);
  glBufferData(GL_ARRAY_BUFFER, GLsizeiptr(v.size() * sizeof(Vertex)), v.data(), GL_STREAM_DRAW);
  glUniformMatrix4fv(mvp_location_, 1, GL_FALSE, mvp);
  glUniform3fv(light_location_, 1, light_dir);
  glDrawArrays(mode, 0, GLsizei(v.size()));
  glBindVertexArray(0);
}

void Renderer::AppendRect(float x0, float y0, float x1, float y1, const Rgb& c) {
  const float pts[6][2] = {{x0, y0}, {x1, y0}, {x1, y1}, {x0, y0}, {x1, y1}, {x0, y1}};
  for (const auto& p : pts) {
    overlay_triangles_.push_back({{p[0], p[1], 0.f}, {0.f, 0.f, 0.f}, {c[0], c[1], c[2]}});
  }
}

void Renderer::AppendLine(float x0, float y0, float x1, float y1, const Rgb& c) {
  overlay_lines_.push_back({{x0, y0, 0.f}, {0.f, 0.f, 0.f}, {c[0], c[1], c[2]}});
  overlay_lines_.push_back({{x1, y1, 0.f}, {0.f, 0.f, 0.f}, {c[0], c[1], c[2]}});
}

void Renderer::AppendText(const std::string& text, float x, float y, float scale,
                          const Rgb& color) {
  // stb_easy_font emits quads of 4 vertices (x, y, z floats + 4 colour bytes = 16 bytes).
  text_quads_.resize(16 * 4 * kMaxTextQuads);
  char* buffer = text_quads_.data();
  unsigned char rgba[4] = {255, 255, 255, 255};
  std::vector<char> copy(text.begin(), text.end());
  copy.push_back('\0');
  const int quads = stb_easy_font_print(0.f, 0.f, copy.data(), rgba, buffer,
                                        static_cast<int>(text_quads_.size()));
  for (int q = 0; q < quads; ++q) {
    float corner[4][2];
    for (int k = 0; k < 4; ++k) {
      float xy[2];
      std::memcpy(xy, buffer + (q * 4 + k) * 16, sizeof xy);
      corner[k][0] = x + scale * xy[0];
      corner[k][1] = y + scale * xy[1];
    }
    for (int k : {0, 1, 2, 0, 2, 3}) {
      overlay_triangles_.push_back(
          {{corner[k][0], corner[k][1], 0.f}, {0.f, 0.f, 0.f}, {color[0], color[1], color[2]}});
    }
  }
}

std::array<float, 4> Renderer::AppendPanel(const PixelRect& r) {
  const float x0 = float(r.x), y0 = float(r.y), x1 = float(r.x + r.width), y1 = float(r.y + r.height);
  AppendRect(x0, y0, x1, y1, {0.05f, 0.05f, 0.07f});
  return {x0, y0, x1, y1};
}

void Renderer::BuildChart(const SessionSnapshot& s, int width, int height) {
  const auto [x0, y0, x1, y1] = AppendPanel(MakeHudLayout(width, height).chart);
  const Rgb frame(0.45f, 0.45f, 0.5f);
  AppendLine(x0, y0, x1, y0, frame);
  AppendLine(x1, y0, x1, y1, frame);
  AppendLine(x1, y1, x0, y1, frame);
  AppendLine(x0, y1, x0, y0, frame);
  double fmax = 1e-3;
  for (const auto& f : s.force_history) fmax = std::max(fmax, f.force_n);
  char label[64];
  std::snprintf(label, sizeof label, "|F| N, last %.0f s, max %.3g", SessionReceiver::kHistorySeconds,
                fmax);
  AppendText(label, x0 + 4, y0 + 3, 1.0f, {0.8f, 0.8f, 0.8f});
  const float top = y0 + 14, bottom = y1 - 3;
  const double t_end = s.now_s, t_start = t_end - SessionReceiver::kHistorySeconds;
  const Rgb trace(1.0f, 0.45f, 0.3f);
  for (size_t i = 1; i < s.force_history.size(); ++i) {
    const auto& a = s.force_history[i - 1];
    const auto& b = s.force_history[i];
    auto px = [&](double t) { return float(x0 + (t - t_start) / (t_end - t_start) * (x1 - x0)); };
    auto py = [&](double f) { return float(bottom - f / fmax * (bottom - top)); };
    AppendLine(px(a.time_s), py(a.force_n), px(b.time_s), py(b.force_n), trace);
  }
}

void Renderer::AppendForceArrow(const Eigen::Vector3d& at, const Eigen::Vector3d& f,
                                double extent, double radius) {
  const double fn = f.norm();
  force_scale_n_ = std::max(force_scale_n_, fn);
  if (fn > 1e-12 && force_scale_n_ > 0) {
    const double len = 0.3 * extent * std::clamp(fn / force_scale_n_, 0.05, 1.0);
    scene_.AppendArrow(at, at + len * f / fn, 0.6 * radius, kForceArrowColor);
  }
}

void Renderer::AppendGraspsAndContacts(const thread_shape_t& shape, double extent,
                                       double radius) {
  for (int g = 0; g < shape.num_grasps; ++g) {
    const auto& row = shape.grasps[g];
    const Eigen::Vector3d at(row[0], row[1], row[2]);
    scene_.AppendSphere(at, 2.0 * radius, GraspColor(g));
    AppendForceArrow(at, Eigen::Vector3d(row[3], row[4], row[5]), extent, radius);
  }
  // Contacts: a bead on each of the two closest points and the segment joining them, drawn
  // over the thread (their own depth only): the closest points lie inside the tube.
  for (int c = 0; c < shape.num_contacts; ++c) {
    const auto& row = shape.contacts[c];
    const Eigen::Vector3d a(row[0], row[1], row[2]), b(row[3], row[4], row[5]);
    highlights_.AppendSphere(a, 1.2 * radius, kContactColor);
    highlights_.AppendSphere(b, 1.2 * radius, kContactColor);
    if ((b - a).norm() > 1e-12) highlights_.AppendTube({a, b}, 0.5 * radius, 8, kContactColor);
  }
}

void Renderer::AppendMaterialTube(const thread_shape_t& shape, const std::vector<Point3>& nodes,
                                  const std::vector<Point3>& path, double radius) {
  const std::vector<CurveFrame> curve = RotationMinimisingFrames(path);
  const MaterialRings rings =
      InterpolateMaterialFrames(shape.frames, kSplineSamplesPerSegment, curve);
  const Rgb base = StatusColor(shape.status);
  if (rings.angle.empty()) {  // counts that do not fit: the plain tube
    scene_.AppendTube(path, radius, kTubeSides, base);
    return;
  }
  twist_legend_.shown = true;
  twist_legend_.full_scale = TwistFullScale(nodes);
  for (const auto& row : shape.frames) {
    twist_legend_.max_abs = std::max(twist_legend_.max_abs, std::abs(row[3]));
  }
  TubePaint paint;
  paint.angle = rings.angle;
  paint.color.reserve(path.size());
  for (double t : rings.twist) paint.color.push_back(TwistColor(base, t, twist_legend_.full_scale));
  paint.stripe_half_columns = kStripeHalfColumns;
  paint.stripe_color = kStripeColor;
  scene_.AppendPaintedTube(path, curve, radius, kStripedTubeSides, paint);
}

void Renderer::BuildTwistLegend(const Rgb& base, int width, int height) {
  const auto [x0, y0, x1, y1] = AppendPanel(MakeHudLayout(width, height).legend);
  const Rgb text(0.8f, 0.8f, 0.8f);
  char line[160];
  std::snprintf(line, sizeof line, "twist: full colour at 1 turn/L = %.3g rad/unit",
                twist_legend_.full_scale);
  AppendText(line, x0 + 4, y0 + 3, 1.0f, text);
  // The colour bar, -1 .. +1 turn per length, on this tube's state colour.
  const float bx0 = x0 + 4, bx1 = x0 + 204, by0 = y0 + 16, by1 = y0 + 26;
  constexpr int kSteps = 40;
  for (int k = 0; k < kSteps; ++k) {
    const double v = -1.0 + 2.0 * (k + 0.5) / kSteps;
    AppendRect(bx0 + (bx1 - bx0) * k / kSteps, by0, bx0 + (bx1 - bx0) * (k + 1) / kSteps, by1,
               TwistColor(base, v, 1.0));
  }
  AppendText("-1 left", bx0, by1 + 2, 1.0f, text);
  AppendText("0", 0.5f * (bx0 + bx1) - 2, by1 + 2, 1.0f, text);
  AppendText("+1 right", bx1 - 40, by1 + 2, 1.0f, text);
  std::snprintf(line, sizeof line, "max |twist| %.3g rad/unit (%.2f turns/L)\ndark stripe: director d1",
                twist_legend_.max_abs,
                twist_legend_.full_scale > 0 ? twist_legend_.max_abs / twist_legend_.full_scale : 0.0);
  AppendText(line, x0 + 4, by1 + 15, 1.0f, text);
}

void Renderer::BuildShape(const thread_shape_t& shape, const FrameInfo& info) {
  std::vector<Point3> nodes;
  nodes.reserve(shape.positions.size());
  for (const auto& p : shape.positions) nodes.emplace_back(p[0], p[1], p[2]);
  Eigen::Vector3d lo = nodes.front(), hi = nodes.front();
  for (const auto& p : nodes) {
    lo = lo.cwiseMin(p);
    hi = hi.cwiseMax(p);
  }
  const double extent = std::max((hi - lo).norm(), 1e-3);
  const double radius = 0.012 * extent;
  // Threads (the registry's chains) and rods (shapes with material frames) are smooth
  // curves through their nodes; the Zeeman and cusp "shapes" are linkages (rods between
  // joints), drawn straight.
  const ModelRegistration* model = FindModel(shape.model);
  const bool framed = shape.num_frames > 0 && shape.num_frames + 1 == shape.num_nodes;
  const bool smooth = framed || (model != nullptr && model->capabilities.chain.has_value());
  const std::vector<Point3> path = CatmullRomCurve(nodes, smooth ? kSplineSamplesPerSegment : 1);
  if (framed) {
    AppendMaterialTube(shape, nodes, path, radius);
  } else {
    scene_.AppendTube(path, radius, kTubeSides, StatusColor(shape.status));
  }
  scene_.AppendSphere(nodes.front(), 2.2 * radius, {0.6f, 0.6f, 0.62f});  // clamp
  const Eigen::Vector3d grasp(shape.grasp[0], shape.grasp[1], shape.grasp[2]);
  // With named grasps every row is drawn (the first is the legacy grasp); otherwise the
  // single grasp, which the mouse may be dragging.
  if (shape.num_grasps == 0) {
    scene_.AppendSphere(grasp, 2.0 * radius,
                        info.dragging ? Rgb(1.0f, 1.0f, 0.5f) : GraspColor(0));
  }
  const Eigen::Vector3d d(shape.grip_direction[0], shape.grip_direction[1],
                          shape.grip_direction[2]);
  if (d.norm() > 1e-9) {
    scene_.AppendArrow(grasp, grasp + 0.12 * extent * d.normalized(), 0.5 * radius,
                       {0.8f, 0.4f, 0.9f});
  }
  // Force arrows: direction of the model force, length relative to the largest |F| seen,
  // so the arrows stay readable for any scene's force scale.
  if (shape.num_grasps == 0) {
    AppendForceArrow(grasp, Eigen::Vector3d(shape.force[0], shape.force[1], shape.force[2]),
                     extent, radius);
  }
  AppendGraspsAndContacts(shape, extent, radius);
}

namespace {

// The HUD's text: session, shape, solver status, knot and grasp mode.
std::string HudText(const SessionSnapshot& s, const FrameInfo& info) {
  char line[256];
  std::string text;
  // Strings of messages (scene, model, method, knot) are hostile text: escaped and cut short,
  // so no newline, control byte or long string can forge or push away HUD lines.
  const auto shown = [](const std::string& t) { return messages::EscapeForDisplay(t, 40); };
  std::snprintf(line, sizeof line, "snapthread  session %s\n", shown(info.session).c_str());
  text += line;
  if (s.has_shape) {
    const double fN = Norm3(s.shape.force_newtons);
    std::snprintf(line, sizeof line,
                  "scene %s (%s), %d nodes\nshape seq %lld  %.0f Hz  bad msgs %lld\n"
                  "state %s   snaps %lld\n|F| %.3f N\n",
                  shown(s.shape.scene).c_str(), shown(s.shape.model).c_str(), s.shape.num_nodes,
                  static_cast<long long>(s.shape.seq), s.shape_rate_hz,
                  static_cast<long long>(s.bad_messages), StatusName(s.shape.status),
                  static_cast<long long>(s.shape.snaps), fN);
    text += line;
  } else {
    std::snprintf(line, sizeof line, "waiting for %s_SHAPE\non %s\nbad msgs %lld\n",
                  shown(info.session).c_str(), info.lcm_url.c_str(),
                  static_cast<long long>(s.bad_messages));
    text += line;
  }
  if (s.has_status) {
    std::snprintf(line, sizeof line,
                  "method %s  iters %d\nresidual %.2e  lambda_min %.3g\n"
                  "updates %.0f Hz  solve p50 %.0f us p99 %.0f us\ndropped poses %lld\n",
                  shown(s.status.method).c_str(), s.status.iterations, s.status.residual,
                  s.status.lambda_min, s.status.update_rate_hz, s.status.solve_us_p50,
                  s.status.solve_us_p99, static_cast<long long>(s.status.dropped_poses));
    text += line;
  }
  if (s.has_shape || s.has_status) {
    // The knot type: the status's, with its determinant, else the shape's; the
    // contacts of the shape drawn, else the status's count.
    const bool status_knot = s.has_status && !s.status.knot.empty();
    const std::string& knot = status_knot ? s.status.knot : s.shape.knot;
    std::snprintf(line, sizeof line, "knot %s", knot.empty() ? "-" : shown(knot).c_str());
    text += line;
    if (status_knot && s.status.knot_determinant > 0) {
      std::snprintf(line, sizeof line, " (det %d)", s.status.knot_determinant);
      text += line;
    }
    const int contacts = s.has_shape ? s.shape.num_contacts : s.status.contacts;
    std::snprintf(line, sizeof line, "  contacts %d\n", contacts);
    text += line;
  }
  if (info.grasp_mode) text += info.dragging ? "GRASP: dragging\n" : "GRASP mode: drag the grasp\n";
  return text;
}

}  // namespace

void Renderer::Draw(const SessionSnapshot& s, const OrbitCamera& camera, int width, int height,
                    const FrameInfo& info) {
  glViewport(0, 0, width, height);
  glClearColor(kBackground[0], kBackground[1], kBackground[2], 1.0f);
  glClear(GL_COLOR_BUFFER_BIT | GL_DEPTH_BUFFER_BIT);
  glUseProgram(program_);
  scene_.Clear();
  highlights_.Clear();
  twist_legend_ = {};
  overlay_triangles_.clear();
  overlay_lines_.clear();

  if (s.has_shape) BuildShape(s.shape, info);

  const double aspect = double(width) / height;
  float mvp[16];
  ToFloat(camera.Projection(aspect) * camera.View(), mvp);
  const Eigen::Vector3d l = (camera.Eye() - camera.Target()).normalized();
  const float light[3] = {float(l.x()), float(l.y()), float(l.z())};
  glEnable(GL_DEPTH_TEST);
  DrawVertices(scene_.vertices(), GL_TRIANGLES, mvp, light);
  if (!highlights_.vertices().empty()) {
    glClear(GL_DEPTH_BUFFER_BIT);
    DrawVertices(highlights_.vertices(), GL_TRIANGLES, mvp, light);
  }

  // Overlay in pixel coordinates (origin top-left, y down).
  const Rgb text_color = s.has_shape ? StatusColor(s.shape.status) : Rgb(0.8f, 0.8f, 0.8f);
  AppendText(HudText(s, info), 10.f, 10.f, 1.5f, text_color);
  BuildChart(s, width, height);
  if (twist_legend_.shown) BuildTwistLegend(StatusColor(s.shape.status), width, height);

  Eigen::Matrix4d ortho = Eigen::Matrix4d::Identity();
  ortho(0, 0) = 2.0 / width;
  ortho(1, 1) = -2.0 / height;
  ortho(0, 3) = -1.0;
  ortho(1, 3) = 1.0;
  ToFloat(ortho, mvp);
  glDisable(GL_DEPTH_TEST);
  DrawVertices(overlay_triangles_, GL_TRIANGLES, mvp, light);
  DrawVertices(overlay_lines_, GL_LINES, mvp, light);
}

}  // namespace snapthread::viewer
