#include "lib/synthetic/render.h"

#include <algorithm>
#include <cmath>

#include "core/parallel.h"
#include "lib/synthetic/board.h"

namespace lumislab {

ScreenView ScreenView::Of(const SynthScene& scene) {
  ScreenView view;
  const PinholeCamera camera(scene.camera);
  view.width = scene.camera.width;
  view.height = scene.camera.height;
  const double half_w = 0.5 * scene.screen_w_mm, half_h = 0.5 * scene.screen_h_mm;
  Eigen::Vector2d xy;
  for (int y = 0; y < view.height; ++y)
    for (int x = 0; x < view.width; ++x)
      if (camera.PlanePoint(x, y, scene.distance_mm, &xy) && std::abs(xy.x()) <= half_w &&
          std::abs(xy.y()) <= half_h) {
        view.pixels.push_back(y * view.width + x);
        view.lab_mm.push_back(xy);
      }
  return view;
}

PlaneLight ScreenLight(const SynthScene& scene, const DualFilter& filter,
                       const Eigen::Vector2d& c) {
  const Eigen::Vector2d half(0.5 * scene.screen_w_mm, 0.5 * scene.screen_h_mm);
  return PlaneLight::ThroughSlides(scene.luminaire, filter, scene.grid.spacing_mm, c,
                                   scene.distance_mm, c - half, c + half);
}

void RenderPosition(const SynthScene& scene, const ScreenView& view, int i, int j,
                    double radiometric_scale, ImageF* plus, ImageF* minus) {
  // Where the stage put the luminaire: the nominal centre plus a listed stage_error's offset.
  const Eigen::Vector2d c = scene.grid.Centre(i, j) + scene.StageOffsetMm(i, j);
  RenderAt(scene, view, c, scene.camera.exposure / radiometric_scale, plus, minus);
}

void RenderAt(const SynthScene& scene, const ScreenView& view, const Eigen::Vector2d& c,
              double gain, ImageF* plus, ImageF* minus) {
  *plus = ImageF(view.width, view.height, 3);
  *minus = ImageF(view.width, view.height, 3);
  const DualFilter filter = scene.Filter();
  const PlaneLight light = ScreenLight(scene, filter, c);
  Eigen::Vector3d e_plus, e_minus;
  for (size_t k = 0; k < view.pixels.size(); ++k) {
    // The luminaire was moved by -c: lab (x, y) is (x, y) + c in the luminaire frame.
    const Eigen::Vector2d st = view.lab_mm[k] + c;
    light.Slides(st.x(), st.y(), &e_plus, &e_minus);
    float* p = &plus->data[size_t(view.pixels[k]) * 3];
    float* n = &minus->data[size_t(view.pixels[k]) * 3];
    for (int ch = 0; ch < 3; ++ch) {
      p[ch] = float(e_plus[ch] * gain);
      n[ch] = float(e_minus[ch] * gain);
    }
  }
}

double MaxSlideIrradiance(const SynthScene& scene, const ScreenView& view, int stride,
                          int threads) {
  const DualFilter filter = scene.Filter();
  std::vector<double> max_of(scene.grid.count(), 0.0);
  ParallelFor(scene.grid.count(), threads, [&](int q) {
    Eigen::Vector3d e_plus, e_minus;
    const Eigen::Vector2d c = scene.grid.Centre(q % scene.grid.nu, q / scene.grid.nu);
    const PlaneLight light = ScreenLight(scene, filter, c);
    for (size_t k = 0; k < view.pixels.size(); k += stride) {
      const Eigen::Vector2d st = view.lab_mm[k] + c;
      light.Slides(st.x(), st.y(), &e_plus, &e_minus);
      max_of[q] = std::max({max_of[q], e_plus.maxCoeff(), e_minus.maxCoeff()});
    }
  });
  return *std::max_element(max_of.begin(), max_of.end());
}

ImageF RenderCalibration(const SynthScene& scene, int threads) {
  const PinholeCamera camera(scene.camera);
  BoardLook look;
  look.screen_half_mm = {0.5 * scene.screen_w_mm, 0.5 * scene.screen_h_mm};
  if (!scene.camera.lens)  // the ideal pinhole, as it always was (the same photo to the bit)
    return RenderBoardPhoto(
        scene.calibration, scene.camera.width, scene.camera.height,
        [&](const Eigen::Vector2d& px, Eigen::Vector2d* lab) {
          return camera.PlanePoint(px.x(), px.y(), scene.distance_mm, lab);
        },
        look, threads);
  const PixelRays rays(camera, threads);
  return RenderBoardPhoto(
      scene.calibration, scene.camera.width, scene.camera.height,
      [&](const Eigen::Vector2d& px, Eigen::Vector2d* lab) {
        return camera.PlanePointOfRay(rays(px.x(), px.y()), scene.distance_mm, lab);
      },
      look, threads);
}

}  // namespace lumislab
