#include "study/preview_sweep.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <filesystem>
#include <regex>
#include <sstream>

#include "core/atomic_file.h"
#include "core/error.h"
#include "core/exr_io.h"
#include "core/log.h"
#include "core/slab.h"
#include "core/stop_signal.h"
#include "lib/lightfield/tone_map.h"
#include "study/stages.h"
#include "study/study.h"

namespace fs = std::filesystem;

namespace lumislab {
namespace {

std::string Num6p(double x) { return Num(x, 6); }

std::string Pct(double x) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%.3g %%", 100 * x);
  return buf;
}

// One render of the sweep: its row's labels and the preview's arguments beyond --slab, --out.
struct PreviewPoint {
  std::string scene, knob, value;
  std::vector<std::string> args;
  bool reference = false;
};

}  // namespace

std::string PreviewCsvHeader() { return "scene,knob,value,rel_l2,p95,frame_ms,wall_s"; }

std::string PreviewCsvLine(const PreviewRow& r) {
  return r.scene + "," + r.knob + "," + r.value + "," + Num6p(r.rel_l2) + "," + Num6p(r.p95) + "," +
         Num6p(r.frame_ms) + "," + Num6p(r.wall_s);
}

std::vector<PreviewRow> ReadPreviewCsv(const std::string& path) {
  std::vector<PreviewRow> rows;
  ReadCsvLines(path, PreviewCsvHeader(), 7, [&](const std::vector<std::string>& f) {
    PreviewRow r;
    r.scene = f[0], r.knob = f[1], r.value = f[2];
    r.rel_l2 = std::stod(f[3]), r.p95 = std::stod(f[4]);
    r.frame_ms = std::stod(f[5]), r.wall_s = std::stod(f[6]);
    rows.push_back(r);
  });
  return rows;
}

std::string PreviewReport(const std::vector<PreviewRow>& rows) {
  std::ostringstream s;
  for (const char* scene : {"crypt", "plane2d"}) {
    bool any = false;
    for (const PreviewRow& r : rows) any |= r.scene == scene;
    if (!any) continue;
    s << "### " << (std::string(scene) == "crypt" ? "Crypt" : "Receiver plane at 2d") << "\n\n"
      << "| knob | value | rel. L2 | p95 per pixel | OSMesa frame | wall (tool) |\n"
      << "|---|---|---|---|---|---|\n";
    for (const PreviewRow& r : rows) {
      if (r.scene != scene) continue;
      char frame[32] = "-", wall[32];
      if (r.frame_ms > 0) std::snprintf(frame, sizeof frame, "%.3g ms", r.frame_ms);
      std::snprintf(wall, sizeof wall, "%.3g s", r.wall_s);
      s << "| " << r.knob << " | " << r.value << " | " << Pct(r.rel_l2) << " | " << Pct(r.p95)
        << " | " << frame << " | " << wall << " |\n";
    }
    s << "\n";
  }
  return s.str();
}

double PixelErrorPercentile(const ImageF& image, const ImageF& reference, double q) {
  if (image.data.size() != reference.data.size() || reference.channels != 3)
    throw BadInput("images to compare differ in size or are not 3-channel");
  const size_t pixels = reference.data.size() / 3;
  std::vector<double> peak(pixels), error(pixels);
  double top = 0;
  for (size_t px = 0; px < pixels; ++px) {
    for (size_t c = 3 * px; c < 3 * px + 3; ++c) {
      peak[px] = std::max(peak[px], std::abs(double(reference.data[c])));
      error[px] = std::max(error[px], std::abs(double(image.data[c]) - reference.data[c]));
    }
    top = std::max(top, peak[px]);
  }
  // The lit pixels (above 1e-3 of the peak, as CompareImages' worst pixel) and their mean.
  std::vector<size_t> lit;
  double mean = 0;
  for (size_t px = 0; px < pixels; ++px)
    if (peak[px] > 1e-3 * top) lit.push_back(px), mean += peak[px];
  if (lit.empty()) return 0;
  const double floor = 0.1 * mean / lit.size();
  std::vector<double> relative;
  for (size_t px : lit) relative.push_back(error[px] / std::max(peak[px], floor));
  const size_t k =
      std::min(relative.size() - 1, size_t(std::floor(q * (relative.size() - 1) + 0.5)));
  std::nth_element(relative.begin(), relative.begin() + k, relative.end());
  return relative[k];
}

double PreviewFrameMs(const std::string& slab, const std::vector<std::string>& args,
                      const std::string& log, int threads) {
  std::vector<std::string> all = {"--slab", slab};
  all.insert(all.end(), args.begin(), args.end());
  all.insert(all.end(), {"--bench", "--bench-frames", "5", "--threads", std::to_string(threads)});
  WriteTextAtomically(log, "");
  RunStage("lumislab-preview", all, log);
  // "bench: 5 frames (...), median 12.3 ms = 81.3 fps"
  static const std::regex kLine(R"(bench: .* median ([0-9.eE+-]+) ms)");
  const std::string text = ReadTextFile(log);
  double ms = -1;
  for (auto it = std::sregex_iterator(text.begin(), text.end(), kLine);
       it != std::sregex_iterator(); ++it)
    ms = std::stod((*it)[1].str());
  if (!(ms >= 0)) throw Failure("lumislab-preview --bench logged no frame time; see " + log);
  return ms;
}

void RunPreviewSweep(const PreviewSweepOptions& o, std::vector<PreviewRow>* rows,
                     const std::function<void()>& save) {
  MakeDirectories(o.work);
  const SlabInfo info = SlabInfo::Load(o.slab);
  const std::string size = std::to_string(o.width) + "x" + std::to_string(o.height);
  const std::string plane_size = std::to_string(o.width) + "x" + std::to_string(o.width);
  const std::string threads = std::to_string(o.threads);
  const std::vector<std::pair<std::string, std::vector<std::string>>> scenes = {
      {"crypt", {"--scene", "crypt", "--size", size}},
      {"plane2d",
       {"--scene", "plane", "--receiver-plane", Num(2 * info.distance_mm, 8), "--size",
        plane_size}}};
  for (const auto& [scene, scene_args] : scenes) {
    // The reference every point is measured against, rendered once (kept as an EXR).
    const std::string ref =
        o.work + "/" + scene + "_reference_N" + std::to_string(o.reference_samples) + ".exr";
    const std::string log = o.work + "/log.txt";
    if (!fs::exists(ref)) {
      std::vector<std::string> args = {"--slab",
                                       o.slab,
                                       "--out",
                                       ref,
                                       "--reference",
                                       "--samples",
                                       std::to_string(o.reference_samples),
                                       "--threads",
                                       threads};
      args.insert(args.end(), scene_args.begin(), scene_args.end());
      RunStage("lumislab-preview", args, log);
    }
    const ImageF reference = ReadExr(ref, {"R", "G", "B"});

    std::vector<PreviewPoint> points;
    for (int n : o.samples)
      points.push_back({scene,
                        "ref_samples",
                        std::to_string(n),
                        {"--reference", "--samples", std::to_string(n)},
                        true});
    points.push_back({scene, "opengl", "base (shadows 512; float)", {}, false});
    if (scene == "crypt") {
      for (int s : o.shadow_sizes)
        points.push_back(
            {scene, "shadow_size", std::to_string(s), {"--shadow-size", std::to_string(s)}, false});
      points.push_back({scene, "pcf", "on (512)", {"--shadow-pcf"}, false});
      // Without shadows the preview merges 2 x 2 positions by default; this row is the full
      // per-position render without shadows, the merge has its own rows.
      points.push_back({scene, "shadows", "off", {"--no-shadows", "--merge-group", "1"}, false});
      // The faster-frames shortcuts (docs/method.md §4.2): shadow maps shared within 1 shadow texel
      // of edge shift, and 2 x 2 positions merged for receivers beyond the depth of a 5 % bound,
      // with and without shadows.
      points.push_back({scene, "shadow_share", "1 texel", {"--shadow-share", "1"}, false});
      points.push_back(
          {scene, "merge", "2x2 at 5 %", {"--merge-group", "2", "--merge-error", "0.05"}, false});
      points.push_back({scene,
                        "merge",
                        "2x2 at 5 %; no shadows",
                        {"--no-shadows", "--merge-group", "2", "--merge-error", "0.05"},
                        false});
    }
    points.push_back({scene, "srgbe", "on", {"--srgbe"}, false});
    for (const char* filter : {"nearest", "cubic"})
      points.push_back({scene, "texture_filter", filter, {"--texture-filter", filter}, false});

    for (const PreviewPoint& p : points) {
      const bool done = std::any_of(rows->begin(), rows->end(), [&](const PreviewRow& r) {
        return r.scene == p.scene && r.knob == p.knob && r.value == p.value;
      });
      if (done) continue;
      if (StopRequested()) throw Failure("stopped by a signal; run again to continue");
      std::string name = p.scene + "_" + p.knob + "_" + p.value;
      for (char& c : name)
        if (!std::isalnum(static_cast<unsigned char>(c))) c = '_';
      const std::string image_path = o.work + "/" + name + ".exr";
      std::vector<std::string> args = {"--slab", o.slab, "--out", image_path, "--threads", threads};
      args.insert(args.end(), scene_args.begin(), scene_args.end());
      args.insert(args.end(), p.args.begin(), p.args.end());
      PreviewRow row{p.scene, p.knob, p.value};
      if (p.reference || p.scene != "crypt") {
        // The plane's view does not move, so the preview has no frame to time there.
        row.wall_s = RunStage("lumislab-preview", args, log);
      } else {
        // One process: the image, then the frame time of 5 frames with the camera moving.
        const std::string bench_log = o.work + "/" + name + ".log";
        const auto start = std::chrono::steady_clock::now();
        args.erase(args.begin(), args.begin() + 2);  // PreviewFrameMs adds --slab
        args.erase(std::find(args.begin(), args.end(), "--threads"),
                   std::find(args.begin(), args.end(), "--threads") + 2);
        row.frame_ms = PreviewFrameMs(o.slab, args, bench_log, o.threads);
        row.wall_s =
            std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
      }
      const ImageF image = ReadExr(image_path, {"R", "G", "B"});
      row.rel_l2 = CompareImages(image, reference).relative_l2;
      row.p95 = PixelErrorPercentile(image, reference, 0.95);
      if (!std::isfinite(row.rel_l2) || !std::isfinite(row.p95))
        throw Failure("preview " + p.scene + " " + p.knob + " = " + p.value +
                      ": a non-finite error");
      rows->push_back(row);
      save();
    }
  }
}

}  // namespace lumislab
