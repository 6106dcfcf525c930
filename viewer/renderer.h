// OpenGL 3.3 core drawing of one frame: the thread as a lit tube along the spline through
// its nodes, clamp, grasps, grip direction, force arrows, active contacts, status text
// (with the knot type) and a |force| strip chart. Needs a current GL context (GLFW + libepoxy); all geometry is rebuilt per frame
// (a few thousand vertices) and streamed in one buffer.
#pragma once

#include <string>
#include <vector>

#include <epoxy/gl.h>

#include "mesh_builder.h"
#include "orbit_camera.h"
#include "session_receiver.h"

namespace snapthread::viewer {

// Colour coding of the solver state (force_model_t.STATUS_*), also used by the tests.
Rgb StatusColor(int status);
inline const Rgb kBackground(0.11f, 0.12f, 0.15f);

struct FrameInfo {
  std::string session;
  std::string lcm_url;
  bool grasp_mode = false;
  bool dragging = false;
};

class Renderer {
 public:
  Renderer() = default;
  ~Renderer();
  Renderer(const Renderer&) = delete;
  Renderer& operator=(const Renderer&) = delete;

  // Compiles the shaders and creates the buffers; false with the reason on failure.
  bool Init(std::string* error);
  // Draws into the current framebuffer of size width x height (pixels).
  void Draw(const SessionSnapshot& s, const OrbitCamera& camera, int width, int height,
            const FrameInfo& info);

 private:
  void DrawVertices(const std::vector<Vertex>& v, GLenum mode, const float* mvp,
                    const float* light_dir);
  void AppendText(const std::string& text, float x, float y, float scale, const Rgb& color);
  void AppendRect(float x0, float y0, float x1, float y1, const Rgb& color);
  void AppendLine(float x0, float y0, float x1, float y1, const Rgb& color);
  void BuildChart(const SessionSnapshot& s, int width, int height);
  void AppendForceArrow(const Eigen::Vector3d& at, const Eigen::Vector3d& f, double extent,
                        double radius);
  // Every grasp of thread_shape_t.grasps with its force arrow, and every active contact.
  void AppendGraspsAndContacts(const thread_shape_t& shape, double extent, double radius);

  GLuint program_ = 0;
  GLuint vao_ = 0;
  GLuint vbo_ = 0;
  GLint mvp_location_ = -1;
  GLint light_location_ = -1;
  MeshBuilder scene_;
  MeshBuilder highlights_;  // drawn over scene_ (active contacts)
  std::vector<Vertex> overlay_triangles_;
  std::vector<Vertex> overlay_lines_;
  static constexpr int kMaxTextQuads = 4000;  // per AppendText call (~ 40 lines of text)
  std::vector<char> text_quads_;              // stb_easy_font output, reused
  double force_scale_n_ = 0.0;  // running max |F| for the arrow length
};

}  // namespace snapthread::viewer
