#include "lib/synthetic/board.h"

#include <cmath>

#include "core/parallel.h"

namespace lumislab {

double BoardReflectance(const CalibrationTarget& t, const Eigen::Vector2d& p,
                        const BoardLook& look) {
  if (look.screen_half_mm.x() > 0 &&
      (std::abs(p.x()) > look.screen_half_mm.x() || std::abs(p.y()) > look.screen_half_mm.y()))
    return 0;
  const Eigen::Vector2d q = (p - t.origin_mm) / t.square_mm;  // in squares
  if (q.x() < 0 || q.y() < 0 || q.x() >= t.squares_x || q.y() >= t.squares_y) {
    const int zone = look.quiet_zone_squares;
    if (zone >= 0 && (q.x() < -zone || q.y() < -zone || q.x() > t.squares_x + zone ||
                      q.y() > t.squares_y + zone))
      return look.surround;
    return look.white;
  }
  if (look.dot && (q - Eigen::Vector2d(0.5, 0.5)).norm() <= 0.2) return look.white;
  const int a = int(q.x()), b = int(q.y());
  return (a + b) % 2 == 0 ? look.black : look.white;  // square (0, 0) is black
}

ImageF RenderBoardPhoto(const CalibrationTarget& target, int width, int height,
                        const ScreenOfPixel& screen_of_pixel, const BoardLook& look, int threads) {
  ImageF image(width, height, 1);
  ParallelFor(height, threads, [&](int y) {
    Eigen::Vector2d lab;
    for (int x = 0; x < width; ++x) {
      double sum = 0;
      for (int k = 0; k < kBoardSamples; ++k) {
        const double u = (k + 0.5) / kBoardSamples;
        const double v = ((k * kBoardSampleStride) % kBoardSamples + 0.5) / kBoardSamples;
        if (screen_of_pixel({x - 0.5 + u, y - 0.5 + v}, &lab))
          sum += BoardReflectance(target, lab, look);
      }
      image.at(x, y, 0) = float(sum / kBoardSamples);
    }
  });
  return image;
}

}  // namespace lumislab
