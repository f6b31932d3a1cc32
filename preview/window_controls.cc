// The controls panel of the window (Dear ImGui): what the frame shows and every setting that
// changes it, each a flag of the headless path (the "command line" at the bottom).
#include <imgui.h>

#include <algorithm>
#include <cmath>
#include <string>

#include "lib/lightfield/tone_map.h"
#include "preview/cli.h"
#include "preview/window_state.h"

namespace lumislab {
namespace {

void StatusPanel(WindowState& s) {
  // A frame that adds no light only draws the picture and the panel; the last render is the
  // frame that did (all lights after a camera, pose or option change; new positions otherwise).
  ImGui::Text("%.1f fps (frame %.1f ms)  last render %.0f ms, %d lights",
              s.frame_ms > 0 ? 1000 / s.frame_ms : 0.0, s.frame_ms, s.render_ms, s.render_lights);
  ImGui::Text("positions %d/%d", s.renderer->PositionCount(), s.renderer->LightCount());
  if (s.last_arrived.first >= 0) {
    ImGui::SameLine();
    ImGui::Text(" last %d,%d", s.last_arrived.first, s.last_arrived.second);
  }
  DrawPositionGrid(s);
}

void ExposurePanel(WindowState& s) {
  ToneMapping& tone = s.config.tone;
  float stops = float(tone.exposure_stops);
  if (ImGui::SliderFloat("stops", &stops, -10, 10, "%+.1f")) {
    tone.exposure_stops = stops;
    s.picture_stale = true;
  }
  const char* curves[] = {"linear", "filmic"};
  int curve = tone.curve == ToneCurve::kFilmic;
  if (ImGui::Combo("tone map", &curve, curves, 2)) {
    tone.curve = curve ? ToneCurve::kFilmic : ToneCurve::kLinear;
    s.picture_stale = true;
  }
  const char* modes[] = {"off", "lit", "p99"};
  int mode = int(tone.auto_exposure);
  if (ImGui::Combo("auto exposure", &mode, modes, 3)) {
    tone.auto_exposure = AutoExposure(mode);
    s.picture_stale = true;
  }
  ImGui::Text("factor %.4g", s.exposure_factor);
  const char* views[] = {"normal", "false-colour"};
  int view = s.config.false_colour;
  if (ImGui::Combo("view", &view, views, 2)) {
    // False colour renders the irradiance before albedo (MakeRenderOptions): a new render.
    s.config.false_colour = view == 1;
    s.options_changed = true;
  }
}

void ShadowsPanel(WindowState& s) {
  PreviewConfig& c = s.config;
  s.options_changed |= ImGui::Checkbox("shadows", &c.shadows);
  ImGui::SameLine();
  s.options_changed |= ImGui::Checkbox("PCF", &c.shadow_pcf);
  ImGui::SameLine();
  s.options_changed |= ImGui::Checkbox("cull", &c.shadow_cull);
  const int sizes[] = {128, 256, 512, 1024, 2048, 4096};
  const char* names[] = {"128", "256", "512", "1024", "2048", "4096"};
  int index = int(std::find(std::begin(sizes), std::end(sizes), c.shadow_size) - sizes);
  if (index < 6) {  // a --shadow-size not in the list is shown, not offered
    if (ImGui::Combo("shadow size", &index, names, 6)) {
      c.shadow_size = sizes[index];
      s.rebuild_renderer = true;
    }
  } else {
    ImGui::Text("shadow size %d", c.shadow_size);
  }
  // Faster frames (docs/method.md §4.2): each shortcut's knob, 0 / 1 = off.
  float share = float(c.shadow_share);
  if (ImGui::SliderFloat("share maps (texels)", &share, 0.0f, 4.0f, "%.2f")) {
    c.shadow_share = share;
    s.options_changed = true;
  }
  s.options_changed |=
      ImGui::SliderInt("merge block", &c.merge_group, 0, 4, c.merge_group == 0 ? "auto" : "%d");
  float merge_error = float(c.merge_error);
  if (ImGui::SliderFloat("merge error", &merge_error, 0.001f, 1.0f, "%.3f",
                         ImGuiSliderFlags_Logarithmic)) {
    c.merge_error = merge_error;
    s.options_changed = true;
  }
  // Coarse shading and reprojection: their tolerances (0: off; coarse shading starts at auto).
  float coarse = float(CoarseTolerance(c, s.setup));
  if (ImGui::SliderFloat("coarse shading", &coarse, 0.0f, 0.5f, "%.3f")) {
    c.coarse_tolerance = coarse;
    s.options_changed = true;
  }
  float reproject = float(c.reproject_tolerance);
  if (ImGui::SliderFloat("reproject", &reproject, 0.0f, 0.5f, "%.3f")) {
    c.reproject_tolerance = reproject;
    s.options_changed = true;
  }
  int format = c.srgbe;
  ImGui::Text("accumulation");
  ImGui::SameLine();
  s.options_changed |= ImGui::RadioButton("float", &format, 0);
  ImGui::SameLine();
  s.options_changed |= ImGui::RadioButton("sRGBE", &format, 1);
  c.srgbe = format == 1;
  const char* filters[] = {"bilinear", "nearest", "cubic"};
  int filter = int(c.texture_filter);
  if (ImGui::Combo("texture filter", &filter, filters, 3)) {
    c.texture_filter = TextureFilter(filter);
    s.options_changed = true;
  }
}

void LuminairePanel(WindowState& s) {
  std::vector<double>& pose = s.config.scene.pose;
  ImGui::TextDisabled("Ctrl+drag: move, Shift+drag: aim");
  s.pose_changed |= ImGui::DragScalarN("position mm", ImGuiDataType_Double, pose.data(), 3, 5.f,
                                       nullptr, nullptr, "%.0f");
  s.pose_changed |= ImGui::DragScalarN("rx ry rz deg", ImGuiDataType_Double, pose.data() + 3, 3,
                                       0.5f, nullptr, nullptr, "%.1f");
}

void CameraPanel(WindowState& s) {
  if (s.setup.plane) {
    ImGui::TextDisabled("plane view: fixed orthographic camera");
    return;
  }
  int mode = s.fly;
  ImGui::RadioButton("orbit", &mode, 0);
  ImGui::SameLine();
  ImGui::RadioButton("fly", &mode, 1);
  s.fly = mode == 1;
  ImGui::SameLine();
  ImGui::TextDisabled(s.fly ? "arrows, PgUp/PgDn" : "drag, wheel");
  std::vector<double>& v = s.config.camera;
  s.camera_changed |= ImGui::DragScalarN("yaw pitch", ImGuiDataType_Double, v.data(), 2, 0.5f,
                                         nullptr, nullptr, "%.1f");
  v[1] = std::clamp(v[1], -85.0, 85.0);
  const double min_distance = 10, max_distance = 1e5;
  s.camera_changed |= ImGui::DragScalar("distance mm", ImGuiDataType_Double, &v[2], 10.f,
                                        &min_distance, &max_distance, "%.0f");
  s.camera_changed |= ImGui::DragScalarN("target mm", ImGuiDataType_Double, v.data() + 3, 3, 5.f,
                                         nullptr, nullptr, "%.0f");
}

void CommandLinePanel(WindowState& s) {
  if (ImGui::Button("screenshot (P)")) s.screenshot_requested = true;
  if (!s.last_saved.empty()) {
    ImGui::SameLine();
    ImGui::TextDisabled("%s", s.last_saved.c_str());
  }
  const std::string line = CurrentCommandLine(s, "image.png");
  if (ImGui::Button("copy command line")) ImGui::SetClipboardText(line.c_str());
  ImGui::PushTextWrapPos(ImGui::GetCursorPosX() + 340);
  ImGui::TextDisabled("%s", line.c_str());
  ImGui::PopTextWrapPos();
}

}  // namespace

void DrawPositionGrid(const WindowState& s) {
  const float cell = 9, gap = 2;
  const int nu = s.info.grid.nu, nv = s.info.grid.nv;
  const ImVec2 origin = ImGui::GetCursorScreenPos();
  ImDrawList* draw = ImGui::GetWindowDrawList();
  for (int j = 0; j < nv; ++j) {
    for (int i = 0; i < nu; ++i) {
      const ImVec2 a(origin.x + i * (cell + gap), origin.y + (nv - 1 - j) * (cell + gap));
      const bool here = s.renderer->HasPosition(i, j);
      const bool last = s.last_arrived == std::pair{i, j};
      draw->AddRectFilled(a, ImVec2(a.x + cell, a.y + cell),
                          last   ? IM_COL32(250, 230, 60, 255)
                          : here ? IM_COL32(50, 220, 80, 255)
                                 : IM_COL32(60, 60, 60, 255));
    }
  }
  ImGui::Dummy(ImVec2(std::max(1, nu) * (cell + gap), std::max(1, nv) * (cell + gap)));
}

void DrawControls(WindowState& s) {
  ImGui::SetNextWindowPos(ImVec2(8, 8), ImGuiCond_FirstUseEver);
  ImGui::SetNextWindowSize(ImVec2(360, 0), ImGuiCond_FirstUseEver);
  ImGui::SetNextWindowBgAlpha(0.8f);
  ImGui::Begin("lumislab-preview", nullptr, ImGuiWindowFlags_AlwaysAutoResize);
  ImGui::PushItemWidth(200);
  StatusPanel(s);
  if (ImGui::CollapsingHeader("exposure", ImGuiTreeNodeFlags_DefaultOpen)) ExposurePanel(s);
  if (ImGui::CollapsingHeader("shadows and accumulation", ImGuiTreeNodeFlags_DefaultOpen))
    ShadowsPanel(s);
  if (ImGui::CollapsingHeader("luminaire", ImGuiTreeNodeFlags_DefaultOpen)) LuminairePanel(s);
  if (ImGui::CollapsingHeader("camera", ImGuiTreeNodeFlags_DefaultOpen)) CameraPanel(s);
  CommandLinePanel(s);
  ImGui::PopItemWidth();
  ImGui::End();
}

std::string CurrentCommandLine(const WindowState& s, const std::string& out) {
  PreviewConfig c = s.config;
  if (s.setup.plane) c.camera.clear();
  return HeadlessCommandLine(c, out);
}

}  // namespace lumislab
