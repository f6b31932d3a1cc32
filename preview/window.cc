#include "preview/window.h"

#include <glad/gl.h>
// glad first.
#define GLFW_INCLUDE_NONE
#include <GLFW/glfw3.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <sstream>

#include "core/error.h"
#include "core/log.h"
#include "core/stop_signal.h"
#include "lib/lightfield/camera.h"
#include "lib/lightfield/tone_map.h"
#include "preview/gl_context.h"
#include "preview/image_files.h"

namespace lumislab {
namespace {

using Clock = std::chrono::steady_clock;

// Everything the callbacks and the frame steps share.
struct WindowState {
  const PreviewConfig* config = nullptr;
  SlabInfo info;
  SceneSetup setup;
  Renderer* renderer = nullptr;
  double exposure_stops = 0;
  double exposure_factor = 0;  // automatic part; 0 until the first frame
  bool dragging_orbit = false, dragging_pan = false;
  double last_x = 0, last_y = 0;
  bool camera_changed = true;
  bool screenshot_requested = false;
  bool quit = false;
  std::pair<int, int> last_arrived{-1, -1};
  Clock::time_point last_poll = Clock::now();
};

WindowState& State(GLFWwindow* w) {
  return *static_cast<WindowState*>(glfwGetWindowUserPointer(w));
}

void OnKey(GLFWwindow* w, int key, int, int action, int) {
  if (action != GLFW_PRESS && action != GLFW_REPEAT) return;
  WindowState& s = State(w);
  RenderOptions o = s.renderer->options();
  switch (key) {
    case GLFW_KEY_ESCAPE:
    case GLFW_KEY_Q:
      s.quit = true;
      break;
    case GLFW_KEY_EQUAL:
    case GLFW_KEY_KP_ADD:
      s.exposure_stops += 0.5;
      break;
    case GLFW_KEY_MINUS:
    case GLFW_KEY_KP_SUBTRACT:
      s.exposure_stops -= 0.5;
      break;
    case GLFW_KEY_S:
      o.shadows = !o.shadows;
      s.renderer->SetOptions(o);
      break;
    case GLFW_KEY_F:
      o.srgbe = !o.srgbe;
      s.renderer->SetOptions(o);
      break;
    case GLFW_KEY_P:
      s.screenshot_requested = true;
      break;
    default:
      break;
  }
}

void OnMouseButton(GLFWwindow* w, int button, int action, int) {
  WindowState& s = State(w);
  glfwGetCursorPos(w, &s.last_x, &s.last_y);
  if (button == GLFW_MOUSE_BUTTON_LEFT) s.dragging_orbit = action == GLFW_PRESS;
  if (button == GLFW_MOUSE_BUTTON_RIGHT || button == GLFW_MOUSE_BUTTON_MIDDLE) {
    s.dragging_pan = action == GLFW_PRESS;
  }
}

// Left drag orbits, right (or middle) drag pans the target in the view plane.
void OnCursorPos(GLFWwindow* w, double x, double y) {
  WindowState& s = State(w);
  const double dx = x - s.last_x, dy = y - s.last_y;
  s.last_x = x;
  s.last_y = y;
  if (s.dragging_orbit) {
    s.setup.camera_yaw_deg -= 0.3 * dx;
    s.setup.camera_pitch_deg = std::clamp(s.setup.camera_pitch_deg + 0.3 * dy, -85.0, 85.0);
    s.camera_changed = true;
  } else if (s.dragging_pan) {
    const double yaw = s.setup.camera_yaw_deg * M_PI / 180;
    const double k = 0.002 * s.setup.camera_distance;
    s.setup.camera_target +=
        Eigen::Vector3d(-std::cos(yaw) * dx * k, dy * k, std::sin(yaw) * dx * k);
    s.camera_changed = true;
  }
}

void OnScroll(GLFWwindow* w, double, double dy) {
  WindowState& s = State(w);
  s.setup.camera_distance *= std::pow(0.9, dy);
  s.camera_changed = true;
}

void InstallCallbacks(GLFWwindow* window, WindowState* state) {
  glfwSetWindowUserPointer(window, state);
  glfwSetKeyCallback(window, OnKey);
  glfwSetMouseButtonCallback(window, OnMouseButton);
  glfwSetCursorPosCallback(window, OnCursorPos);
  glfwSetScrollCallback(window, OnScroll);
}

void SaveScreenshot(const std::string& path, int w, int h) {
  std::vector<uint8_t> bottom_up(size_t(w) * h * 3);
  glBindFramebuffer(GL_READ_FRAMEBUFFER, 0);
  glReadBuffer(GL_BACK);
  glPixelStorei(GL_PACK_ALIGNMENT, 1);
  glReadPixels(0, 0, w, h, GL_RGB, GL_UNSIGNED_BYTE, bottom_up.data());
  std::vector<uint8_t> rgb(bottom_up.size());
  const size_t row = size_t(w) * 3;
  for (int y = 0; y < h; ++y) {
    std::copy_n(&bottom_up[size_t(h - 1 - y) * row], row, &rgb[size_t(y) * row]);
  }
  WritePng(path, w, h, rgb);
  LogInfo("screenshot -> ", path);
}

// Overlay in the top-left corner: one small square per grid position (i to the right, j up),
// bright when the position has arrived, dark when not. Drawn with scissored clears.
void DrawArrivalOverlay(const SlabInfo& info, const Renderer& renderer, int fb_h) {
  const int cell = 8, gap = 2, margin = 8;
  glEnable(GL_SCISSOR_TEST);
  for (int j = 0; j < info.grid.nv; ++j) {
    for (int i = 0; i < info.grid.nu; ++i) {
      const bool here = renderer.HasPosition(i, j);
      glScissor(margin + i * (cell + gap),
                fb_h - margin - info.grid.nv * (cell + gap) + j * (cell + gap), cell, cell);
      glClearColor(here ? 0.2f : 0.15f, here ? 0.9f : 0.15f, here ? 0.3f : 0.15f, 1.0f);
      glClear(GL_COLOR_BUFFER_BIT);
    }
  }
  glDisable(GL_SCISSOR_TEST);
  glClearColor(0, 0, 0, 0);
}

// --watch: at most once per --poll, loads positions that arrived since.
void PollSlab(WindowState& s) {
  if (!s.config->watch ||
      std::chrono::duration<double>(Clock::now() - s.last_poll).count() < s.config->poll_s) {
    return;
  }
  s.last_poll = Clock::now();
  try {
    s.info = SlabInfo::Load(s.config->slab_dir);
    const auto added = LoadNewPositions(s.config->slab_dir, s.info, *s.renderer, s.config->threads);
    if (!added.empty()) s.last_arrived = added.back();
  } catch (const Error& e) {
    LogDebug("poll: ", e.what());
  }
}

void UpdateCamera(WindowState& s, int fb_w, int fb_h) {
  if (s.setup.plane) {
    s.renderer->SetCamera(PlaneView(s.setup.plane_z, s.setup.extent));
  } else if (s.camera_changed) {
    s.renderer->SetCamera(OrbitCamera(s.setup, double(fb_w) / std::max(1, fb_h)));
  }
  s.camera_changed = false;
}

// Adds what is new to the accumulation and shows it; returns the lights added.
int DrawFrame(WindowState& s, int fb_w, int fb_h) {
  const int added = s.renderer->Render();
  if (added > 0 || s.exposure_factor == 0) {
    s.exposure_factor = ExposureFactor(s.renderer->Read(), 0, s.config->auto_exposure);
  }
  s.renderer->Display(s.exposure_factor * std::pow(2.0, s.exposure_stops), fb_w, fb_h);
  DrawArrivalOverlay(s.info, *s.renderer, fb_h);
  return added;
}

std::string TitleText(const WindowState& s) {
  std::ostringstream title;
  title << "lumislab-preview  " << s.renderer->PositionCount() << "/" << s.info.grid.count()
        << " positions";
  if (s.last_arrived.first >= 0) {
    title << " (last " << s.last_arrived.first << "," << s.last_arrived.second << ")";
  }
  title << "  shadows " << (s.renderer->options().shadows ? "on" : "off") << "  "
        << (s.renderer->options().srgbe ? "sRGBE" : "float");
  return title.str();
}

// P saves a screenshot; --screenshot saves one once every position is in. True: quit now.
bool SaveScreenshots(WindowState& s, int fb_w, int fb_h) {
  const std::string& path = s.config->screenshot;
  if (s.screenshot_requested) {
    SaveScreenshot(path.empty() ? "lumislab-preview.png" : path, fb_w, fb_h);
    s.screenshot_requested = false;
  }
  if (path.empty() || s.renderer->PositionCount() < s.info.grid.count()) return false;
  SaveScreenshot(path, fb_w, fb_h);
  LogInfo(TitleText(s));
  return true;
}

}  // namespace

int RunWindow(const PreviewConfig& config, const SlabInfo& info) {
  WindowContext context(config.width, config.height, "lumislab-preview");
  GLFWwindow* window = context.window();
  WindowState state;
  state.config = &config;
  state.info = info;
  state.setup = MakeSceneSetup(config.scene, info);
  state.exposure_stops = config.exposure_stops;
  int fb_w = 0, fb_h = 0;
  glfwGetFramebufferSize(window, &fb_w, &fb_h);
  Renderer renderer(info, fb_w, fb_h, MakeRenderOptions(config, state.setup));
  renderer.SetScene(state.setup.mesh);
  renderer.SetPose(state.setup.pose);
  state.renderer = &renderer;
  InstallCallbacks(window, &state);
  const auto arrived = LoadNewPositions(config.slab_dir, info, renderer, config.threads);
  if (!arrived.empty()) state.last_arrived = arrived.back();
  while (!glfwWindowShouldClose(window) && !state.quit && !StopRequested()) {
    glfwPollEvents();
    PollSlab(state);
    glfwGetFramebufferSize(window, &fb_w, &fb_h);
    if (fb_w > 0 && fb_h > 0) renderer.Resize(fb_w, fb_h);
    UpdateCamera(state, fb_w, fb_h);
    const int added = DrawFrame(state, fb_w, fb_h);
    glfwSetWindowTitle(window, TitleText(state).c_str());
    if (SaveScreenshots(state, fb_w, fb_h)) break;
    glfwSwapBuffers(window);
    if (added == 0) glfwWaitEventsTimeout(config.watch ? config.poll_s : 0.1);
  }
  return 0;
}

}  // namespace lumislab
