// OpenGL 3.3 core drawing of one frame: the thread as a lit tube along the spline through
// its nodes (a rod's with its material stripe and twist colours and their legend), clamp,
// grasps, grip direction, force arrows, active contacts, status text (with the knot type)
// and a |force| strip chart. Needs a current GL context (GLFW + libepoxy); all geometry is
// rebuilt per frame (a few thousand vertices) and streamed in one buffer.
#pragma once

#include <array>
#include <string>
#include <vector>

#include <epoxy/gl.h>

#include "hud_layout.h"
#include "marker_colors.h"
#include "mesh_builder.h"
#include "orbit_camera.h"
#include "session_receiver.h"
#include "spline.h"

namespace snapthread::viewer {


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
  // A HUD panel's dark background; returns its corners {x0, y0, x1, y1} in pixels.
  std::array<float, 4> AppendPanel(const PixelRect& r);
  // The thread, clamp, grasps, grip direction, force arrows and contacts of a shape.
  void BuildShape(const thread_shape_t& shape, const FrameInfo& info);
  void BuildChart(const SessionSnapshot& s, int width, int height);
  void AppendForceArrow(const Eigen::Vector3d& at, const Eigen::Vector3d& f, double extent,
                        double radius);
  // Every grasp of thread_shape_t.grasps with its force arrow, and every active contact.
  void AppendGraspsAndContacts(const thread_shape_t& shape, double extent, double radius);

  // The rod (a shape with one frame row per edge): the tube turned so its dark stripe
  // follows d1 and coloured by twist density (material_frames.h).
  void AppendMaterialTube(const thread_shape_t& shape, const std::vector<Point3>& nodes,
                          const std::vector<Point3>& path, double radius);
  // The twist colour bar and its scale (HudLayout::legend), when a rod is drawn.
  void BuildTwistLegend(const Rgb& base, int width, int height);

  struct TwistLegend {
    bool shown = false;
    double full_scale = 0.0;  // rad per model length at full colour (one turn per length)
    double max_abs = 0.0;     // largest |twist density| of the shape
  };
  TwistLegend twist_legend_;
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
