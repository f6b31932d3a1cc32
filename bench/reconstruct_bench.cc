// reconstruct_bench: how much the reconstruction costs on top of merely decoding the photos.
// Per position, N runs (median): decode only, then the full per-position reconstruction
// (decode, merge + remap + area average, fit, EXR write). Prints a table and the ratio
// reconstruct / decode (target <= 1.25: the stage should be decode-bound), writes CSV. Then the
// same for camera photos of 6000 x 4000 with 3 exposures per slide, as JPEG, 16-bit TIFF and DNG
// (bench/camera_dataset.h): decode, full time per position and their ratio per format, in wall
// time and in process CPU time (robust to other processes sharing the cores).
// Single-threaded by default (--threads 1); never asserted in tests.
#include <CLI/CLI.hpp>
#include <algorithm>
#include <chrono>
#include <cstdio>
#include <ctime>
#include <filesystem>
#include <fstream>
#include <opencv2/core.hpp>

#include "camera_dataset.h"
#include "core/atomic_file.h"
#include "core/error.h"
#include "core/exr_io.h"
#include "reconstruct/reconstructor.h"
#include "synthetic_dataset.h"

namespace lumislab {
namespace {

double Median(std::vector<double> v) {
  std::sort(v.begin(), v.end());
  return v.empty() ? 0 : v[v.size() / 2];
}

double Seconds(std::chrono::steady_clock::time_point t0) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
}

// CPU time of the whole process (user + system, all threads), seconds: unlike wall time, not
// inflated while other processes hold the cores (on a shared machine wall times vary widely).
double ProcessCpuSeconds() {
  timespec t{};
  clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &t);
  return double(t.tv_sec) + 1e-9 * double(t.tv_nsec);
}

struct Row {
  int i = 0, j = 0;
  double decode = 0, rec_decode = 0, map = 0, merge = 0, remap = 0, fit = 0, write = 0, total = 0;
  double decode_cpu = 0, total_cpu = 0;  // process CPU time of decode only and of the full run
  int k = 0, f = 1, iterations = 0;
};

// Per position, `runs` times: decode only, then the full reconstruction with the EXR write.
std::vector<Row> Measure(const Dataset& dataset, const ScreenCalibration& calibration,
                         const SlabInfo& info, const ReconstructOptions& options,
                         const std::string& slab_dir, int runs, int positions) {
  std::vector<Row> rows;
  for (int j = 0; j < dataset.grid.nv; ++j)
    for (int i = 0; i < dataset.grid.nu; ++i) {
      if (positions > 0 && int(rows.size()) >= positions) break;
      std::vector<double> decode, rec_decode, map, merge, remap, fit, write, total, decode_cpu,
          total_cpu;
      Row row;
      row.i = i, row.j = j;
      for (int r = 0; r < runs; ++r) {
        auto t0 = std::chrono::steady_clock::now();
        double c0 = ProcessCpuSeconds();
        { const auto photos = DecodePosition(dataset, calibration, i, j); }
        decode.push_back(Seconds(t0));
        decode_cpu.push_back(ProcessCpuSeconds() - c0);
        t0 = std::chrono::steady_clock::now();
        c0 = ProcessCpuSeconds();
        PositionReport report;
        const SlabPosition p =
            ReconstructPosition(dataset, calibration, info, i, j, options, &report);
        const auto tw = std::chrono::steady_clock::now();
        WriteSlabPosition(slab_dir, info, p);
        write.push_back(Seconds(tw));
        total.push_back(Seconds(t0));
        total_cpu.push_back(ProcessCpuSeconds() - c0);
        rec_decode.push_back(report.decode_s);
        map.push_back(report.map_s);
        merge.push_back(report.merge_s);
        remap.push_back(report.remap_s);
        fit.push_back(report.fit_s);
        row.k = report.samples_per_texel;
        row.f = report.downsample;
        row.iterations = report.fit_iterations;
      }
      row.decode = Median(decode), row.rec_decode = Median(rec_decode);
      row.map = Median(map), row.merge = Median(merge), row.remap = Median(remap);
      row.fit = Median(fit);
      row.write = Median(write);
      row.total = Median(total);
      row.decode_cpu = Median(decode_cpu), row.total_cpu = Median(total_cpu);
      rows.push_back(row);
    }

  return rows;
}

// Decode vs full time per position for camera photos of each format (one position, brackets).
void CameraFormats(const std::string& out_dir, int width, int height, int runs, int resolution,
                   const std::string& formats) {
  std::printf("\ncamera photos: %dx%d, 3 exposures per slide (6 photos per position), slab %d^2\n",
              width, height, resolution);
  std::printf("%-12s %10s %10s %10s %10s %7s | %10s %10s %7s %4s\n", "format", "MB/photo", "decode",
              "merge", "full", "ratio", "cpu decode", "cpu full", "ratio", "F");
  for (const auto format :
       {bench::CameraFormat::kJpeg, bench::CameraFormat::kTiff16, bench::CameraFormat::kDng}) {
    const char* key = format == bench::CameraFormat::kJpeg     ? "jpeg"
                      : format == bench::CameraFormat::kTiff16 ? "tiff"
                                                               : "dng";
    if (formats.find(key) == std::string::npos) continue;
    const std::string dir = out_dir + "/camera";
    bench::MakeCameraDataset(dir, format, width, height);
    const Dataset dataset = Dataset::Load(dir);
    const ScreenCalibration calibration = ScreenCalibration::Load(dir + "/calib/screen.json");
    const SlabInfo info = SlabInfo::FromDataset(dataset, resolution);
    ReconstructOptions options;
    options.resolution = resolution;
    const std::string slab_dir = out_dir + "/camera_slab";
    MakeDirectories(slab_dir);
    const Row r = Measure(dataset, calibration, info, options, slab_dir, runs, 1).at(0);
    const double mb =
        double(std::filesystem::file_size(dataset.Path(dataset.photos[0].file))) / (1 << 20);
    std::printf("%-12s %10.1f %10.1f %10.1f %10.1f %7.3f | %10.1f %10.1f %7.3f %4d\n",
                bench::CameraFormatName(format), mb, 1e3 * r.decode, 1e3 * r.merge, 1e3 * r.total,
                r.total / r.decode, 1e3 * r.decode_cpu, 1e3 * r.total_cpu,
                r.total_cpu / r.decode_cpu, r.f);
    std::printf(
        "%-12s full's stages (wall ms): decode %.1f, map %.1f, merge %.1f, remap %.1f, "
        "fit %.1f, write %.1f\n",
        "", 1e3 * r.rec_decode, 1e3 * r.map, 1e3 * r.merge, 1e3 * r.remap, 1e3 * r.fit,
        1e3 * r.write);
    std::filesystem::remove_all(dir);
    std::filesystem::remove_all(slab_dir);
  }
  std::printf(
      "(ms, medians; decode = decoding the position's 6 photos only (DecodePosition); full = "
      "the whole position from the files (ReconstructPosition: the same decode, then merge, "
      "rectify, fit) plus the EXR write; both single-threaded with --threads 1, wall clock, "
      "and the process's CPU time (user + system), which other processes on the machine do "
      "not inflate; target full / decode <= 1.25)\n");
}

int RunBench(int argc, char** argv) {
  std::string dataset_dir, out_dir = "/tmp/lumislab_reconstruct_bench", csv;
  int runs = 5, threads = 1, resolution = 300, positions = 0, image_px = 2000;
  CLI::App app{"reconstruct_bench: decode time vs full per-position reconstruction time"};
  app.add_option("--dataset", dataset_dir,
                 "dataset folder with calib/screen.json (default: make a synthetic 2x2 one)");
  app.add_option("--out", out_dir, "scratch folder (slab written here)")->capture_default_str();
  app.add_option("--csv", csv, "CSV output (default: <out>/reconstruct_bench.csv)");
  app.add_option("--runs", runs, "runs per position (median)")->capture_default_str();
  app.add_option("--threads", threads, "OpenCV threads")->capture_default_str();
  app.add_option("--resolution", resolution, "slab resolution")->capture_default_str();
  app.add_option("--positions", positions, "only the first N positions (0: all)");
  app.add_option("--image-px", image_px, "synthetic dataset: photo size (square, 16-bit PNG)")
      ->capture_default_str();
  int camera_w = 6000, camera_h = 4000;
  bool no_camera = false;
  std::string formats = "jpeg,tiff,dng";
  app.add_option("--formats", formats, "camera photos: which formats (jpeg, tiff, dng)")
      ->capture_default_str();
  app.add_option("--camera-width", camera_w, "camera photos: width")->capture_default_str();
  app.add_option("--camera-height", camera_h, "camera photos: height")->capture_default_str();
  app.add_flag("--no-camera", no_camera, "skip the JPEG / TIFF / DNG camera photo table");
  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    return app.exit(e) == 0 ? 0 : 2;
  }
  if (runs < 1 || threads < 1) throw BadInput("--runs and --threads: expected >= 1");
  if (camera_w < 64 || camera_h < 64 || camera_w > 20000 || camera_h > 20000 || camera_w % 2 ||
      camera_h % 2)
    throw BadInput("--camera-width, --camera-height: expected even sizes in [64, 20000]");
  cv::setNumThreads(threads);
  MakeDirectories(out_dir);
  if (dataset_dir.empty()) {
    dataset_dir = out_dir + "/dataset";
    std::filesystem::remove_all(dataset_dir);
    testing::SyntheticOptions o;
    o.nu = o.nv = 2;
    o.screen_mm = 1200;
    o.image_px = image_px;
    o.px_per_mm = 0.9 * image_px / 1200.0;
    o.perspective = 0.0002;
    o.ext = ".png";
    std::printf("making a synthetic dataset in %s (%dx%d 16-bit PNG)\n", dataset_dir.c_str(),
                image_px, image_px);
    testing::MakeSyntheticDataset(dataset_dir, o);
  }
  if (csv.empty()) csv = out_dir + "/reconstruct_bench.csv";
  const Dataset dataset = Dataset::Load(dataset_dir);
  const ScreenCalibration calibration = ScreenCalibration::Load(dataset_dir + "/calib/screen.json");
  const SlabInfo info = SlabInfo::FromDataset(dataset, resolution);
  const std::string slab_dir = out_dir + "/slab";
  MakeDirectories(slab_dir);
  ReconstructOptions options;
  options.resolution = resolution;
  options.Check();

  const std::vector<Row> rows =
      Measure(dataset, calibration, info, options, slab_dir, runs, positions);
  std::printf(
      "\nreconstruct_bench: %s, %dx%d photos, slab %d^2, %d run(s) per position (median), "
      "%d thread(s)\n",
      dataset_dir.c_str(), calibration.image_width, calibration.image_height, resolution, runs,
      threads);
  std::printf("%-8s %9s | %9s %7s %7s %7s %7s %7s %9s | %6s %3s %2s %3s\n", "position", "decode",
              "decode", "map", "merge", "remap", "fit", "write", "total", "ratio", "K", "F", "CG");
  std::string csv_text =
      "i,j,decode_only_ms,decode_ms,map_ms,merge_ms,remap_area_ms,fit_ms,write_ms,total_ms,"
      "ratio,samples_per_texel,downsample,cg_iterations\n";
  std::vector<double> ratios, stage_ratios, decodes, totals;
  for (const Row& r : rows) {
    const double ratio = r.total / r.decode;
    ratios.push_back(ratio);
    // Less sensitive to run-to-run decode jitter (+-10 % here): decode plus the other stages.
    stage_ratios.push_back(1 + (r.map + r.merge + r.remap + r.fit + r.write) / r.decode);
    decodes.push_back(r.decode);
    totals.push_back(r.total);
    std::printf("%3d,%-4d %9.1f | %9.1f %7.1f %7.1f %7.1f %7.1f %7.1f %9.1f | %6.3f %3d %2d %3d\n",
                r.i, r.j, 1e3 * r.decode, 1e3 * r.rec_decode, 1e3 * r.map, 1e3 * r.merge,
                1e3 * r.remap, 1e3 * r.fit, 1e3 * r.write, 1e3 * r.total, ratio, r.k, r.f,
                r.iterations);
    char line[512];
    std::snprintf(line, sizeof(line),
                  "%d,%d,%.3f,%.3f,%.3f,%.3f,%.3f,%.3f,%.3f,%.3f,%.4f,%d,%d,%d\n", r.i, r.j,
                  1e3 * r.decode, 1e3 * r.rec_decode, 1e3 * r.map, 1e3 * r.merge, 1e3 * r.remap,
                  1e3 * r.fit, 1e3 * r.write, 1e3 * r.total, ratio, r.k, r.f, r.iterations);
    csv_text += line;
  }
  std::printf(
      "(ms, medians; decode = decoding the position's photos only; map..write = stages of "
      "the full reconstruction, whose own decode is the second column)\n");
  std::printf(
      "median: decode %.1f ms, reconstruct %.1f ms, ratio reconstruct/decode %.3f "
      "(target <= 1.25); 1 + non-decode stages / decode %.3f\n",
      1e3 * Median(decodes), 1e3 * Median(totals), Median(ratios), Median(stage_ratios));
  WriteTextAtomically(csv, csv_text);
  std::printf("csv: %s\n", csv.c_str());
  if (!no_camera) CameraFormats(out_dir, camera_w, camera_h, runs, resolution, formats);
  return 0;
}

}  // namespace
}  // namespace lumislab

int main(int argc, char** argv) {
  return lumislab::RunMain("reconstruct_bench", [&] { return lumislab::RunBench(argc, argv); });
}
