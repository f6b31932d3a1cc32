// The frame loop's GL calls (docs/method.md §4.2, "What a frame does"), counted through the glad
// loader (gl_call_counter.h) on OSMesa: a camera move and a full frame (every shadow map drawn
// again), with the default shortcuts (coarse shading, reprojection) and with every position
// shaded exactly. No frame reads anything back or waits for the GL unless it is profiled, and
// the calls per frame do not grow with the positions beyond the stated bound.
#include <glad/gl.h>
#include <gtest/gtest.h>

#include <algorithm>
#include <cstdio>
#include <map>
#include <memory>
#include <string>
#include <vector>

#include "gl_call_counter.h"
#include "lib/lightfield/camera.h"
#include "lib/lightfield/light_field.h"
#include "lib/lightfield/scene_setup.h"
#include "lib/synthetic/truth.h"
#include "preview/config.h"
#include "preview/gl_context.h"
#include "preview/renderer.h"

namespace lumislab {
namespace {

OffscreenContext& Context() {
  static OffscreenContext* context = new OffscreenContext(16, 16);
  return *context;
}

// Calls that read back from the GL or wait for it: none may be in a frame that is not profiled.
const char* const kSyncCalls[] = {"glReadPixels",
                                  "glReadnPixels",
                                  "glGetBufferSubData",
                                  "glGetNamedBufferSubData",
                                  "glMapBuffer",
                                  "glMapBufferRange",
                                  "glMapNamedBuffer",
                                  "glMapNamedBufferRange",
                                  "glGetTexImage",
                                  "glGetTextureImage",
                                  "glGetTextureSubImage",
                                  "glGetnTexImage",
                                  "glGetCompressedTexImage",
                                  "glFinish",
                                  "glClientWaitSync",
                                  "glWaitSync",
                                  "glGetQueryObjectiv",
                                  "glGetQueryObjectuiv",
                                  "glGetQueryObjecti64v",
                                  "glGetQueryObjectui64v",
                                  "glGetQueryBufferObjectiv",
                                  "glGetQueryBufferObjectuiv",
                                  "glGetQueryBufferObjecti64v",
                                  "glGetQueryBufferObjectui64v"};

// The calls of one frame of each kind.
struct FrameCalls {
  std::map<std::string, long> camera_move, full_frame;
  long camera_total = 0, full_total = 0;
  double reprojected_exact = 0;  // the camera move's (0: shaded in full)
};

// A 96 x 96 view of the crypt lit by an nu x nv truth slab (all positions present), after the
// frames that link the programs; then one camera move and one full frame counted.
FrameCalls CountFrames(int nu, int nv, const RenderOptions& options) {
  Context();
  const SlabInfo info = DefaultSlabInfo(nu, nv, 20, 24);
  const SceneSetup setup = MakeSceneSetup("crypt", info);
  Renderer r(info, 96, 96, options);
  r.SetScene(setup.mesh);
  r.SetPose(setup.pose);
  SceneSetup view = setup;
  r.SetCamera(OrbitCamera(view, 1.0));
  const Luminaire luminaire = DefaultScene().luminaire;
  for (int j = 0; j < nv; ++j) {
    for (int i = 0; i < nu; ++i) {
      r.SetPosition(
          i, j,
          IntensityFromIrradiance(info, i, j, TruthPosition(luminaire, info, i, j).irradiance));
    }
  }
  auto move = [&] {
    view.camera_yaw_deg += 0.5;
    r.SetCamera(OrbitCamera(view, 1.0));
    r.Render();
  };
  r.Render();
  move();  // a reprojected view: its programs linked
  // A full frame, then the counted move: it keeps that view as reprojection's source and
  // reprojects from it, whatever the slab.
  r.SetPose(setup.pose);
  r.Render();
  r.Read();
  FrameCalls calls;
  {
    GlCallCounter counter;
    move();
    calls.camera_move = counter.Counts();
    calls.camera_total = counter.Total();
  }
  calls.reprojected_exact = r.shortcuts().reprojected_exact;
  r.Read();
  {
    GlCallCounter counter;
    r.SetPose(setup.pose);  // every shadow map and the view drawn again
    r.Render();
    calls.full_frame = counter.Counts();
    calls.full_total = counter.Total();
  }
  return calls;
}

std::string List(const std::map<std::string, long>& counts) {
  std::string s;
  for (const auto& [name, n] : counts) s += name + " " + std::to_string(n) + ", ";
  return s;
}

void ExpectNoSync(const std::map<std::string, long>& counts, const std::string& what) {
  for (const char* name : kSyncCalls) EXPECT_EQ(counts.count(name), 0u) << what << ": " << name;
}

// The shortcuts of lumislab-preview's defaults with shadows (preview/config.cc).
RenderOptions Defaults() {
  RenderOptions options;
  options.coarse_tolerance = 0.1;
  options.reproject_tolerance = 0.1;
  return options;
}

TEST(PreviewGlCalls, NoReadBackOrWaitInAFrame) {
  for (const auto& [name, options] : std::vector<std::pair<std::string, RenderOptions>>{
           {"defaults", Defaults()}, {"exact", RenderOptions{}}}) {
    const FrameCalls calls = CountFrames(3, 3, options);
    RecordProperty(name + "_camera_move_calls", int(calls.camera_total));
    RecordProperty(name + "_full_frame_calls", int(calls.full_total));
    std::printf("%s: camera move %ld calls (%s)\n%s: full frame %ld calls (%s)\n", name.c_str(),
                calls.camera_total, List(calls.camera_move).c_str(), name.c_str(), calls.full_total,
                List(calls.full_frame).c_str());
    ExpectNoSync(calls.camera_move, name + " camera move");
    ExpectNoSync(calls.full_frame, name + " full frame");
  }
}

// The bound (docs/method.md §4.2, "What a frame does"): a frame's calls grow with the positions
// only by one layered shadow draw (3 calls: its maps, their scissor rectangles, the draw) per
// maps_per_draw = min(kShadowBatch, GL_MAX_VIEWPORTS) maps drawn, and one light pass per
// kLightsPerPass lights (64: 3 x 3 and 9 x 7 are one pass each). So a camera move of 9 x 7
// positions makes no more calls than one of 3 x 3, and a full frame at most
// 3 (ceil(63 / maps_per_draw) - 1) more.
constexpr long kCallsPerShadowDraw = 3;

TEST(PreviewGlCalls, CallsDoNotGrowWithThePositions) {
  Context();
  GLint viewports = 0;
  glGetIntegerv(GL_MAX_VIEWPORTS, &viewports);
  const long maps_per_draw = std::min<long>(32, viewports);  // kShadowBatch (renderer_gl.h)
  const long extra_draws = (63 + maps_per_draw - 1) / maps_per_draw - 1;
  for (const auto& [name, options] : std::vector<std::pair<std::string, RenderOptions>>{
           {"defaults", Defaults()}, {"exact", RenderOptions{}}}) {
    const FrameCalls small = CountFrames(3, 3, options), large = CountFrames(9, 7, options);
    std::printf(
        "%s: camera move %ld -> %ld calls (reprojected: %.3f, %.3f of the pixels exact), full "
        "frame %ld -> %ld calls (3x3 -> 9x7; %ld maps per shadow draw)\n",
        name.c_str(), small.camera_total, large.camera_total, small.reprojected_exact,
        large.reprojected_exact, small.full_total, large.full_total, maps_per_draw);
    if (options.reproject_tolerance > 0) {  // like with like: both moves reprojected
      EXPECT_GT(small.reprojected_exact, 0) << name;
      EXPECT_GT(large.reprojected_exact, 0) << name;
    }
    EXPECT_LE(large.camera_total, small.camera_total)
        << name << ": " << List(small.camera_move) << " vs " << List(large.camera_move);
    EXPECT_LE(large.full_total, small.full_total + kCallsPerShadowDraw * extra_draws)
        << name << ": " << List(small.full_frame) << " vs " << List(large.full_frame);
  }
}

// --profile: a profiled frame times its phases with GL_TIME_ELAPSED queries where the context has
// them (llvmpipe does), read after the frame, and still calls no glFinish.
TEST(PreviewGlCalls, ProfileUsesTimerQueriesNotGlFinish) {
  Context();
  const SlabInfo info = DefaultSlabInfo(3, 3, 20, 24);
  const SceneSetup setup = MakeSceneSetup("crypt", info);
  RenderOptions options;
  options.time_phases = true;
  Renderer r(info, 96, 96, options);
  r.SetScene(setup.mesh);
  r.SetPose(setup.pose);
  r.SetCamera(OrbitCamera(setup, 1.0));
  const Luminaire luminaire = DefaultScene().luminaire;
  for (int j = 0; j < 3; ++j)
    for (int i = 0; i < 3; ++i)
      r.SetPosition(
          i, j,
          IntensityFromIrradiance(info, i, j, TruthPosition(luminaire, info, i, j).irradiance));
  r.Render();
  r.SetPose(setup.pose);
  GlCallCounter counter;
  r.Render();
  const std::map<std::string, long> calls = counter.Counts();
  const PhaseTimes& t = r.phase_times();
  std::printf("profiled full frame: G-buffer %.3f ms, shadow maps %.3f ms, light %.3f ms (%s)\n",
              t.depth_ms, t.shadow_ms, t.light_ms, t.gpu_timer ? "GL_TIME_ELAPSED" : "glFinish");
  EXPECT_TRUE(t.gpu_timer);  // llvmpipe has timer queries
  EXPECT_EQ(calls.count("glFinish"), 0u);
  EXPECT_EQ(calls.at("glBeginQuery"), 4);  // three phases and the open one after the last
  EXPECT_EQ(calls.at("glGetQueryObjectui64v"), 3);
  EXPECT_GT(t.depth_ms, 0);
  EXPECT_GT(t.shadow_ms, 0);
  EXPECT_GT(t.light_ms, 0);
}

// The log line of the shortcuts chosen (docs/method.md §4.2, "Shortcuts by backend"): software or
// hardware by GL_RENDERER, the values in use and why; the choice itself is the same on both.
TEST(PreviewShortcutChoice, SaysWhichAndWhyByBackend) {
  EXPECT_TRUE(IsSoftwareRenderer("llvmpipe (LLVM 15.0.6, 256 bits)"));
  EXPECT_TRUE(IsSoftwareRenderer("softpipe"));
  EXPECT_FALSE(IsSoftwareRenderer("NVIDIA H200/PCIe/SSE2"));
  PreviewConfig config;
  const SlabInfo info = DefaultSlabInfo(3, 3, 20, 24);
  const SceneSetup setup = MakeSceneSetup("crypt", info);
  const RenderOptions options = MakeRenderOptions(config, setup);
  EXPECT_EQ(options.coarse_tolerance, 0.1);  // the llvmpipe defaults, unchanged
  EXPECT_EQ(options.reproject_tolerance, 0.1);
  const std::string software = ShortcutChoice(config, options, "llvmpipe (LLVM 15.0.6)");
  const std::string hardware = ShortcutChoice(config, options, "NVIDIA H200/PCIe/SSE2");
  std::printf("%s\n%s\n", software.c_str(), hardware.c_str());
  EXPECT_NE(software.find("software renderer"), std::string::npos);
  EXPECT_NE(software.find("coarse shading 0.1 (auto)"), std::string::npos);
  EXPECT_NE(software.find("reprojection 0.1"), std::string::npos);
  EXPECT_NE(software.find("Table 1"), std::string::npos);
  EXPECT_NE(hardware.find("hardware renderer"), std::string::npos);
  EXPECT_NE(hardware.find("unmeasured"), std::string::npos);
}

}  // namespace
}  // namespace lumislab
