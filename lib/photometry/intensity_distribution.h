// A far-field intensity distribution as the lighting industry's files hold it (docs/formats.md
// §17): type C photometry, intensity on a grid of C planes (azimuth) and gamma angles (polar), in
// candela (photometric) or W/sr (radiometric). gamma = 0 along +z of the luminaire frame, C = 0
// towards +x, C = 90 towards -y (core/geometry.h TypeCDirection). The grid covers only the part of
// the sphere the symmetry leaves (IES LM-63 and EULUMDAT store it the same way); Intensity() and
// TotalFlux() apply the symmetry.
#pragma once

#include <string>
#include <utility>
#include <vector>

namespace lumislab {

// Which part of the C range the planes cover, and what the rest of the sphere is.
enum class CSymmetry {
  kAxial,     // one plane: rotationally symmetric about the gamma = 0 axis
  kQuadrant,  // C 0-90: symmetric about the C0-C180 and the C90-C270 planes
  kC0C180,    // C 0-180: symmetric about the C0-C180 plane (C and 360 - C alike)
  kC90C270,   // C 90-270: symmetric about the C90-C270 plane (C and 180 - C alike)
  kNone,      // C 0-360 (360 repeating 0, or left out: periodic)
};
const char* CSymmetryName(CSymmetry s);

// The luminous opening, mm, in LM-63's convention: length along the C0-C180 axis (x), width
// along the C90-C270 axis (y; C90 towards -y), height along gamma = 0 (z); a negative width/length
// is a round opening of that diameter (LM-63 §"luminous opening"); all 0: a point.
struct LuminousOpening {
  double width_mm = 0;
  double length_mm = 0;
  double height_mm = 0;
};

// The openings both IES and EULUMDAT hold alike (LM-63-2019 §5.10 / Annex D's shapes; EULUMDAT's
// luminous area: length or diameter, width 0 = round, heights): a point (0, 0, height >= 0), a
// rectangle or box (width > 0, length > 0, height >= 0), a circle or vertical cylinder (width =
// length < 0, the diameter, height >= 0). Ellipses, mixed signs, a zero side beside a non-zero one
// (EULUMDAT reads width 0 as round) and a negative height (LM-63's spheres and horizontal
// cylinders) are refused: InputError(where, field, ...), exit 2. The EULUMDAT writer checks its
// opening, and `lumislab-export` checks --opening-mm with it, so an IES and an LDT file describe
// one shape.
void CheckPortableOpening(const LuminousOpening& o, const std::string& where,
                          const std::string& field);

struct IntensityDistribution {
  std::string format;             // "IES LM-63-2002", "EULUMDAT", ... (what it was read as)
  std::vector<double> c_deg;      // strictly increasing, one of CSymmetry's ranges
  std::vector<double> gamma_deg;  // strictly increasing, within [0, 180]
  std::vector<double> values;     // values[ic * gamma_deg.size() + ig]; cd or W/sr, >= 0
  bool photometric = true;        // cd (lm) or W/sr (W)
  LuminousOpening opening;
  // Keywords and other text fields, in file order: IES keywords as the file names them
  // ("TEST", "MANUFAC", ...); EULUMDAT's text lines under the IES name where one exists
  // (company -> "MANUFAC", luminaire name -> "LUMINAIRE", ...), else "_LDT_<FIELD>".
  std::vector<std::pair<std::string, std::string>> keywords;
  double input_watts = 0;  // luminaire input power, W (0: unknown)
  // Read from IES files, not keywords (what `export info` lists as keywords is in the file):
  std::string lamps;                 // line 10: "<number of lamps> x <lm per lamp | absolute ...>"
  std::string file_generation_type;  // LM-63-2002/2019 line 11's second value as written

  double At(size_t ic, size_t ig) const { return values[ic * gamma_deg.size() + ig]; }
  CSymmetry Symmetry() const;
  // Intensity towards (C, gamma) in degrees (any C; gamma in [0, 180]): the symmetry maps C into
  // the stored range, then bilinear in (C, gamma); 0 beyond the stored gamma range.
  double Intensity(double c_deg, double gamma_deg) const;
  // C (degrees, any) mapped by the symmetry into the stored range (the periodic gap of kNone
  // past the last plane left as is): the plane Intensity() reads.
  double StoredC(double c_deg) const;
  // The index of the stored plane that C maps to (StoredC within 1e-6 degrees), or -1.
  int StoredPlane(double c_deg) const;
  // Total flux (lm or W): the zonal sum photometry tools use, I at each grid angle times the
  // solid angle of its cell; cell borders halfway between neighbouring angles, the first and
  // last gamma cells ending at the stored range, C cells spanning the symmetry's range scaled
  // to the whole 360 degrees.
  double TotalFlux() const;
  // Flux within gamma in [0, gamma_max_deg] (the same zonal sum, cells clipped at gamma_max).
  double FluxWithin(double gamma_max_deg) const;
  // The keyword's value, or "" when absent.
  std::string Keyword(const std::string& name) const;
  // BadInput naming `file` when the grid is not a valid type C grid (sizes, order, ranges) or a
  // value is negative or not finite.
  void Check(const std::string& file) const;
};

// Reads an IES LM-63 (.ies) or EULUMDAT (.ldt) file, chosen by its content (an IES file's first
// line starts with "IES" or it has a "TILT=" line; anything else is read as EULUMDAT).
IntensityDistribution ReadIntensityFile(const std::string& path);

}  // namespace lumislab
