// Rays importance-sampled from sources whose light is known in closed form, as TM-25 ray sets:
// the ray source's tests (tests/lib/synthetic/ray_source_test.cc) and the TM-25 round trip through
// a capture (tests/export/tm25_source_test.cc). Seeded, so every run draws the same rays.
#pragma once

#include <cmath>
#include <cstdint>
#include <random>

#include "lib/photometry/tm25.h"

namespace lumislab::ray_samples {

constexpr double kPiD = 3.14159265358979323846;

// Uniform in [0, 1) from 53 bits of a 64-bit Mersenne twister (the same on every platform).
inline double Uniform(std::mt19937_64& rng) { return double(rng() >> 11) * 0x1.0p-53; }

// A direction with intensity cos^n about +z: cos(theta) = U^(1 / (n + 1)).
inline void CosineLobeDirection(double n, std::mt19937_64& rng, float* k) {
  const double mu = std::pow(1 - Uniform(rng), 1 / (n + 1));
  const double phi = 2 * kPiD * Uniform(rng);
  const double s = std::sqrt(std::max(0.0, 1 - mu * mu));
  k[0] = float(s * std::cos(phi));
  k[1] = float(s * std::sin(phi));
  k[2] = float(mu);
}

// A point emitter at p with I = cos^n (1 W/sr on the axis): total flux 2 pi / (n + 1) W, n_rays
// rays of equal flux.
inline Tm25RaySet PointEmitterRays(double x, double y, double z, double n, int n_rays,
                                   uint64_t seed) {
  Tm25RaySet set;
  set.photometric = false;
  set.creation_method = 0;
  const double flux = 2 * kPiD / (n + 1);
  set.radiant_flux_w = flux;
  set.luminous_flux_lm = std::nan("");
  std::mt19937_64 rng(seed);
  set.rays.resize(n_rays);
  for (Tm25Ray& r : set.rays) {
    r.x = float(x);
    r.y = float(y);
    r.z = float(z);
    CosineLobeDirection(n, rng, &r.kx);
    r.flux = float(flux / n_rays);
  }
  return set;
}

// A Lambertian disc of radius a in the plane z = z0, centred at (x0, y0), facing +z, of radiance
// L (W/m^2/sr): flux pi L pi a^2 (a in mm, 1e-6 m^2/mm^2), origins uniform on the disc,
// directions cosine-weighted.
inline void AddLambertianDisc(double x0, double y0, double z0, double a_mm, double radiance,
                              int n_rays, uint64_t seed, Tm25RaySet* set) {
  set->photometric = false;
  set->creation_method = 0;
  const double flux = kPiD * radiance * kPiD * a_mm * a_mm * 1e-6;
  set->radiant_flux_w = (set->rays.empty() ? 0 : set->radiant_flux_w) + flux;
  set->luminous_flux_lm = std::nan("");
  std::mt19937_64 rng(seed);
  for (int k = 0; k < n_rays; ++k) {
    Tm25Ray r;
    const double rho = a_mm * std::sqrt(Uniform(rng)), phi = 2 * kPiD * Uniform(rng);
    r.x = float(x0 + rho * std::cos(phi));
    r.y = float(y0 + rho * std::sin(phi));
    r.z = float(z0);
    CosineLobeDirection(1, rng, &r.kx);
    r.flux = float(flux / n_rays);
    set->rays.push_back(r);
  }
}

}  // namespace lumislab::ray_samples
