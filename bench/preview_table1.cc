// The paper's Table 1 (Granier et al. 2003) redone on this machine through OSMesa (or a GPU
// through EGL: --backend egl) at 400x400 (--size WxH):
// crypt and cloister; 5x5, 7x7 and 9x7 slabs at 300x300; with and without shadows. Reports the
// median fps of frames with a moving camera (shadow maps cached: what the window does while
// orbiting) and of full frames that also re-render every shadow map (what the paper did each
// frame), next to the paper's figures; plus the time to add one new position in live mode.
#include <CLI/CLI.hpp>
#include <algorithm>
#include <chrono>
#include <cstdio>
#include <fstream>

#include "core/error.h"
#include "core/log.h"
#include "lib/lightfield/light_field.h"
#include "lib/lightfield/scene_setup.h"
#include "lib/lightfield/tone_map.h"
#include "lib/synthetic/truth.h"
#include "preview/cli.h"
#include "preview/gl_context.h"
#include "preview/renderer.h"

namespace lumislab {
namespace {

using Clock = std::chrono::steady_clock;

double Seconds(Clock::time_point start) {
  return std::chrono::duration<double>(Clock::now() - start).count();
}

double Median(std::vector<double> v) {
  std::sort(v.begin(), v.end());
  return v[v.size() / 2];
}

struct Slab {
  SlabInfo info;
  std::vector<ImageF> intensity;  // grid index order
};

Slab MakeSlab(int nu, int nv) {
  Slab slab{DefaultSlabInfo(nu, nv, 5, 300), {}};
  const Luminaire luminaire = DefaultScene().luminaire;
  for (int j = 0; j < nv; ++j) {
    for (int i = 0; i < nu; ++i) {
      slab.intensity.push_back(IntensityFromIrradiance(
          slab.info, i, j, TruthPosition(luminaire, slab.info, i, j).irradiance));
    }
  }
  return slab;
}

void UploadAll(const Slab& slab, Renderer& r) {
  for (int j = 0; j < slab.info.grid.nv; ++j) {
    for (int i = 0; i < slab.info.grid.nu; ++i) {
      r.SetPosition(i, j, slab.intensity[slab.info.grid.Index(i, j)]);
    }
  }
}

int Run(int argc, char** argv) {
  int frames = 7, shadow_size = 512;
  std::string csv = "preview_table1.csv", size_text = "400x400", backend = "osmesa";
  bool quick = false, profile = false, no_cull = false;
  RenderOptions fast;  // the shortcuts' settings of the "on" columns (defaults: the tool's)
  fast.shadow_share_texels = 0;
  fast.merge_group = 0;  // auto, as lumislab-preview: 2 without shadows, off with them
  fast.merge_error = 0.05;
  fast.coarse_tolerance = -1;  // auto, as lumislab-preview: 0.1 with shadows, off without
  fast.reproject_tolerance = 0.1;
  CLI::App app{"preview_table1: the paper's Table 1 through OSMesa or EGL (docs/testing.md)"};
  app.add_option("--frames", frames, "frames per cell (median)")->capture_default_str();
  app.add_option("--size", size_text, "image size WxH (or one side N: N x N)")
      ->capture_default_str();
  app.add_option("--backend", backend,
                 "osmesa (llvmpipe) or egl (a GPU; exit 1 where EGL finds none, as "
                 "lumislab-preview --backend egl)")
      ->check(CLI::IsMember({"osmesa", "egl"}))
      ->capture_default_str();
  app.add_option("--shadow-size", shadow_size, "shadow-map side")->capture_default_str();
  app.add_option("--csv", csv, "CSV output")->capture_default_str();
  app.add_flag("--quick", quick, "only crypt 5x5 and cloister 9x7 with shadows, no live");
  app.add_flag("--profile", profile,
               "time the phases of each frame (GL_TIME_ELAPSED queries where the context has "
               "them, else glFinish between phases; the output says which)");
  app.add_option("--shadow-share", fast.shadow_share_texels,
                 "on columns: shadow-map sharing, largest edge shift in shadow texels (0: off)")
      ->capture_default_str();
  app.add_option("--merge-group", fast.merge_group,
                 "on columns: merged block side (1: off; 0: auto, 2 without shadows)")
      ->capture_default_str();
  app.add_option("--merge-error", fast.merge_error, "on columns: merged lights' error bound")
      ->capture_default_str();
  app.add_option("--coarse-shading", fast.coarse_tolerance,
                 "on columns: coarse shading's tolerance (0: off; < 0: auto, 0.1 with shadows)")
      ->capture_default_str();
  app.add_option("--reproject", fast.reproject_tolerance,
                 "on columns: reprojection's tolerance after camera moves (0: off)")
      ->capture_default_str();
  app.add_flag("--no-shadow-cull", no_cull,
               "on columns: every face in the shadow maps (default: only those turned to the "
               "light, as lumislab-preview in a closed room)");
  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    const int code = app.exit(e);
    return code == 0 ? 0 : static_cast<int>(ExitCode::kBadInput);
  }
  SetLogTool("preview_table1");
  int width = 0, height = 0;
  const std::string size_wxh =
      size_text.find('x') == std::string::npos ? size_text + "x" + size_text : size_text;
  if (!ParseSize(size_wxh, &width, &height))
    throw InputError("--size", "size", "WxH, each 1..8192, e.g. 1920x1080", size_text);
  const double aspect = double(width) / height;
  const HeadlessContext context(backend == "egl");
  std::printf("backend %s, renderer: %s, %dx%d, shadow maps %d^2, median of %d frames\n",
              backend.c_str(), context.Renderer().c_str(), width, height, shadow_size, frames);
  struct Paper {
    int nu, nv;
    double crypt, crypt_ns, cloister, cloister_ns;
  };
  const Paper paper[] = {
      {5, 5, 2.7, 3.2, 1.3, 1.6}, {7, 7, 1.5, 1.7, 0.7, 0.85}, {9, 7, 1.2, 1.4, 0.55, 0.7}};
  std::ofstream out(csv);
  std::printf(
      "shortcuts on: --shadow-share %g --merge-group %d --merge-error %g --coarse-shading %g "
      "--reproject %g%s\n",
      fast.shadow_share_texels, fast.merge_group, fast.merge_error, fast.coarse_tolerance,
      fast.reproject_tolerance, no_cull ? " --no-shadow-cull" : "");
  out << "scene,triangles,grid,shadows,paper_fps,fps_cached_off,fps_full_off,fps_cached_on,"
         "fps_full_on,ratio_cached_off,ratio_full_off,ratio_cached_on,ratio_full_on,"
         "rel_l2_on_vs_off,rel_l2_moved,shadow_group,shadow_shift_texels,merged_lights,z_merge_mm,"
         "reprojected_exact\n";
  std::printf("%-9s %5s %-5s %-4s %6s %13s %13s | %11s %11s | %8s %8s %3s %6s %3s %7s %5s\n", "",
              "", "", "", "", "--- off ---", "--- on ----", "ratio off", "ratio on", "on vs",
              "on vs", "sha", "shift", "mrg", "z merge", "repr");
  std::printf(
      "%-9s %5s %-5s %-4s %6s %6s %6s %6s %6s | %5s %5s %5s %5s | %8s %8s %3s %6s %3s %7s %5s\n",
      "scene", "tris", "grid", "shad", "paper", "camera", "full", "camera", "full", "cam", "full",
      "cam", "full", "off L2", "moved", "g", "texel", "n", "mm", "exact");
  for (const std::string scene : {"crypt", "cloister"}) {
    SceneRequest request;
    request.name = scene;
    for (const Paper& p : paper) {
      const Slab slab = MakeSlab(p.nu, p.nv);
      SceneSetup setup = MakeSceneSetup(request, slab.info);
      if (quick &&
          !((scene == "crypt" && p.nu == 5) || (scene == "cloister" && p.nv == 7 && p.nu == 9))) {
        continue;
      }
      for (bool shadows : {true, false}) {
        if (quick && !shadows) continue;
        // Two renderers: "off" is the full per-position render, "on" has the shortcuts. Their
        // frames alternate, so both see the same load on a shared machine.
        RenderOptions options;
        options.shadows = shadows;
        options.shadow_size = shadow_size;
        options.cull_back_faces = setup.closed_room;
        options.time_phases = profile;
        RenderOptions options_on = options;
        options_on.shadow_share_texels = fast.shadow_share_texels;
        options_on.merge_group = fast.merge_group > 0 ? fast.merge_group : (shadows ? 1 : 2);
        options_on.merge_error = fast.merge_error;
        options_on.coarse_tolerance =
            fast.coarse_tolerance >= 0 ? fast.coarse_tolerance : (shadows ? 0.1 : 0);
        options_on.reproject_tolerance = fast.reproject_tolerance;
        options_on.shadow_cull = setup.closed_room && !no_cull;  // as lumislab-preview
        Renderer off(slab.info, width, height, options), on(slab.info, width, height, options_on);
        for (Renderer* r : {&off, &on}) {
          r->SetScene(setup.mesh);
          r->SetPose(setup.pose);
          UploadAll(slab, *r);
          r->SetCamera(OrbitCamera(setup, aspect));
          r->Render();  // warm-up: shaders, shadow maps
        }
        const ImageDifference error = CompareImages(on.Read(), off.Read());

        struct Times {
          std::vector<double> cached, full, c_depth, c_light, f_shadow, f_light;
        } times[2];
        SceneSetup moving = setup;
        for (int f = 0; f < frames; ++f) {
          for (int k = 0; k < 2; ++k) {
            Renderer& r = k == 0 ? off : on;
            // Each frame a new view, 2 degrees on; the same views for both renderers.
            const double step = 2.0 * (2 * f + 1);
            moving.camera_yaw_deg = setup.camera_yaw_deg + step;
            r.SetCamera(OrbitCamera(moving, aspect));
            auto start = Clock::now();
            r.Render();
            r.Finish();
            times[k].cached.push_back(Seconds(start));
            times[k].c_depth.push_back(r.phase_times().depth_ms);
            times[k].c_light.push_back(r.phase_times().light_ms);
            moving.camera_yaw_deg = setup.camera_yaw_deg + step + 2;
            r.SetCamera(OrbitCamera(moving, aspect));
            r.SetPose(setup.pose);  // invalidates every shadow map, as a pose change does
            start = Clock::now();
            r.Render();
            r.Finish();
            times[k].full.push_back(Seconds(start));
            times[k].f_shadow.push_back(r.phase_times().shadow_ms);
            times[k].f_light.push_back(r.phase_times().light_ms);
          }
        }
        // The image after camera moves: three more views, 2 degrees apart, after the last full
        // frame (what reprojection reuses), each compared on against off; the largest error.
        double move_error = 0;
        for (int m = 1; m <= 3; ++m) {
          moving.camera_yaw_deg = setup.camera_yaw_deg + 2.0 * (2 * frames) + 2.0 * m;
          for (Renderer* r : {&off, &on}) {
            r->SetCamera(OrbitCamera(moving, aspect));
            r->Render();
          }
          move_error = std::max(move_error, CompareImages(on.Read(), off.Read()).relative_l2);
        }
        if (profile) {
          std::printf(
              "  on: depth range of the maps %.0f .. %.0f mm; tiles list %.0f %% of the lights\n",
              on.shortcuts().z_min, on.shortcuts().z_max, 100 * on.ListedLightFraction());
          for (int k = 0; k < 2; ++k) {
            std::printf(
                "  %s phases (ms, %s): camera move: G-buffer %.2f light %.2f; full: shadow maps "
                "%.2f light %.2f\n",
                k ? "on " : "off",
                (k ? on : off).phase_times().gpu_timer ? "GL_TIME_ELAPSED queries"
                                                       : "wall time, glFinish between phases",
                Median(times[k].c_depth), Median(times[k].c_light), Median(times[k].f_shadow),
                Median(times[k].f_light));
          }
        }
        const ShortcutState& state = on.shortcuts();
        const double paper_fps = scene == "crypt" ? (shadows ? p.crypt : p.crypt_ns)
                                                  : (shadows ? p.cloister : p.cloister_ns);
        double fps[2][2];
        for (int k = 0; k < 2; ++k) {
          fps[k][0] = 1 / Median(times[k].cached);
          fps[k][1] = 1 / Median(times[k].full);
        }
        char grid[16];
        std::snprintf(grid, sizeof(grid), "%dx%d", p.nu, p.nv);
        std::printf(
            "%-9s %5zu %-5s %-4s %6.2f %6.2f %6.2f %6.2f %6.2f | %5.1f %5.1f %5.1f %5.1f | "
            "%8.2e %8.2e %3d %6.2f %3d %7.0f %4.1f%%\n",
            scene.c_str(), setup.mesh.triangles(), grid, shadows ? "yes" : "no", paper_fps,
            fps[0][0], fps[0][1], fps[1][0], fps[1][1], fps[0][0] / paper_fps,
            fps[0][1] / paper_fps, fps[1][0] / paper_fps, fps[1][1] / paper_fps, error.relative_l2,
            move_error, state.shadow_group, state.shadow_shift, state.merged_lights, state.z_merge,
            100 * state.reprojected_exact);
        std::fflush(stdout);
        out << scene << ',' << setup.mesh.triangles() << ',' << grid << ','
            << (shadows ? "yes" : "no") << ',' << paper_fps << ',' << fps[0][0] << ',' << fps[0][1]
            << ',' << fps[1][0] << ',' << fps[1][1] << ',' << fps[0][0] / paper_fps << ','
            << fps[0][1] / paper_fps << ',' << fps[1][0] / paper_fps << ',' << fps[1][1] / paper_fps
            << ',' << error.relative_l2 << ',' << move_error << ',' << state.shadow_group << ','
            << state.shadow_shift << ',' << state.merged_lights << ',' << state.z_merge << ','
            << state.reprojected_exact << '\n';
      }
    }
  }
  // Live mode: positions arrive one at a time (crypt, 9x7, shadows); each Render adds exactly the
  // new light (its shadow map and one light pass) to the accumulated image.
  if (!quick) {
    const Slab slab = MakeSlab(9, 7);
    const SceneSetup setup = MakeSceneSetup("crypt", slab.info);
    RenderOptions options;
    options.shadow_size = shadow_size;
    Renderer r(slab.info, width, height, options);
    r.SetScene(setup.mesh);
    r.SetPose(setup.pose);
    r.SetCamera(OrbitCamera(setup, aspect));
    r.Render();
    std::vector<double> upload, add;
    const Luminaire luminaire = DefaultScene().luminaire;
    for (int j = 0; j < 7; ++j) {
      for (int i = 0; i < 9; ++i) {
        const SlabPosition pos = TruthPosition(luminaire, slab.info, i, j);
        auto start = Clock::now();
        r.SetPosition(i, j, IntensityFromIrradiance(slab.info, i, j, pos.irradiance));
        upload.push_back(Seconds(start));
        start = Clock::now();
        if (r.Render() != 1) throw Failure("live mode added more than the new position");
        r.Finish();
        add.push_back(Seconds(start));
      }
    }
    std::printf(
        "live (crypt, 9x7, shadows): add one position: E' + upload %.1f ms, shadow map + light "
        "pass %.1f ms (median of 63)\n",
        1000 * Median(upload), 1000 * Median(add));
    out << "live_add_one_position_ms," << 1000 * (Median(upload) + Median(add)) << '\n';
  }
  return 0;
}

}  // namespace
}  // namespace lumislab

int main(int argc, char** argv) {
  return lumislab::RunMain("preview_table1", [&] { return lumislab::Run(argc, argv); });
}
