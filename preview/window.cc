#include "preview/window.h"

#include <glad/gl.h>
// glad first.
#define GLFW_INCLUDE_NONE
#include <GLFW/glfw3.h>

#include <chrono>
#include <cmath>
#include <opencv2/imgcodecs.hpp>
#include <sstream>

#include "core/atomic_file.h"
#include "core/error.h"
#include "core/log.h"
#include "core/stop_signal.h"
#include "lib/lightfield/camera.h"
#include "lib/lightfield/tone_map.h"
#include "preview/gl_context.h"

namespace lumislab {
namespace {

struct WindowState {
  SceneSetup* setup = nullptr;
  Renderer* renderer = nullptr;
  double exposure_stops = 0;
  bool dragging_orbit = false, dragging_pan = false;
  double last_x = 0, last_y = 0;
  bool camera_changed = true;
  bool screenshot_requested = false;
  bool quit = false;
};

WindowState* State(GLFWwindow* w) { return static_cast<WindowState*>(glfwGetWindowUserPointer(w)); }

void SaveScreenshot(const std::string& path, int w, int h) {
  std::vector<unsigned char> rgb(size_t(w) * h * 3);
  glBindFramebuffer(GL_READ_FRAMEBUFFER, 0);
  glReadBuffer(GL_BACK);
  glPixelStorei(GL_PACK_ALIGNMENT, 1);
  glReadPixels(0, 0, w, h, GL_RGB, GL_UNSIGNED_BYTE, rgb.data());
  cv::Mat image(h, w, CV_8UC3);
  for (int y = 0; y < h; ++y) {
    for (int x = 0; x < w; ++x) {
      for (int c = 0; c < 3; ++c) {
        image.at<cv::Vec3b>(y, x)[2 - c] = rgb[(size_t(h - 1 - y) * w + x) * 3 + c];
      }
    }
  }
  WriteAtomically(path, [&](const std::string& tmp) {
    if (!cv::imwrite(tmp, image)) throw IoError(path, "cannot write PNG");
  });
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

}  // namespace

int RunWindow(const PreviewConfig& config, SlabInfo info) {
  WindowContext context(config.width, config.height, "lumislab-preview");
  SceneSetup setup = MakeSceneSetup(config.scene, info);
  RenderOptions options = MakeRenderOptions(config, setup);
  int fb_w = 0, fb_h = 0;
  glfwGetFramebufferSize(context.window(), &fb_w, &fb_h);
  Renderer renderer(info, fb_w, fb_h, options);
  renderer.SetScene(setup.mesh);
  renderer.SetPose(setup.pose);
  WindowState state;
  state.setup = &setup;
  state.renderer = &renderer;
  state.exposure_stops = config.exposure_stops;
  GLFWwindow* window = context.window();
  glfwSetWindowUserPointer(window, &state);
  glfwSetKeyCallback(window, [](GLFWwindow* w, int key, int, int action, int) {
    if (action != GLFW_PRESS && action != GLFW_REPEAT) return;
    WindowState& s = *State(w);
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
  });
  glfwSetMouseButtonCallback(window, [](GLFWwindow* w, int button, int action, int) {
    WindowState& s = *State(w);
    glfwGetCursorPos(w, &s.last_x, &s.last_y);
    if (button == GLFW_MOUSE_BUTTON_LEFT) s.dragging_orbit = action == GLFW_PRESS;
    if (button == GLFW_MOUSE_BUTTON_RIGHT || button == GLFW_MOUSE_BUTTON_MIDDLE) {
      s.dragging_pan = action == GLFW_PRESS;
    }
  });
  glfwSetCursorPosCallback(window, [](GLFWwindow* w, double x, double y) {
    WindowState& s = *State(w);
    const double dx = x - s.last_x, dy = y - s.last_y;
    s.last_x = x;
    s.last_y = y;
    if (s.dragging_orbit) {
      s.setup->camera_yaw_deg -= 0.3 * dx;
      s.setup->camera_pitch_deg = std::clamp(s.setup->camera_pitch_deg + 0.3 * dy, -85.0, 85.0);
      s.camera_changed = true;
    } else if (s.dragging_pan) {
      const double yaw = s.setup->camera_yaw_deg * M_PI / 180;
      const double k = 0.002 * s.setup->camera_distance;
      s.setup->camera_target +=
          Eigen::Vector3d(-std::cos(yaw) * dx * k, dy * k, std::sin(yaw) * dx * k);
      s.camera_changed = true;
    }
  });
  glfwSetScrollCallback(window, [](GLFWwindow* w, double, double dy) {
    WindowState& s = *State(w);
    s.setup->camera_distance *= std::pow(0.9, dy);
    s.camera_changed = true;
  });

  auto last_poll = std::chrono::steady_clock::now();
  std::vector<std::pair<int, int>> arrived =
      LoadNewPositions(config.slab_dir, info, renderer, config.threads);
  double exposure_factor = 0;
  bool screenshot_done = false;
  std::pair<int, int> last = arrived.empty() ? std::pair<int, int>{-1, -1} : arrived.back();
  while (!glfwWindowShouldClose(window) && !state.quit && !StopRequested()) {
    glfwPollEvents();
    if (config.watch &&
        std::chrono::duration<double>(std::chrono::steady_clock::now() - last_poll).count() >=
            config.poll_s) {
      last_poll = std::chrono::steady_clock::now();
      try {
        info = SlabInfo::Load(config.slab_dir);
        const auto added = LoadNewPositions(config.slab_dir, info, renderer, config.threads);
        if (!added.empty()) last = added.back();
      } catch (const Error& e) {
        LogDebug("poll: ", e.what());
      }
    }
    glfwGetFramebufferSize(window, &fb_w, &fb_h);
    if (fb_w > 0 && fb_h > 0) renderer.Resize(fb_w, fb_h);
    if (state.camera_changed && !setup.plane) {
      renderer.SetCamera(OrbitCamera(setup, double(fb_w) / std::max(1, fb_h)));
    } else if (setup.plane) {
      renderer.SetCamera(PlaneView(setup.plane_z, setup.extent));
    }
    state.camera_changed = false;
    const int added = renderer.Render();
    if (added > 0 || exposure_factor == 0) {
      exposure_factor = ExposureFactor(renderer.Read(), 0, config.auto_exposure);
    }
    renderer.Display(exposure_factor * std::pow(2.0, state.exposure_stops), fb_w, fb_h);
    DrawArrivalOverlay(info, renderer, fb_h);
    std::ostringstream title;
    title << "lumislab-preview  " << renderer.PositionCount() << "/" << info.grid.count()
          << " positions";
    if (last.first >= 0) title << " (last " << last.first << "," << last.second << ")";
    title << "  shadows " << (renderer.options().shadows ? "on" : "off") << "  "
          << (renderer.options().srgbe ? "sRGBE" : "float");
    glfwSetWindowTitle(window, title.str().c_str());
    const bool complete = renderer.PositionCount() == info.grid.count();
    if (state.screenshot_requested) {
      SaveScreenshot(config.screenshot.empty() ? "lumislab-preview.png" : config.screenshot, fb_w,
                     fb_h);
      state.screenshot_requested = false;
    }
    if (!config.screenshot.empty() && complete && !screenshot_done) {
      SaveScreenshot(config.screenshot, fb_w, fb_h);
      screenshot_done = true;
      LogInfo(title.str());
      break;
    }
    glfwSwapBuffers(window);
    if (added == 0) glfwWaitEventsTimeout(config.watch ? config.poll_s : 0.1);
  }
  return 0;
}

}  // namespace lumislab
