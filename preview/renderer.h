// The preview renderer (docs/method.md §4): per grid position a textured spot light at c_ij with
// the projective texture E'_ij, f = cos(theta) cos(theta') / delta^2 and a shadow map from c_ij;
// light only towards +z of the luminaire frame and only through the screen window; Lambertian
// materials; float (RGBA32F, additive blending) or sRGBE-packed accumulation (paper §4.2).
// Needs a current GL 4.5 core context (OffscreenContext or WindowContext).
// A luminaire folder (docs/method.md §4.12): every orientation's positions are lights, each pass
// one orientation's, shaded in its capture frame and weighted by the blend (LightOrientation).
//
// Deferred shading: a G-buffer (luminaire-frame position, normal, albedo per pixel) is drawn when
// the view changes, and each light pass is one full-screen pass over it; the shaders have the
// options compiled in (LightProgram).
// Caching: shadow maps are kept until the scene, the luminaire pose or an option that shapes them
// changes, or a position's new E' reaches beyond the rectangle its map was drawn over; the
// accumulated image and the G-buffer are kept until the camera, the scene, the pose, an option or
// the size changes, or an accumulated position's E' is replaced, so a newly arrived position only
// costs its own light pass. Lights are batched (texture arrays, up to kLightsPerPass per pass,
// kShortcutLightsPerPass with the shortcuts).
//
// The methods are in files by phase: renderer.cc (set-up, uploads, Render(), read-back),
// renderer_shadows.cc (shadow maps and their sharing), renderer_merge.cc (merged lights),
// renderer_tiles.cc (light culling by tiles), renderer_light.cc (light passes, coarse shading),
// renderer_reproject.cc (reprojection), renderer_orientations.cc (a luminaire folder's
// orientations); the shaders in preview/shaders/.
#pragma once

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <array>
#include <string>
#include <vector>

#include "core/image.h"
#include "core/luminaire_set.h"
#include "core/slab.h"
#include "lib/lightfield/scenes.h"

namespace lumislab {

// How E'_ij is read between its texel centres (docs/method.md §4.6's knob): the hardware's
// bilinear filter (the paper's, the default), the nearest texel, or Catmull-Rom cubic
// interpolation (16 texel reads instead of one filtered read).
enum class TextureFilter { kBilinear = 0, kNearest = 1, kCubic = 2 };

struct RenderOptions {
  // What is drawn.
  bool shadows = true;
  bool srgbe = false;                              // sRGBE-packed accumulation instead of float
  int shadow_size = 512;                           // shadow-map texels per side
  bool shadow_pcf = false;                         // 2x2 filtered depth compare (softer edges)
  double radiance_scale = 1.0 / 3.14159265358979;  // albedo/pi (radiance); 1: irradiance view
  bool cull_back_faces = false;  // camera passes only: see into a closed room from outside
  // Shadow maps hold only the faces turned to the light (docs/method.md §4.2). In a closed scene
  // (every surface facing the room, solids facing out) the nearest surface along a ray from the
  // light faces it; silhouettes can lose up to a shadow texel (crypt: 0.6 % of the image).
  bool shadow_cull = false;
  // Albedo 1 everywhere: with radiance_scale 1 the image is the irradiance E arriving at each
  // surface (W/m^2), which --view false-colour maps.
  bool unit_albedo = false;
  TextureFilter texture_filter = TextureFilter::kBilinear;

  // Shortcuts (docs/method.md §4.2, "Faster frames"): each changes the image within the bound
  // its knob sets; all off (the defaults): the full per-position render.
  // Shadow-map sharing: neighbouring positions in blocks of g x g share one map rendered from
  // the block's centre, g the largest whose shadow edges move by at most this many shadow texels
  // over the depth range the maps see (0: off, every position its own map).
  double shadow_share_texels = 0;
  // Light merging: blocks of merge_group x merge_group positions become one light (summed E'
  // texture, the mean of the members' shadow lookups) for receivers beyond the depth where the
  // merged term's error is bounded by merge_error times the block's peak term (1: off).
  int merge_group = 1;
  double merge_error = 0.01;
  // Coarse shading: a pass with at least kCoarseMinLights lights is shaded at every second pixel
  // of every second row, and a pixel takes the bilinear mean of its (up to four) samples where
  // they lie on its surface and their sums spread by at most this fraction of their peak; the
  // others are shaded exactly (0: off, every pixel exact).
  double coarse_tolerance = 0;
  // Reprojection: after a camera move (pose, scene, options unchanged) a pixel takes the sums of
  // the last view shaded in full, interpolated where four of its pixels lie on the pixel's
  // surface and their sums spread by at most this fraction of their peak; the others are shaded
  // exactly (0: off).
  double reproject_tolerance = 0;
  // Sharing or merging on: positions then use the shortcuts' light program and passes (a
  // merged light's entry, a shared map), and their shadow maps are drawn whole.
  bool SharesOrMergesLights() const { return shadow_share_texels > 0 || merge_group > 1; }

  // Exact savings: the same image bit for bit; off only to check that.
  // Each position's shadow map is drawn (and cleared) only over the rectangle its lookups can
  // reach: where its E' is not zero, widened by the texture filter's and the normal offset's
  // reach (a lookup outside multiplies an E' of 0). Maps shared or merged are drawn whole.
  bool shadow_scissor = true;
  // A frame's shadow maps in one instanced draw where the driver has
  // ARB_shader_viewport_layer_array (false: one draw per map, as without it). Fixed when the
  // renderer is created.
  bool layered_shadow_maps = true;
  // Light culling by tiles: each tile of 16 x 16 pixels shades only the lights whose E' can be
  // non-zero at one of its pixels (a light left out adds E' = 0).
  bool tiled_lights = true;

  // Profiling: phase_times() holds each phase's GL time (GL_TIME_ELAPSED queries read after the
  // frame), or where the context has no timer queries wall times with glFinish() after each.
  bool time_phases = false;
};

// Time of the phases of the last Render() (milliseconds; only with time_phases).
// depth_ms: the G-buffer; shadow_ms: the shadow maps (and, when maps are drawn, a reprojection
// before them); light_ms: the light passes (and a reprojection without maps drawn).
// gpu_timer: measured by GL_TIME_ELAPSED queries (the GL's own time of each phase); false: wall
// time with glFinish() between phases (contexts without timer queries).
struct PhaseTimes {
  double depth_ms = 0, shadow_ms = 0, light_ms = 0;
  bool gpu_timer = false;
};

constexpr int kLightsPerPass = 64;
// Coarse shading pays where the light loop outweighs the interpolation test (about as costly as
// a few lights); passes with fewer lights (live mode adds one) are shaded exactly.
constexpr int kCoarseMinLights = 8;
constexpr int kShortcutLightsPerPass = 128;  // the shortcuts' program (members + merged lights)

// What the shortcuts chose at the last Render() (for the bench, the window and the log).
struct ShortcutState {
  int shadow_group = 1;         // g of the shadow-map sharing (1: none)
  double shadow_shift = 0;      // its largest shadow-edge shift (shadow texels)
  double z_min = 0, z_max = 0;  // depth range the maps see (mm, luminaire frame)
  int shadow_maps = 0;          // distinct maps in use
  int merged_lights = 0;        // merged lights in the last pass
  double z_merge = 0;           // receivers at least this deep (mm) used the merged lights
  // The last view: fraction of the pixels reprojection shaded exactly (0: not reprojected).
  double reprojected_exact = 0;
};

// One orientation of a luminaire folder (docs/method.md §4.12, "The preview of a luminaire
// folder"): its pose (x_capture = R x_luminaire + centre, w_capture = R w_luminaire) and the cone
// of directions its slab sees (core/luminaire_set.h). Its positions light the scene from
// R^T (c - centre), their directions looked up through R, each weighted per direction w
// (luminaire frame, from its origin) by t_k / sum_j t_j, t_j = ConeTaper(cone_j, R_j w) over the
// orientations with a position present (where no cone holds w, the one with the largest margin
// adds its light alone).
struct LightOrientation {
  Eigen::Matrix3d capture_from_luminaire = Eigen::Matrix3d::Identity();  // R_k
  Eigen::Vector3d centre_mm = Eigen::Vector3d::Zero();                   // centre_k
  OrientationCone cone;
};
// The largest number of orientations the light program's uniform arrays hold.
constexpr int kMaxOrientations = 32;

class Renderer {
 public:
  // `orientations` empty: one slab, whose capture frame is the luminaire frame (as before).
  // Otherwise a luminaire folder's orientations, every one a slab of `info`'s layout; light
  // k * grid.count() + p is position p of orientation k. The shortcuts (shadow-map sharing,
  // light merging) serve one slab: with several orientations they are refused (BadInput).
  Renderer(const SlabInfo& info, int width, int height, const RenderOptions& options,
           const std::vector<LightOrientation>& orientations = {});
  ~Renderer();
  Renderer(const Renderer&) = delete;
  Renderer& operator=(const Renderer&) = delete;

  void SetScene(const Mesh& mesh);
  // Luminaire frame -> scene frame (rigid).
  void SetPose(const Eigen::Isometry3d& luminaire_to_scene);
  // Clip-from-scene matrix of the camera.
  void SetCamera(const Eigen::Matrix4f& view_projection);
  void SetOptions(const RenderOptions& options);
  const RenderOptions& options() const { return options_; }
  void Resize(int width, int height);
  // Uploads E'_ij (3 channels, slab layout) of position (i, j) of `orientation`; it is added at
  // the next Render. An orientation's first position changes the others' blend weights: the
  // image is summed afresh.
  void SetPosition(int i, int j, const ImageF& intensity, int orientation = 0);
  bool HasPosition(int i, int j, int orientation = 0) const;
  int PositionCount() const;
  // Positions of every orientation (grid.count() x orientations).
  int LightCount() const { return int(present_.size()); }
  int OrientationCount() const { return int(orientations_.size()); }

  // Brings the accumulated image up to date; returns how many lights it added. Issues the frame's
  // GL work without reading anything back or waiting for it (docs/method.md §4.2, "What a frame
  // does"), unless time_phases; Read() waits for it, Finish() too (for timing frames).
  int Render();
  void Finish() const;
  // Shadow maps rendered since construction (to show they are cached).
  int ShadowMapRenders() const { return shadow_renders_; }
  // Shadow-map texels drawn so far (the scissor rectangles' areas).
  long long ShadowTexelsDrawn() const { return shadow_texels_; }
  const PhaseTimes& phase_times() const { return times_; }
  // The last light pass with tiled_lights: the lights listed per tile, as a fraction of the
  // pass's lights times the tiles (1 without tiled_lights).
  double ListedLightFraction() const;
  // Reprojection's share of pixels shaded exactly is read here (waiting for the last frame if
  // need be), not in the frame.
  const ShortcutState& shortcuts() const;
  // The accumulated image (radiance or irradiance, W/m^2 [/sr]), 3 channels, row 0 on top.
  ImageF Read() const;
  // Draws the accumulation tone-mapped (exposure factor, sRGB) into framebuffer 0.
  void Display(double exposure, int viewport_w, int viewport_h) const;

 private:
  struct Gl;  // the GL objects (renderer_gl.h)
  // One light of a pass: a position's, or a merged block's (renderer_merge.cc).
  struct LightEntry {
    Eigen::Vector2d centre, shadow_centre;
    int layer = 0, shadow_layer = 0;
    int span_begin = -1, span_count = 1;     // merged: its members' entries (shadows averaged)
    std::array<int, 4> support{0, 0, 0, 0};  // slab texels where its E' is not 0 (support_)
  };
  // One shadow map: its layer, seen from centre (a position's, or a shared map's block mean).
  struct ShadowJob {
    int layer = 0;
    int orientation = 0;  // whose capture frame the map is drawn in
    Eigen::Vector2d centre;
    int x0 = 0, y0 = 0, x1 = 0, y1 = 0;  // the map texels drawn: [x0, x1) x [y0, y1)
  };
  // How a light pass shades: every pixel exactly; coarse shading's samples, their resolve and the
  // compute pass over the pixels listed; reprojection's pass (it lists for kExactList too).
  enum class Shading { kExact, kCoarse, kResolve, kExactList, kReproject };

  // renderer.cc: the render targets at the present size; Render()'s phases.
  void AllocateTargets();
  // Clears the sums and draws the G-buffer of the present view.
  void DrawView();
  // The positions present and not yet in the accumulated image.
  std::vector<int> PositionsToAdd() const;

  // renderer_shadows.cc.
  // The map position l's light reads (its own, or with sharing its block's, in the layer
  // shadow_layer_ names): whole, or without the shortcuts its rectangle (shadow_scissor).
  ShadowJob ShadowJobFor(int l) const;
  // Draws the maps the positions `todo` read that are not valid, choosing the sharing first.
  void UpdateShadowMaps(const std::vector<int>& todo);
  // Clears and draws the maps (shadow_valid_ is the caller's).
  void RenderShadowMaps(const std::vector<ShadowJob>& jobs);
  // Shadow-map sharing: each position's map layer and centre (shadow_layer_, shadow_centre_).
  void ChooseShadowGroups();

  // renderer_merge.cc.
  // Builds and uploads the merged texture of merge block `group` and its depth bound.
  void MergedTexture(int group);
  // The light passes that add `todo` with sharing or merging on.
  void ShortcutPasses(const std::vector<int>& todo);

  // renderer_tiles.cc: the light lists of the tiles for one pass's entries (lights: their
  // PackLights, 4 floats each; near_end and far_begin as EntriesPass's), after the tiles' bounds
  // if the G-buffer changed.
  void TileLists(int lights_per_pass, const float* lights, const std::vector<LightEntry>& entries,
                 int near_end, int far_begin);

  // renderer_light.cc.
  // The light passes that add `lights` (with sharing or merging: ShortcutPasses).
  void LightPasses(const std::vector<int>& lights);
  // One pass of up to kLightsPerPass positions, each its own light and shadow map.
  void LightPass(const std::vector<int>& lights);
  static void PackLights(const std::vector<LightEntry>& entries, std::vector<float>* lights,
                         std::vector<int>* layers);
  // One light pass over `entries` (shortcuts: the shortcuts' program, whose lights
  // [0, near_end) shade receivers nearer than z_far and [far_begin, size) the others).
  void EntriesPass(const std::vector<LightEntry>& entries, bool shortcuts, int near_end,
                   int far_begin, double z_far);
  // The passes that shade `lights` lights at the present options.
  std::vector<Shading> ShadingPasses(int lights) const;
  void SetCommonUniforms(unsigned program, Shading shading);
  // The light program for the present options (shortcuts: the shortcuts'), linked when first
  // used.
  unsigned LightProgram(bool shortcuts, Shading shading = Shading::kExact);
  void DrawLightPass(Shading shading);

  // renderer_reproject.cc.
  // The view shaded in full so far becomes reprojection's source (before the G-buffer changes).
  void KeepViewAsSource();
  // After a new G-buffer: reprojects the source's sums when it may (true); otherwise the view is
  // to be shaded in full (false).
  bool TryReproject();
  void Reproject();

  // renderer_orientations.cc: a luminaire folder's orientations.
  // The orientation of light l; its position in the grid.
  int OrientationOf(int l) const { return l / info_.grid.count(); }
  int GridIndexOf(int l) const { return l % info_.grid.count(); }
  // Capture frame of orientation k from the luminaire frame, [R_k | centre_k] (a single slab:
  // the identity).
  Eigen::Matrix4f CaptureFromLuminaire(int k) const;
  // The light program's orientation uniforms for this pass's orientation (pass_orientation_).
  void SetOrientationUniforms(unsigned program) const;
  // Refuses options a luminaire folder cannot have.
  void CheckOrientationOptions(const RenderOptions& options) const;

  SlabInfo info_;
  // One entry for a single slab (identity, not posed), else the folder's orientations.
  std::vector<LightOrientation> orientations_;
  bool posed_ = false;                     // a luminaire folder: the shaders transform and blend
  std::vector<bool> orientation_present_;  // a position of it is present (it takes part in blends)
  int pass_orientation_ = 0;               // the orientation of the light pass being drawn
  int tile_bounds_orientation_ = 0;        // the frame the tiles' bounds were computed in
  int width_, height_;
  RenderOptions options_;
  Eigen::Matrix4f view_projection_ = Eigen::Matrix4f::Identity();
  Eigen::Isometry3d pose_ = Eigen::Isometry3d::Identity();
  int vertex_count_ = 0;
  std::vector<bool> present_, shadow_valid_, accumulated_;
  // Per position, the slab texels where its E' is not zero: [x0, x1) x [y0, y1) (empty: x0 >= x1);
  // per layer, the map texels its map was drawn over (ShadowJob's rectangle).
  std::vector<std::array<int, 4>> support_, shadow_rect_;
  bool view_valid_ = false;
  // Reprojection (RenderOptions::reproject_tolerance): the view drawn now and whether every pixel
  // of it was shaded (the sums can be reused); the source view, its lights; whether the next
  // view may reuse it; while Reproject() shades its list, the light passes run only that.
  Eigen::Matrix4f drawn_view_projection_ = Eigen::Matrix4f::Identity();
  Eigen::Matrix4f source_view_projection_ = Eigen::Matrix4f::Identity();
  std::vector<bool> source_lights_;
  bool view_shaded_in_full_ = false, source_valid_ = false;
  mutable bool reproject_next_ = true;  // set where reprojection's count is read (const)
  bool list_only_ = false;
  bool tile_bounds_valid_ = false;  // the tiles' bounds are of the present G-buffer
  int tile_stride_ = 0;             // uints per tile in the light lists
  int tile_list_lights_ = 0;        // the last lists' lights (near and far)
  int shadow_renders_ = 0;
  long long shadow_texels_ = 0;
  int ping_ = 0;  // sRGBE: which of the two targets holds the current sum
  PhaseTimes times_;
  // Shortcuts: CPU copies of E' (merged textures are built from them), per position the layer
  // and centre of the shadow map it uses, per merge block its texture's state and depth bound.
  std::vector<ImageF> intensity_;
  std::vector<int> shadow_layer_;
  std::vector<Eigen::Vector2d> shadow_centre_;
  bool groups_valid_ = false;
  std::vector<bool> merged_valid_;
  std::vector<double> merged_z_;  // z_G times the error bound (mm)
  int merged_group_size_ = 0;
  // mutable: shortcuts() fills in reprojected_exact when the frame that counted it is done.
  mutable ShortcutState state_;
  // Reprojection's count is being copied (Gl::reproject_fence): read it once the fence passed.
  mutable bool reproject_count_pending_ = false;
  // Reads the copied count when its fence has passed (wait: until it has), and with it whether
  // the next move may reproject from the source; false if not yet.
  bool ReadReprojectCount(bool wait) const;
  void DropReprojectCount();
  Gl* gl_;
};

// The light program's blend taper (shaders/cone_taper.glsl) at capture-frame unit directions,
// evaluated by the current GL context: for the test that pins it equal to ConeTaper.
std::vector<double> ShaderConeTaper(const OrientationCone& cone,
                                    const std::vector<Eigen::Vector3d>& w_capture,
                                    double taper_deg = kDefaultTaperDeg);

}  // namespace lumislab
