// reference_table: the exact CPU reference (docs/method.md §4.5) of the built-in synthetic
// luminaire's truth slab (9 x 7, h = 5 mm, d = 750 mm, 300 texels) against the analytic image of
// its emitters, per samples per basis support N: the receiver plane at D = d, 2d and 4d (64 x 64
// pixels over the window's cone; error over the pixels the grid covers, GridCovers) and the crypt
// (160 x 120; error over every pixel: its far walls lie outside the window's cone and the
// grid's coverage, which no N repairs). Columns: time (median of `runs`), relative L2 against
// the analytic image and against the same view at N = 16 (both over those pixels; on the plane
// the pixels near the window's edge, where a support's rays land on both sides of it, converge
// slowest), and the 95th percentile of the per-pixel error against N = 16 (every pixel)
// relative to the view's 99th-percentile value.
// Usage: reference_table [threads (0: all cores)] [runs] [csv path]
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <functional>
#include <string>
#include <vector>

#include "core/parallel.h"
#include "lib/lightfield/reference_render.h"
#include "lib/synthetic/scene.h"
#include "lib/synthetic/truth.h"

namespace lumislab {
namespace {

double RelativeL2(const ImageF& a, const ImageF& b, const std::vector<bool>& use) {
  double num = 0, den = 0;
  for (size_t p = 0; p < use.size(); ++p) {
    if (!use[p]) continue;
    for (int c = 0; c < 3; ++c) {
      const double d = double(a.data[3 * p + c]) - b.data[3 * p + c];
      num += d * d;
      den += double(b.data[3 * p + c]) * b.data[3 * p + c];
    }
  }
  return den > 0 ? std::sqrt(num / den) : 0.0;
}

// 95th percentile of max-channel |a - b| over the pixels, relative to b's 99th percentile.
double P95(const ImageF& a, const ImageF& b) {
  std::vector<double> err, level;
  for (size_t p = 0; 3 * p < b.data.size(); ++p) {
    double e = 0, l = 0;
    for (int c = 0; c < 3; ++c) {
      e = std::max(e, std::abs(double(a.data[3 * p + c]) - b.data[3 * p + c]));
      l = std::max(l, double(b.data[3 * p + c]));
    }
    err.push_back(e);
    level.push_back(l);
  }
  auto percentile = [](std::vector<double> v, double q) {
    std::sort(v.begin(), v.end());
    return v[size_t(q * (v.size() - 1))];
  };
  const double scale = percentile(level, 0.99);
  return scale > 0 ? percentile(err, 0.95) / scale : 0.0;
}

int Main(int argc, char** argv) {
  const int threads = ResolveThreads(argc > 1 ? std::atoi(argv[1]) : 0);
  const int runs = argc > 2 ? std::max(1, std::atoi(argv[2])) : 1;
  const std::string csv_path = argc > 3 ? argv[3] : "reference_table.csv";
  const SynthScene scene = DefaultScene();
  const SlabInfo info = TruthSlabInfo(scene, 300);
  std::vector<ImageF> irradiance(size_t(info.grid.count()));
  ParallelFor(info.grid.count(), threads, [&](int k) {
    irradiance[k] =
        TruthPosition(scene.luminaire, info, k % info.grid.nu, k / info.grid.nu).irradiance;
  });
  std::vector<PointSource> sources;
  for (const Emitter& e : scene.luminaire.emitters)
    sources.push_back({e.position_mm, [e](const Eigen::Vector3d& w) { return e.Intensity(w); }});

  std::ofstream csv(csv_path);
  csv << "view,N,seconds,l2_vs_analytic,l2_vs_N16,p95_vs_N16\n";
  std::printf("%d threads, median of %d runs\n\n", threads, runs);
  std::printf("| view | N | time (s) | vs analytic (L2) | vs N = 16 (L2) | vs N = 16 (p95) |\n");
  std::printf("|---|---|---|---|---|---|\n");
  struct View {
    std::string name;
    SceneRequest request;
    int width, height;
    bool covered_only;
  };
  std::vector<View> views;
  for (double factor : {1.0, 2.0, 4.0}) {
    SceneRequest r;
    r.name = "plane";
    r.receiver_plane_mm = factor * info.distance_mm;
    // 1.1 x the window's cone: pixel centres not commensurate with the texels and the grid (a
    // symmetric set-up puts texel edges on the strata's boundaries, where every even N is exact).
    r.extent_mm = 1.1 * info.layout.window_w_mm * factor;
    views.push_back({"plane D = " + std::to_string(int(factor)) + "d", r, 64, 64, true});
  }
  SceneRequest crypt;
  crypt.name = "crypt";
  views.push_back({"crypt", crypt, 160, 120, false});
  for (const View& v : views) {
    const ReferenceScene view(MakeSceneSetup(v.request, info), v.width, v.height);
    std::vector<bool> use(size_t(view.width()) * view.height(), true);
    if (v.covered_only)
      for (int y = 0; y < view.height(); ++y)
        for (int x = 0; x < view.width(); ++x) {
          const SurfacePoint p = view.Primary(x, y);
          use[size_t(y) * view.width() + x] = p.hit && GridCovers(scene.luminaire, info, p.x);
        }
    ReferenceOptions options;
    options.threads = threads;
    options.progress = false;
    const ImageF analytic = RenderPointSources(view, sources, options).image;
    options.samples = 16;
    const ImageF best = RenderReference(view, info, irradiance, options).image;
    for (int n : {1, 2, 4, 8, 16}) {
      options.samples = n;
      std::vector<double> seconds;
      ImageF image;
      for (int run = 0; run < runs; ++run) {
        const auto start = std::chrono::steady_clock::now();
        image = RenderReference(view, info, irradiance, options).image;
        seconds.push_back(
            std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count());
      }
      std::sort(seconds.begin(), seconds.end());
      const double t = seconds[seconds.size() / 2];
      const double l2_analytic = RelativeL2(image, analytic, use);
      const double l2_best = RelativeL2(image, best, use), p95 = P95(image, best);
      std::printf("| %s | %d | %.3f | %.3g | %.3g | %.3g |\n", v.name.c_str(), n, t, l2_analytic,
                  l2_best, p95);
      csv << v.name << "," << n << "," << t << "," << l2_analytic << "," << l2_best << "," << p95
          << "\n";
    }
  }
  std::printf("\nCSV: %s\n", csv_path.c_str());
  return 0;
}

}  // namespace
}  // namespace lumislab

int main(int argc, char** argv) { return lumislab::Main(argc, argv); }
