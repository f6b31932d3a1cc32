// ANSI/IES TM-25-13 ray files (docs/formats.md §17 gives the byte layout): a binary header,
// then per ray float32 x y z (mm), kx ky kz (unit direction) and the flagged columns. The
// writer writes rays with position, direction and one flux column (luminous or radiant); the
// reader reads any valid file (every flag, spectral tables, extra columns, text block) and keeps
// position, direction and the luminous flux when the file has it, else the radiant flux.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

namespace lumislab {

struct Tm25Ray {
  float x = 0, y = 0, z = 0;     // mm
  float kx = 0, ky = 0, kz = 1;  // unit direction
  float flux = 0;                // lm or W (RaySet::photometric)
};

struct Tm25RaySet {
  bool photometric = true;  // rays carry luminous flux (lm); else radiant flux (W)
  // Header totals (TM-25 4.7.1.4/5): NaN when the file does not know one.
  double luminous_flux_lm = 0;
  double radiant_flux_w = 0;
  int creation_method = 1;  // 0 simulated, 1 measured
  std::string date_time;    // ISO 8601, at most 28 characters
  // Description block (4.7.3): UTF-32 in the file, UTF-8 here (the writer writes a byte that
  // is not valid UTF-8 as U+FFFD; at most 1000 characters a field).
  std::string name, manufacturer, model_creator, rayfile_creator, equipment, camera,
      light_source_operation, additional_info, data_reference;
  std::vector<Tm25Ray> rays;

  double FluxSum() const;  // sum of the rays' flux
};

// Bytes of the fixed header (file type to the description block): 36288.
constexpr size_t kTm25FixedHeaderBytes = 36288;

// Reads a TM-25 file. Not TM-25, a version other than 2013, flags other than 0/1, a header
// inconsistent with itself, a size that does not match the ray count, a NaN or infinite value,
// a zero direction or a negative flux: BadInput naming the file and the field (or the ray).
Tm25RaySet ReadTm25(const std::string& path);
// Writes position, direction and the flux column (luminous or radiant, by `photometric`),
// little-endian; the header totals as given (NaN allowed: unknown). Atomic.
void WriteTm25(const Tm25RaySet& rays, const std::string& path);

}  // namespace lumislab
