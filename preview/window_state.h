// What the window (preview/window.cc) and its controls panel (preview/window_controls.cc) share:
// the live settings, which are a PreviewConfig so that every one of them is also a headless
// flag (HeadlessCommandLine), and the state of the frame loop.
#pragma once

#include <chrono>
#include <memory>
#include <string>
#include <utility>
#include <vector>

#include "core/image.h"
#include "core/slab.h"
#include "lib/lightfield/scene_setup.h"
#include "preview/config.h"
#include "preview/light_source.h"
#include "preview/renderer.h"

namespace lumislab {

struct WindowState {
  using Clock = std::chrono::steady_clock;

  // The settings now: tone, camera (config.camera, six values), luminaire pose
  // (config.scene.pose, six values), shadows, accumulation, size.
  PreviewConfig config;
  SlabInfo info;
  LightSource source;  // the slab, or the luminaire folder's orientations
  SceneSetup setup;    // mesh and plane of the scene; its pose and camera follow the config
  std::unique_ptr<Renderer> renderer;

  // The picture: the accumulated image, its exposure factor and its sRGB bytes (a texture).
  ImageF image;
  double exposure_factor = 1;
  bool picture_stale = true;  // re-tone-map and upload
  unsigned texture = 0;
  int texture_w = 0, texture_h = 0;

  // Requests from the controls and the callbacks, applied at the start of the next frame.
  bool camera_changed = true, pose_changed = false, options_changed = false,
       rebuild_renderer = false;
  bool fly = false;  // camera: orbit about the target, or fly (turn about the eye, arrow keys)
  bool dragging_orbit = false, dragging_pan = false, dragging_move = false, dragging_aim = false;
  double last_x = 0, last_y = 0;
  bool screenshot_requested = false;
  bool quit = false;

  // What the panel reports.
  std::pair<int, int> last_arrived{-1, -1};
  Clock::time_point last_poll = Clock::now();
  double frame_ms = 0;   // the last frame's work (events, render, picture, panel)
  double render_ms = 0;  // the last Render() that added light, and how many lights
  int render_lights = 0;
  int frames = 0;
  std::string last_saved;  // the last screenshot's path
};

// The controls panel (Dear ImGui, inside a frame): changes `s` and sets its request flags.
void DrawControls(WindowState& s);
// The grid of positions, one square each (i to the right, j up), green when arrived.
void DrawPositionGrid(const WindowState& s);
// The window's current settings as the headless command line that renders them into `out`.
std::string CurrentCommandLine(const WindowState& s, const std::string& out);

}  // namespace lumislab
