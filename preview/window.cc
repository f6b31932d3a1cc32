#include "preview/window.h"

#include <glad/gl.h>
// glad first.
#define GLFW_INCLUDE_NONE
#include <GLFW/glfw3.h>
#include <backends/imgui_impl_glfw.h>
#include <backends/imgui_impl_opengl3.h>
#include <imgui.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <ctime>
#include <filesystem>

#include "core/error.h"
#include "core/log.h"
#include "core/stop_signal.h"
#include "lib/lightfield/camera.h"
#include "lib/lightfield/tone_map.h"
#include "preview/gl_context.h"
#include "preview/image_files.h"
#include "preview/window_state.h"

namespace lumislab {
namespace {

using Clock = WindowState::Clock;

WindowState& State(GLFWwindow* w) {
  return *static_cast<WindowState*>(glfwGetWindowUserPointer(w));
}

void OnKey(GLFWwindow* w, int key, int, int action, int) {
  if (action != GLFW_PRESS && action != GLFW_REPEAT) return;
  if (ImGui::GetIO().WantCaptureKeyboard) return;
  WindowState& s = State(w);
  PreviewConfig& c = s.config;
  switch (key) {
    case GLFW_KEY_ESCAPE:
    case GLFW_KEY_Q:
      s.quit = true;
      break;
    case GLFW_KEY_EQUAL:
    case GLFW_KEY_KP_ADD:
      c.tone.exposure_stops += 0.5;
      s.picture_stale = true;
      break;
    case GLFW_KEY_MINUS:
    case GLFW_KEY_KP_SUBTRACT:
      c.tone.exposure_stops -= 0.5;
      s.picture_stale = true;
      break;
    case GLFW_KEY_S:
      c.shadows = !c.shadows;
      s.options_changed = true;
      break;
    case GLFW_KEY_F:
      c.srgbe = !c.srgbe;
      s.options_changed = true;
      break;
    case GLFW_KEY_P:
      s.screenshot_requested = true;
      break;
    default:
      break;
  }
}

// Left drag orbits (fly: turns about the eye), right or middle drag pans; with Ctrl a left drag
// moves the luminaire horizontally, with Shift it aims it.
void OnMouseButton(GLFWwindow* w, int button, int action, int mods) {
  WindowState& s = State(w);
  glfwGetCursorPos(w, &s.last_x, &s.last_y);
  const bool press = action == GLFW_PRESS && !ImGui::GetIO().WantCaptureMouse;
  if (button == GLFW_MOUSE_BUTTON_LEFT) {
    s.dragging_move = press && (mods & GLFW_MOD_CONTROL);
    s.dragging_aim = press && (mods & GLFW_MOD_SHIFT) && !s.dragging_move;
    s.dragging_orbit = press && !s.dragging_move && !s.dragging_aim;
  }
  if (button == GLFW_MOUSE_BUTTON_RIGHT || button == GLFW_MOUSE_BUTTON_MIDDLE) {
    s.dragging_pan = press;
  }
}

Eigen::Vector3d EyeOffset(double yaw_deg, double pitch_deg) {  // unit, target -> eye
  const double yaw = yaw_deg * M_PI / 180, pitch = pitch_deg * M_PI / 180;
  return {std::cos(pitch) * std::sin(yaw), std::sin(pitch), std::cos(pitch) * std::cos(yaw)};
}

Eigen::Vector3d Target(const std::vector<double>& camera) {
  return {camera[3], camera[4], camera[5]};
}

void SetTarget(std::vector<double>& camera, const Eigen::Vector3d& t) {
  camera[3] = t.x();
  camera[4] = t.y();
  camera[5] = t.z();
}

// Turns the camera by (d_yaw, d_pitch) degrees: about the target (orbit) or the eye (fly).
void Turn(WindowState& s, double d_yaw, double d_pitch) {
  std::vector<double>& c = s.config.camera;
  const Eigen::Vector3d eye = Target(c) + c[2] * EyeOffset(c[0], c[1]);
  c[0] += d_yaw;
  c[1] = std::clamp(c[1] + d_pitch, -85.0, 85.0);
  if (s.fly) SetTarget(c, eye - c[2] * EyeOffset(c[0], c[1]));
  s.camera_changed = true;
}

// Rotates the luminaire's pose by `rotation` (scene frame) about its own position.
void Aim(WindowState& s, const Eigen::Matrix3d& rotation) {
  Eigen::Isometry3d pose = PoseFromValues(s.config.scene.pose);
  pose.linear() = rotation * pose.linear();
  s.config.scene.pose = ValuesFromPose(pose);
  s.pose_changed = true;
}

void OnCursorPos(GLFWwindow* w, double x, double y) {
  WindowState& s = State(w);
  const double dx = x - s.last_x, dy = y - s.last_y;
  s.last_x = x;
  s.last_y = y;
  if (s.setup.plane) return;
  std::vector<double>& c = s.config.camera;
  const double yaw = c[0] * M_PI / 180;
  // Screen right and "screen up on the floor" in the horizontal plane of the scene (y up).
  const Eigen::Vector3d right(std::cos(yaw), 0, -std::sin(yaw)),
      ahead(-std::sin(yaw), 0, -std::cos(yaw));
  if (s.dragging_orbit) {
    Turn(s, -0.3 * dx, s.fly ? -0.3 * dy : 0.3 * dy);
  } else if (s.dragging_pan) {
    const double k = 0.002 * c[2];
    SetTarget(c, Target(c) - right * dx * k + Eigen::Vector3d(0, dy * k, 0));
    s.camera_changed = true;
  } else if (s.dragging_move) {
    const double k = 0.002 * c[2];
    const Eigen::Vector3d move = right * dx * k - ahead * dy * k;
    for (int a = 0; a < 3; ++a) s.config.scene.pose[a] += move[a];
    s.pose_changed = true;
  } else if (s.dragging_aim) {
    Aim(s, (Eigen::AngleAxisd(0.3 * dx * M_PI / 180, Eigen::Vector3d::UnitY()) *
            Eigen::AngleAxisd(0.3 * dy * M_PI / 180, right))
               .toRotationMatrix());
  }
}

void OnScroll(GLFWwindow* w, double, double dy) {
  WindowState& s = State(w);
  if (ImGui::GetIO().WantCaptureMouse || s.setup.plane) return;
  s.config.camera[2] = std::clamp(s.config.camera[2] * std::pow(0.9, dy), 10.0, 1e5);
  s.camera_changed = true;
}

// Fly mode: arrow keys move along the view and sideways, PgUp/PgDn up and down, at a speed of
// half the camera distance per second.
void FlyKeys(WindowState& s, GLFWwindow* w, double seconds) {
  if (!s.fly || s.setup.plane || ImGui::GetIO().WantCaptureKeyboard) return;
  std::vector<double>& c = s.config.camera;
  const Eigen::Vector3d forward = -EyeOffset(c[0], c[1]);
  const Eigen::Vector3d right = forward.cross(Eigen::Vector3d::UnitY()).normalized();
  Eigen::Vector3d move = Eigen::Vector3d::Zero();
  auto down = [&](int key) { return glfwGetKey(w, key) == GLFW_PRESS ? 1.0 : 0.0; };
  move += forward * (down(GLFW_KEY_UP) - down(GLFW_KEY_DOWN));
  move += right * (down(GLFW_KEY_RIGHT) - down(GLFW_KEY_LEFT));
  move += Eigen::Vector3d::UnitY() * (down(GLFW_KEY_PAGE_UP) - down(GLFW_KEY_PAGE_DOWN));
  if (move.isZero()) return;
  SetTarget(c, Target(c) + move * 0.5 * c[2] * std::min(seconds, 0.2));
  s.camera_changed = true;
}

void InstallCallbacks(GLFWwindow* window, WindowState* state) {
  glfwSetWindowUserPointer(window, state);
  glfwSetKeyCallback(window, OnKey);
  glfwSetMouseButtonCallback(window, OnMouseButton);
  glfwSetCursorPosCallback(window, OnCursorPos);
  glfwSetScrollCallback(window, OnScroll);
}

// The window as shown (picture and panel), from the back buffer before the swap.
void SaveScreenshot(WindowState& s, const std::string& path, int w, int h) {
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
  WritePng(path, w, h, rgb);  // atomic: temporary name, renamed into place
  s.last_saved = path;
  LogInfo("screenshot -> ", path);
  LogInfo("the same picture headless: ", CurrentCommandLine(s, "image.png"));
}

// A screenshot name in the working folder that no file has yet.
std::string NewScreenshotName() {
  const std::time_t now = std::time(nullptr);
  char stamp[32];
  std::strftime(stamp, sizeof(stamp), "%Y%m%d-%H%M%S", std::localtime(&now));
  for (int k = 0;; ++k) {
    const std::string name =
        "lumislab-preview-" + std::string(stamp) + (k ? "-" + std::to_string(k) : "") + ".png";
    if (!std::filesystem::exists(name)) return name;
  }
}

// --watch: at most once per --poll, loads positions that arrived since.
void PollSlab(WindowState& s) {
  if (!s.config.watch ||
      std::chrono::duration<double>(Clock::now() - s.last_poll).count() < s.config.poll_s) {
    return;
  }
  s.last_poll = Clock::now();
  try {
    if (!s.source.luminaire) s.info = SlabInfo::Load(s.config.slab_dir);
    const auto added = LoadNewLights(s.source, s.info, *s.renderer, s.config.threads);
    if (!added.empty()) s.last_arrived = added.back();
  } catch (const Error& e) {
    LogDebug("poll: ", e.what());
  }
}

// A renderer for the current settings with every position on disk (again, after a new
// shadow-map size).
void MakeRenderer(WindowState& s, int fb_w, int fb_h) {
  s.renderer.reset();
  const RenderOptions options = MakeRenderOptions(s.config, s.setup);
  const GLubyte* gl_renderer = glGetString(GL_RENDERER);
  LogInfo(ShortcutChoice(s.config, options,
                         gl_renderer ? reinterpret_cast<const char*>(gl_renderer) : ""));
  s.renderer = std::make_unique<Renderer>(s.info, fb_w, fb_h, options,
                                          RendererOrientations(s.source, s.info));
  s.renderer->SetScene(s.setup.mesh);
  s.renderer->SetPose(PoseFromValues(s.config.scene.pose));
  const auto arrived = LoadNewLights(s.source, s.info, *s.renderer, s.config.threads);
  if (!arrived.empty()) s.last_arrived = arrived.back();
  s.camera_changed = true;
}

// Hands the requests of the controls and the callbacks to the renderer.
void ApplyRequests(WindowState& s, int fb_w, int fb_h) {
  if (s.rebuild_renderer) MakeRenderer(s, fb_w, fb_h);
  s.rebuild_renderer = false;
  if (s.options_changed) s.renderer->SetOptions(MakeRenderOptions(s.config, s.setup));
  s.options_changed = false;
  if (s.pose_changed) s.renderer->SetPose(PoseFromValues(s.config.scene.pose));
  s.pose_changed = false;
  if (fb_w != s.config.width || fb_h != s.config.height) s.camera_changed = true;  // aspect
  s.config.width = fb_w;
  s.config.height = fb_h;
  s.renderer->Resize(fb_w, fb_h);
  if (s.setup.plane) {
    s.renderer->SetCamera(PlaneView(s.setup.plane_z, s.setup.extent));
  } else if (s.camera_changed) {
    SetCameraValues(s.config.camera, s.setup);
    s.renderer->SetCamera(OrbitCamera(s.setup, double(fb_w) / std::max(1, fb_h)));
  }
  s.camera_changed = false;
}

// The picture: the accumulation read back, tone-mapped exactly as a headless PNG
// (ToneMapToSrgb8), uploaded as an 8-bit texture. Only when the image or the tone changed.
void UpdatePicture(WindowState& s, bool image_changed) {
  if (image_changed || s.image.empty()) {
    s.image = s.renderer->Read();
    s.picture_stale = true;
  }
  if (!s.picture_stale) return;
  s.picture_stale = false;
  s.exposure_factor = ExposureFactor(s.image, s.config.tone);
  // The picture the headless path writes for the same settings: tone-mapped, or the false-colour
  // view with its colour bar (wider than the image).
  std::vector<uint8_t> rgb;
  int w = s.image.width, h = s.image.height;
  if (s.config.false_colour) {
    Rgb8Image picture = FalseColourView(s.config, s.setup, s.info, s.image);
    rgb = std::move(picture.rgb);
    w = picture.width, h = picture.height;
  } else {
    rgb = ToneMapToSrgb8(s.image, s.config.tone);
  }
  if (!s.texture) glGenTextures(1, &s.texture);
  glBindTexture(GL_TEXTURE_2D, s.texture);
  glPixelStorei(GL_UNPACK_ALIGNMENT, 1);
  if (s.texture_w != w || s.texture_h != h) {
    s.texture_w = w;
    s.texture_h = h;
    glTexImage2D(GL_TEXTURE_2D, 0, GL_RGB8, s.texture_w, s.texture_h, 0, GL_RGB, GL_UNSIGNED_BYTE,
                 rgb.data());
    glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MIN_FILTER, GL_NEAREST);
    glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MAG_FILTER, GL_NEAREST);
  } else {
    glTexSubImage2D(GL_TEXTURE_2D, 0, 0, 0, s.texture_w, s.texture_h, GL_RGB, GL_UNSIGNED_BYTE,
                    rgb.data());
  }
}

// One frame: requests, render, picture, panel. Returns whether Render() added light.
bool Frame(WindowState& s, GLFWwindow* window, double seconds) {
  int fb_w = 0, fb_h = 0;
  glfwGetFramebufferSize(window, &fb_w, &fb_h);
  if (fb_w <= 0 || fb_h <= 0) return false;
  FlyKeys(s, window, seconds);
  ApplyRequests(s, fb_w, fb_h);
  const auto start = Clock::now();
  const int added = s.renderer->Render();
  if (added > 0) {
    s.renderer->Finish();  // "last render" is the GL's work, not only its issue (rare: new light)
    s.render_ms = std::chrono::duration<double, std::milli>(Clock::now() - start).count();
    s.render_lights = added;
  }
  UpdatePicture(s, added > 0);

  ImGui_ImplOpenGL3_NewFrame();
  ImGui_ImplGlfw_NewFrame();
  ImGui::NewFrame();
  // Row 0 of the picture is its top: texture row 0 at v = 0, which ImGui draws at the top.
  ImGui::GetBackgroundDrawList()->AddImage(
      reinterpret_cast<ImTextureID>(static_cast<intptr_t>(s.texture)), ImVec2(0, 0),
      ImGui::GetIO().DisplaySize);
  if (s.config.ui) DrawControls(s);
  ImGui::Render();
  glBindFramebuffer(GL_FRAMEBUFFER, 0);
  glViewport(0, 0, fb_w, fb_h);
  glDisable(GL_DEPTH_TEST);
  glDisable(GL_BLEND);
  glClearColor(0, 0, 0, 1);
  glClear(GL_COLOR_BUFFER_BIT);
  ImGui_ImplOpenGL3_RenderDrawData(ImGui::GetDrawData());
  ++s.frames;

  if (s.screenshot_requested) {
    const std::string& path = s.config.screenshot;
    SaveScreenshot(s, path.empty() ? NewScreenshotName() : path, fb_w, fb_h);
    s.screenshot_requested = false;
  }
  // --screenshot: once every position is in and the panel has laid itself out (ImGui sizes a
  // new window over its first frames), save and quit.
  if (!s.config.screenshot.empty() && s.renderer->PositionCount() == s.renderer->LightCount() &&
      s.frames >= 3) {
    SaveScreenshot(s, s.config.screenshot, fb_w, fb_h);
    s.quit = true;
  }
  return added > 0;
}

// Dear ImGui on the window's context; torn down with it.
class ImGuiScope {
 public:
  explicit ImGuiScope(GLFWwindow* window) {
    IMGUI_CHECKVERSION();
    ImGui::CreateContext();
    ImGui::GetIO().IniFilename = nullptr;  // no imgui.ini in the working folder
    ImGui::StyleColorsDark();
    // After InstallCallbacks: ImGui's callbacks chain to ours.
    if (!ImGui_ImplGlfw_InitForOpenGL(window, true) || !ImGui_ImplOpenGL3_Init("#version 410 core"))
      throw Failure("Dear ImGui could not start on the window's GL context");
  }
  ~ImGuiScope() {
    ImGui_ImplOpenGL3_Shutdown();
    ImGui_ImplGlfw_Shutdown();
    ImGui::DestroyContext();
  }
  ImGuiScope(const ImGuiScope&) = delete;
  ImGuiScope& operator=(const ImGuiScope&) = delete;
};

}  // namespace

int RunWindow(const PreviewConfig& config, const LightSource& source, const SlabInfo& info) {
  WindowContext context(config.width, config.height, "lumislab-preview");
  GLFWwindow* window = context.window();
  WindowState state;
  state.config = config;
  state.info = info;
  state.source = source;
  state.setup = MakePreviewSetup(config, info);
  state.config.scene.pose = ValuesFromPose(state.setup.pose);
  state.config.camera = CameraValues(state.setup);
  InstallCallbacks(window, &state);
  const ImGuiScope imgui(window);
  int fb_w = 0, fb_h = 0;
  glfwGetFramebufferSize(window, &fb_w, &fb_h);
  MakeRenderer(state, fb_w, fb_h);
  auto last = Clock::now();
  while (!glfwWindowShouldClose(window) && !state.quit && !StopRequested()) {
    glfwPollEvents();
    PollSlab(state);
    const auto now = Clock::now();
    const double seconds = std::chrono::duration<double>(now - last).count();
    last = now;
    const bool added = Frame(state, window, seconds);
    state.frame_ms = std::chrono::duration<double, std::milli>(Clock::now() - now).count();
    if (state.quit) break;
    glfwSwapBuffers(window);
    // Idle (nothing added, no key held for flying): wait for input or the next poll.
    if (!added && !state.fly && !state.dragging_orbit)
      glfwWaitEventsTimeout(config.watch ? config.poll_s : 0.1);
  }
  if (state.texture) glDeleteTextures(1, &state.texture);
  state.renderer.reset();
  return 0;
}

}  // namespace lumislab
